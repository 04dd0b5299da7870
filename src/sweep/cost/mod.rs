//! The cost of accuracy: every fidelity setting trades time for error. [`cost_of_accuracy`] runs
//! a configuration once per setting and round (a fresh engine each, so nothing comes from the
//! cache), the rounds interleaved — reference, setting 1, setting 2, …, then again, and a last
//! reference run — so a slow spell of the machine falls on every setting alike. Each row reports
//! the median wall and CPU time with their range, and against the reference, paired by round
//! ([`rows`]), the median ratio with its interval, or "no measurable difference" when the
//! interval holds 1. Each row changes what its label names from the reference: the
//! configuration's fidelity with per-pixel spectra on the full grid in double precision.
//! Products are compared with the reference run of the same configuration and seed (first
//! round):
//!
//! - **ΔMAE**: the chl-a log-space MAE against the truth, minus the reference's (points of %);
//! - **chl per pixel**: median |retrieved / reference retrieved − 1| over pixels both return
//!   (same grid only; a coarser grid has other pixels);
//! - **Rrs(443) per pixel**: median |Rrs / reference Rrs − 1| over water pixels (same grid only).

use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RunConfig, RunOutput};
use crate::parse::FieldError;
use crate::study::StudyError;
use crate::timing::measure;

use super::apply;

mod per_pixel;
mod rows;
pub use per_pixel::PerPixel;
pub use rows::{CostRow, ErrorOf, cheapest_within, pareto_front};

/// How the table is measured and what each row changes, in the words the CLI, the app's Cost
/// window and the review pack print under it.
pub const COST_METHOD: &str = "Rounds run the reference, then each setting in turn, and again; one more reference run closes the table. Each run is set against the reference's time at that moment (interpolated between the reference runs either side of it, after a running median of three has set a single slow reference run aside), and a row's verdict is the median of its per-round ratios with a sign-test interval of at least 90 % coverage: \"no measurable difference\" when the interval holds 1 (with 5 to 7 rounds every round must agree; from 8, one slow run is tolerated). The Pareto front and the cheapest setting compare rows by the same pairing. CPU is the process's user + system time (all threads). Each row changes what its label names from the reference, the configuration's fidelity with per-pixel spectra on the full grid in double precision: the defaults row changes two settings (band nodes 4, single precision), the \"fast\" row three. Per-pixel columns compare the same pixels with the same noise, so they isolate the setting's own error; a preview's ΔMAE mixes that with fewer pixels in the sample.";

