//! Instrument effects: what the optics do to the light between the entrance pupil and the
//! detector, declared in the instrument file (each design its own), applied at one place and,
//! where a mission's Level-1 processor would, corrected there with the processor's knowledge.
//!
//! | effect | module | what it needs from the scene | corrected by |
//! |---|---|---|---|
//! | stray light (halo, out-of-field veil) | [`stray_light`] | the whole band image | deconvolution with the known PSF (Zong et al. 2006) |
//! | polarisation sensitivity | [`polarisation`] | the path's Stokes Q and U per column | l2gen's polcor (Meister et al. 2005) |
//! | spectral stray light | [`spectral_stray`] | each pixel's band vector | the inverse of the known matrix (Zong et al. 2006) |
//! | spatial response (MTF budget) | [`mtf`] | the scene around each pixel (it sets the sampling's PSF) | not corrected (as most Level-1 processors) |
//! | non-linearity | [`nonlinearity`] | the electrons each element collects (the detector applies it) | the calibration's linearisation with the believed curve |
//! | fixed patterns (striping, dead and hot elements) | [`fixed_patterns`] | the detector's elements | dead elements filled or flagged by the calibration |
//! | band-to-band misregistration | [`misregistration`] | each band's whole image | co-registration with the believed shifts |
//! | time-delay integration | [`tdi`] | the focal planes' electronics (and the MTF budget's along-track losses) | calibrated through the same stages |
//! | compression | [`compression`] | Level-0's counts (the coder: [`crate::instrument::compression`]) | decoded on the ground (near-lossless: its error stays) |
//! | on-board binning | [`binning`] | the instrument itself (the instrument as flown) | – (a design choice) |
//! | spectral knowledge error (band centre, width, smile) | [`spectral_knowledge`] | the spectral response the scene is sampled with | not correctable: the processor's bands are its knowledge |
//!
//! Every effect is a type behind [`Effect`], listed in [`InstrumentEffect`] (the one place an
//! effect is registered: its module and one arm of [`InstrumentEffect::effect`]). The engine
//! applies the list in order to the pupil radiance (stage `Effects`) before the detector sees
//! it, and undoes it in reverse order on Level-1 (stage `Level1`), each effect with what the
//! processor believes: [`Knowledge`]. An instrument with no effects runs exactly as before.
//!
//! ## References
//! - Zong, Y., Brown, S. W., Johnson, B. C., Lykke, K. R., Ohno, Y. (2006) Simple spectral stray
//!   light correction method for array spectroradiometers. Appl. Opt. 45, 1111–1119.
//! - Meister, G., Kwiatkowska, E. J., Franz, B. A., Patt, F. S., Feldman, G. C., McClain, C. R.
//!   (2005) Moderate-Resolution Imaging Spectroradiometer ocean color polarization correction.
//!   Appl. Opt. 44, 5524–5535.

pub mod binning;
pub mod compression;
pub mod convolve;
pub mod fixed_patterns;
pub mod misregistration;
pub mod mtf;
pub mod nonlinearity;
pub mod polarisation;
pub mod spectral_knowledge;
pub mod spectral_stray;
pub mod stokes_columns;
pub mod stray_light;
pub mod tdi;

use ndarray::Array3;
use serde::{Deserialize, Serialize};

pub use binning::Binning;
pub use compression::Compression;
pub use fixed_patterns::FixedPatterns;
pub use misregistration::Misregistration;
pub use mtf::MtfBudget;
pub use nonlinearity::NonLinearity;
pub use polarisation::Polarisation;
pub use spectral_knowledge::SpectralKnowledge;
pub use spectral_stray::SpectralStrayLight;
pub use stokes_columns::StokesColumns;
pub use stray_light::StrayLight;
pub use tdi::Tdi;

use super::InstrumentError;
use crate::control::RunControl;
use crate::parse::FieldError;

