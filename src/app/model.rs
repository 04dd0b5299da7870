//! What the app holds and persists: the designs (A, B, …), the scene, the retrieval, seeds,
//! preview settings, requirements and the view. Nothing here draws.

use serde::{Deserialize, Serialize};

pub use super::designs::{MAPS_AT_OPEN, MAX_DESIGNS, label};
pub use super::view::{Layout, ProductKind};

use crate::colormap::significant;
use crate::engine::{Fidelity, RunConfig};
use crate::instrument::InstrumentSpec;
use crate::retrieval::{AlmiSettings, RetrievalSpec, SambucaSettings};
use crate::scene::{MapSpec, SceneSpec};
use crate::study::{ProductRequirement, Requirements, Source, StudySpec};

/// One instrument slot: the instrument being edited and the preset it came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Slot {
    /// Preset name it was loaded from.
    pub preset: String,
    /// The preset as loaded (to mark edits).
    pub original: InstrumentSpec,
    /// The instrument as edited.
    pub spec: InstrumentSpec,
}

impl Slot {
    /// A slot holding `spec` loaded from preset `name`.
    #[must_use]
    pub fn new(name: &str, spec: InstrumentSpec) -> Self {
        Self { preset: name.into(), original: spec.clone(), spec }
    }

    /// Has the instrument been edited since it was loaded?
    #[must_use]
    pub fn modified(&self) -> bool {
        self.spec != self.original
    }
}

/// The limits the app judges by when the study states none: the default study's (chl MAE ≤ 20 %,
/// |bias| ≤ 10 %, ≥ 95 % returned; NAP and CDOM looser) plus depth MAE ≤ 10 %, SNR ≥ 100 and
/// the dominant substrate right in ≥ 70 % of pixels.
#[must_use]
pub fn fallback_requirements() -> Requirements {
    let p = |variable: &str, mae: f64, bias: Option<f64>, returned: Option<f64>| ProductRequirement {
        variable: variable.into(),
        mae_pct: Some(mae),
        bias_pct: bias,
        returned_pct: returned,
    };
    Requirements {
        products: vec![
            p("chl_mg_m3", 20.0, Some(10.0), Some(95.0)),
            p("nap_g_m3", 30.0, None, None),
            p("cdom_per_m", 50.0, None, None),
            p("depth_m", 10.0, None, None),
        ],
        snr: Some(100.0),
        substrate_pct: Some(70.0),
        rrs: None,
        ..Requirements::default()
    }
}

