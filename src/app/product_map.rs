//! What a map panel shows of a run: a product's values (or its truth) and where they are valid,
//! the difference and class agreement of two designs on the first one's pixels, and the
//! substrate classes of the legend. Colour mapping and the raster thread are in `raster.rs`.

use ndarray::Array2;

use super::model::ProductKind;
use crate::engine::{RunOutput, ViewOf};
use crate::instrument::{Detector, DetectorMode};

/// A map's values and where they are valid.
#[derive(Debug, Clone, PartialEq)]
pub struct MapData {
    /// Values (row, column).
    pub values: Array2<f32>,
    /// Valid pixels.
    pub valid: Array2<bool>,
}

/// The product `kind` (band `band`) of `out`; `truth` takes the scene's truth instead of the
/// retrieval where there is one. `None` when the run has no such product.
#[must_use]
pub fn product_map(out: &RunOutput, kind: ProductKind, band: usize, truth: bool) -> Option<MapData> {
    let truth_maps = &out.truth;
    let water = truth_maps.surface.water_mask();
    let ret = out.retrievals.first();
    let returned = |p: &crate::retrieval::Product| Array2::from_shape_fn(p.flags.dim(), |(i, j)| p.returned(i, j));
    let product_or_truth =
        |t: &Array2<f32>, pick: fn(&crate::retrieval::Product) -> Option<&Array2<f32>>| -> Option<MapData> {
            if truth {
                return Some(MapData { values: t.clone(), valid: water.clone() });
            }
            let p = &ret?.product;
            let map = pick(p)?;
            let ok = returned(p);
            Some(MapData {
                valid: Array2::from_shape_fn(map.dim(), |(i, j)| ok[[i, j]] && map[[i, j]] > 0.0),
                values: map.clone(),
            })
        };
    let nb = out.report.shape.2;
    let band = band.min(nb.saturating_sub(1));
    match kind {
        ProductKind::Chl => product_or_truth(&truth_maps.chl_mg_m3, |p| p.chl_mg_m3.as_ref()),
        ProductKind::Nap => product_or_truth(&truth_maps.nap_g_m3, |p| p.nap_g_m3.as_ref()),
        ProductKind::Cdom => product_or_truth(&truth_maps.cdom_per_m, |p| p.cdom_per_m.as_ref()),
        ProductKind::Depth => product_or_truth(truth_maps.depth_m.as_ref()?, |p| p.depth_m.as_ref()),
        ProductKind::Extra(_) => {
            // A retrieval's own product; its truth where the retrieval says what it is.
            let key = kind.variable()?;
            let ret = ret?;
            let values = if truth { out.truth_map(key)? } else { ret.product.map(key)? };
            let ok = if truth { water } else { returned(&ret.product) };
            let valid = Array2::from_shape_fn(values.dim(), |(i, j)| ok[[i, j]] && values[[i, j]] > 0.0);
            Some(MapData { values: values.clone(), valid })
        }
        ProductKind::Substrate => {
            let (f, names) = if truth {
                (truth_maps.substrate_fractions.as_ref()?, &truth_maps.substrate_names)
            } else {
                let p = &ret?.product;
                (p.substrate_fractions.as_ref()?, &p.substrate_names)
            };
            // The truth and the retrieval may list substrates in different orders: every map is
            // coloured by its class's place in one list (`substrate_classes`), so one colour is
            // one substrate in every panel and in the legend.
            let class_of = class_indices(names, &substrate_classes(out));
            let dominant = Array2::from_shape_fn((f.dim().0, f.dim().1), |(i, j)| {
                let k = (0..f.dim().2).max_by(|&a, &b| f[[i, j, a]].total_cmp(&f[[i, j, b]])).unwrap_or(0);
                class_of.get(k).copied().unwrap_or(0.0)
            });
            let valid = if truth { water } else { returned(&ret?.product) };
            Some(MapData { values: dominant, valid })
        }
        ProductKind::SiopSet => {
            if truth {
                return None;
            }
            let p = &ret?.product;
            let s = p.siop_set.as_ref()?;
            Some(MapData {
                values: s.mapv(f32::from),
                valid: Array2::from_shape_fn(s.dim(), |(i, j)| s[[i, j]] >= 0 && p.returned(i, j)),
            })
        }
        ProductKind::Rrs => {
            let (values, flags) = cube_band(out, if truth { ViewOf::TruthRrs } else { ViewOf::Rrs }, band)?;
            let valid = Array2::from_shape_fn(values.dim(), |(i, j)| water[[i, j]] && (truth || flags[[i, j]] == 0));
            Some(MapData { values, valid })
        }
        ProductKind::Level1 => {
            let (values, _) = cube_band(out, if truth { ViewOf::Toa } else { ViewOf::Level1 }, band)?;
            Some(MapData { valid: values.mapv(|v| v.is_finite() && v > 0.0), values })
        }
        ProductKind::Snr => {
            // Analytic SNR at each pixel's own radiance (detector noise model, noise on).
            let detector =
                Detector::new(&out.config.instrument, &out.response, DetectorMode::default(), out.config.seed);
            let (l, _) = cube_band(out, ViewOf::Toa, band)?;
            let values = Array2::from_shape_fn(l.dim(), |(i, j)| {
                let d = out.viewing.detector_index[j];
                crate::instrument::analytic_snr(&detector, d, band, f64::from(l[[i, j]])) as f32
            });
            Some(MapData { valid: values.mapv(|v| v.is_finite() && v > 0.0), values })
        }
    }
}