/// One instrument effect as the file states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum InstrumentEffect {
    /// Spatial stray light: a far-field halo around every pixel's PSF and a veil from beyond the
    /// field of view.
    StrayLight(StrayLight),
    /// Polarisation sensitivity: the response depends on the light's linear polarisation.
    Polarisation(Polarisation),
    /// The spatial response: the MTF budget whose PSF the scene is sampled with.
    SpatialResponse(MtfBudget),
    /// Spectral stray light: each band's light partly scattered into the others.
    SpectralStrayLight(SpectralStrayLight),
    /// The detector's response departs from a straight line.
    NonLinearity(NonLinearity),
    /// Striping, dead and hot elements left after the calibration.
    FixedPatterns(FixedPatterns),
    /// On-board compression of Level-0.
    Compression(Compression),
    /// Band-to-band misregistration: each band's grid shifted from the others.
    Misregistration(Misregistration),
    /// Time-delay integration on every focal plane.
    Tdi(Tdi),
    /// The bands' centres, widths or smile differ from what the processor believes.
    SpectralKnowledge(SpectralKnowledge),
    /// On-board binning of k × k pixels into one.
    Binning(Binning),
}

impl InstrumentEffect {
    /// The effect behind the file's entry (the registry: one arm per effect).
    #[must_use]
    pub fn effect(&self) -> &dyn Effect {
        match self {
            Self::StrayLight(e) => e,
            Self::Polarisation(e) => e,
            Self::SpatialResponse(e) => e,
            Self::SpectralStrayLight(e) => e,
            Self::NonLinearity(e) => e,
            Self::FixedPatterns(e) => e,
            Self::Compression(e) => e,
            Self::Misregistration(e) => e,
            Self::Tdi(e) => e,
            Self::SpectralKnowledge(e) => e,
            Self::Binning(e) => e,
        }
    }

    /// Does the focal plane or its electronics make it (non-linearity, fixed patterns,
    /// misregistration, compression, TDI, the bands' spectral knowledge), rather than the optics?
    #[must_use]
    pub fn on_the_focal_plane(&self) -> bool {
        self.effect().role() != Role::Optics
    }

    /// Is it an error source (which `shoal budget`'s perfect switches remove), rather than a
    /// design choice (binning)?
    #[must_use]
    pub fn makes_error(&self) -> bool {
        self.effect().role() != Role::Design
    }

    /// The entry as the optics apply it, the processor's knowledge left out: the key of the
    /// radiance at the detector, which a change of the processor's knowledge does not touch.
    #[must_use]
    pub fn as_applied(&self) -> Self {
        let correction = Knowledge::default();
        match self {
            Self::StrayLight(e) => Self::StrayLight(StrayLight { correction, ..e.clone() }),
            Self::Polarisation(e) => Self::Polarisation(Polarisation { correction, ..e.clone() }),
            Self::SpatialResponse(e) => Self::SpatialResponse(*e),
            Self::SpectralStrayLight(e) => Self::SpectralStrayLight(SpectralStrayLight { correction, ..e.clone() }),
            Self::NonLinearity(e) => Self::NonLinearity(NonLinearity { correction, ..e.clone() }),
            Self::FixedPatterns(e) => Self::FixedPatterns(FixedPatterns { interpolate_dead: true, ..e.clone() }),
            Self::Compression(e) => Self::Compression(*e),
            Self::Misregistration(e) => Self::Misregistration(Misregistration { correction, ..e.clone() }),
            Self::Tdi(e) => Self::Tdi(*e),
            Self::SpectralKnowledge(e) => Self::SpectralKnowledge(e.clone()),
            Self::Binning(e) => Self::Binning(*e),
        }
    }
}

/// What the processor knows of an effect: whether it corrects it, and how wrong its model is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Knowledge {
    /// The Level-1 processor corrects the effect.
    pub corrected: bool,
    /// Relative error of the processor's model of the effect's size (0.1: it believes the
    /// effect 10 % stronger than it is; −1 to 1).
    pub error: f64,
}

impl Default for Knowledge {
    fn default() -> Self {
        Self { corrected: true, error: 0.0 }
    }
}