/// The whole persisted state of the app.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AppState {
    /// The session format's version ([`crate::schema`]).
    pub schema_version: u32,
    /// The designs compared, in order: A, B, C, … (at least one, at most [`MAX_DESIGNS`]).
    pub designs: Vec<Slot>,
    /// Parameters linked across the designs (field names): an edit of one sets it in all.
    pub linked: Vec<String>,
    /// The design the editor shows (an index into `designs`). (Saved as `editing_design`:
    /// sessions from before the designs' list saved a number under `editing`, which is ignored.)
    #[serde(rename = "editing_design")]
    pub editing: usize,
    /// The design the others are compared with in the parameter table ("Parameters against A").
    pub reference: usize,
    /// The designs the maps show beside the truth (small multiples), in the designs' order.
    pub on_maps: Vec<usize>,
    /// The two designs of the difference layout (first − second).
    pub pair: [usize; 2],
    /// Scene preset name.
    pub scene_name: String,
    /// The scene.
    pub scene: SceneSpec,
    /// Added to every random-field seed of the scene.
    pub scene_seed: u64,
    /// Instrument noise seed.
    pub noise_seed: u64,
    /// The retrievals the app offers, as the engine runs them: aLMI and SAMBUCA with their
    /// settings, then the study's own (a program, QAA). The app edits these specs; no mirror of
    /// them is kept.
    pub retrievals: Vec<RetrievalSpec>,
    /// The one that runs (an index into `retrievals`).
    pub selected_retrieval: usize,
    /// Preview decimations, coarsest first; the last is the final resolution (saved states
    /// before the rename call it `levels`: [`crate::schema::RENAMES`]).
    pub decimations: Vec<usize>,
    /// Product shown.
    pub product: ProductKind,
    /// Band of band products.
    pub band: usize,
    /// Map arrangement.
    pub layout: Layout,
    /// Requirements: the study's, as `shoal study` checks them (the same [`Requirements::check_run`]).
    /// Saved as `product_requirements`: sessions from before this format kept MAE limits only,
    /// and are read with these defaults rather than refused.
    #[serde(rename = "product_requirements", default = "fallback_requirements")]
    pub requirements: Requirements,
    /// Dark theme.
    pub dark: bool,
    /// Study name for captions.
    pub study_name: String,
    /// The fidelity of every run (its `decimation` is the preview level's, set per run): the
    /// defaults, the study's, or a setting applied from the Cost window.
    pub fidelity: Fidelity,
    /// Stop at the previews: the final (finest) level is not run until this is off (for a long
    /// retrieval at full resolution, or a slow machine).
    pub preview_only: bool,
    /// The calibration of both instruments (its systematic errors are worst-case controls).
    pub calibration: crate::calibration::CalibrationSpec,
    /// The radiance the SNR is stated at (`None`: the scene's median water radiance).
    pub snr_reference: Option<crate::spectral::SpectrumSource>,
    /// The atmospheric correction of both instruments: exact, the paper's per-scene
    /// approximation, or image-based from a band pair.
    pub correction: crate::correction::CorrectionSpec,
}

impl Default for AppState {
    fn default() -> Self {
        Self::from_study(&fallback_study(), None).unwrap_or_else(|_| {
            let scene = SceneSpec::preset("lake_hume_bloom").unwrap_or_else(|_| unreachable!("built-in preset"));
            Self::new(fallback_designs(), "lake_hume_bloom", scene)
        })
    }
}

/// The default study's two instruments, when nothing else is to hand.
fn fallback_designs() -> Vec<Slot> {
    ["cubesat", "smallsat"]
        .map(|n| Slot::new(n, InstrumentSpec::preset(n).unwrap_or_else(|_| unreachable!("built-in preset"))))
        .to_vec()
}

fn fallback_study() -> StudySpec {
    StudySpec::default_study().unwrap_or_else(|_| StudySpec {
        name: crate::study::DEFAULT_STUDY.into(),
        description: String::new(),
        scene: Source::Preset("lake_hume_bloom".into()),
        instruments: vec![Source::Preset("cubesat".into()), Source::Preset("smallsat".into())],
        retrievals: vec![],
        seeds: vec![1],
        detector: None,
        calibration: None,
        correction: None,
        fidelity: None,
        requirements: None,
        snr_reference: None,
        budgets: None,
    })
}

impl AppState {
    fn new(designs: Vec<Slot>, scene_name: &str, scene: SceneSpec) -> Self {
        let shown = designs.len().clamp(1, MAPS_AT_OPEN);
        Self {
            designs,
            linked: Vec::new(),
            editing: 0,
            reference: 0,
            on_maps: (0..shown).collect(),
            pair: [0, 1],
            scene_name: scene_name.into(),
            scene,
            scene_seed: 0,
            noise_seed: 1,
            retrievals: super::retrievals::built_in(AlmiSettings::default(), SambucaSettings::default()),
            selected_retrieval: 0,
            schema_version: crate::schema::VERSION,
            decimations: vec![24, 4, 1],
            product: ProductKind::Chl,
            band: 3,
            layout: Layout::TruthAB,
            requirements: fallback_requirements(),
            dark: false,
            study_name: crate::study::DEFAULT_STUDY.into(),
            fidelity: Fidelity::default(),
            preview_only: false,
            calibration: crate::calibration::CalibrationSpec::default(),
            snr_reference: None,
            correction: crate::correction::CorrectionSpec::default(),
        }
    }

