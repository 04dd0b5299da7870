//! A retrieval over a whole Rrs image: the products, per-pixel flags, and what it was given.

use std::path::{Path, PathBuf};

use ndarray::{Array2, Array3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::Mode;
use super::RetrievalError;
use super::algorithm::{ALMI, BUILT_IN};
use super::almi::{AlmiFlags, AlmiSet, AlmiSettings};
use super::almi_lanes::{PackedSets, Scratch, invert_packed};
use super::almi_reference::invert_reference;
use super::band_model::{BandModel, BandResponse};
use super::sambuca::SambucaSettings;
use super::sets::default_almi_sets;
use crate::control::RunControl;
use crate::correction::RrsFlags;
use crate::instrument::BandAtmosphere;
use crate::instrument::Response;
use crate::parse::FieldError;
use crate::water::{SiopSource, SiopSpec, SubstrateLibrary, WaterGeometry};

/// Which retrieval, with its settings, as a study file writes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum RetrievalSpec {
    /// aLMI over a list of SIOP sets (default: the eight built-in sets).
    Almi {
        /// The SIOP sets to choose from.
        #[serde(default = "default_almi_sets")]
        siop_sets: Vec<SiopSource>,
        /// Settings.
        #[serde(default)]
        settings: AlmiSettings,
    },
    /// SAMBUCA-style inversion with one SIOP set and a substrate library.
    Sambuca {
        /// SIOP set (default: the scene's).
        #[serde(default)]
        siop: Option<SiopSource>,
        /// Substrates to unmix, in pairs (default: the scene's).
        #[serde(default)]
        substrates: Option<Vec<String>>,
        /// Settings.
        #[serde(default)]
        settings: SambucaSettings,
    },
    /// A user's own program, run on a NetCDF file of the Rrs ([`super::external`]).
    External(super::external::ExternalSpec),
    /// The Quasi-Analytical Algorithm v6 ([`super::qaa`]): IOPs with no SIOP assumed, chl from
    /// a_ph(443).
    Qaa {
        /// Settings.
        #[serde(default)]
        settings: super::qaa::QaaSettings,
    },
}

/// The built-in retrievals' names ([`RetrievalSpec::name`]): a retrieval of the user's may
/// not take one (its files and variables would overwrite the built-in's), in any case.
pub const BUILT_IN_NAMES: [&str; BUILT_IN.len()] = {
    let mut out = [""; BUILT_IN.len()];
    let mut i = 0;
    while i < BUILT_IN.len() {
        out[i] = BUILT_IN[i].name;
        i += 1;
    }
    out
};

impl RetrievalSpec {
    /// The spec with an external command's `{dir}` replaced by `dir`, the study file's directory
    /// (the other retrievals take their relative paths from the scene's directory as they run).
    pub fn with_dir(&self, dir: Option<&Path>) -> Result<Self, RetrievalError> {
        match self {
            Self::External(e) => Ok(Self::External(e.with_dir(dir)?)),
            other => Ok(other.clone()),
        }
    }

    /// Check the settings that need no image (counts, coefficients, bounds) against
    /// [`crate::ranges`], so a run can refuse them before any stage runs.
    pub fn validate(&self) -> Result<(), RetrievalError> {
        self.algorithm().validate()
    }
}

/// Per-pixel flags of a product.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProductFlags;

impl ProductFlags {
    /// A value was returned.
    pub const RETURNED: u8 = 1;
    /// aLMI: the unconstrained solution was non-negative.
    pub const PHYSICAL: u8 = 2;
    /// A constituent sits on a bound.
    pub const AT_BOUND: u8 = 4;
    /// The optimiser converged.
    pub const CONVERGED: u8 = 8;
    /// SAMBUCA: the bottom is detectable (SDI ≥ 1).
    pub const BOTTOM_VISIBLE: u8 = 16;
    /// No solution (too few valid bands, or none fitted).
    pub const FAILED: u8 = 32;
    /// Land: not retrieved.
    pub const LAND: u8 = 64;
    /// SAMBUCA reference mode: the kept fit reported success with the depth still at its start
    /// (the package's stall, [`super::sambuca_reference`]).
    pub const STALLED: u8 = 128;
}

