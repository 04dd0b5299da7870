//! What a run will ask of the machine, known before it starts: the bytes of its cubes, maps and
//! rasters and the work of its radiative transfer, against a budget. A run that would not fit is
//! refused at validation with one line naming the fields that drive it and what would fit —
//! instead of an allocation failure (an abort) minutes in, or a run that never ends.
//!
//! The estimate is an upper bound built from the products' element types (a pixel-band of the
//! chain holds radiance, the truth's Rrs, Level-0 counts and flags, Level-1, Rrs and their flags)
//! and the scene's stored maps; `shoal bench` and the tests hold it against measured peaks.
//!
//! The budget it is held to is [`crate::budget::MachineBudget`].

use crate::atmosphere::{AtmosphereSpec, RtAccuracy};
use crate::budget::{Demand, Lever, Part};
use crate::correction::ImageCorrection;
use crate::instrument::InstrumentKind;
use crate::scene::{Georeference, MapSpec, SceneSpec};

use super::RunConfig;

/// Bytes a run holds per pixel and band: radiance, truth Rrs, Level-1 and Rrs (f32 each), the
/// Level-0 counts (u16), three flag planes (u8), and the analogue signal when kept (f32) — 24 —
/// plus the stages' working copies while they run (measured: the default study peaks at 30 per
/// pixel-band; see the tests).
const BYTES_PER_PIXEL_BAND: f64 = 36.0;
/// Bytes a run holds per pixel beyond its bands: the truth's maps, the retrievals' products and
/// flags, the view geometry of each column.
const BYTES_PER_PIXEL: f64 = 160.0;
/// Bytes per scene cell of a stored map (f32), and the peak while a random field is synthesised
/// (complex f32 spectrum, its transpose, the field).
const BYTES_PER_CELL_MAP: f64 = 4.0;
const BYTES_PER_CELL_RANDOM_FIELD: f64 = 20.0;
/// Seconds of radiative transfer per unit of work (layers × streams² × Fourier terms × orders,
/// orders counted up to [`ORDERS_COUNTED`]), fitted to LUT build times of the Lake Hume scene on
/// the 2-core machine of `shoal bench` (0.04 s at the defaults, 0.49 s with layers of 0.0005,
/// 5.0 s at 48 streams, 96 terms and layers of 0.002) and rounded up, so the plan overestimates
/// those by 1.3–3.5×.
const SECONDS_PER_RT_WORK: f64 = 1e-9;
/// Orders the successive-orders solver runs at most in practice: it stops when an order adds less
/// than `order_tolerance`, within a few tens of orders for any atmosphere Shoal accepts.
const ORDERS_COUNTED: f64 = 100.0;
/// Wavelength nodes a LUT build solves (the fit of `SECONDS_PER_RT_WORK` is per build);
/// `shoal atmosphere` solves one column per wavelength it prints. With 20, the plan
/// overestimates `shoal atmosphere`'s measured time on its default grid by 1.3–2× (default and
/// high accuracy, AOT 0.1 and 2, on the machine of `shoal bench`).
const LUT_NODES: f64 = 20.0;
/// A fixed part of every LUT build, s.
const RT_OVERHEAD_S: f64 = 0.05;
/// Bytes per level and pair of quadrature streams the solver holds while it solves a Fourier
/// term: the level's mixed scattering kernel, one 3 × 3 Stokes block of f64 per stream pair
/// (`atmosphere::sos::solve`); the fields per level and stream are smaller by a factor of streams.
const RT_BYTES_PER_LEVEL_STREAM_PAIR: f64 = 72.0;
/// Bytes per pixel and band of a run that does not keep its cubes, at its peak: the pupil
/// radiance and the true Rrs while the radiance stage makes them (4 + 4; the run then keeps
/// only the true Rrs its comparisons read, `correction::TruthRrsSample`, and lets the cube go),
/// the radiance and the Level-0 counts and flags while the detector reads out (4 + 3), the
/// counts and the Level-1 (which takes the Level-0's flags) while it is calibrated (2 + 5);
/// every correction writes its Rrs over the Level-1. Rounded up for the stages' working copies.
/// Measured peaks (VmHWM, `shoal study --no-cubes`): the default study 0.53 GiB (plan 0.71),
/// `four_designs_lake_hume` 1.71 GiB (plan 1.85), Sentinel-2 MSI alone (16 million pixels) 2.20
/// GiB (plan 3.03).
const LEAN_BYTES_PER_PIXEL_BAND: f64 = 9.0;
/// What a lean run adds per pixel and band where Level-0 keeps the analogue signal beside the
/// counts (quantisation off: the ideal-ADC closure setting), f32.
const ANALOG_BYTES_PER_PIXEL_BAND: f64 = 4.0;
/// Bytes per pixel and band an instrument's optical effects add (`instrument::effects`): the
/// radiance at the detector, then the measured Level-1 and its stray part while the processor
/// corrects it.
const EFFECTS_BYTES_PER_PIXEL_BAND: f64 = 8.0;
/// Bytes per pixel of a lean run beyond its bands: its truth maps (13), its products as they are
/// made and the retrieval's rows before they are joined (about 45), an image-based correction's
/// aerosol maps (AOT and Ångström: 8, and the band pair's ε and long-band signal while the fit
/// runs: 8), rounded up.
const LEAN_BYTES_PER_PIXEL: f64 = 80.0;
/// Bytes per pixel a study keeps of each run until its tables and figures are written: the
/// truth's maps (chl, NAP, CDOM, depth, three substrate fractions, surface: at most 29) and an
/// image-based correction's aerosol maps (8), with [`PRODUCT_BYTES_PER_PIXEL`] per retrieval.
const KEPT_BYTES_PER_PIXEL: f64 = 40.0;
/// Bytes per pixel of one retrieval's products: aLMI's three maps, cost, SIOP set and flags (19),
/// SAMBUCA's depth, three substrate fractions, cost, SDI, iterations and flags (27), rounded up
/// for a retrieval's extra maps.
const PRODUCT_BYTES_PER_PIXEL: f64 = 32.0;

