//! A cost row's products against the reference run's, pixel by pixel: the same pixels with the
//! same noise, so the difference is the setting's own error. Only on the same grid; a preview
//! has other pixels and gets none.

use crate::engine::RunOutput;

/// Per-pixel differences from the reference, % (all `None` on another grid, and for products
/// the retrieval does not make).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PerPixel {
    /// Median |chl / reference chl − 1| over pixels both return.
    pub chl_pct: Option<f64>,
    /// Its 95th percentile: an error at edges (the spatial response) or in a few hard pixels
    /// shows here while the median stays at zero.
    pub chl_p95_pct: Option<f64>,
    /// Median |NAP / reference NAP − 1|.
    pub nap_pct: Option<f64>,
    /// Median |CDOM / reference CDOM − 1|.
    pub cdom_pct: Option<f64>,
    /// Median |depth / reference depth − 1| (depth retrievals).
    pub depth_pct: Option<f64>,
    /// Pixels whose dominant bottom type differs from the reference's, % of pixels both
    /// return (retrievals of bottom fractions).
    pub bottom_changed_pct: Option<f64>,
    /// Median |Rrs / reference Rrs − 1| at the band nearest 443 nm over water pixels.
    pub rrs_pct: Option<f64>,
}

/// The `q` quantile of `v`: the element of rank ⌊q·n⌋ (for q = ½ the upper median), `None` if
/// empty.
fn quantile(v: &mut [f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let k = ((v.len() as f64 * q) as usize).min(v.len() - 1);
    Some(*v.select_nth_unstable_by(k, f64::total_cmp).1)
}

fn median_pct(mut v: Vec<f64>) -> Option<f64> {
    quantile(&mut v, 0.5).map(|x| 100.0 * x)
}

impl PerPixel {
    /// The reference against itself: zero for every product `out` makes.
    #[must_use]
    pub fn of_itself(out: &RunOutput) -> Self {
        let product = out.retrievals.first().map(|r| &r.product);
        let has = |yes: bool| yes.then_some(0.0);
        Self {
            chl_pct: has(product.is_some()),
            chl_p95_pct: has(product.is_some()),
            nap_pct: has(product.is_some()),
            cdom_pct: has(product.is_some()),
            depth_pct: has(product.is_some_and(|p| p.depth_m.is_some())),
            bottom_changed_pct: has(product.is_some_and(|p| p.substrate_fractions.is_some())),
            rrs_pct: Some(0.0),
        }
    }

    /// `out`'s first retrieval and Rrs against `reference`'s, when the grids match.
    #[must_use]
    pub fn between(out: &RunOutput, reference: &RunOutput) -> Self {
        let (Some(a), Some(b)) = (out.retrievals.first(), reference.retrievals.first()) else { return Self::default() };
        let (a, b) = (&a.product, &b.product);
        // The Rrs is compared where both runs kept their cubes (the engine of the cost table does).
        let rrs_cubes = out.cubes.as_ref().zip(reference.cubes.as_ref()).map(|(x, y)| (&x.rrs.rrs, &y.rrs.rrs));
        if a.flags.dim() != b.flags.dim() || rrs_cubes.is_some_and(|(x, y)| x.dim() != y.dim()) {
            return Self::default();
        }
        let (rows, cols) = a.flags.dim();
        // A variable either product lacks (an external retrieval's choice) is not compared.
        let pairs = |v: &str| a.map(v).zip(b.map(v));
        let (chl_maps, nap_maps, cdom_maps) = (pairs("chl_mg_m3"), pairs("nap_g_m3"), pairs("cdom_per_m"));
        let (mut chl, mut nap, mut cdom, mut depth, mut rrs) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut bottom_changed, mut bottom_pixels) = (0usize, 0usize);
        let relative = |v: &mut Vec<f64>, x: f32, y: f32| {
            let (x, y) = (f64::from(x), f64::from(y));
            if y > 0.0 && x.is_finite() {
                v.push((x / y - 1.0).abs());
            }
        };
        let depths = a.depth_m.as_ref().zip(b.depth_m.as_ref());
        let bottoms = a.substrate_fractions.as_ref().zip(b.substrate_fractions.as_ref());
        let band = out
            .response
            .bands
            .bands
            .iter()
            .enumerate()
            .min_by(|x, y| (x.1.centre_nm - 443.0).abs().total_cmp(&(y.1.centre_nm - 443.0).abs()))
            .map_or(0, |(i, _)| i);
        for r in 0..rows {
            for c in 0..cols {
                if a.returned(r, c) && b.returned(r, c) {
                    for (v, maps) in [(&mut chl, chl_maps), (&mut nap, nap_maps), (&mut cdom, cdom_maps)] {
                        if let Some((ma, mb)) = maps {
                            relative(v, ma[[r, c]], mb[[r, c]]);
                        }
                    }
                    if let Some((da, db)) = depths {
                        relative(&mut depth, da[[r, c]], db[[r, c]]);
                    }
                    if let Some((fa, fb)) = bottoms {
                        let n = a.substrate_names.len().min(b.substrate_names.len());
                        let dominant = |f| crate::retrieval::dominant(f, n, r, c);
                        bottom_pixels += 1;
                        bottom_changed += usize::from(dominant(fa) != dominant(fb));
                    }
                }
                if let Some((x, y)) = rrs_cubes.filter(|_| out.truth.surface.is_water(r, c)) {
                    let (x, y) = (f64::from(x[[r, c, band]]), f64::from(y[[r, c, band]]));
                    if y.abs() > 1e-6 {
                        rrs.push((x / y - 1.0).abs());
                    }
                }
            }
        }
        Self {
            chl_p95_pct: quantile(&mut chl, 0.95).map(|x| 100.0 * x),
            chl_pct: median_pct(chl),
            nap_pct: median_pct(nap),
            cdom_pct: median_pct(cdom),
            depth_pct: median_pct(depth),
            bottom_changed_pct: (bottom_pixels > 0).then(|| 100.0 * bottom_changed as f64 / bottom_pixels as f64),
            rrs_pct: median_pct(rrs),
        }
    }
}