impl Knowledge {
    /// The processor's factor on the effect's true size (0 when it does not correct).
    #[must_use]
    pub fn factor(&self) -> f64 {
        if self.corrected { 1.0 + self.error } else { 0.0 }
    }

    fn validate(&self, range: &crate::ranges::Range, at: &str) -> Result<(), InstrumentError> {
        check(range, self.error, &format!("{at}.correction.error"))
    }
}

/// What an effect reads besides the radiance cube.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Needs {
    /// The path radiance's Stokes Q and U per column and band ([`StokesColumns`]).
    pub stokes: bool,
}

/// The run's facts an effect may use.
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    /// Ground distance between output rows and between output columns, m (decimation included).
    pub spacing_m: (f64, f64),
    /// The instrument's own ground sample distance, m (a pixel of the full-resolution grid).
    pub pixel_m: f64,
    /// Band centres, nm.
    pub centres_nm: &'a [f64],
    /// The path's Q and U in the instrument's frame, when an effect asks for them.
    pub stokes: Option<&'a StokesColumns>,
}

/// Where an effect arises, which decides who carries it and what removes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The optics make it (stray light, polarisation, the MTF budget).
    Optics,
    /// The focal plane's readout or the electronics downstream of the detector make it
    /// (misregistration, compression, spectral knowledge).
    FocalPlane,
    /// The detector itself carries it, and its key and the calibration's include it
    /// (non-linearity, fixed patterns, TDI).
    Detector,
    /// A design choice on the focal plane, not an error (`shoal budget`'s perfect switches keep
    /// it): on-board binning.
    Design,
}

/// One instrument effect.
pub trait Effect: Sync {
    /// Its name in messages and tables.
    fn name(&self) -> &'static str;
    /// Where it arises (no default: a new effect says).
    fn role(&self) -> Role;
    /// Check the fields (`at` names the entry: `effects[0].StrayLight`).
    fn validate(&self, at: &str) -> Result<(), InstrumentError>;
    /// What it reads besides the cube.
    fn needs(&self) -> Needs {
        Needs::default()
    }
    /// Does it change the radiance cube (`false`: it acts elsewhere, as the spatial response in
    /// the sampling)?
    fn on_the_cube(&self) -> bool {
        true
    }
    /// Turn the radiance reaching the pupil into what reaches the detector, in place (nothing
    /// for an effect that acts elsewhere: [`Self::on_the_cube`] false).
    fn apply(&self, _cube: &mut Array3<f32>, _ctx: &Context, _control: &RunControl) -> Result<(), InstrumentError> {
        Ok(())
    }
    /// The Level-1 processor's correction, in place, with its [`Knowledge`] (nothing for an
    /// effect the calibration or the ground handles, or that no processor corrects).
    fn correct(&self, _cube: &mut Array3<f32>, _ctx: &Context, _control: &RunControl) -> Result<(), InstrumentError> {
        Ok(())
    }
}

/// Check every entry of an instrument's list.
pub fn validate(effects: &[InstrumentEffect]) -> Result<(), InstrumentError> {
    for (i, e) in effects.iter().enumerate() {
        let effect = e.effect();
        effect.validate(&format!("instrument.effects[{i}].{}", effect.name()))?;
    }
    Ok(())
}

/// The entries the detector carries (non-linearity, fixed patterns), in order: part of the
/// detector's key (as applied) and of the calibration's (with what the processor knows).
#[must_use]
pub fn on_the_detector(effects: &[InstrumentEffect]) -> Vec<InstrumentEffect> {
    let carried = |e: &&InstrumentEffect| e.effect().role() == Role::Detector;
    effects.iter().filter(carried).cloned().collect()
}

/// Does any entry need the path's Stokes vector?
#[must_use]
pub fn needs_stokes(effects: &[InstrumentEffect]) -> bool {
    effects.iter().any(|e| e.effect().needs().stokes)
}

/// Does any entry change the radiance cube (else the `Effects` stage has nothing to do)?
#[must_use]
pub fn any_on_the_cube(effects: &[InstrumentEffect]) -> bool {
    effects.iter().any(|e| e.effect().on_the_cube())
}

