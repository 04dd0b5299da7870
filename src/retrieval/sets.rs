//! The eight built-in aLMI SIOP sets and how they are made.
//!
//! The paper gave aLMI "eight averaged SIOP sets that capture the range of variability in NAP and
//! CDOM based on in situ measurements at Lake Hume" (Matthews et al. 2023, §2.2.4). Lake Hume's
//! measurements are not public. Shoal builds its sets the same way from the public SAMBUCA
//! station table (`assets/phytoplankton/sambuca_SIOPMatrix.csv`: Great Barrier Reef, Tasmania and
//! Wallis Lake cruises): stations with all of a*_NAP(440), S_NAP, bb*_NAP(555), the bb_NAP
//! spectral exponent and S_CDOM inside physical ranges are standardised on
//! (ln a*_NAP(440), S_NAP, ln bb*_NAP(555), n_bbNAP, S_CDOM) and clustered by k-means (k = 8,
//! k-means++ seeding, 20 seeded restarts, lowest within-cluster sum of squares). Each set holds
//! its cluster's geometric-mean a*_NAP(440) and bb*_NAP(555) and mean slopes; phytoplankton and
//! water are those of the reservoir scene (`cyanobacteria_reservoir`), since the paper's sets
//! vary only NAP and CDOM. `shoal dev almi-sets DIR` regenerates the files in `presets/siop/`.
//!
//! ## References
//! - Matthews, M. W. et al. (2023) Sensors 23, 7824, §2.2.4.
//! - Arthur, D. & Vassilvitskii, S. (2007) k-means++: the advantages of careful seeding. Proc.
//!   18th ACM-SIAM SODA, 1027–1035.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use super::RetrievalError;
use crate::parse::FieldError;
use crate::spectral::Table;
use crate::water::SiopSource;

/// Names of the built-in aLMI sets.
pub const ALMI_SETS: [&str; 8] = ["almi_1", "almi_2", "almi_3", "almi_4", "almi_5", "almi_6", "almi_7", "almi_8"];

/// The eight built-in sets as SIOP sources.
#[must_use]
pub fn default_almi_sets() -> Vec<SiopSource> {
    ALMI_SETS.iter().map(|n| SiopSource::Preset((*n).to_string())).collect()
}

/// One cluster's SIOP parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterSiop {
    /// Stations in the cluster.
    pub stations: usize,
    /// a*_NAP(440), m² g⁻¹ (geometric mean).
    pub a_nap_440: f64,
    /// NAP absorption slope, nm⁻¹.
    pub s_nap: f64,
    /// bb*_NAP(555), m² g⁻¹ (geometric mean).
    pub bb_nap_555: f64,
    /// bb_NAP spectral exponent.
    pub n_bb_nap: f64,
    /// CDOM absorption slope, nm⁻¹.
    pub s_cdom: f64,
}

/// The station features (ln a*_NAP, S_NAP, ln bb*_NAP, n_bb, S_CDOM) of the physically valid rows.
pub fn station_features() -> Result<Vec<[f64; 5]>, RetrievalError> {
    let t = Table::from_asset("phytoplankton/sambuca_SIOPMatrix.csv")?;
    let col = |name: &str| t.column_f64(name);
    let (anap, snap, bbnap, nbb, scdom) = (
        col("A_NAP_STAR_440NM")?,
        col("A_NAP_SLOPE")?,
        col("BB_NAP_STAR_555NM")?,
        col("BB_NAP_SLOPE")?,
        col("A_CDOM_SLOPE")?,
    );
    Ok((0..anap.len())
        .filter(|&i| {
            (0.001..=0.2).contains(&anap[i])
                && (-0.02..=-0.005).contains(&snap[i])
                && (0.0005..=0.05).contains(&bbnap[i])
                && (0.0..=3.0).contains(&nbb[i])
                && (-0.03..=-0.005).contains(&scdom[i])
        })
        .map(|i| [anap[i].ln(), -snap[i], bbnap[i].ln(), nbb[i], -scdom[i]])
        .collect())
}

