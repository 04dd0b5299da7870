//! What the simulated image holds: the share of its water pixels in each 1-m depth bin and on
//! each substrate (dominant, and mean fraction), so that a reproduction can be compared with the
//! paper's scene ("seagrass a substantial share at every depth") and a reader sees what the truth
//! was. Counted over the pixels the instrument saw, at the run's decimation.

use serde::Serialize;

use super::truth::Truth;

/// One 1-m depth bin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DepthBin {
    /// Lower edge, m (the bin is [from, from + 1)).
    pub from_m: f64,
    /// Share of water pixels in it, %.
    pub share_pct: f64,
    /// Share of the bin's pixels whose dominant substrate is each substrate, % (same order as
    /// [`SceneShares::substrates`]).
    pub dominant_pct: Vec<f64>,
}

/// One substrate over the water pixels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubstrateShare {
    /// Name.
    pub name: String,
    /// Mean areal fraction, %.
    pub mean_fraction_pct: f64,
    /// Pixels where it is the largest fraction, %.
    pub dominant_pct: f64,
}

/// The truth's shares over the water pixels of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct SceneShares {
    /// Water pixels seen.
    pub water_pixels: usize,
    /// Depth range of the water pixels, m (`None`: optically deep).
    pub depth_range_m: Option<(f64, f64)>,
    /// 1-m depth bins from the shallowest pixel's floor.
    pub depth_bins: Vec<DepthBin>,
    /// Substrates (empty for a deep scene).
    pub substrates: Vec<SubstrateShare>,
}

impl SceneShares {
    /// Count the shares of `truth` in one pass over its pixels (the radiance stage does it
    /// once per cube; runs that reuse the cube reuse the count).
    #[must_use]
    pub fn of(truth: &Truth) -> Self {
        let surface = &truth.surface;
        let n = surface.codes().len();
        let depth = truth.depth_m.as_ref().and_then(|d| d.as_slice());
        let fractions = truth.substrate_fractions.as_ref().and_then(|f| f.as_slice());
        let n_sub = if fractions.is_some() { truth.substrate_names.len() } else { 0 };
        let water = surface.water_count();
        let mut out = Self { water_pixels: water, ..Self::default() };
        if water == 0 {
            return out;
        }
        let (lo, hi) = depth.map_or((0.0, 0.0), |d| {
            d.iter()
                .enumerate()
                .filter(|(p, _)| surface.is_water_at(*p))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (_, &v)| (a.min(f64::from(v)), b.max(f64::from(v))))
        });
        let first = lo.floor();
        let bins = if depth.is_some() { ((hi - first).floor() as usize + 1).min(1000) } else { 0 };
        let mut bin_count = vec![0usize; bins];
        let mut bin_dominant = vec![vec![0usize; n_sub]; bins];
        let mut fraction_sum = vec![0.0f64; n_sub];
        let mut dominant_count = vec![0usize; n_sub];
        for p in (0..n).filter(|&p| surface.is_water_at(p)) {
            // The largest fraction (the first of equals).
            let dominant = fractions.map(|f| {
                let here = &f[p * n_sub..(p + 1) * n_sub];
                let mut best = 0;
                for (s, &v) in here.iter().enumerate() {
                    fraction_sum[s] += f64::from(v);
                    if v > here[best] {
                        best = s;
                    }
                }
                dominant_count[best] += 1;
                best
            });
            if let Some(d) = depth {
                let b = ((f64::from(d[p]) - first).floor() as usize).min(bins - 1);
                bin_count[b] += 1;
                if let Some(s) = dominant {
                    bin_dominant[b][s] += 1;
                }
            }
        }
        let pct = |k: usize, of: usize| if of == 0 { 0.0 } else { 100.0 * k as f64 / of as f64 };
        out.substrates = (0..n_sub)
            .map(|s| SubstrateShare {
                name: truth.substrate_names[s].clone(),
                mean_fraction_pct: 100.0 * fraction_sum[s] / water as f64,
                dominant_pct: pct(dominant_count[s], water),
            })
            .collect();
        if depth.is_some() {
            out.depth_range_m = Some((lo, hi));
            out.depth_bins = (0..bins)
                .map(|b| DepthBin {
                    from_m: first + b as f64,
                    share_pct: pct(bin_count[b], water),
                    dominant_pct: bin_dominant[b].iter().map(|&k| pct(k, bin_count[b])).collect(),
                })
                .collect();
        }
        out
    }

    /// The shares as lines for a terminal report (empty for a deep scene without substrates).
    #[must_use]
    pub fn table(&self) -> String {
        let mut out = String::new();
        if let Some((lo, hi)) = self.depth_range_m {
            out.push_str(&format!("truth: {} water pixels, depth {lo:.2}–{hi:.2} m\n", self.water_pixels));
        }
        if !self.substrates.is_empty() {
            let names: Vec<String> = self.substrates.iter().map(|s| format!("{:>12}", s.name)).collect();
            out.push_str(&format!("{:<14} {:>7} {}\n", "depth (m)", "water %", names.join(" ")));
            for b in &self.depth_bins {
                let shares: Vec<String> = b.dominant_pct.iter().map(|v| format!("{v:>12.1}")).collect();
                out.push_str(&format!(
                    "{:<14} {:>7.1} {}\n",
                    format!("{:.0}–{:.0}", b.from_m, b.from_m + 1.0),
                    b.share_pct,
                    shares.join(" ")
                ));
            }
            let all: Vec<String> = self.substrates.iter().map(|s| format!("{:>12.1}", s.dominant_pct)).collect();
            out.push_str(&format!("{:<14} {:>7.1} {}\n", "all (dominant)", 100.0, all.join(" ")));
        }
        out
    }
}