/// Band `band` of one of a run's cubes at full resolution and its flags (zero for the truth and
/// the pupil radiance): from the cubes when the run kept them, else from its views, each kept
/// pixel standing for its block ([`crate::engine::CubeViews`]).
fn cube_band(out: &RunOutput, of: ViewOf, band: usize) -> Option<(Array2<f32>, Array2<u8>)> {
    let Some(cubes) = out.cubes.as_ref() else { return out.views.as_ref()?.band(of, band) };
    let (cube, flags) = match of {
        ViewOf::Toa => (&cubes.radiance.radiance, None),
        ViewOf::TruthRrs => (&*cubes.radiance.truth_rrs, None),
        ViewOf::Level1 => (&cubes.level1.radiance, Some(&cubes.level1.flags)),
        ViewOf::Rrs => (&cubes.rrs.rrs, Some(&cubes.rrs.flags)),
    };
    let values = cube.index_axis(ndarray::Axis(2), band).to_owned();
    let flags = flags.map_or_else(|| Array2::zeros(values.dim()), |f| f.index_axis(ndarray::Axis(2), band).to_owned());
    Some((values, flags))
}

/// A − B on A's pixels (A and B any two designs): B is sampled at the pixel nearest each of A's
/// ground points.
#[must_use]
pub fn difference(a: &MapData, a_out: &RunOutput, b: &MapData, b_out: &RunOutput) -> MapData {
    let (rows, cols) = a.values.dim();
    let mut values = Array2::zeros((rows, cols));
    let mut valid = Array2::from_elem((rows, cols), false);
    for r in 0..rows {
        for c in 0..cols {
            let (x, y) = a_out.viewing.ground_m(0, r, c);
            if let Some((rb, cb)) = b_out.viewing.nearest_pixel(x, y, b_out.config.instrument.heading_deg)
                && rb < b.values.dim().0
                && cb < b.values.dim().1
                && a.valid[[r, c]]
                && b.valid[[rb, cb]]
            {
                values[[r, c]] = a.values[[r, c]] - b.values[[rb, cb]];
                valid[[r, c]] = true;
            }
        }
    }
    MapData { values, valid }
}

/// The substrate classes of a run's maps, in legend order: the scene's substrates, then any the
/// retrieval unmixes that the scene does not have.
#[must_use]
pub fn substrate_classes(out: &RunOutput) -> Vec<String> {
    let mut classes = out.truth.substrate_names.clone();
    for r in &out.retrievals {
        for n in &r.product.substrate_names {
            if !classes.contains(n) {
                classes.push(n.clone());
            }
        }
    }
    classes
}

/// The legend position of each of `names` in `classes` (past the end when absent).
#[must_use]
pub fn class_indices(names: &[String], classes: &[String]) -> Vec<f32> {
    names.iter().map(|n| classes.iter().position(|c| c == n).unwrap_or(classes.len()) as f32).collect()
}

/// Where two class maps agree (0) or not (1), A's pixels against B's nearest ground point.
#[must_use]
pub fn agreement(a: &MapData, a_out: &RunOutput, b: &MapData, b_out: &RunOutput) -> MapData {
    let mut d = difference(a, a_out, b, b_out);
    d.values.mapv_inplace(|v| if v == 0.0 { 0.0 } else { 1.0 });
    d
}