/// The part that is the random fields' synthesis: held while the scene is built, before any cube.
const SYNTHESIS: &str = "the scene's random-field synthesis (while the scene is built)";

/// Bands an instrument will have (without reading its band files).
fn band_count(kind: &InstrumentKind) -> usize {
    kind.model().band_count()
}

/// The scene's stored maps and their peak while built.
fn scene_parts(scene: &SceneSpec, parts: &mut Vec<Part>) {
    let cells = (scene.width as f64) * (scene.height as f64);
    let mut maps: Vec<&MapSpec> = vec![&scene.chl_mg_m3, &scene.nap_g_m3, &scene.cdom_per_m];
    maps.extend(scene.depth_m.as_ref());
    maps.extend(scene.substrates.iter().map(|s| &s.fraction));
    maps.extend(scene.land.as_ref().map(|l| &l.mask));
    let stored = maps
        .iter()
        .filter(|m| matches!(m, MapSpec::RandomField { .. } | MapSpec::Image { .. } | MapSpec::Raster { .. }))
        .count();
    let random = maps.iter().any(|m| matches!(m, MapSpec::RandomField { .. }));
    let transient = if random { BYTES_PER_CELL_RANDOM_FIELD } else { 0.0 };
    if stored > 0 {
        let lever = Lever::SceneGrid { width: scene.width, height: scene.height };
        let fields = "scene.width, scene.height (or the georeference raster's grid)";
        parts.push(Part {
            what: format!("scene maps ({stored} stored, {} × {} cells)", scene.width, scene.height),
            bytes: cells * stored as f64 * BYTES_PER_CELL_MAP,
            fields,
            lever,
        });
        if transient > 0.0 {
            parts.push(Part { what: SYNTHESIS.into(), bytes: cells * transient, fields, lever });
        }
    }
    if matches!(scene.georeference, Some(Georeference::Raster(_)))
        || maps.iter().any(|m| matches!(m, MapSpec::Raster { .. }))
    {
        // A raster is read whole (as f64) once; its size is known when its header is read, and
        // the reader refuses one larger than the budget's share then ([`raster_limit_samples`]).
        parts.push(Part {
            what: "the scene's rasters (checked when read)".into(),
            bytes: 0.0,
            fields: "the raster files",
            lever: Lever::SceneGrid { width: scene.width, height: scene.height },
        });
    }
}

