//! Cache coherence: the stage cache never serves a stale product.
//!
//! The oracle is a fresh engine: whatever a cached engine returns after an edit must equal, bit
//! for bit, what an engine with an empty cache returns for the same configuration. And every input
//! a user can set must either change what a run produces or be listed in [`NO_EFFECT`] with the
//! reason — so a new field that never reaches a cache key (or a stage) cannot go unnoticed.
//!
//! The base configuration asks for everything a field could act on: a shallow reef with land
//! (adjacency), a wind-roughened surface with `SunGlint`, the spatial response, both retrievals, a
//! diffuser incidence; a spectrograph or filter imager for their `kind` fields. It is small (a
//! 16 × 12 image) so that each edit costs two short runs.

use crate::common::Kept;
use std::hash::{Hash, Hasher};

use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, RunOutput};
use shoal::instrument::InstrumentSpec;
use shoal::ranges::{self, Range};
use shoal::retrieval::RetrievalSpec;
use shoal::scene::{Effect, MapSpec, SceneSpec};
use shoal::spectral::SpectrumSource;

use crate::common::{both_retrievals, instrument_for, sweep_path};

mod edits;
use edits::structural_edits;

/// Inputs that do not change a run's output, and why. Everything else must.
const NO_EFFECT: &[(&str, &str)] = &[
    ("requirements.", "a study's pass/fail threshold: read after the runs, never by a stage"),
    ("atmosphere_run.", "`shoal atmosphere`'s own inputs (its day and geometry): not part of a run"),
    ("instrument.name", "a label for reports and file names"),
    ("instrument.description", "a label"),
    (
        "instrument.focal_planes[].detectors",
        "a further plane's detectors need only cover the first plane's swath (checked); the image is the first plane's grid",
    ),
];

fn documented(what: &str) -> Option<&'static str> {
    NO_EFFECT.iter().find(|(p, _)| what.starts_with(p)).map(|(_, why)| *why)
}

/// The base configuration for a field: every path of the range table exists in it.
fn base(path: &str) -> RunConfig {
    let mut instrument = InstrumentSpec::preset(instrument_for(path)).unwrap();
    instrument.detectors = 16;
    instrument.lines = 12;
    // A dark current and fixed patterns, so that the dark frames and their exposure matter.
    instrument.dark_current_e_s = 200.0;
    instrument.prnu = 0.01;
    instrument.dsnu_e = 5.0;
    crate::common::with_dark_laws(&mut instrument);
    if path.contains("effects[]") {
        crate::common::with_optical_effects(&mut instrument);
    }
    for p in &mut instrument.focal_planes {
        p.prnu = 0.01;
        p.dsnu_e = 5.0;
    }
    // Heron Island's reef cut to 2.4 × 1.6 km around the swath, with its cay moved 700 m west of
    // it (the adjacency FFT then runs on 240 × 160 cells instead of 1100 × 600).
    let mut scene = SceneSpec::preset("heron_island_reef").unwrap();
    (scene.width, scene.height) = (240, 160);
    if let Some(land) = &mut scene.land {
        land.mask = ron::from_str(
            "Shapes(background: 0.0, shapes: [Ellipse(centre_m: (-700.0, 0.0), radii_m: (200.0, 100.0), \
             angle_deg: 10.0, value: 1.0)])",
        )
        .unwrap();
    }
    if path == "fidelity.band_nodes" {
        // Band nodes act only without adjacency (whose environment term needs whole spectra).
        scene.effects.retain(|e| *e != Effect::Adjacency);
    }
    scene.atmosphere.surface = shoal::atmosphere::SeaSurface::Wind { speed_m_s: 5.0 };
    if path.starts_with("scene.atmosphere.aerosol.Mixture") {
        // A user's mixture (continental's fractions; the oceanic one 0 until changed).
        scene.atmosphere.aerosol = shoal::atmosphere::AerosolType::Mixture(Default::default());
    }
    if path.starts_with("scene.atmosphere.aerosol.LogNormal") {
        // A user's size distribution: the bushfire-smoke scene's two modes.
        scene.atmosphere.aerosol = SceneSpec::preset("lake_hume_smoke").unwrap().atmosphere.aerosol;
    }
    if path.contains("clouds.") {
        // Clouds and their shadows over the 2.4 × 1.6 km reef: 40 % of 300 m clouds at 300 m.
        scene.clouds =
            Some(shoal::scene::CloudLayer { cover: 0.4, size_m: 300.0, height_m: 300.0, ..Default::default() });
    }
    for e in [Effect::SunGlint, Effect::SpatialResponse] {
        if !scene.effects.contains(&e) {
            scene.effects.push(e);
        }
    }
    let mut c = RunConfig::new(scene, instrument);
    c.retrievals = both_retrievals();
    if path.contains(".External.") {
        // A program that writes nothing after 3 s: a 1 s limit stops it first (another failure).
        c.retrievals.push(crate::common::external_retrieval(&["sleep", "3"]));
    }
    c.calibration.sun_incidence_deg = Some(30.0);
    // Coarse LUT nodes keep each run short; they are inputs like any other.
    c.fidelity.lut_wavelength_step_nm = 40.0;
    c.fidelity.lut_view_step_deg = 10.0;
    if path.starts_with("correction.image.dark") {
        // Dark-spectrum fitting's settings act only when it is the fit. The base's glint (~0.02
        // sr⁻¹ at nadir) is left in, as ACOLITE's fit reads it: taken away, none of the four
        // dark-spectrum settings changed this small reef's output any more.
        c.correction.method = shoal::correction::Method::Image(shoal::correction::ImageCorrection {
            glint: false,
            ..shoal::correction::ImageCorrection::dark_spectrum()
        });
    } else if path.starts_with("correction.image") {
        // The image-based correction's settings act only when it is on. The base looks near the
        // sun's glint (normalised glint ~0.02 sr⁻¹ at nadir): the glint is taken away but no
        // pixel left out, so that every other setting reaches the Rrs.
        c.correction.method = shoal::correction::Method::Image(shoal::correction::ImageCorrection {
            glint_threshold_per_sr: 1.0,
            ..shoal::correction::ImageCorrection::default()
        });
    }
    c.validate().unwrap();
    c
}