    /// The state of a study (`dir`: its file's directory, for its relative paths): its
    /// instruments as the designs (the first [`MAX_DESIGNS`]), its scene and its first retrieval.
    pub fn from_study(study: &StudySpec, dir: Option<&std::path::Path>) -> Result<Self, String> {
        let resolved = study.resolve(dir).map_err(|e| e.to_string())?;
        let label = |i: usize| match study.instruments.get(i) {
            Some(Source::Preset(n)) => n.clone(),
            _ => format!("{} instrument {}", study.name, i + 1),
        };
        let first = resolved.runs.first().ok_or("the study has no run")?;
        // One run per instrument (the first seed's), in the study's order.
        let mut designs: Vec<Slot> = Vec::new();
        let mut seen: Vec<&str> = Vec::new();
        for run in &resolved.runs {
            if !seen.contains(&run.0.as_str()) && designs.len() < MAX_DESIGNS {
                designs.push(Slot::new(&label(seen.len()), run.2.instrument.clone()));
                seen.push(&run.0);
            }
        }
        let scene_name = match &study.scene {
            Source::Preset(n) => n.clone(),
            _ => first.2.scene.name.clone(),
        };
        let mut s = Self::new(designs, &scene_name, first.2.scene.clone());
        s.settle();
        s.study_name.clone_from(&study.name);
        // The study's retrievals as they run (`{dir}` in a program's command is the study file's
        // directory by now), its first selected.
        s.offer_study_retrievals(&first.2.retrievals);
        s.product = ProductKind::of_variable(s.retrieval_spec().algorithm().headline()).unwrap_or(ProductKind::Chl);
        if let Some(r) = &study.requirements {
            s.requirements = r.clone();
        }
        s.fidelity = Fidelity { decimation: 1, ..first.2.fidelity.clone() };
        s.calibration = first.2.calibration.clone();
        s.snr_reference = first.2.snr_reference.clone();
        s.correction = first.2.correction.clone();
        Ok(s)
    }

    /// The slot being edited.
    pub fn editing_mut(&mut self) -> &mut Slot {
        let i = self.editing.min(self.designs.len().saturating_sub(1));
        &mut self.designs[i]
    }

    /// The scene with the scene seed added to its random fields.
    #[must_use]
    pub fn seeded_scene(&self) -> SceneSpec {
        let mut scene = self.scene.clone();
        if self.scene_seed != 0 {
            let bump = |m: &mut MapSpec, k: u64| {
                if let MapSpec::RandomField { seed, .. } = m {
                    *seed = seed.wrapping_add(self.scene_seed.wrapping_mul(1_000_003).wrapping_add(k));
                }
            };
            bump(&mut scene.chl_mg_m3, 1);
            bump(&mut scene.nap_g_m3, 2);
            bump(&mut scene.cdom_per_m, 3);
            if let Some(d) = scene.depth_m.as_mut() {
                bump(d, 4);
            }
            for (k, layer) in scene.substrates.iter_mut().enumerate() {
                bump(&mut layer.fraction, 5 + k as u64);
            }
            // The aerosol's map, the land mask and the clouds are drawn from the seed too.
            scene.aot550_map.iter_mut().for_each(|m| bump(m, 1000));
            scene.land.iter_mut().for_each(|l| bump(&mut l.mask, 1001));
            scene.clouds.iter_mut().for_each(|c| {
                c.seed = c.seed.wrapping_add(self.scene_seed.wrapping_mul(1_000_003).wrapping_add(1002));
            });
        }
        scene
    }

    /// The run configurations of the designs, in order (the default image-based correction
    /// takes the aerosol from each design's own best pair: [`design_pair`]).
    #[must_use]
    pub fn configs(&self) -> Vec<RunConfig> {
        let scene = self.seeded_scene();
        self.designs
            .iter()
            .map(|slot| {
                let mut c = RunConfig::new(scene.clone(), slot.spec.clone());
                c.fidelity = Fidelity { decimation: 1, ..self.fidelity.clone() };
                c.seed = self.noise_seed;
                c.retrievals = vec![self.retrieval_spec()];
                c.calibration = self.calibration.clone();
                c.snr_reference.clone_from(&self.snr_reference);
                c.correction = self.correction.clone();
                if let crate::correction::Method::Image(i) = &mut c.correction.method {
                    *i = design_pair(i.clone(), &slot.spec);
                }
                c
            })
            .collect()
    }