/// Optical depth of a column as the solver layers it, an upper bound: Rayleigh at the shortest
/// wavelength (~1.2 at 325 nm, sea level) plus the aerosol's (its τ at 550 nm, up to ×3 in the
/// UV).
fn column_depth(aot550: f64) -> f64 {
    1.3 + 3.0 * aot550
}

/// Layers the solver makes of a column with aerosol `aot550`.
fn layers(acc: &RtAccuracy, aot550: f64) -> f64 {
    (column_depth(aot550) / acc.max_layer_depth).ceil().max(acc.min_layers as f64)
}

/// Planned seconds of one radiative-transfer solve of a column with aerosol `aot550` at the
/// nodes of a LUT: each successive order of scattering visits every layer, stream pair and
/// Fourier term, once per wavelength node; the fit (`SECONDS_PER_RT_WORK`) absorbs the nodes.
fn rt_seconds(acc: &RtAccuracy, aot550: f64) -> f64 {
    let streams = acc.streams as f64;
    let orders = (acc.max_orders as f64).min(ORDERS_COUNTED);
    RT_OVERHEAD_S + layers(acc, aot550) * streams * streams * acc.fourier_terms as f64 * orders * SECONDS_PER_RT_WORK
}

/// Planned seconds of the atmosphere's radiative transfer: the scene's atmosphere, and the
/// image-based correction's family when there is one.
#[must_use]
pub fn atmosphere_seconds(config: &RunConfig) -> f64 {
    let acc = &config.scene.atmosphere.accuracy;
    rt_seconds(acc, config.scene.atmosphere.aot550) + config.correction.image().map_or(0.0, |i| family_seconds(acc, i))
}

/// The image-based correction's family: one more atmosphere per model and AOT node, and the
/// shared Rayleigh one; their columns are no deeper than the family's largest AOT.
fn family_seconds(acc: &RtAccuracy, image: &ImageCorrection) -> f64 {
    let deepest = image.aot_nodes.iter().copied().fold(0.0, f64::max);
    (image.models.len() * image.aot_nodes.len() + 1) as f64 * rt_seconds(acc, deepest)
}

/// The solver's memory: per level, the scattering kernel of every pair of quadrature streams
/// (2·streams per hemisphere pair), on each worker thread solving a Fourier term.
fn rt_part(acc: &RtAccuracy, aot550: f64) -> Part {
    let layers = layers(acc, aot550);
    let quadrature = 2.0 * acc.streams as f64;
    let threads = rayon::current_num_threads() as f64;
    Part {
        what: format!("radiative transfer ({layers:.0} layers, {} streams)", acc.streams),
        bytes: (layers + 1.0) * quadrature * quadrature * RT_BYTES_PER_LEVEL_STREAM_PAIR * threads,
        fields: "scene.atmosphere.accuracy.max_layer_depth, streams",
        lever: Lever::Layers,
    }
}

fn atmosphere_part(config: &RunConfig) -> Part {
    rt_part(&config.scene.atmosphere.accuracy, config.scene.atmosphere.aot550)
}

/// What `shoal atmosphere` will ask for: `solves` wavelengths, each a radiative transfer solve
/// of `spec`'s column at one wavelength (a LUT build solves [`LUT_NODES`] of them).
#[must_use]
pub fn atmosphere_command_demand(spec: &AtmosphereSpec, solves: usize) -> Demand {
    let one = rt_seconds(&spec.accuracy, spec.aot550) - RT_OVERHEAD_S;
    Demand {
        parts: vec![rt_part(&spec.accuracy, spec.aot550)],
        atmosphere_s: RT_OVERHEAD_S + one * solves as f64 / LUT_NODES,
    }
}

