//! The run report: what ran, what came from the cache, what was skipped, and how long it took.

use serde::Serialize;

use super::Stage;
use crate::correction::{BandDifference, SceneApproximation};

/// What happened to a stage in a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StageStatus {
    /// Computed in this run.
    Ran,
    /// Reused from an earlier run (its inputs had not changed).
    Cached,
}

/// One stage of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageReport {
    /// The stage.
    pub stage: Stage,
    /// Ran or cached.
    pub status: StageStatus,
    /// Wall time, s (0 when cached).
    pub seconds: f64,
}

/// An effect and why it was not computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkippedEffect {
    /// The effect.
    pub effect: crate::scene::Effect,
    /// Why.
    pub reason: String,
}

/// JSON has no NaN (serde_json writes `null`): read `null` back as NaN, so a summary with a
/// missing value (no aerosol in the scene, no pixel retrieved) round-trips through `review.json`.
fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(<Option<f64> as serde::Deserialize>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// [`nan_if_null`] for a (median, 5th, 95th percentile) triple.
fn nan_triple_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<(f64, f64, f64), D::Error> {
    let (a, b, c) = <(Option<f64>, Option<f64>, Option<f64>) as serde::Deserialize>::deserialize(d)?;
    let nan = |v: Option<f64>| v.unwrap_or(f64::NAN);
    Ok((nan(a), nan(b), nan(c)))
}

/// The image-based correction's aerosol against the scene's true aerosol.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize, Default)]
pub struct AerosolSummary {
    /// Retrieved AOT(550) over the water pixels: median, 5th and 95th percentiles.
    #[serde(deserialize_with = "nan_triple_if_null")]
    pub aot550: (f64, f64, f64),
    /// The scene's AOT(550): the atmosphere's, or the median of its map over the water pixels.
    #[serde(deserialize_with = "nan_if_null")]
    pub aot550_true: f64,
    /// Median over the water pixels of |retrieved − true AOT(550)|, each pixel against the
    /// AOT under it.
    #[serde(deserialize_with = "nan_if_null")]
    pub aot550_abs_error: f64,
    /// Retrieved Ångström exponent (443–865 nm), median over the water pixels.
    #[serde(deserialize_with = "nan_if_null")]
    pub angstrom: f64,
    /// The scene's aerosol model's Ångström exponent (443–865 nm).
    #[serde(deserialize_with = "nan_if_null")]
    pub angstrom_true: f64,
    /// Share of retrieved pixels whose measured ε lay outside the family's range, %.
    #[serde(deserialize_with = "nan_if_null")]
    pub outside_family_pct: f64,
    /// Mean passes of the NIR water-leaving iteration (1 without it).
    #[serde(deserialize_with = "nan_if_null")]
    pub passes_mean: f64,
    /// What the correction did, in words (its fit; for dark-spectrum fitting the models the
    /// tiles chose).
    pub fit: String,
    /// The band-pair fit: the measured ε at the pair (the ratio of the aerosol radiances at its
    /// short and long band, as the fit forms it) over the retrieved pixels, median, 5th and 95th
    /// percentiles (NaN for dark-spectrum fitting).
    #[serde(default = "nan_triple", deserialize_with = "nan_triple_if_null")]
    pub epsilon: (f64, f64, f64),
    /// The band-pair fit: each member's ε at the pair as the fit places the median pixel's
    /// measured ε among them (each model at the AOT that gives that pixel's long-band signal, at
    /// the centre column). Two members closer than the measured ε's spread cannot be told apart.
    #[serde(default)]
    pub members_epsilon: Vec<(String, f64)>,
}

fn nan_triple() -> (f64, f64, f64) {
    (f64::NAN, f64::NAN, f64::NAN)
}

impl AerosolSummary {
    /// The measured ε against the members', in words ("" without a band-pair fit).
    #[must_use]
    pub fn epsilon_words(&self) -> String {
        if self.members_epsilon.is_empty() || !self.epsilon.0.is_finite() {
            return String::new();
        }
        let members: Vec<String> = self.members_epsilon.iter().map(|(m, e)| format!("{m} {e:.4}")).collect();
        format!(
            "ε at the pair {:.4} (5–95 %: {:.4}–{:.4}) against the members' {}",
            self.epsilon.0,
            self.epsilon.1,
            self.epsilon.2,
            members.join(", ")
        )
    }
}

/// Water pixels the exact correction left out for high glint (its `glint_threshold_per_sr`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HighGlint {
    /// Water pixels left out.
    pub pixels: usize,
    /// Water pixels corrected (left out or not).
    pub water_pixels: usize,
    /// The threshold, sr⁻¹.
    pub threshold_per_sr: f64,
    /// The wind the processor assumed, m/s.
    pub assumed_wind_m_s: f64,
}