    /// The levels set, coarsest first, validated (1–64, decreasing, ending at the final one).
    #[must_use]
    pub fn levels(&self) -> Vec<usize> {
        let mut l: Vec<usize> = self.decimations.iter().copied().filter(|d| (1..=64).contains(d)).collect();
        l.sort_unstable_by(|a, b| b.cmp(a));
        l.dedup();
        if l.is_empty() { vec![24, 4, 1] } else { l }
    }

    /// The levels the engine runs: [`Self::levels`], without the final one when
    /// [`Self::preview_only`] (unless it is the only one).
    #[must_use]
    pub fn decimations(&self) -> Vec<usize> {
        let mut l = self.levels();
        if self.preview_only && l.len() > 1 {
            l.pop();
        }
        l
    }

    /// The parameters edited away from each design's preset, for captions ("A aperture_mm 60 →
    /// 105.8"), each by its path ([`crate::fields::diff`]: `effects.0.StrayLight.halo_fraction`):
    /// numbers to four significant digits (never a float's raw digits), a list whose length changed
    /// by its lengths, text and switches as they were and are, anything else as "edited"; a field
    /// with more than [`MAX_CHANGES_PER_FIELD`] changes inside it as their count.
    #[must_use]
    pub fn changes(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (i, slot) in self.designs.iter().enumerate() {
            let changes = crate::fields::diff(&slot.spec, &slot.original);
            // A field with more than a few changes inside it (a QE table, a band list edited
            // entry by entry) is one line: "A quantum_efficiency: 40 values edited".
            let top = |c: &crate::fields::Change| c.path.split('.').next().unwrap_or_default().to_string();
            let mut summarised: Vec<String> = Vec::new();
            for change in &changes {
                use serde_json::Value;
                let k = &change.path;
                let field = top(change);
                if field == "name" || field == "description" || summarised.contains(&field) {
                    continue;
                }
                let inside = changes.iter().filter(|c| top(c) == field).count();
                if inside > MAX_CHANGES_PER_FIELD {
                    out.push(format!("{} {field}: {inside} values edited", label(i)));
                    summarised.push(field);
                    continue;
                }
                let what = match (&change.before, &change.after) {
                    (Value::Number(a), Value::Number(b)) => {
                        let sig = |n: &serde_json::Number| n.as_f64().map_or_else(|| n.to_string(), four_digits);
                        format!("{} → {}", sig(a), sig(b))
                    }
                    (Value::Array(a), Value::Array(b)) => format!("{} → {} entries", a.len(), b.len()),
                    (Value::Array(a), Value::Null) => format!("{} → 0 entries", a.len()),
                    (Value::Null, Value::Array(b)) => format!("0 → {} entries", b.len()),
                    (Value::String(a), Value::String(b)) => format!("{a} → {b}"),
                    (Value::Bool(a), Value::Bool(b)) => format!("{a} → {b}"),
                    _ => "edited".to_string(),
                };
                out.push(format!("{} {k} {what}", label(i)));
            }
        }
        out
    }
}

/// Changes inside one top-level field of an instrument listed one by one in a caption; more are
/// counted ([`AppState::changes`]).
const MAX_CHANGES_PER_FIELD: usize = 3;

/// `x` to four significant digits: as people write it inside 0.001–10⁶ ("105.8"), else in
/// e-notation with its four digits ("3.330e-4", where `significant` would say "3e-4").
fn four_digits(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) { significant(x, 4) } else { format!("{x:.3e}") }
}