/// A retrieval's products over the image.
#[derive(Debug, Clone, PartialEq)]
pub struct Product {
    /// The retrieval's title ([`super::algorithm::Identity::title`]), or an external retrieval's name.
    pub name: String,
    /// Chlorophyll-a, mg m⁻³ (0 where not returned; `None`: an external retrieval that does not
    /// return it).
    pub chl_mg_m3: Option<Array2<f32>>,
    /// CDOM absorption at the reference wavelength, m⁻¹ (as `chl_mg_m3`).
    pub cdom_per_m: Option<Array2<f32>>,
    /// NAP, g m⁻³ (as `chl_mg_m3`).
    pub nap_g_m3: Option<Array2<f32>>,
    /// Depth, m (SAMBUCA).
    pub depth_m: Option<Array2<f32>>,
    /// Substrate names of `substrate_fractions`.
    pub substrate_names: Vec<String>,
    /// Fraction of each substrate (SAMBUCA), (row, column, substrate).
    pub substrate_fractions: Option<Array3<f32>>,
    /// Names of the SIOP sets (aLMI).
    pub siop_set_names: Vec<String>,
    /// Index of the chosen SIOP set (aLMI), −1 where none.
    pub siop_set: Option<Array2<i16>>,
    /// Cost (aLMI) or objective (SAMBUCA) at the solution.
    pub cost: Array2<f32>,
    /// Substrate detectability index (SAMBUCA).
    pub sdi: Option<Array2<f32>>,
    /// Iterations (SAMBUCA).
    pub iterations: Option<Array2<u16>>,
    /// Further named maps the retrieval returns beside the core (QAA's IOPs: `adg443_per_m`, …),
    /// keys of [`crate::variable::EXTRAS`]: mapped and written, scored where the algorithm says
    /// what their truth is.
    pub extras: Vec<(String, Array2<f32>)>,
    /// [`ProductFlags`].
    pub flags: Array2<u8>,
}

impl Product {
    /// A product named `name` with `flags` and no map yet (no cost, classes or solver fields):
    /// what a retrieval that returns only scalar maps fills in.
    #[must_use]
    pub fn bare(name: String, flags: Array2<u8>) -> Self {
        Self {
            name,
            chl_mg_m3: None,
            cdom_per_m: None,
            nap_g_m3: None,
            depth_m: None,
            substrate_names: Vec::new(),
            substrate_fractions: None,
            siop_set_names: Vec::new(),
            siop_set: None,
            cost: Array2::zeros(flags.dim()),
            sdi: None,
            iterations: None,
            extras: Vec::new(),
            flags,
        }
    }

    /// Did the retrieval return a value at (row, column)?
    #[must_use]
    pub fn returned(&self, r: usize, c: usize) -> bool {
        self.flags[[r, c]] & ProductFlags::RETURNED != 0
    }

    /// The map of a scalar variable (`chl_mg_m3`, `nap_g_m3`, `cdom_per_m`, `depth_m`), if
    /// this product has it (the same names as `instrument::Truth::map`).
    #[must_use]
    pub fn map(&self, variable: &str) -> Option<&Array2<f32>> {
        use crate::variable::key;
        match variable {
            key::CHL => self.chl_mg_m3.as_ref(),
            key::NAP => self.nap_g_m3.as_ref(),
            key::CDOM => self.cdom_per_m.as_ref(),
            key::DEPTH => self.depth_m.as_ref(),
            other => self.extras.iter().find(|(k, _)| k == other).map(|(_, m)| m),
        }
    }

    /// Every scalar map it has, by key: the core variables ([`crate::variable::KEYS`]) it
    /// returns, then its extras.
    #[must_use]
    pub fn maps(&self) -> Vec<(&str, &Array2<f32>)> {
        crate::variable::KEYS
            .iter()
            .filter_map(|&v| self.map(v).map(|m| (v, m)))
            .chain(self.extras.iter().map(|(k, m)| (k.as_str(), m)))
            .collect()
    }
}

