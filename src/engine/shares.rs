//! What the simulated image holds: the share of its water pixels in each 1-m depth bin and on
//! each substrate (dominant, and mean fraction), so that a reproduction can be compared with the
//! paper's scene ("seagrass a substantial share at every depth") and a reader sees what the truth
//! was. Counted over the pixels the instrument saw, at the run's decimation.

use serde::Serialize;

use crate::instrument::RadianceCube;

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
    /// Count the shares of `cube`'s truth.
    #[must_use]
    pub fn of(cube: &RadianceCube) -> Self {
        let water: Vec<(usize, usize)> = cube.land.indexed_iter().filter(|(_, l)| **l == 0).map(|(rc, _)| rc).collect();
        let n = water.len();
        let mut out = Self { water_pixels: n, ..Self::default() };
        if n == 0 {
            return out;
        }
        let pct = |k: usize, of: usize| if of == 0 { 0.0 } else { 100.0 * k as f64 / of as f64 };
        let dominant = |r: usize, c: usize| -> Option<usize> {
            let f = cube.substrate_fractions.as_ref()?;
            (0..f.dim().2).max_by(|&a, &b| f[[r, c, a]].total_cmp(&f[[r, c, b]]))
        };
        let n_sub = cube.substrate_names.len();
        if let Some(f) = &cube.substrate_fractions {
            for (s, name) in cube.substrate_names.iter().enumerate() {
                let mean = water.iter().map(|&(r, c)| f64::from(f[[r, c, s]])).sum::<f64>() / n as f64;
                let dom = water.iter().filter(|&&(r, c)| dominant(r, c) == Some(s)).count();
                out.substrates.push(SubstrateShare {
                    name: name.clone(),
                    mean_fraction_pct: 100.0 * mean,
                    dominant_pct: pct(dom, n),
                });
            }
        }
        if let Some(depth) = &cube.depth_m {
            let d: Vec<f64> = water.iter().map(|&(r, c)| f64::from(depth[[r, c]])).collect();
            let (lo, hi) = d.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
            out.depth_range_m = Some((lo, hi));
            let first = lo.floor();
            let bins = ((hi - first).floor() as usize + 1).min(1000);
            let mut counts = vec![0usize; bins];
            let mut dom = vec![vec![0usize; n_sub]; bins];
            for (i, &(r, c)) in water.iter().enumerate() {
                let b = ((d[i] - first).floor() as usize).min(bins - 1);
                counts[b] += 1;
                if let Some(s) = dominant(r, c) {
                    dom[b][s] += 1;
                }
            }
            out.depth_bins = (0..bins)
                .map(|b| DepthBin {
                    from_m: first + b as f64,
                    share_pct: pct(counts[b], n),
                    dominant_pct: dom[b].iter().map(|&k| pct(k, counts[b])).collect(),
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
