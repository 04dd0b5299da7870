//! The cost of accuracy: every fidelity setting trades time for error. [`cost_of_accuracy`] runs
//! a configuration once per setting and round (a fresh engine each, so nothing comes from the
//! cache), the rounds interleaved — reference, setting 1, setting 2, …, then again — so a slow
//! spell of the machine falls on every setting alike ([`crate::timing`]). Each row reports the
//! median wall and CPU time with their range, and against the reference either a ratio or, when
//! the ranges overlap, "no measurable difference". Products are compared with the reference
//! run of the same configuration and seed (first round):
//!
//! - **ΔMAE**: the chl-a log-space MAE against the truth, minus the reference's (points of %);
//! - **chl per pixel**: median |retrieved / reference retrieved − 1| over pixels both return
//!   (same grid only; a coarser grid has other pixels);
//! - **Rrs(443) per pixel**: median |Rrs / reference Rrs − 1| over water pixels (same grid only).

use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RunConfig, RunOutput};
use crate::parse::FieldError;
use crate::study::StudyError;
use crate::timing::{Comparison, Sample, Summary, measure};

use super::apply;

/// One measured setting.
#[derive(Debug, Clone, PartialEq)]
pub struct CostRow {
    /// What the setting is.
    pub label: String,
    /// Its timed runs so far (one per round).
    pub samples: Vec<Sample>,
    /// Median and range of the samples.
    pub time: Summary,
    /// Against the reference's time (the reference row: no measurable difference with itself).
    pub comparison: Comparison,
    /// chl-a MAE against the truth, %.
    pub chl_mae_pct: f64,
    /// `chl_mae_pct` minus the reference's, points of %.
    pub delta_mae_pct: f64,
    /// Median per-pixel chl difference from the reference, % (same grid only).
    pub chl_pixel_pct: Option<f64>,
    /// 95th percentile of the per-pixel chl difference, % (same grid only): a setting whose
    /// error lives at edges (the spatial response) or in a few hard pixels shows here while its
    /// median stays at zero.
    pub chl_pixel_p95_pct: Option<f64>,
    /// Median per-pixel Rrs(443) difference from the reference, % (same grid only).
    pub rrs_pixel_pct: Option<f64>,
    /// Median per-pixel depth difference from the reference, % (same grid, depth retrievals).
    pub depth_pixel_pct: Option<f64>,
}

impl CostRow {
    /// A row timed at `walls` seconds (CPU twice the wall), chl MAE 37 % (+0.07 points), with the
    /// per-pixel chl error `pixel` (also the Rrs error) and its 95th percentile `p95`: for the
    /// tests of the tables that print rows.
    #[cfg(test)]
    #[must_use]
    pub(crate) fn timed(
        label: &str,
        walls: &[f64],
        comparison: Comparison,
        pixel: Option<f64>,
        p95: Option<f64>,
    ) -> Self {
        let samples: Vec<Sample> = walls.iter().map(|&w| Sample { wall_s: w, cpu_s: Some(2.0 * w) }).collect();
        Self {
            label: label.into(),
            time: Summary::of(&samples),
            samples,
            comparison,
            chl_mae_pct: 37.0,
            delta_mae_pct: 0.07,
            chl_pixel_pct: pixel,
            chl_pixel_p95_pct: p95,
            rrs_pixel_pct: pixel,
            depth_pixel_pct: None,
        }
    }

    /// Median wall time, s.
    #[must_use]
    pub fn seconds(&self) -> f64 {
        self.time.wall_s
    }

    /// The error the Pareto front and the tolerance use: the median per-pixel chl difference
    /// from the reference, %, on the same grid. `None` for a preview: its pixels are a subset of
    /// the reference's, so it is a different product (fewer pixels), not a cheaper equal one.
    #[must_use]
    pub fn chl_error_pct(&self) -> Option<f64> {
        self.chl_pixel_pct.filter(|v| v.is_finite())
    }

    /// Is this row measurably faster than `other` (its slowest run beats `other`'s fastest)?
    #[must_use]
    pub fn measurably_faster_than(&self, other: &Self) -> bool {
        self.time.wall_range_s.1 < other.time.wall_range_s.0
    }
}