/// The image-based correction `image` as design `spec` runs it: the default pair (779/865 nm),
/// where the design lacks it, becomes the first mission pair its bands make (MODIS 748/869, a
/// SWIR pair: [`crate::correction::MISSION_PAIRS_NM`]); the aerosol row of the metrics names the
/// pair each design used. A pair the user chose is kept (the menu greys it for designs without it).
#[must_use]
pub fn design_pair(
    image: crate::correction::ImageCorrection,
    spec: &InstrumentSpec,
) -> crate::correction::ImageCorrection {
    if image.pair_nm != crate::correction::ImageCorrection::default().pair_nm {
        return image;
    }
    let Ok(bands) = spec.kind.model().band_set() else { return image };
    image.for_bands(&bands.centres_nm()).unwrap_or(image)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_the_cubesat_vs_smallsat_study_with_a_missions_correction() {
        let s = AppState::default();
        // The realistic processor: the aerosol from the designs' own 779/865 nm bands.
        let image = s.correction.image().expect("the default corrects from the image");
        assert_eq!(image.pair_nm, [779.0, 865.0]);
        assert_eq!(s.study_name, crate::study::DEFAULT_STUDY);
        assert_eq!(
            (s.designs[0].preset.as_str(), s.designs[1].preset.as_str(), s.scene_name.as_str()),
            ("cubesat", "smallsat", "lake_hume_bloom")
        );
        assert_eq!(s.configs().len(), 2);
        assert_eq!((s.on_maps.as_slice(), s.pair), (&[0, 1][..], [0, 1]), "A vs B, as before designs were a list");
        assert!(!s.designs[0].modified());
    }

    #[test]
    fn edits_are_listed_for_captions() {
        let mut s = AppState::default();
        s.designs[0].spec.aperture_mm = 80.0;
        assert!(s.designs[0].modified());
        assert_eq!(s.changes(), vec!["A aperture_mm 60 → 80".to_string()]);
        // A float's raw digits never reach a caption.
        s.designs[0].spec.aperture_mm = 105.800_000_000_000_01;
        assert_eq!(s.changes(), vec!["A aperture_mm 60 → 105.8".to_string()]);
        s.designs[0].spec.exposure_s = 3.33e-4;
        assert!(s.changes().contains(&"A exposure_s 0.0015 → 3.330e-4".to_string()), "{:?}", s.changes());
    }

    #[test]
    fn the_app_fidelity_reaches_every_run_and_old_sessions_read_the_defaults() {
        let mut s = AppState::default();
        assert_eq!(s.fidelity, Fidelity::default());
        s.fidelity.band_nodes = 4;
        s.fidelity.decimation = 8;
        for c in s.configs() {
            assert_eq!(c.fidelity.band_nodes, 4);
            assert_eq!(c.fidelity.decimation, 1, "the preview level sets decimation, not the state");
        }
        // A session saved before the field existed reads as the defaults.
        // (`fidelity` is the last field: cut it and close the struct.)
        let mut saved = s.clone();
        saved.band = 5;
        let text = ron::to_string(&saved).unwrap();
        let cut = text.rfind(",fidelity:").unwrap();
        let old: AppState = ron::from_str(&format!("{})", &text[..cut])).unwrap();
        assert_eq!(old.fidelity, Fidelity::default());
        assert_eq!(old.band, 5, "the rest of the session is read");
    }

    #[test]
    fn the_scene_seed_moves_every_random_field() {
        let mut s = AppState::default();
        let before = s.seeded_scene();
        s.scene_seed = 3;
        assert_ne!(s.seeded_scene().chl_mg_m3, before.chl_mg_m3);
        assert_eq!(s.seeded_scene().nap_g_m3, before.nap_g_m3, "constant maps have no seed");
        let hazy = crate::scene::SceneSpec::preset("lake_hume_haze").unwrap();
        let s = AppState { scene: hazy.clone(), scene_seed: 3, ..AppState::default() };
        assert_ne!(s.seeded_scene().aot550_map, hazy.aot550_map, "the aerosol's map is reseeded");
    }
}