/// k-means of `points` into `k` clusters (k-means++ seeding, `restarts` seeded restarts).
#[must_use]
pub fn kmeans(points: &[[f64; 5]], k: usize, restarts: usize, seed: u64) -> Vec<usize> {
    let n = points.len();
    let dist = |a: &[f64; 5], b: &[f64; 5]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
    let mut best: (f64, Vec<usize>) = (f64::INFINITY, vec![0; n]);
    for restart in 0..restarts {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed.wrapping_add(restart as u64));
        let mut centres: Vec<[f64; 5]> = vec![points[rng.random_range(0..n)]];
        while centres.len() < k {
            let d: Vec<f64> =
                points.iter().map(|p| centres.iter().map(|c| dist(p, c)).fold(f64::INFINITY, f64::min)).collect();
            let total: f64 = d.iter().sum();
            let mut pick = rng.random::<f64>() * total;
            let mut chosen = n - 1;
            for (i, v) in d.iter().enumerate() {
                if pick < *v {
                    chosen = i;
                    break;
                }
                pick -= v;
            }
            centres.push(points[chosen]);
        }
        let mut labels = vec![0; n];
        for _ in 0..200 {
            let new: Vec<usize> = points
                .iter()
                .map(|p| (0..k).min_by(|&a, &b| dist(p, &centres[a]).total_cmp(&dist(p, &centres[b]))).unwrap_or(0))
                .collect();
            let changed = new != labels;
            labels = new;
            for (c, centre) in centres.iter_mut().enumerate() {
                let members: Vec<&[f64; 5]> =
                    points.iter().zip(&labels).filter(|(_, l)| **l == c).map(|(p, _)| p).collect();
                if !members.is_empty() {
                    for d in 0..5 {
                        centre[d] = members.iter().map(|m| m[d]).sum::<f64>() / members.len() as f64;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        let inertia: f64 = points.iter().zip(&labels).map(|(p, &l)| dist(p, &centres[l])).sum();
        if inertia < best.0 {
            best = (inertia, labels);
        }
    }
    best.1
}

/// The eight clusters' SIOPs, ordered by a*_NAP(440).
pub fn almi_clusters() -> Result<Vec<ClusterSiop>, RetrievalError> {
    let raw = station_features()?;
    if raw.len() < 8 {
        return Err(RetrievalError::Invalid(FieldError {
            field: "SIOP table".into(),
            message: format!("only {} valid stations", raw.len()),
        }));
    }
    // Standardise each feature so none dominates the distance.
    let mut mean = [0.0; 5];
    let mut std = [0.0; 5];
    for d in 0..5 {
        mean[d] = raw.iter().map(|p| p[d]).sum::<f64>() / raw.len() as f64;
        std[d] = (raw.iter().map(|p| (p[d] - mean[d]).powi(2)).sum::<f64>() / raw.len() as f64).sqrt().max(1e-12);
    }
    let z: Vec<[f64; 5]> = raw.iter().map(|p| std::array::from_fn(|d| (p[d] - mean[d]) / std[d])).collect();
    let labels = kmeans(&z, 8, 20, 2023);
    let mut clusters: Vec<ClusterSiop> = (0..8)
        .map(|c| {
            let m: Vec<&[f64; 5]> = raw.iter().zip(&labels).filter(|(_, l)| **l == c).map(|(p, _)| p).collect();
            let avg = |d: usize| m.iter().map(|p| p[d]).sum::<f64>() / m.len().max(1) as f64;
            ClusterSiop {
                stations: m.len(),
                a_nap_440: avg(0).exp(),
                s_nap: avg(1),
                bb_nap_555: avg(2).exp(),
                n_bb_nap: avg(3),
                s_cdom: avg(4),
            }
        })
        .collect();
    clusters.sort_by(|a, b| a.a_nap_440.total_cmp(&b.a_nap_440));
    Ok(clusters)
}

/// The RON text of set `index` (0-based) from `cluster`.
#[must_use]
pub fn set_ron(index: usize, cluster: &ClusterSiop, total_stations: usize) -> String {
    format!(
        "// aLMI SIOP set {n} of 8, generated by `shoal dev almi-sets` (see src/retrieval/sets.rs): the NAP and\n\
         // CDOM SIOPs of k-means cluster {n} ({s} of {total_stations} stations) of the SAMBUCA station table\n\
         // (assets/phytoplankton/sambuca_SIOPMatrix.csv; CSIRO), with the phytoplankton and fresh water of\n\
         // the `cyanobacteria_reservoir` set. CDOM at 440 nm.\n\
         SiopSpec(\n    name: \"almi_{n}\",\n    description: \"aLMI set {n}/8: a*_NAP(440) {a:.4} m2/g, S_NAP {sn:.5}, bb*_NAP(555) {b:.5} m2/g, n {nb:.3}, S_CDOM {sc:.5}\",\n    \
         water_absorption: Asset(file: \"water/water_absorption_wasi6.csv\", column: \"a_w_per_m\"),\n    \
         water_backscatter: Asset(file: \"water/water_scattering_pure.csv\", column: \"bb_w_S0\"),\n    \
         phytoplankton_absorption: Asset(file: \"phytoplankton/aph_specific_wasi6_classes.csv\", column: \"cyanobacteria\", outside: Zero),\n    \
         phytoplankton_backscatter: Asset(file: \"phytoplankton/bbph_norm_wasi6.csv\", column: \"bb_phy_norm\", scale: 0.001, outside: Clamp),\n    \
         cdom_absorption: Exponential(coefficient: 1.0, reference_nm: 440.0, slope_per_nm: {sc:.6}),\n    \
         nap_absorption: Exponential(coefficient: {a:.6}, reference_nm: 440.0, slope_per_nm: {sn:.6}),\n    \
         nap_backscatter: PowerLaw(coefficient: {b:.6}, reference_nm: 555.0, exponent: {nb:.4}),\n    \
         water_refractive_index: 1.34,\n)\n",
        n = index + 1,
        s = cluster.stations,
        a = cluster.a_nap_440,
        sn = cluster.s_nap,
        b = cluster.bb_nap_555,
        nb = cluster.n_bb_nap,
        sc = cluster.s_cdom,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_committed_sets_are_what_the_generator_makes() {
        let clusters = almi_clusters().unwrap();
        let total: usize = clusters.iter().map(|c| c.stations).sum();
        assert!(total > 100, "{total} stations");
        for (i, c) in clusters.iter().enumerate() {
            let path = format!("siop/{}.ron", ALMI_SETS[i]);
            let committed = crate::assets::preset(&path).map(|a| a.text).unwrap_or_default();
            assert_eq!(committed, set_ron(i, c, total), "{path} is stale: run `shoal dev almi-sets presets/siop`");
            assert!(crate::water::SiopSpec::preset(ALMI_SETS[i]).is_ok());
        }
    }
}