/// The report of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct RunReport {
    /// Scene and instrument names.
    pub scene: String,
    /// Instrument name.
    pub instrument: String,
    /// Image size simulated: rows, columns, bands.
    pub shape: (usize, usize, usize),
    /// Decimation factor.
    pub decimation: usize,
    /// Rows and columns not simulated because they look beyond the scene.
    pub cropped: (usize, usize),
    /// Stages in chain order.
    pub stages: Vec<StageReport>,
    /// Effects the scene did not ask for (never computed).
    pub skipped_effects: Vec<SkippedEffect>,
    /// Simulation-grid wavelengths per geometry group.
    pub grid_points: Vec<usize>,
    /// Water-model evaluations in the radiance stage (0 when cached).
    pub water_evaluations: u64,
    /// Of which with the bottom term.
    pub bottom_evaluations: u64,
    /// Spatial-response quadrature points per pixel.
    pub spatial_samples: usize,
    /// Level-0 pixel-bands flagged saturated.
    pub saturated: usize,
    /// Level-0 pixel-bands at zero counts.
    pub zero_counts: usize,
    /// What on-board compression did to Level-0 (`None`: not compressed).
    pub compression: Option<crate::instrument::compression::CompressionReport>,
    /// Sun incidence on the calibration diffuser, degrees.
    pub diffuser_incidence_deg: f64,
    /// Calibration frames that saturated.
    pub diffuser_saturated_frames: usize,
    /// The paper's per-scene approximation terms (none when the image holds no water).
    pub approximation: Option<SceneApproximation>,
    /// Per band: the per-scene approximation against the exact correction (same Level-1).
    pub approximation_vs_exact: Vec<BandDifference>,
    /// Per band: the delivered Rrs against the true band Rrs, over every ⌊N/200 000⌋-th of the
    /// image's N pixels ([`crate::correction::compare_with_truth`]).
    pub rrs_vs_truth: Vec<BandDifference>,
    /// What the image-based correction retrieved of the aerosol, against the scene's.
    pub aerosol: Option<AerosolSummary>,
    /// The exact correction's high-glint mask, where it has a threshold and the scene glints.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact_high_glint: Option<HighGlint>,
    /// Line period and exposure, s.
    pub line_period_s: f64,
    /// The truth's depth and substrate shares over the water pixels seen.
    pub truth_shares: crate::instrument::shares::SceneShares,
    /// Plausibility warnings: saturation at the brightest water radiance, smear, f-number.
    pub warnings: Vec<crate::instrument::plausibility::Warning>,
    /// Total wall time, s.
    pub total_seconds: f64,
}

impl RunReport {
    /// Seconds spent in `stage` (0 when cached or absent).
    #[must_use]
    pub fn seconds(&self, stage: Stage) -> f64 {
        self.stages.iter().filter(|s| s.stage == stage).map(|s| s.seconds).sum()
    }

    /// Did `stage` run (rather than come from the cache)?
    #[must_use]
    pub fn ran(&self, stage: Stage) -> bool {
        self.stages.iter().any(|s| s.stage == stage && s.status == StageStatus::Ran)
    }

    /// A plain-text table of the stages.
    #[must_use]
    pub fn table(&self) -> String {
        let mut out = String::from("stage               status    seconds\n");
        for s in &self.stages {
            let status = match s.status {
                StageStatus::Ran => "ran",
                StageStatus::Cached => "cached",
            };
            out.push_str(&format!("{:<19} {:<9} {:>8.3}\n", s.stage.to_string(), status, s.seconds));
        }
        for e in &self.skipped_effects {
            out.push_str(&format!("{:<19} skipped   ({})\n", format!("{:?}", e.effect), e.reason));
        }
        out.push_str(&format!("{:<19} {:<9} {:>8.3}\n", "total", "", self.total_seconds));
        out
    }
}