/// What `shoal correct` will ask for: the scene it reads the atmosphere from, the family's
/// radiative transfer, and its tables for `rows` spectra of `bands` bands (16 atmospheres × 3
/// terms × 8 bytes per row and band).
#[must_use]
pub fn correct_demand(scene: &SceneSpec, image: &ImageCorrection, rows: usize, bands: usize) -> Demand {
    let mut parts = Vec::new();
    scene_parts(scene, &mut parts);
    let deepest = image.aot_nodes.iter().copied().fold(0.0, f64::max);
    parts.push(rt_part(&scene.atmosphere.accuracy, deepest));
    let atmospheres = (image.models.len() * image.aot_nodes.len() + 1) as f64;
    parts.push(Part {
        what: format!("the correction's tables ({rows} spectra × {bands} bands)"),
        bytes: rows as f64 * bands as f64 * atmospheres * 3.0 * 8.0,
        fields: "the --toa rows, correction.image.models, aot_nodes",
        lever: Lever::Image { rows, columns: 1, decimation: 1 },
    });
    Demand { parts, atmosphere_s: family_seconds(&scene.atmosphere.accuracy, image) }
}

/// What `config` will ask for, alone, run by an engine that keeps its cubes.
#[must_use]
pub fn run_demand(config: &RunConfig) -> Demand {
    run_demand_keeping(config, true)
}

/// What `config` will ask for, alone: run by an engine that keeps its cubes (`keep_cubes`) or by
/// a lean one, which holds a cube only until the next stage has read it.
#[must_use]
pub fn run_demand_keeping(config: &RunConfig, keep_cubes: bool) -> Demand {
    // The instrument as flown: a binned one simulates its binned pixels.
    let flown = config.flown();
    let config: &RunConfig = &flown;
    let mut parts = Vec::new();
    scene_parts(&config.scene, &mut parts);
    parts.push(atmosphere_part(config));
    parts.push(if keep_cubes {
        cube_part(config, BYTES_PER_PIXEL_BAND)
    } else {
        cube_part_with(config, lean_bytes_per_pixel_band(config), LEAN_BYTES_PER_PIXEL)
    });
    // The scene's synthesis is over before the cubes are made: the larger of the two counts.
    if let Some(i) = parts.iter().position(|p| p.what == SYNTHESIS) {
        let cubes = parts.last().map_or(0.0, |p| p.bytes);
        if parts[i].bytes <= cubes {
            parts.remove(i);
        } else {
            parts.pop();
        }
    }
    Demand { parts, atmosphere_s: atmosphere_seconds(config) }
}

/// The pixels a run simulates: its lines and detectors at its decimation, cropped to those that
/// can look at the scene (the geometry stage drops the others): at most the scene's diagonal
/// over the ground sampling distance (altitude · pitch / focal length) along each axis.
fn image_size(config: &RunConfig) -> (usize, usize) {
    let i = &config.instrument;
    let d = config.fidelity.decimation.max(1);
    let s = &config.scene;
    let gsd_m = i.altitude_km * 1e3 * i.pixel_pitch_um * 1e-6 / (i.focal_length_mm * 1e-3);
    let diagonal_m = (s.width as f64 * s.cell_m).hypot(s.height as f64 * s.cell_m);
    let across = if gsd_m > 0.0 && diagonal_m > 0.0 { (diagonal_m / gsd_m).ceil() as usize + 2 } else { usize::MAX };
    (i.lines.min(across).div_ceil(d), i.detectors.min(across).div_ceil(d))
}

/// Bytes per pixel and band of `config`'s run at its peak when it keeps no cubes.
fn lean_bytes_per_pixel_band(config: &RunConfig) -> f64 {
    let analog = if config.detector.quantise { 0.0 } else { ANALOG_BYTES_PER_PIXEL_BAND };
    LEAN_BYTES_PER_PIXEL_BAND + analog
}

fn cube_part(config: &RunConfig, bytes_per_pixel_band: f64) -> Part {
    cube_part_with(config, bytes_per_pixel_band, BYTES_PER_PIXEL)
}