/// Hashes of a run's products (name, hash of the exact bits).
type Fingerprint = Vec<(String, u64)>;

/// What a run produces, product by product, as hashes of the exact bits.
fn fingerprint(out: &RunOutput) -> Fingerprint {
    fn h<T: Hash + ?Sized>(v: &T) -> u64 {
        let mut s = std::hash::DefaultHasher::new();
        v.hash(&mut s);
        s.finish()
    }
    let bits = |a: &ndarray::Array3<f32>| h(&a.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    let bits2 = |a: &ndarray::Array2<f32>| h(&a.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    let mut f = vec![
        ("pupil radiance".to_string(), bits(&out.kept().radiance.radiance)),
        ("true Rrs".into(), bits(&out.kept().radiance.truth_rrs)),
        ("true chl".into(), bits2(&out.truth.chl_mg_m3)),
        ("level-0 DN".into(), h(&out.kept().level0.dn.iter().collect::<Vec<_>>())),
        ("level-0 flags".into(), h(&out.kept().level0.flags.iter().collect::<Vec<_>>())),
        ("level-1".into(), bits(&out.kept().level1.radiance)),
        ("Rrs".into(), bits(&out.kept().rrs.rrs)),
        ("Rrs flags".into(), h(&out.kept().rrs.flags.iter().collect::<Vec<_>>())),
        ("correction diagnostics".into(), h(&format!("{:?}", out.report.approximation))),
        ("SNR".into(), h(&format!("{:?}", out.snr))),
        ("warnings".into(), h(&format!("{:?}", out.report.warnings))),
    ];
    for r in &out.retrievals {
        let p = &r.product;
        f.push((
            format!("{} maps", p.name),
            h(&format!("{:?}", (&p.chl_mg_m3, &p.nap_g_m3, &p.cdom_per_m, &p.depth_m))),
        ));
        f.push((
            format!("{} rest", p.name),
            h(&format!("{:?}", (&p.substrate_fractions, &p.siop_set, &p.cost, &p.flags, &p.iterations, &p.sdi))),
        ));
        f.push((format!("{} metrics", p.name), h(&format!("{:?}", r.metrics))));
        f.push((format!("{} failure", p.name), h(&r.failure)));
    }
    f
}

fn fresh(config: &RunConfig) -> Fingerprint {
    fingerprint(&Engine::new().run(config, &RunControl::new()).unwrap())
}

/// Products that differ between two fingerprints.
fn differing(a: &[(String, u64)], b: &[(String, u64)]) -> Vec<String> {
    if a.len() != b.len() {
        return vec![format!("{} products against {}", a.len(), b.len())];
    }
    a.iter().zip(b).filter(|(x, y)| x != y).map(|(x, _)| x.0.clone()).collect()
}

/// Values inside `range` near `current` (so the run stays small), in the order to try: one
/// more or one fewer for counts, 10 % more or less otherwise (1 % of the span around 0).
fn other_values(range: &Range, current: f64) -> Vec<f64> {
    let candidates = if range.whole {
        [current + 1.0, current - 1.0]
    } else if current == 0.0 {
        let step = 0.01 * (range.hi - range.lo);
        [current + step, current - step]
    } else {
        [current * 1.1, current / 1.1]
    };
    candidates.into_iter().filter(|v| range.contains(*v)).collect()
}

/// Field-specific values where a quarter of the way would not reach the code path (clamped or
/// capped by the small image, or a bound the base sits at).
fn chosen_value(path: &str) -> Option<f64> {
    Some(match path {
        // Clamped to the 16 detectors of the base: any value above 16 is the same patch.
        "fidelity.snr_detectors" => 6.0,
        // Decimation 2: a preview of the 16 × 12 image.
        "fidelity.decimation" => 2.0,
        // Orders: the base converges in fewer than the default cap; a cap of 2 stops it early.
        "scene.atmosphere.accuracy.max_orders" => 2.0,
        // A well and an ADC only act when they clip: 2000 e-, or 10 bits at 3 e-/DN (3069 e-),
        // are below the base's brightest water signal; 10 % changes are not.
        "instrument.well_depth_e" => 2000.0,
        "instrument.adc_bits" => 10.0,
        // Fourier terms: the azimuthal series is complete before the default's 24 terms; two
        // terms cut it.
        "scene.atmosphere.accuracy.fourier_terms" => 2.0,
        // A further plane's pitch must tile the grid: three times the first's.
        "instrument.focal_planes[].pixel_pitch_um" => 46.5,
        // The aerosol pair's long band (its `pair_nm.1`): 900 nm is the CubeSat's Oa19, where a
        // quarter of the way to 2500 nm would be a band it lacks.
        "correction.image.pair_nm" => 900.0,
        // An AOT node (its `aot_nodes.2`, 0.2) moved within its neighbours 0.1 and 0.4.
        "correction.image.aot_nodes" => 0.15,
        // l2gen's 0.005 sr⁻¹ against the base's 1: every pixel of the base is above it.
        "correction.image.glint_threshold_per_sr" => 0.005,
        // The processor's wind 2 m/s stronger than the base's 5 m/s: it takes away more glint.
        "correction.image.glint_wind_error_m_s" => 2.0,
        // The same for the base's exact correction.
        "correction.glint_wind_error_m_s" => 2.0,
        // l2gen's 0.005 sr⁻¹ where the base's exact correction masks nothing (unset).
        "correction.glint_threshold_per_sr" => 0.005,
        // Above the clouds' albedo (0.72): no cloud is screened.
        "correction.image.clouds.threshold" => 0.9,
        // Shadows projected from the base clouds' own 300 m, where the default 1500 m puts every
        // projected shadow off the 16 × 12 image.
        "correction.image.clouds.height_m" => 300.0,
        // Dark-spectrum fitting over the 16 × 12 image: 8-pixel tiles (2 × 2 where the default
        // is one scene-wide tile); 20 darkest pixels where the default's 200 take them all; a
        // gas threshold of 0.99 and a band range starting at 770 nm, each leaving out bands the
        // default fits (its two lowest-AOT bands are below 800 nm here).
        "correction.image.dark.tile_px" => 8.0,
        "correction.image.dark.pixels" => 20.0,
        "correction.image.dark.min_gas_transmittance" => 0.99,
        "correction.image.dark.wave_range_nm" => 770.0,
        // SAMBUCA's fits converge in fewer than 100 iterations; 3 stops them early.
        "retrievals[i].Sambuca.settings.max_iterations" => 3.0,
        // Under the base program's 3 s.
        "retrievals[i].External.time_limit_s" => 1.0,
        // A CTE spans 0.99–1: 10 % either side of the base's 0.9999 leaves the range.
        "instrument.effects[].Tdi.cte" => 0.999,
        _ => return None,
    })
}

/// `config` with the field at `path` set to `value` (map values as constant maps).
fn set(config: &RunConfig, path: &str, value: f64) -> RunConfig {
    try_set(config, path, value).unwrap()
}

/// [`set`], or why `config` has no field at `path` (a wind speed over a flat surface, a
/// mixture's fraction under a WMO model, a setting of a correction that is off).
fn try_set(config: &RunConfig, path: &str, value: f64) -> Result<RunConfig, String> {
    let mut c = config.clone();
    let m = MapSpec::Constant(value);
    match path {
        "scene.chl_mg_m3" => c.scene.chl_mg_m3 = m,
        "scene.nap_g_m3" => c.scene.nap_g_m3 = m,
        "scene.cdom_per_m" => c.scene.cdom_per_m = m,
        "scene.depth_m" => c.scene.depth_m = Some(m),
        "scene.aot550_map" => c.scene.aot550_map = Some(m),
        "scene.substrates[i].fraction" => c.scene.substrates[0].fraction = m,
        // A spectrum's values: the land's reflectance, constant over wavelength.
        "scene.land.reflectance" => {
            if let Some(land) = &mut c.scene.land {
                land.reflectance = SpectrumSource::Constant(value);
            }
        }
        // A formula spectrum's reference wavelength: the detector's QE as a power law about it.
        "spectrum.reference_nm" => {
            c.instrument.quantum_efficiency =
                SpectrumSource::PowerLaw { coefficient: 0.7, reference_nm: value, exponent: 0.2 };
        }
        _ => {
            c = shoal::sweep::apply(config, &[(&sweep_path(path), value)]).map_err(|e| e.to_string())?;
        }
    }
    Ok(c)
}

/// The value of a numeric field in `config` (maps: the value their constant would take).
fn current(config: &RunConfig, path: &str) -> f64 {
    if path == "spectrum.reference_nm" {
        return 550.0;
    }
    let tree = serde_json::to_value(config).unwrap();
    let mut node = &tree;
    for key in sweep_path(path).split('.') {
        node = match node {
            serde_json::Value::Array(items) => &items[key.parse::<usize>().unwrap()],
            other => match other.get(key) {
                Some(n) => n,
                None => return 1.0, // a map (not a number): any constant differs from it
            },
        };
    }
    node.as_f64().unwrap_or(1.0)
}

#[test]
fn every_range_field_changes_the_output_or_is_documented_and_the_cache_follows() {
    let mut checked = 0;
    let mut documented_count = 0;
    let mut not_run_inputs = 0;
    let mut failures = Vec::new();
    // One cached engine per base instrument, with its base run's fingerprint.
    let mut engines: Vec<(String, Engine, Fingerprint)> = Vec::new();
    for range in ranges::ALL {
        if range.path.starts_with("requirements.") || range.path.starts_with("atmosphere_run.") {
            // Study thresholds (see NO_EFFECT) and `shoal atmosphere`'s own inputs: not a run's.
            not_run_inputs += 1;
            continue;
        }
        let config = base(range.path);
        // One cached engine per base instrument, warmed on its base run.
        let adjacency = if config.scene.effects.contains(&Effect::Adjacency) { "" } else { " without adjacency" };
        let image = config.correction.image().map_or(String::new(), |i| format!(" image-corrected, {}", i.label()));
        let aerosol = config.scene.atmosphere.aerosol.name();
        let effects = if config.instrument.effects.is_empty() { "" } else { " with optical effects" };
        let clouds = if config.scene.clouds.is_some() { " under clouds" } else { "" };
        let key = format!(
            "{}{adjacency}{image}{effects}{clouds}, {aerosol}, {} retrievals",
            config.instrument.name,
            config.retrievals.len()
        );
        if !engines.iter().any(|(k, _, _)| *k == key) {
            let mut e = Engine::new();
            let before = fingerprint(&e.run(&config, &RunControl::new()).unwrap());
            engines.push((key.clone(), e, before));
        }
        let (_, engine, before) = engines.iter_mut().find(|(k, _, _)| *k == key).unwrap();
        // The first nearby value the configuration accepts (a cross-field rule may refuse one).
        let tries =
            chosen_value(range.path).map_or_else(|| other_values(range, current(&config, range.path)), |v| vec![v]);
        let Some((value, edited)) =
            tries.into_iter().map(|v| (v, set(&config, range.path, v))).find(|(_, c)| c.validate().is_ok())
        else {
            failures.push(format!("{}: no nearby value is accepted", range.path));
            continue;
        };
        let cached = fingerprint(&engine.run(&edited, &RunControl::new()).unwrap());
        let truth = fresh(&edited);
        let stale = differing(&cached, &truth);
        if !stale.is_empty() {
            failures.push(format!("{} = {value}: the cached engine served stale {stale:?}", range.path));
        }
        match (differing(&truth, before).is_empty(), documented(range.path)) {
            (true, None) => failures.push(format!(
                "{} = {value} changed nothing a run produces (list it in NO_EFFECT with the reason, or find why)",
                range.path
            )),
            (false, Some(why)) => {
                failures.push(format!("{} = {value} changed the output, but NO_EFFECT says: {why}", range.path))
            }
            (true, Some(_)) => documented_count += 1,
            (false, None) => checked += 1,
        }
        // Back to the base: the cache must serve the base again, exactly.
        let back = fingerprint(&engine.run(&config, &RunControl::new()).unwrap());
        let changed = differing(&back, before);
        if !changed.is_empty() {
            failures.push(format!("{}: returning to the base is not the base ({changed:?})", range.path));
        }
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures.join("\n"));
    eprintln!(
        "coherence: {checked} range fields change the output; {documented_count} checked to change nothing \
         (NO_EFFECT); {not_run_inputs} are study thresholds or `shoal atmosphere` inputs, not run inputs"
    );
    assert_eq!(checked + documented_count + not_run_inputs, ranges::ALL.len());
    assert!(checked >= 60, "only {checked} fields checked");
}

#[test]
fn every_enum_and_list_field_changes_the_output_and_the_cache_follows() {
    let config = base("");
    let mut engine = Engine::new();
    let before = fingerprint(&engine.run(&config, &RunControl::new()).unwrap());
    let edits = structural_edits();
    for (what, edit) in &edits {
        let mut edited = config.clone();
        edit(&mut edited);
        edited.validate().unwrap_or_else(|e| panic!("{what}: {e}"));
        let cached = fingerprint(&engine.run(&edited, &RunControl::new()).unwrap());
        let truth = fresh(&edited);
        let stale = differing(&cached, &truth);
        assert!(stale.is_empty(), "{what}: the cached engine served stale {stale:?}");
        let changed = !differing(&truth, &before).is_empty();
        match documented(what) {
            None => assert!(changed, "{what} changed nothing a run produces"),
            Some(why) => assert!(!changed, "{what} changed the output, but NO_EFFECT says: {why}"),
        }
    }
    assert!(edits.len() >= 25);
}

/// Random sequences of edits (range fields at random allowed values, and the structural edits)
/// through one cached engine: after every edit its output equals a fresh engine's, bit for bit.
#[test]
fn a_cached_engine_after_random_edits_matches_a_fresh_engine() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(16);
    // Random values near the current one (a factor 0.5–2, or ±2 for counts): far-off values of
    // sizes (detectors, scene cells, streams) would make single runs minutes long.
    let fields: Vec<&Range> = ranges::ALL
        .iter()
        .filter(|r| documented(r.path).is_none() && !r.path.contains("kind.") && r.path != "fidelity.decimation")
        .collect();
    let edits = structural_edits();
    let mut config = base("");
    let mut engine = Engine::new();
    let steps = 24;
    for step in 0..steps {
        let what = if rng.random_bool(0.7) {
            let range = fields[rng.random_range(0..fields.len())];
            let now = current(&config, range.path);
            let mut v = if range.whole {
                now + f64::from(rng.random_range(-2i32..=2))
            } else if now == 0.0 {
                range.lo + 0.05 * (range.hi - range.lo) * rng.random::<f64>()
            } else {
                now * 2f64.powf(rng.random_range(-1.0..1.0))
            };
            if !range.contains(v) || v == now {
                let Some(&near) = other_values(range, now).first() else { continue };
                v = near;
            }
            // A field this configuration does not have, or a cross-field rule (e.g. a detector
            // count the image cannot hold): another step.
            let Ok(next) = try_set(&config, range.path, v) else { continue };
            if next.validate().is_err() {
                continue;
            }
            config = next;
            format!("{} = {v}", range.path)
        } else {
            let (what, edit) = &edits[rng.random_range(0..edits.len())];
            let mut next = config.clone();
            edit(&mut next);
            if next.validate().is_err() {
                continue;
            }
            config = next;
            (*what).to_string()
        };
        let Ok(out) = engine.run(&config, &RunControl::new()) else {
            // An edit the chain refuses at run time must be refused by a fresh engine too.
            assert!(Engine::new().run(&config, &RunControl::new()).is_err(), "step {step} ({what})");
            continue;
        };
        let stale = differing(&fingerprint(&out), &fresh(&config));
        assert!(stale.is_empty(), "step {step} ({what}): stale {stale:?}");
    }
}