/// Everything a retrieval reads besides its own settings.
#[derive(Debug, Clone)]
pub struct RetrievalInputs<'a> {
    /// Rrs, (row, column, band).
    pub rrs: &'a Array3<f32>,
    /// Rrs flags.
    pub flags: &'a Array3<u8>,
    /// What covers each pixel (only water is retrieved).
    pub surface: &'a crate::instrument::SurfaceMap,
    /// The bands' responses (what a band Rrs averages over).
    pub bands: Vec<BandResponse>,
    /// Per column: sun and view zenith at the ground.
    pub geometry: Vec<WaterGeometry>,
    /// Noise-equivalent ΔRrs per band, sr⁻¹.
    pub nedr: Vec<f64>,
    /// The scene's SIOP set and the directory its CSV paths are relative to.
    pub scene_siop: (SiopSpec, Option<PathBuf>),
    /// The scene's substrates.
    pub scene_substrates: Vec<String>,
    /// Directory relative paths in the retrieval's own settings are taken from.
    pub base_dir: Option<&'a Path>,
}

/// The bands' responses as the chain's truth weights them (photon weights × T_up·Ed) at output
/// column `column` of `atmosphere`.
#[must_use]
pub fn band_responses(response: &Response, atmosphere: &BandAtmosphere, column: usize) -> Vec<BandResponse> {
    let mut out: Vec<Option<BandResponse>> = vec![None; response.n_bands()];
    for (gi, group) in response.groups.iter().enumerate() {
        for (k, &b) in group.bands.iter().enumerate() {
            let (first, w) = &atmosphere.truth_weights[gi][column][k];
            out[b] = Some(BandResponse {
                name: response.bands.bands[b].name.clone(),
                wavelengths_nm: (0..w.len()).map(|i| group.grid.wavelength_nm(first + i)).collect(),
                weights: w.clone(),
            });
        }
    }
    out.into_iter().flatten().collect()
}

/// Default aLMI bands: centroids 400–780 nm outside the O₂ A band (759–771 nm).
fn default_almi_bands(bands: &[BandResponse]) -> Vec<usize> {
    let usable: Vec<usize> = (0..bands.len())
        .filter(|&b| {
            let c = bands[b].centroid_nm();
            (400.0..=780.0).contains(&c) && !(759.0..=771.0).contains(&c)
        })
        .collect();
    // A spectrograph has more usable bands than aLMI's linear system takes: keep an evenly
    // spaced subset of at most MAX_BANDS, first and last included.
    let max = super::almi::MAX_BANDS;
    if usable.len() <= max {
        return usable;
    }
    (0..max).map(|k| usable[k * (usable.len() - 1) / (max - 1)]).collect()
}

/// aLMI's model at the instrument's bands: the bands it uses and each SIOP set's band IOPs,
/// packed side by side for the pixel loop. Reading and integrating eight sets is most of a small
/// preview's retrieval time, and depends only on the spec and the bands.
#[derive(Debug, Clone)]
pub struct AlmiModel {
    /// The instrument bands in use.
    used: Vec<usize>,
    /// The sets at those bands.
    sets: Vec<AlmiSet>,
    /// The sets packed in lanes.
    packed: PackedSets,
}