fn cube_part_with(config: &RunConfig, bytes_per_pixel_band: f64, bytes_per_pixel: f64) -> Part {
    let i = &config.instrument;
    let (rows, cols) = image_size(config);
    let bands = band_count(&i.kind);
    let pixels = rows as f64 * cols as f64;
    // Optical effects: the radiance at the detector beside the pupil's, and the processor's
    // copy of Level-1 with its stray part while it corrects (f32 each).
    let effects =
        if !crate::instrument::effects::any_on_the_cube(&i.effects) { 0.0 } else { EFFECTS_BYTES_PER_PIXEL_BAND };
    Part {
        what: format!("cubes of {} ({rows} × {cols} pixels × {bands} bands)", i.name),
        bytes: pixels * (bands as f64 * (bytes_per_pixel_band + effects) + bytes_per_pixel),
        fields: "instrument.lines, instrument.detectors, the bands, fidelity.decimation",
        lever: Lever::Image { rows, columns: cols, decimation: config.fidelity.decimation.max(1) },
    }
}

/// Bytes of `config`'s pupil radiance product as the cache counts it (the radiance and the true
/// Rrs, f32 per pixel and band, and the truth's maps): what a study with several seeds keeps
/// cached so that each seed after the first reuses it.
#[must_use]
pub fn radiance_bytes(config: &RunConfig) -> usize {
    let (rows, cols) = image_size(config);
    let pixels = rows as f64 * cols as f64;
    (pixels * (band_count(&config.instrument.kind) as f64 * 8.0 + 16.0)) as usize
}

/// What a study's runs ask for together. The runs are made one at a time by a lean engine
/// ([`super::Engine::lean`]): the largest run's working set (its cubes as the stages hand them
/// on, all of them when `keep_cubes`, to be written), the products and truth maps every run
/// leaves behind until the tables and figures are written, the engine's bounded cache, and the
/// largest scene and atmosphere (built one at a time).
#[must_use]
pub fn study_demand(configs: &[&RunConfig], keep_cubes: bool, cache_bytes: usize) -> Demand {
    let mut demand = Demand::default();
    for c in configs {
        let one = run_demand(c);
        demand.atmosphere_s = demand.atmosphere_s.max(one.atmosphere_s);
        let shared: Vec<Part> = one.parts.into_iter().filter(|p| !p.what.starts_with("cubes")).collect();
        if shared.iter().map(|p| p.bytes).sum::<f64>() > demand.bytes() {
            demand.parts = shared;
        }
    }
    // The largest run at work: its cubes as the stages hand them on (all of them when kept, to
    // be written) and its products as they are made.
    let part = |c: &RunConfig| {
        if keep_cubes {
            cube_part_with(c, BYTES_PER_PIXEL_BAND, BYTES_PER_PIXEL)
        } else {
            cube_part_with(c, lean_bytes_per_pixel_band(c), LEAN_BYTES_PER_PIXEL)
        }
    };
    let largest = configs.iter().enumerate().max_by(|(_, a), (_, b)| part(a).bytes.total_cmp(&part(b).bytes));
    let largest = largest.map(|(i, c)| (i, part(c)));
    // The products and truth maps every other run leaves behind.
    for (i, c) in configs.iter().enumerate() {
        if largest.as_ref().is_some_and(|(l, _)| *l == i) {
            continue;
        }
        let (rows, cols) = image_size(c);
        let kept = KEPT_BYTES_PER_PIXEL + c.retrievals.len() as f64 * PRODUCT_BYTES_PER_PIXEL;
        demand.parts.push(Part {
            what: format!("the products and truth maps of {} ({rows} × {cols} pixels)", c.instrument.name),
            bytes: rows as f64 * cols as f64 * kept,
            ..cube_part(c, 0.0)
        });
    }
    if let Some((_, run)) = largest {
        // The scene's synthesis is over before the first run starts: the larger of the two counts.
        if let Some(i) = demand.parts.iter().position(|p| p.what == SYNTHESIS) {
            if demand.parts[i].bytes <= run.bytes {
                demand.parts.remove(i);
                demand.parts.push(run);
            }
        } else {
            demand.parts.push(run);
        }
    }
    demand.parts.push(Part {
        what: "the engine's cache".into(),
        bytes: cache_bytes as f64,
        fields: "",
        lever: Lever::Files,
    });
    demand
}