/// One fidelity setting: its label and the fields it sets.
pub struct Setting {
    /// Label.
    pub label: String,
    /// Numeric fields set, by path ([`apply`]).
    pub set: Vec<(&'static str, f64)>,
    /// Any other change (switches, lists), made after `set`.
    pub edit: Option<fn(&mut RunConfig)>,
}

/// aLMI's settings and sets in the first retrieval, if it is aLMI.
fn almi(config: &mut RunConfig) -> Option<(&mut Vec<crate::water::SiopSource>, &mut crate::retrieval::AlmiSettings)> {
    match config.retrievals.first_mut() {
        Some(crate::retrieval::RetrievalSpec::Almi { siop_sets, settings }) => Some((siop_sets, settings)),
        _ => None,
    }
}

/// The first retrieval's SAMBUCA settings, if it is SAMBUCA.
fn sambuca(config: &mut RunConfig) -> Option<&mut crate::retrieval::SambucaSettings> {
    match config.retrievals.first_mut() {
        Some(crate::retrieval::RetrievalSpec::Sambuca { settings, .. }) => Some(settings),
        _ => None,
    }
}

/// The settings measured for `base`, each one change from the reference (the base's fidelity
/// with per-pixel spectra on the full grid; [`crate::engine::Fidelity::full`] for the defaults):
/// the reference, the shipped defaults, previews at 2–24× the base decimation, per-pixel spectra
/// at band nodes (not with adjacency, which needs whole spectra), spectral step, LUT nodes,
/// radiative-transfer streams, orders and Fourier terms, the SNR patch, and one combination; then
/// the rows of the first retrieval — aLMI's weighting and number of SIOP sets, or SAMBUCA's
/// Gauss nodes per band, iterations, starts and weighting — and, when the scene asks for the
/// instrument's spatial response, its quadrature points per GSD. Rows that could change nothing
/// for `base` are left out (a row identical to the reference would read as a free setting).
#[must_use]
pub fn settings_for(base: &RunConfig) -> Vec<Setting> {
    use crate::scene::Effect;
    let base_decimation = base.fidelity.decimation;
    let s = |label: &str, set: Vec<(&'static str, f64)>| Setting { label: label.into(), set, edit: None };
    let e = |label: &str, edit: fn(&mut RunConfig)| Setting { label: label.into(), set: Vec::new(), edit: Some(edit) };
    let effects = &base.scene.effects;
    let mut out = vec![
        s("reference (full fidelity)", vec![]),
        e("the defaults (band nodes 4, single precision)", |c| {
            c.fidelity.band_nodes = crate::engine::DEFAULT_BAND_NODES;
            c.fidelity.water_single_precision = crate::engine::DEFAULT_WATER_SINGLE_PRECISION;
        }),
    ];
    for d in [2, 4, 8, 16, 24] {
        out.push(s(
            &format!("preview 1/{}", d * base_decimation),
            vec![("fidelity.decimation", (d * base_decimation) as f64)],
        ));
    }
    if !effects.contains(&Effect::Adjacency) {
        out.extend([
            s("band nodes 2 per band", vec![("fidelity.band_nodes", 2.0)]),
            s("band nodes 3 per band", vec![("fidelity.band_nodes", 3.0)]),
            // The defaults but for the kernel's precision (the defaults before 2026-11-25).
            e("band nodes 4, double precision", |c| {
                c.fidelity.band_nodes = 4;
                c.fidelity.water_single_precision = false;
            }),
        ]);
    }
    out.extend([
        s("spectral step 2 nm", vec![("fidelity.spectral_step_nm", 2.0)]),
        s("spectral step 5 nm", vec![("fidelity.spectral_step_nm", 5.0)]),
        s("LUT wavelength nodes 10 nm", vec![("fidelity.lut_wavelength_step_nm", 10.0)]),
        s("LUT wavelength nodes 40 nm", vec![("fidelity.lut_wavelength_step_nm", 40.0)]),
        s("LUT view nodes 10°", vec![("fidelity.lut_view_step_deg", 10.0)]),
        s("RT 8 streams", vec![("scene.atmosphere.accuracy.streams", 8.0)]),
        s("RT 16 streams", vec![("scene.atmosphere.accuracy.streams", 16.0)]),
        s("RT single scattering", vec![("scene.atmosphere.accuracy.max_orders", 1.0)]),
        s("RT 8 Fourier terms", vec![("scene.atmosphere.accuracy.fourier_terms", 8.0)]),
        s("SNR patch 16 frames", vec![("fidelity.snr_frames", 16.0)]),
    ]);
    if effects.contains(&Effect::SpatialResponse) {
        // The default is 2 points per GSD and axis.
        out.extend([
            s("spatial response 1 point per GSD", vec![("fidelity.spatial_samples_per_gsd", 1.0)]),
            s("spatial response 3 points per GSD", vec![("fidelity.spatial_samples_per_gsd", 3.0)]),
        ]);
    }
    match base.retrievals.first() {
        Some(crate::retrieval::RetrievalSpec::Almi { .. }) => out.extend([
            e("aLMI unweighted (one solve per set)", |c| {
                if let Some((_, settings)) = almi(c) {
                    settings.noise_weighting = false;
                }
            }),
            e("aLMI 4 of 8 SIOP sets", |c| {
                if let Some((sets, _)) = almi(c) {
                    sets.truncate(4);
                }
            }),
        ]),
        // The defaults: 3 Gauss nodes per band, 100 iterations, adaptive starts, noise-weighted.
        Some(crate::retrieval::RetrievalSpec::Sambuca { .. }) => out.extend([
            e("SAMBUCA 1 Gauss node per band", |c| sambuca(c).into_iter().for_each(|s| s.nodes_per_band = 1)),
            e("SAMBUCA 2 Gauss nodes per band", |c| sambuca(c).into_iter().for_each(|s| s.nodes_per_band = 2)),
            e("SAMBUCA 5 Gauss nodes per band", |c| sambuca(c).into_iter().for_each(|s| s.nodes_per_band = 5)),
            e("SAMBUCA 25 iterations per start", |c| sambuca(c).into_iter().for_each(|s| s.max_iterations = 25)),
            e("SAMBUCA 50 iterations per start", |c| sambuca(c).into_iter().for_each(|s| s.max_iterations = 50)),
            e("SAMBUCA shallow start only", |c| {
                sambuca(c).into_iter().for_each(|s| s.starts = crate::retrieval::Starts::Shallow);
            }),
            e("SAMBUCA shallow and deep starts, every pixel", |c| {
                sambuca(c).into_iter().for_each(|s| s.starts = crate::retrieval::Starts::ShallowAndDeep);
            }),
            e("SAMBUCA unweighted", |c| sambuca(c).into_iter().for_each(|s| s.noise_weighting = false)),
        ]),
        _ => {}
    }
    out.push(s(
        "fast: 2 nm, LUT 40 nm, 8 streams",
        vec![
            ("fidelity.spectral_step_nm", 2.0),
            ("fidelity.lut_wavelength_step_nm", 40.0),
            ("scene.atmosphere.accuracy.streams", 8.0),
        ],
    ));
    out
}

/// The fidelity the row `label` of [`settings_for`] runs with, applied to `base`'s (the reference
/// row: `base`'s own): `None` when the row is not a fidelity setting alone (it changes the
/// atmosphere's accuracy, the retrieval, or the resolution), so it cannot become a run's
/// fidelity.
#[must_use]
pub fn fidelity_of(label: &str, base: &RunConfig) -> Option<crate::engine::Fidelity> {
    let setting = settings_for(base).into_iter().find(|s| s.label == label)?;
    // The row's configuration; the reference (nothing set) is `base` itself, so applying it
    // goes back to `base`'s fidelity.
    let mut config = apply(base, &setting.set).ok()?;
    if let Some(edit) = setting.edit {
        edit(&mut config);
    }
    // A fidelity setting alone: nothing but the fidelity differs, and not its resolution.
    let fidelity = config.fidelity.clone();
    config.fidelity = base.fidelity.clone();
    (config == *base && fidelity.decimation == base.fidelity.decimation).then_some(fidelity)
}

fn chl_mae(out: &RunOutput) -> f64 {
    out.retrievals.first().and_then(|r| r.metrics.get("chl_mg_m3")).map_or(f64::NAN, crate::metrics::Metrics::mae_pct)
}

/// The `q` quantile of `v`: the element of rank ⌊q·n⌋ (for q = ½ the upper median, as the
/// table's medians always were), `None` if empty.
fn quantile(v: &mut [f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let k = ((v.len() as f64 * q) as usize).min(v.len() - 1);
    Some(*v.select_nth_unstable_by(k, f64::total_cmp).1)
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    quantile(&mut v, 0.5)
}

/// A row's per-pixel differences from the reference: median relative difference of retrieved
/// chl, of Rrs at the band nearest 443 nm, and of retrieved depth (depth retrievals), when the
/// grids match.
struct PerPixel {
    chl: Option<f64>,
    chl_p95: Option<f64>,
    rrs: Option<f64>,
    depth: Option<f64>,
}

impl PerPixel {
    const NONE: Self = Self { chl: None, chl_p95: None, rrs: None, depth: None };
}

fn per_pixel(out: &RunOutput, reference: &RunOutput) -> PerPixel {
    let (Some(a), Some(b)) = (out.retrievals.first(), reference.retrievals.first()) else { return PerPixel::NONE };
    if a.product.chl_mg_m3.dim() != b.product.chl_mg_m3.dim()
        || out.correction.rrs.rrs.dim() != reference.correction.rrs.rrs.dim()
    {
        return PerPixel::NONE;
    }
    let (rows, cols) = a.product.chl_mg_m3.dim();
    let mut chl = Vec::new();
    let mut rrs = Vec::new();
    let mut depth = Vec::new();
    let depths = a.product.depth_m.as_ref().zip(b.product.depth_m.as_ref());
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
            if a.product.returned(r, c) && b.product.returned(r, c) {
                let (x, y) = (f64::from(a.product.chl_mg_m3[[r, c]]), f64::from(b.product.chl_mg_m3[[r, c]]));
                if y > 0.0 {
                    chl.push((x / y - 1.0).abs());
                }
                if let Some((da, db)) = depths {
                    let (x, y) = (f64::from(da[[r, c]]), f64::from(db[[r, c]]));
                    if y > 0.0 && x.is_finite() {
                        depth.push((x / y - 1.0).abs());
                    }
                }
            }
            if out.radiance.truth.land[[r, c]] == 0 {
                let (x, y) = (
                    f64::from(out.correction.rrs.rrs[[r, c, band]]),
                    f64::from(reference.correction.rrs.rrs[[r, c, band]]),
                );
                if y.abs() > 1e-6 {
                    rrs.push((x / y - 1.0).abs());
                }
            }
        }
    }
    PerPixel { chl_p95: quantile(&mut chl, 0.95), chl: median(chl), rrs: median(rrs), depth: median(depth) }
}

/// Measure every setting of [`settings_for`] `base` on it (whose decimation is the reference's), in
/// `rounds` interleaved rounds (at least 1); `on_row` hears of each row each time it gains a
/// sample, with the round it came from (0-based).
pub fn cost_of_accuracy(
    base: &RunConfig,
    rounds: usize,
    control: &RunControl,
    mut on_row: impl FnMut(usize, &CostRow),
) -> Result<Vec<CostRow>, StudyError> {
    let settings = settings_for(base);
    // Every row is one change from the reference: `base`'s fidelity with every approximation the
    // table prices off (per-pixel spectra on the full grid, in double precision), whatever band
    // nodes `base` uses.
    let mut base = base.clone();
    base.fidelity.band_nodes = 0;
    base.fidelity.water_single_precision = false;
    let base = &base;
    let configs = settings
        .iter()
        .map(|setting| {
            let mut config = apply(base, &setting.set)
                .map_err(|m| StudyError::Invalid(FieldError { field: setting.label.clone(), message: m }))?;
            if let Some(edit) = setting.edit {
                edit(&mut config);
            }
            Ok::<_, StudyError>(config)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows: Vec<CostRow> = Vec::with_capacity(settings.len());
    let mut reference: Option<RunOutput> = None;
    for round in 0..rounds.max(1) {
        for (i, (setting, config)) in settings.iter().zip(&configs).enumerate() {
            let mut engine = Engine::new();
            let (run, sample) = measure(|| engine.run(config, control));
            let run = run.map_err(|e| match e {
                EngineError::Cancelled => StudyError::Cancelled,
                other => StudyError::Run { instrument: config.instrument.name.clone(), message: other.to_string() },
            })?;
            if round == 0 {
                let mae = chl_mae(&run);
                let (delta, diff) = match &reference {
                    None => {
                        let has_depth = run.retrievals.first().is_some_and(|r| r.product.depth_m.is_some());
                        (
                            0.0,
                            PerPixel {
                                chl: Some(0.0),
                                chl_p95: Some(0.0),
                                rrs: Some(0.0),
                                depth: has_depth.then_some(0.0),
                            },
                        )
                    }
                    Some(r) => (mae - chl_mae(r), per_pixel(&run, r)),
                };
                rows.push(CostRow {
                    label: setting.label.clone(),
                    samples: Vec::new(),
                    time: Summary::of(&[]),
                    comparison: Comparison::NoMeasurableDifference,
                    chl_mae_pct: mae,
                    delta_mae_pct: delta,
                    chl_pixel_pct: diff.chl.map(|v| 100.0 * v),
                    chl_pixel_p95_pct: diff.chl_p95.map(|v| 100.0 * v),
                    rrs_pixel_pct: diff.rrs.map(|v| 100.0 * v),
                    depth_pixel_pct: diff.depth.map(|v| 100.0 * v),
                });
                if reference.is_none() {
                    reference = Some(run);
                }
            }
            rows[i].samples.push(sample);
            rows[i].time = Summary::of(&rows[i].samples);
            let reference_time = rows[0].time;
            rows[i].comparison = if i == 0 {
                Comparison::NoMeasurableDifference
            } else {
                Comparison::of(&rows[i].time, &reference_time)
            };
            on_row(round, &rows[i]);
        }
    }
    Ok(rows)
}

/// The full-resolution rows on the time–error Pareto front, fastest first: a row is off the
/// front when another is measurably faster ([`CostRow::measurably_faster_than`]) and no less
/// accurate, or as fast within the noise and more accurate. Of rows that tie in both, the first
/// (the reference comes first) stands for them.
#[must_use]
pub fn pareto_front(rows: &[CostRow]) -> Vec<&CostRow> {
    let candidates: Vec<(usize, &CostRow, f64)> =
        rows.iter().enumerate().filter_map(|(i, r)| r.chl_error_pct().map(|e| (i, r, e))).collect();
    let mut front: Vec<&CostRow> = candidates
        .iter()
        .filter(|(i, r, e)| {
            !candidates.iter().any(|(j, o, f)| {
                let tied_time = !o.measurably_faster_than(r) && !r.measurably_faster_than(o);
                (o.measurably_faster_than(r) && f <= e) || (tied_time && (f < e || (f == e && j < i)))
            })
        })
        .map(|(_, r, _)| *r)
        .collect();
    front.sort_by(|a, b| a.seconds().total_cmp(&b.seconds()));
    front
}

/// The cheapest full-resolution row whose chl error from the reference is within
/// `tolerance_pct` and that is measurably faster than the reference; the reference itself when
/// none is.
///
/// "Cheapest" is decided only as far as the timings can tell: the candidates that no other
/// candidate is measurably faster than ([`CostRow::measurably_faster_than`]) tie, and of those
/// the one with the smallest chl error is taken (the first listed of equal errors). The tie is
/// never empty: the candidate with the fastest single run is in it. A median alone once named
/// "band nodes 3" (3.08 s, 0.68 % chl) over the defaults (3.12 s, 0.003 %), whose ranges
/// overlapped.
#[must_use]
pub fn cheapest_within(rows: &[CostRow], tolerance_pct: f64) -> Option<&CostRow> {
    let reference = rows.first()?;
    let candidates: Vec<(&CostRow, f64)> = rows
        .iter()
        .skip(1)
        .filter(|r| !r.samples.is_empty() && r.measurably_faster_than(reference))
        .filter_map(|r| r.chl_error_pct().filter(|&e| e <= tolerance_pct).map(|e| (r, e)))
        .collect();
    let unbeaten = candidates.iter().filter(|(r, _)| !candidates.iter().any(|(o, _)| o.measurably_faster_than(r)));
    unbeaten.min_by(|a, b| a.1.total_cmp(&b.1)).map(|(r, _)| *r).or(Some(reference))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::timing::Sample;

    fn row(label: &str, times: &[f64], pixel: Option<f64>) -> CostRow {
        let samples: Vec<Sample> = times.iter().map(|&w| Sample { wall_s: w, cpu_s: None }).collect();
        CostRow {
            label: label.into(),
            time: Summary::of(&samples),
            samples,
            comparison: Comparison::NoMeasurableDifference,
            chl_mae_pct: 30.0,
            delta_mae_pct: 0.0,
            chl_pixel_pct: pixel,
            chl_pixel_p95_pct: pixel,
            rrs_pixel_pct: pixel,
            depth_pixel_pct: None,
        }
    }

    /// The rows of `base`, each applied: (label, configuration).
    fn applied(base: &RunConfig) -> Vec<(String, RunConfig)> {
        settings_for(base)
            .into_iter()
            .map(|setting| {
                let mut c = apply(base, &setting.set).unwrap_or_else(|e| panic!("{}: {e}", setting.label));
                if let Some(edit) = setting.edit {
                    edit(&mut c);
                }
                (setting.label, c)
            })
            .collect()
    }

    #[test]
    fn each_case_gets_the_rows_of_its_retrieval_and_scene_and_every_row_changes_something() {
        use crate::instrument::InstrumentSpec;
        use crate::retrieval::{RetrievalSpec, SambucaSettings};
        use crate::scene::{Effect, SceneSpec};
        let preset = |s: &str| SceneSpec::preset(s).unwrap_or_else(|e| panic!("{e}"));
        let instrument = |s: &str| InstrumentSpec::preset(s).unwrap_or_else(|e| panic!("{e}"));
        let mut almi = RunConfig::new(preset("lake_hume_bloom"), instrument("cubesat"));
        almi.retrievals = vec![RetrievalSpec::Almi {
            siop_sets: crate::retrieval::sets::default_almi_sets(),
            settings: crate::retrieval::AlmiSettings::default(),
        }];
        let mut reef = preset("heron_island_reef");
        reef.effects.push(Effect::SpatialResponse);
        let mut sambuca = RunConfig::new(reef, instrument("nominal"));
        sambuca.retrievals = vec![RetrievalSpec::Sambuca {
            siop: None,
            substrates: Some(vec!["acropora".into(), "sand".into()]),
            settings: SambucaSettings::default(),
        }];
        let labels = |base: &RunConfig| -> Vec<String> { applied(base).into_iter().map(|(l, _)| l).collect() };
        let has = |labels: &[String], prefix: &str| labels.iter().any(|l| l.starts_with(prefix));
        let (a, b) = (labels(&almi), labels(&sambuca));
        assert!(has(&a, "aLMI ") && !has(&a, "SAMBUCA ") && has(&a, "band nodes 2") && !has(&a, "spatial"), "{a:?}");
        // The reef has adjacency (whole spectra per pixel: band nodes do not apply) and asks for
        // the spatial response.
        assert!(has(&b, "SAMBUCA ") && !has(&b, "aLMI ") && !has(&b, "band nodes 2") && has(&b, "spatial"), "{b:?}");
        for base in [&mut almi, &mut sambuca] {
            // The table's reference: per-pixel spectra on the full grid (see `cost_of_accuracy`).
            base.fidelity.band_nodes = 0;
            base.fidelity.water_single_precision = false;
            let base = &*base;
            for (label, config) in applied(base).into_iter().skip(1) {
                assert_ne!(&config, base, "{label} changes nothing: it would read as a free setting");
            }
        }
    }

    #[test]
    fn only_fidelity_rows_can_become_a_runs_fidelity() {
        use crate::instrument::InstrumentSpec;
        use crate::scene::SceneSpec;
        let base = RunConfig::new(
            SceneSpec::preset("lake_hume_bloom").unwrap_or_else(|e| panic!("{e}")),
            InstrumentSpec::preset("cubesat").unwrap_or_else(|e| panic!("{e}")),
        );
        let f = fidelity_of("band nodes 4, double precision", &base);
        assert_eq!(f.map(|f| (f.band_nodes, f.water_single_precision)), Some((4, false)));
        let f = fidelity_of("band nodes 2 per band", &base).map(|f| (f.band_nodes, f.spectral_step_nm));
        assert_eq!(f, Some((2, base.fidelity.spectral_step_nm)), "only the row's field changes");
        assert_eq!(fidelity_of("reference (full fidelity)", &base), Some(base.fidelity.clone()), "back to it");
        let f = fidelity_of("fast: 2 nm, LUT 40 nm, 8 streams", &base);
        assert!(f.is_none(), "changes the atmosphere's accuracy too");
        for label in ["preview 1/4", "RT 8 streams", "aLMI unweighted (one solve per set)"] {
            assert!(fidelity_of(label, &base).is_none(), "{label}");
        }
        assert!(fidelity_of("no such row", &base).is_none());
        // A row set by an edit of the fidelity alone is one too.
        let f = fidelity_of("the defaults (band nodes 4, single precision)", &base);
        assert_eq!(f.map(|f| (f.band_nodes, f.water_single_precision)), Some((4, true)));
    }

    #[test]
    fn the_front_ignores_differences_within_the_noise_and_previews() {
        let rows = vec![
            row("reference", &[1.6, 1.7, 1.8], Some(0.0)),
            // As fast within the noise, no more accurate: tied with the reference, dropped.
            row("same", &[1.55, 1.65, 1.75], Some(0.0)),
            // Measurably faster, small error: on the front.
            row("fast", &[1.0, 1.05, 1.1], Some(0.5)),
            // As fast as `fast` within the noise but worse: off.
            row("fast-worse", &[1.02, 1.06, 1.09], Some(0.9)),
            // Fastest, larger error: on the front.
            row("fastest", &[0.5, 0.52, 0.55], Some(3.0)),
            // A preview: not a candidate.
            row("preview", &[0.2, 0.21, 0.22], None),
        ];
        let front: Vec<&str> = pareto_front(&rows).iter().map(|r| r.label.as_str()).collect();
        assert_eq!(front, ["fastest", "fast", "reference"]);
        assert_eq!(cheapest_within(&rows, 1.0).unwrap().label, "fast");
        assert_eq!(cheapest_within(&rows, 5.0).unwrap().label, "fastest");
        assert_eq!(cheapest_within(&rows, 0.1).unwrap().label, "reference");
    }

    #[test]
    fn the_cheapest_within_a_tolerance_is_the_most_accurate_of_those_the_timings_cannot_tell_apart() {
        let rows = vec![
            row("reference", &[3.85, 3.92, 4.06], Some(0.0)),
            // The ninth round's table: a lower median, but the ranges overlap those below.
            row("band nodes 3", &[3.05, 3.08, 3.11], Some(0.682)),
            row("defaults", &[3.08, 3.12, 3.19], Some(0.003)),
            row("double precision", &[3.09, 3.16, 3.17], Some(0.003)),
            // Measurably slower than the fastest candidate: not in the tie, though more accurate.
            row("slower", &[3.3, 3.35, 3.4], Some(0.001)),
        ];
        // The defaults and double precision tie in error too: the first listed stands.
        assert_eq!(cheapest_within(&rows, 1.0).unwrap().label, "defaults");
        // Within 0.002 % only the slower row qualifies; it beats the reference measurably.
        assert_eq!(cheapest_within(&rows, 0.002).unwrap().label, "slower");
        // The review's case: the fastest row's slow run overlaps both others, but one of them
        // is measurably faster than the other, which is then out of the tie.
        let spread = vec![
            row("reference", &[10.0, 10.5, 11.0], Some(0.0)),
            row("erratic", &[5.0, 5.1, 9.0], Some(0.9)),
            row("steady", &[6.0, 6.1, 6.2], Some(0.5)),
            row("exact but slower", &[8.8, 8.9, 9.0], Some(0.0)),
        ];
        assert_eq!(cheapest_within(&spread, 1.0).unwrap().label, "steady");
        // A row as fast as the fastest within the noise but beyond the tolerance is no candidate.
        assert_eq!(cheapest_within(&rows[..2], 1.0).unwrap().label, "band nodes 3");
        assert_eq!(cheapest_within(&rows[..2], 0.5).unwrap().label, "reference");
    }
}