/// Build [`AlmiModel`] of `sources` at `inputs.bands`.
pub(super) fn almi_model(
    sources: &[SiopSource],
    settings: &AlmiSettings,
    inputs: &RetrievalInputs<'_>,
) -> Result<AlmiModel, RetrievalError> {
    let used: Vec<usize> = match &settings.bands {
        None => default_almi_bands(&inputs.bands),
        Some(names) => names
            .iter()
            .map(|n| {
                inputs.bands.iter().position(|b| &b.name == n).ok_or_else(|| {
                    RetrievalError::Invalid(FieldError {
                        field: "settings.bands".into(),
                        message: format!(
                            "no band `{n}` (this instrument has {})",
                            inputs.bands.iter().map(|b| b.name.as_str()).collect::<Vec<_>>().join(", ")
                        ),
                    })
                })
            })
            .collect::<Result<_, _>>()?,
    };
    if used.len() < 3 || used.len() > super::almi::MAX_BANDS {
        return Err(RetrievalError::Invalid(FieldError {
            field: "settings.bands".into(),
            message: format!("{} bands (aLMI takes 3 to {})", used.len(), super::almi::MAX_BANDS),
        }));
    }
    let bands: Vec<BandResponse> = used.iter().map(|&b| inputs.bands[b].clone()).collect();
    let library = SubstrateLibrary::embedded()?;
    // One band model per set; independent, so built in parallel (this is most of a small
    // preview's retrieval time).
    let sets = sources
        .par_iter()
        .map(|src| {
            let (spec, dir) = src.load(inputs.base_dir)?;
            let model = BandModel::new(&spec, dir.as_deref(), &library, &[], &bands, 4)?;
            Ok(AlmiSet { name: spec.name.clone(), iops: model.band_iops() })
        })
        .collect::<Result<Vec<_>, RetrievalError>>()?;
    // The chosen-set map and the reports name sets: two of one name (a user's file called like a
    // built-in set, or two files with one `name`) could not be told apart there.
    for (i, set) in sets.iter().enumerate() {
        if sets[..i].iter().any(|s| s.name == set.name) {
            return Err(RetrievalError::Invalid(FieldError {
                field: "siop_sets".into(),
                message: format!("two SIOP sets are called `{}`; give each set its own `name`", set.name),
            }));
        }
    }
    // The sets side by side for the per-pixel loops (bit-identical to the scalar `almi::invert`).
    let packed = PackedSets::new(&sets);
    Ok(AlmiModel { used, sets, packed })
}

/// aLMI over the image with `model` (from [`almi_model`] of the same settings and bands).
pub(super) fn retrieve_almi(
    model: &AlmiModel,
    settings: &AlmiSettings,
    inputs: &RetrievalInputs<'_>,
    control: &RunControl,
) -> Result<Product, RetrievalError> {
    let AlmiModel { used, sets, packed } = model;
    let (rows, cols, nb) = inputs.rrs.dim();
    // Written in place, row by row, as the correction writes its Rrs (collected as rows of
    // per-pixel tuples, the maps were then copied out on one thread: 20–25 ms a design while the
    // other thread waited, perf timeline).
    let n = rows * cols;
    let (mut chl, mut cdom, mut nap, mut cost) = (vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n]);
    let (mut set, mut flags) = (vec![-1i16; n], vec![0u8; n]);
    let outputs = (
        (chl.as_mut_slice(), cdom.as_mut_slice(), nap.as_mut_slice()),
        (set.as_mut_slice(), cost.as_mut_slice(), flags.as_mut_slice()),
    );
    control.fill_rows(outputs, rows, cols, |at, ((chl, cdom, nap), (set, cost, flags))| {
        let r = at.index();
        let mut obs = vec![0.0; used.len()];
        let mut valid = vec![false; used.len()];
        let nedr: Vec<f64> = used.iter().map(|&b| inputs.nedr[b]).collect();
        let mut scratch = Scratch::default();
        for c in 0..cols {
            at.column(c);
            // ([chl, CDOM, NAP], SIOP set (−1: none), cost, flags).
            let (values, set_index, pixel_cost, pixel_flags) = 'pixel: {
                if !inputs.surface.is_water(r, c) {
                    break 'pixel ([0.0; 3], -1, 0.0, ProductFlags::LAND);
                }
                for (k, &b) in used.iter().enumerate() {
                    debug_assert!(b < nb);
                    obs[k] = f64::from(inputs.rrs[[r, c, b]]);
                    valid[k] = inputs.flags[[r, c, b]] & (RrsFlags::INVALID | RrsFlags::SATURATED) == 0;
                }
                let p = match settings.mode {
                    Mode::Improved => invert_packed(&mut scratch, packed, settings, &obs, &valid, &nedr),
                    Mode::Reference => invert_reference(sets, settings.g0, settings.g1, &obs, &valid),
                };
                if p.flags & AlmiFlags::FAILED != 0 || p.set.is_none() {
                    break 'pixel ([0.0; 3], -1, 0.0, ProductFlags::FAILED);
                }
                let mut f = ProductFlags::RETURNED;
                if p.flags & AlmiFlags::PHYSICAL != 0 {
                    f |= ProductFlags::PHYSICAL;
                }
                if p.flags & AlmiFlags::AT_BOUND != 0 {
                    f |= ProductFlags::AT_BOUND;
                }
                ([p.chl as f32, p.cdom as f32, p.nap as f32], p.set.map_or(-1, i16::from), p.cost as f32, f)
            };
            [chl[c], cdom[c], nap[c]] = values;
            (set[c], cost[c], flags[c]) = (set_index, pixel_cost, pixel_flags);
        }
        Ok::<_, RetrievalError>(())
    })?;
    let grid = |v| grid_of(rows, cols, v);
    Ok(Product {
        name: ALMI.title.into(),
        chl_mg_m3: Some(grid(chl)?),
        cdom_per_m: Some(grid(cdom)?),
        nap_g_m3: Some(grid(nap)?),
        depth_m: None,
        substrate_names: Vec::new(),
        substrate_fractions: None,
        siop_set_names: sets.iter().map(|s| s.name.clone()).collect(),
        siop_set: Some(grid_of(rows, cols, set)?),
        cost: grid(cost)?,
        sdi: None,
        iterations: None,
        extras: Vec::new(),
        flags: grid_of(rows, cols, flags)?,
    })
}