/// The retrieved aerosol's percentiles against the scene's (its model's Ångström exponent from
/// its own optics; NaN where the scene has no aerosol).
pub(super) fn aerosol_summary(
    a: &crate::correction::AerosolRetrieval,
    settings: &crate::correction::ImageCorrection,
    truth: &crate::atmosphere::AtmosphereSpec,
    truth_aot: Option<&ndarray::Array2<f32>>,
    centres_nm: &[f64],
) -> AerosolSummary {
    // Quantiles by selection, not sorting: four sorts of a million pixels each took ~0.4 s of one
    // core per run, while the other core waited. The four selections (and the reading of the
    // maps they select from) run side by side.
    let q = |v: &mut [f64], p: f64| crate::metrics::nearest_rank(v, p);
    // Retrieved pixels (land is NaN in the retrieval) against the AOT under each.
    let true_at = |i: usize| truth_aot.and_then(|m| m.as_slice()).map_or(truth.aot550, |m| f64::from(m[i]));
    let retrieved = || a.aot550.iter().enumerate().filter(|(_, v)| v.is_finite());
    let (((aot550, retrieved_n), aot550_true), (aot550_abs_error, (angstrom, angstrom_true))) = rayon::join(
        || {
            rayon::join(
                || {
                    let mut aot: Vec<f64> = a.aot550.iter().filter(|v| v.is_finite()).map(|&v| f64::from(v)).collect();
                    ((q(&mut aot, 0.5), q(&mut aot, 0.05), q(&mut aot, 0.95)), aot.len())
                },
                || {
                    if truth_aot.is_some() {
                        q(&mut retrieved().map(|(i, _)| true_at(i)).collect::<Vec<f64>>(), 0.5)
                    } else {
                        truth.aot550
                    }
                },
            )
        },
        || {
            rayon::join(
                || q(&mut retrieved().map(|(i, v)| (f64::from(*v) - true_at(i)).abs()).collect::<Vec<f64>>(), 0.5),
                || {
                    let mut alpha: Vec<f64> =
                        a.angstrom.iter().filter(|v| v.is_finite()).map(|&v| f64::from(v)).collect();
                    (q(&mut alpha, 0.5), true_angstrom(truth))
                },
            )
        },
    );
    // Only members with a finite ε (a JSON null would not read back as a number).
    let members_epsilon = settings
        .models
        .iter()
        .zip(&a.members_epsilon)
        .filter(|(_, e)| e.is_finite())
        .map(|(m, e)| (m.name(), *e))
        .collect();
    AerosolSummary {
        aot550,
        aot550_true,
        aot550_abs_error,
        angstrom,
        angstrom_true,
        outside_family_pct: if retrieved_n == 0 { 0.0 } else { 100.0 * a.outside_family as f64 / retrieved_n as f64 },
        passes_mean: a.passes_mean,
        fit: fit_words(a, settings, centres_nm),
        epsilon: a.epsilon,
        members_epsilon,
    }
}

/// The Ångström exponent (443/865 nm) of the scene's aerosol model, from its own optics; NaN
/// where the scene has no aerosol.
fn true_angstrom(truth: &crate::atmosphere::AtmosphereSpec) -> f64 {
    crate::atmosphere::AtmosphereSpec { aot550: 1.0, ..truth.clone() }
        .build()
        .ok()
        .and_then(|atm| {
            let tau = |nm: f64| atm.column(nm).ok().and_then(|c| c.aerosol.map(|x| x.0));
            Some(-(tau(865.0)? / tau(443.0)?).ln() / (865.0f64 / 443.0).ln())
        })
        .unwrap_or(f64::NAN)
}

/// The correction's fit in words: its label, and for dark-spectrum fitting the models chosen
/// (share of tiles) and, for one tile, the bands that set the AOT.
fn fit_words(
    a: &crate::correction::AerosolRetrieval,
    settings: &crate::correction::ImageCorrection,
    centres_nm: &[f64],
) -> String {
    let glint = if a.glint_removed {
        format!(
            "; expected glint taken away, {} pixels left out for high glint (L_GN > {} sr⁻¹)",
            a.high_glint, settings.glint_threshold_per_sr
        )
    } else {
        String::new()
    };
    if a.tiles.is_empty() {
        return format!("{}{glint}", settings.label());
    }
    let mut models: Vec<(crate::atmosphere::AerosolType, usize)> = Vec::new();
    for t in &a.tiles {
        match models.iter_mut().find(|m| m.0 == t.model) {
            Some(m) => m.1 += 1,
            None => models.push((t.model, 1)),
        }
    }
    let n = a.tiles.len();
    let chosen: Vec<String> = models
        .iter()
        .map(|(m, k)| format!("{} {:.0} %", format!("{m:?}").to_lowercase(), 100.0 * *k as f64 / n as f64))
        .collect();
    let bands = match a.tiles.as_slice() {
        [one] => {
            let nm = |b: usize| centres_nm.get(b).map_or(f64::NAN, |c| *c);
            format!(", AOT from {:.0} and {:.0} nm", nm(one.bands[0]), nm(one.bands[1]))
        }
        _ => String::new(),
    };
    format!("{}; {} tile{}: {}{bands}{glint}", settings.label(), n, if n == 1 { "" } else { "s" }, chosen.join(", "))
}