/// The app's window, map rasters and textures, bytes (see [`app_demand`]).
const APP_WINDOW_BYTES: f64 = 0.35 * 1024.0 * 1024.0 * 1024.0;

/// What the app holds for `configs` at full resolution ([`super::Engine::for_app`]): each design's
/// views of its cubes (its share of [`super::views::ALL_VIEW_BYTES`]) and its products and truth
/// maps, the largest run at work, and the cache (`cache_bytes`, less what a run takes of
/// [`super::worker::APP_RUN_ENVELOPE_BYTES`]: the most a run and the cache hold together).
#[must_use]
pub fn app_demand(configs: &[&RunConfig], cache_bytes: usize) -> Demand {
    let working = |c: &RunConfig| run_demand_keeping(c, false).bytes();
    let largest = configs.iter().map(|c| working(c)).fold(0.0, f64::max);
    let envelope = super::worker::APP_RUN_ENVELOPE_BYTES as f64;
    // A run and the cache beside it: the cache keeps what the envelope leaves of the run's
    // working set (nothing beside the largest runs, up to `cache_bytes` beside small ones).
    let together = configs
        .iter()
        .map(|c| working(c) + (cache_bytes as f64).min((envelope - working(c)).max(0.0)))
        .fold(0.0, f64::max);
    let cache = together - largest;
    let mut demand = study_demand(configs, false, 0);
    // The window itself: 0.16 GB resident before the first result (measured, 1920 × 1080), and
    // the map panels' rasters and textures beside it.
    demand.parts.push(Part {
        what: "the app's window, its map rasters and textures".into(),
        bytes: APP_WINDOW_BYTES,
        fields: "",
        lever: Lever::Files,
    });
    if let Some(p) = demand.parts.iter_mut().find(|p| p.what == "the engine's cache") {
        p.bytes = cache;
    }
    let share = super::views::view_bytes_per_run(configs.len());
    for c in configs {
        let flown = c.flown();
        let (rows, cols) = image_size(&flown);
        let bands = band_count(&flown.instrument.kind);
        let stride = super::views::stride_for(rows, cols, bands, share);
        let kept = rows.div_ceil(stride) * cols.div_ceil(stride) * bands * super::views::VIEW_BYTES_PER_PIXEL_BAND;
        demand.parts.push(Part {
            what: format!("the views of {}'s cubes (every {stride} pixels)", c.instrument.name),
            bytes: kept as f64,
            ..cube_part(&flown, 0.0)
        });
    }
    demand
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::{DEFAULT_ATMOSPHERE_S, MachineBudget};

    fn default_runs() -> Vec<RunConfig> {
        let study = crate::study::StudySpec::default_study().unwrap_or_else(|e| panic!("{e}"));
        study.resolve(None).unwrap_or_else(|e| panic!("{e}")).runs.into_iter().map(|r| r.2).collect()
    }

    #[test]
    fn the_default_study_fits_and_its_estimate_bounds_the_measured_peak() {
        let runs = default_runs();
        let demand = study_demand(&runs.iter().collect::<Vec<_>>(), false, crate::engine::LEAN_CACHE_BYTES);
        // Measured on `shoal study --no-cubes` at full resolution: 0.53 GiB peak resident (the
        // study prints it; tests/chain/memory.rs holds it under 1 GiB). The estimate is an upper
        // bound within a factor 1.6 (it plans for the working copies).
        let gb = demand.bytes() / 1024.0_f64.powi(3);
        assert!((0.53..0.53 * 1.6).contains(&gb), "{gb} GB: {demand:?}");
        assert!(gb < 1.0, "the default study is planned within 1 GiB: {gb}");
        assert!(demand.atmosphere_s < 60.0, "{}", demand.atmosphere_s);
        let budget = MachineBudget { memory_bytes: 14e9, atmosphere_s: DEFAULT_ATMOSPHERE_S };
        assert!(budget.check(&demand).is_ok());
    }

    #[test]
    fn the_app_plans_eight_designs_as_an_upper_bound_of_their_measured_peak() {
        // The app with the four designs of `four_designs_lake_hume` and four more from the
        // library (OLCI for the 10 m MSI, whose 16 Mpx run alone takes ~2.2 GiB): measured at
        // 3.50–3.51 GiB peak resident at full resolution (VmHWM, 1920 × 1080 under Xvfb, the
        // cache filling the envelope beside the spectrograph's run). The plan is an upper bound
        // within 1.2× of it.
        let mut runs = default_runs();
        let names = ["nominal", "hyperspectral", "filter_imager", "sentinel3a_olci", "smallsat_swir", "modis_aqua"];
        for name in names {
            let mut c = runs[0].clone();
            c.instrument = crate::instrument::InstrumentSpec::preset(name).unwrap_or_else(|e| panic!("{e}"));
            runs.push(c);
        }
        let demand = app_demand(&runs.iter().collect::<Vec<_>>(), crate::engine::worker::APP_CACHE_MAX_BYTES);
        let gb = demand.bytes() / 1024.0_f64.powi(3);
        assert!((3.50..3.50 * 1.2).contains(&gb), "{gb} GiB: {demand:?}");
        assert_eq!(demand.parts.iter().filter(|p| p.what.starts_with("the views")).count(), 8);
    }

    #[test]
    fn the_largest_instrument_is_refused_naming_its_fields_and_what_would_fit() {
        // The largest instrument over the largest scene (the instrument is cropped to the scene).
        let mut c = default_runs().remove(0);
        (c.instrument.lines, c.instrument.detectors) = (100_000, 20_000);
        (c.scene.width, c.scene.height) = (20_000, 20_000);
        let budget = MachineBudget { memory_bytes: 14e9, atmosphere_s: DEFAULT_ATMOSPHERE_S };
        let e = budget.check(&run_demand(&c)).unwrap_err();
        assert!(e.field.contains("instrument.lines") && e.message.contains("fidelity.decimation"), "{e}");
        c.fidelity.decimation = 64;
        assert!(budget.check(&run_demand(&c)).is_ok(), "a preview of it fits");
    }

    #[test]
    fn thin_layers_are_refused_for_their_memory_and_many_terms_for_their_time() {
        let mut c = default_runs().remove(0);
        let budget = MachineBudget { memory_bytes: 14e9, atmosphere_s: DEFAULT_ATMOSPHERE_S };
        // The thinnest layers and the most streams: each level holds (2 · 48)² Stokes blocks.
        let acc = &mut c.scene.atmosphere.accuracy;
        (acc.max_layer_depth, acc.streams) = (1e-4, 48);
        c.scene.atmosphere.aot550 = 5.0;
        let e = budget.check(&run_demand(&c)).unwrap_err();
        assert!(e.field.contains("max_layer_depth") && e.message.contains("raise max_layer_depth"), "{e}");
        // Memory that fits, work that does not fit a budget of 10 s (SHOAL_TIME_BUDGET_S=10):
        // every Fourier term and order at 24 streams, planned at ~45 s. (Within the default
        // 900 s, memory binds first: the work per byte of kernel is bounded by terms × orders.)
        let acc = &mut c.scene.atmosphere.accuracy;
        (acc.max_layer_depth, acc.streams, acc.fourier_terms, acc.max_orders) = (0.002, 24, 96, 500);
        let short = MachineBudget { atmosphere_s: 10.0, ..budget };
        assert!(budget.check(&run_demand(&c)).is_ok());
        let e = short.check(&run_demand(&c)).unwrap_err();
        assert_eq!(e.field, "scene.atmosphere.accuracy", "{e}");
        // The paper's study plans well under a second (the default study adds the image-based
        // correction's aerosol family: its own demand, `family_seconds`).
        let paper = crate::study::StudySpec::preset(crate::study::PAPER_STUDY).unwrap_or_else(|e| panic!("{e}"));
        let paper = paper.resolve(None).unwrap_or_else(|e| panic!("{e}"));
        assert!(atmosphere_seconds(&paper.runs[0].2) < 0.5);
    }
}