/// One fidelity setting: its label and the fields it sets.
pub struct Setting {
    /// Label.
    pub label: String,
    /// Numeric fields set, by path ([`apply`]).
    pub set: Vec<(&'static str, f64)>,
    /// Any other change (switches, lists), made after `set`.
    pub edit: Option<Edit>,
}

/// A change a [`Setting`] makes beyond its numeric fields.
#[derive(Clone, Copy)]
pub enum Edit {
    /// Of the configuration.
    Config(fn(&mut RunConfig)),
    /// Of its first retrieval ([`crate::retrieval::Algorithm::cheaper`]).
    Retrieval(fn(&mut crate::retrieval::RetrievalSpec)),
}

impl Setting {
    /// `config` with this setting's edit made (after its numeric fields, [`apply`]).
    pub fn edit(&self, config: &mut RunConfig) {
        match self.edit {
            Some(Edit::Config(edit)) => edit(config),
            Some(Edit::Retrieval(edit)) => config.retrievals.first_mut().into_iter().for_each(edit),
            None => {}
        }
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
    let e = |label: &str, edit: fn(&mut RunConfig)| Setting {
        label: label.into(),
        set: Vec::new(),
        edit: Some(Edit::Config(edit)),
    };
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
            // The defaults but for the kernel's precision.
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
    let sampled_with_psf = effects.contains(&Effect::SpatialResponse)
        || crate::instrument::effects::spatial_response(&base.instrument.effects).is_some();
    if sampled_with_psf {
        // The default is 2 points per GSD and axis.
        out.extend([
            s("spatial response 1 point per GSD", vec![("fidelity.spatial_samples_per_gsd", 1.0)]),
            s("spatial response 3 points per GSD", vec![("fidelity.spatial_samples_per_gsd", 3.0)]),
        ]);
    }
    // The first retrieval's own rows.
    if let Some(first) = base.retrievals.first() {
        out.extend(first.algorithm().cheaper().into_iter().map(|(label, edit)| Setting {
            label: label.into(),
            set: Vec::new(),
            edit: Some(Edit::Retrieval(edit)),
        }));
    }
    // The image-based corrections priced beside the exact one: the 779/865 nm pair where the
    // design has it, and dark-spectrum fitting.
    let centres = crate::instrument::Response::new(&base.instrument, base.fidelity.spectral_step_nm)
        .map(|r| r.bands.centres_nm())
        .unwrap_or_default();
    if base.correction.image().is_none() {
        if crate::correction::ImageCorrection::default().pair(&centres).is_ok() {
            out.push(e("image-based correction (779/865 nm, NIR iteration)", |c| {
                c.correction.method = crate::correction::Method::Image(crate::correction::ImageCorrection::default());
            }));
        }
        out.push(e("image-based correction (dark spectrum, scene)", |c| {
            c.correction.method = crate::correction::Method::Image(crate::correction::ImageCorrection::dark_spectrum());
        }));
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
    setting.edit(&mut config);
    // A fidelity setting alone: nothing but the fidelity differs, and not its resolution.
    let fidelity = config.fidelity.clone();
    config.fidelity = base.fidelity.clone();
    (config == *base && fidelity.decimation == base.fidelity.decimation).then_some(fidelity)
}

fn chl_mae(out: &RunOutput) -> f64 {
    out.retrievals.first().and_then(|r| r.metrics.get("chl_mg_m3")).map_or(f64::NAN, crate::metrics::Metrics::mae_pct)
}

/// Measure every setting of [`settings_for`] `base` on it (whose decimation is the reference's), in
/// `rounds` interleaved rounds (at least 1) and one closing reference run, and pair each row's
/// runs with the reference's (`rows`); `on_row` hears of each row each time its figures change,
/// with the round (0-based) in progress.
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
            setting.edit(&mut config);
            Ok::<_, StudyError>(config)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let run = |config: &RunConfig| {
        let mut engine = Engine::new();
        let (run, sample) = measure(|| engine.run(config, control));
        let run = run.map_err(|e| match e {
            EngineError::Cancelled => StudyError::Cancelled,
            other => StudyError::Run { instrument: config.instrument.name.clone(), message: other.to_string() },
        })?;
        Ok::<_, StudyError>((run, sample))
    };
    let rounds = rounds.max(1);
    let mut rows: Vec<CostRow> = Vec::with_capacity(settings.len());
    let mut reference: Option<RunOutput> = None;
    for round in 0..=rounds {
        for (i, (setting, config)) in settings.iter().zip(&configs).enumerate() {
            // After the last round, the reference runs once more to close it.
            if round == rounds && i > 0 {
                break;
            }
            let (out, sample) = run(config)?;
            if round == 0 {
                let mae = chl_mae(&out);
                let (delta, errors) = match &reference {
                    None => (0.0, PerPixel::of_itself(&out)),
                    Some(r) => (mae - chl_mae(r), PerPixel::between(&out, r)),
                };
                rows.push(CostRow { errors, ..CostRow::untimed(&setting.label, mae, delta) });
                if reference.is_none() {
                    reference = Some(out);
                }
            }
            rows[i].samples.push(sample);
            rows[i].time = crate::timing::Summary::of(&rows[i].samples);
            rows::pair_with_reference(&mut rows);
            // A reference run closes the round before it: every row's figures move.
            let changed = if i == 0 && round > 0 { 0..rows.len() } else { i..i + 1 };
            for row in &rows[changed] {
                on_row(round.min(rounds - 1), row);
            }
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows of `base`, each applied: (label, configuration).
    fn applied(base: &RunConfig) -> Vec<(String, RunConfig)> {
        settings_for(base)
            .into_iter()
            .map(|setting| {
                let mut c = apply(base, &setting.set).unwrap_or_else(|e| panic!("{}: {e}", setting.label));
                setting.edit(&mut c);
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
}