/// The non-linearity the instrument states, if it states one.
#[must_use]
pub fn non_linearity(effects: &[InstrumentEffect]) -> Option<&NonLinearity> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::NonLinearity(n) => Some(n),
        _ => None,
    })
}

/// The fixed patterns the instrument states, if it states them.
#[must_use]
pub fn fixed_patterns(effects: &[InstrumentEffect]) -> Option<&FixedPatterns> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::FixedPatterns(p) => Some(p),
        _ => None,
    })
}

/// The compression the instrument states, if it states one.
#[must_use]
pub fn compression(effects: &[InstrumentEffect]) -> Option<&Compression> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::Compression(c) => Some(c),
        _ => None,
    })
}

/// The misregistration the instrument states, if it states one.
#[must_use]
pub fn misregistration(effects: &[InstrumentEffect]) -> Option<&Misregistration> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::Misregistration(m) => Some(m),
        _ => None,
    })
}

/// The time-delay integration the instrument states, if it states one.
#[must_use]
pub fn tdi(effects: &[InstrumentEffect]) -> Option<&Tdi> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::Tdi(t) => Some(t),
        _ => None,
    })
}

/// The binning the instrument states, if it bins (a factor or spectral count above 1).
#[must_use]
pub fn binning(effects: &[InstrumentEffect]) -> Option<&Binning> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::Binning(b) if b.factor > 1 || b.spectral > 1 => Some(b),
        _ => None,
    })
}

/// The spectral knowledge error the instrument states, if it states one that changes a band.
#[must_use]
pub fn spectral_knowledge(effects: &[InstrumentEffect]) -> Option<&SpectralKnowledge> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::SpectralKnowledge(k) if !k.is_exact() => Some(k),
        _ => None,
    })
}

/// The MTF budget the instrument states, if it states one.
#[must_use]
pub fn spatial_response(effects: &[InstrumentEffect]) -> Option<&MtfBudget> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::SpatialResponse(m) => Some(m),
        _ => None,
    })
}

/// Apply the list in order.
pub fn apply_all(
    effects: &[InstrumentEffect],
    cube: &mut Array3<f32>,
    ctx: &Context,
    control: &RunControl,
) -> Result<(), InstrumentError> {
    for e in effects {
        e.effect().apply(cube, ctx, control)?;
    }
    Ok(())
}

/// The processor's corrections, last effect first.
pub fn correct_all(
    effects: &[InstrumentEffect],
    cube: &mut Array3<f32>,
    ctx: &Context,
    control: &RunControl,
) -> Result<(), InstrumentError> {
    for e in effects.iter().rev() {
        e.effect().correct(cube, ctx, control)?;
    }
    Ok(())
}

/// The stray-light figure reviews state (3MI's half-bright, half-dark field): the stray signal
/// `distance_m` into the dark half relative to the bright half, in a band at `centre_nm`, of the
/// continuous halo ([`StrayLight::edge_ratio`]); `None` without stray light.
#[must_use]
pub fn edge_ratio(effects: &[InstrumentEffect], distance_m: f64, centre_nm: f64) -> Option<f64> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::StrayLight(s) => Some(s.edge_ratio(distance_m, centre_nm)),
        _ => None,
    })
}

/// The largest polarisation sensitivity of any band (the per-band list's where there is one: it
/// then sets every band); `None` without the effect.
#[must_use]
pub fn polarisation_sensitivity(effects: &[InstrumentEffect]) -> Option<f64> {
    effects.iter().find_map(|e| match e {
        InstrumentEffect::Polarisation(p) if p.per_band.is_empty() => Some(p.sensitivity),
        InstrumentEffect::Polarisation(p) => Some(p.per_band.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
        _ => None,
    })
}

/// A field checked against its entry in [`crate::ranges`], reported under `field`.
pub(crate) fn check(range: &crate::ranges::Range, value: f64, field: &str) -> Result<(), InstrumentError> {
    range.check(value).map_err(|message| InstrumentError::Invalid(FieldError { field: field.to_string(), message }))
}