/// `values` (row-major, one a pixel) as the `rows` × `cols` map of a product.
fn grid_of<T>(rows: usize, cols: usize, values: Vec<T>) -> Result<Array2<T>, RetrievalError> {
    Array2::from_shape_vec((rows, cols), values)
        .map_err(|e| RetrievalError::Invalid(FieldError { field: "product maps".into(), message: e.to_string() }))
}

/// Check SAMBUCA's bounds and quadrature setting; the message names the field.
/// aLMI's settings against their ranges: 1–64 SIOP sets, g0 and g1.
pub(super) fn validate_almi(siop_sets: &[SiopSource], settings: &AlmiSettings) -> Result<(), RetrievalError> {
    use crate::ranges as r;
    if siop_sets.is_empty() || siop_sets.len() > 64 {
        return Err(RetrievalError::Invalid(FieldError {
            field: "siop_sets".into(),
            message: format!("{} sets (allowed: 1 to 64)", siop_sets.len()),
        }));
    }
    let check = |range: &r::Range, v: f64| {
        let field = range.field("retrievals[i].Almi.").into();
        range.check(v).map_err(|message| RetrievalError::Invalid(FieldError { field, message }))
    };
    check(&r::ALMI_G0, settings.g0)?;
    check(&r::ALMI_G1, settings.g1)
}

pub(super) fn validate_sambuca(settings: &SambucaSettings) -> Result<(), RetrievalError> {
    let b = &settings.bounds;
    for (field, (lo, hi)) in
        [("chl_mg_m3", b.chl_mg_m3), ("cdom_per_m", b.cdom_per_m), ("nap_g_m3", b.nap_g_m3), ("depth_m", b.depth_m)]
    {
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
            return Err(RetrievalError::Invalid(FieldError {
                field: format!("settings.bounds.{field}"),
                message: format!("({lo}, {hi}): bounds must be finite with 0 < min < max"),
            }));
        }
    }
    let check = |range: &crate::ranges::Range, v: f64| {
        let field = range.field("retrievals[i].Sambuca.").into();
        range.check(v).map_err(|message| RetrievalError::Invalid(FieldError { field, message }))
    };
    check(&crate::ranges::SAMBUCA_NODES_PER_BAND, settings.nodes_per_band as f64)?;
    check(&crate::ranges::SAMBUCA_MAX_ITERATIONS, f64::from(settings.max_iterations))
}
