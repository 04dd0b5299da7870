//! What each stage's cache key is made of, for the parts of a run that are keyed field by field
//! (the instrument, the detector switches and the fidelity settings; the scene, calibration and
//! correction settings enter their keys whole).
//!
//! [`Inputs::of`] takes these structs apart by **exhaustive destructuring**: a field added to
//! `InstrumentSpec`, `DetectorMode` or `Fidelity` stops this file from compiling until it is
//! placed in the key of the first stage whose product it decides. A hand-listed projection would
//! let the new field miss every key, and the cache would serve a product computed without it
//! (the filter imager's band view angles depend on the focal length and pixel pitch, and the
//! response key did not list them until this file existed). `tests/chain/incremental.rs` checks
//! the outcome: after a change of any one field, a warm engine returns what a fresh one does.

use serde::Serialize;

use super::RunConfig;
use super::config::Fidelity;
use crate::instrument::effects::SpectralKnowledge;
use crate::instrument::{
    BandSelection, DarkTemperature, DetectorMode, FocalPlane, InstrumentEffect, InstrumentKind, InstrumentSpec,
};
use crate::spectral::SpectrumSource;

/// What the spectral response is computed from.
#[derive(Serialize)]
pub(super) struct ResponseInputs<'a> {
    pub kind: &'a InstrumentKind,
    pub quantum_efficiency: &'a SpectrumSource,
    pub detectors: usize,
    /// A filter imager's bands look along track at angles set by the band rows' offset on the
    /// focal plane: `pixel_pitch_um` and `focal_length_mm` move them.
    pub pixel_pitch_um: f64,
    pub focal_length_mm: f64,
    pub spectral_step_nm: f64,
    /// Which bands each further focal plane holds, and its QE.
    pub planes: Vec<PlaneResponse<'a>>,
    /// The bands as the instrument really has them, where they differ from the stated ones
    /// (the grids cover both).
    pub spectral_knowledge: Option<&'a SpectralKnowledge>,
}

/// A further focal plane's part of the spectral response.
#[derive(Serialize)]
pub(super) struct PlaneResponse<'a> {
    pub bands: &'a BandSelection,
    pub quantum_efficiency: &'a SpectrumSource,
}

/// A further focal plane's part of the photon and electron counts.
#[derive(Serialize)]
pub(super) struct PlanePhoton {
    pub pixel_pitch_um: f64,
    pub detectors: usize,
    pub dark_current_e_s: f64,
    pub dark_temperature: Option<DarkTemperature>,
    pub prnu: f64,
    pub dsnu_e: f64,
    pub well_depth_e: f64,
    pub exposure_s: Option<f64>,
}

/// A further focal plane's readout electronics.
#[derive(Serialize)]
pub(super) struct PlaneElectronics {
    pub read_noise_e: f64,
    pub gain_e_per_dn: f64,
    pub bias_dn: f64,
    pub adc_bits: u32,
}

/// A further focal plane taken apart, every field named (see the module's note).
fn plane_parts(p: &FocalPlane) -> (PlaneResponse<'_>, PlanePhoton, PlaneElectronics) {
    let FocalPlane {
        // Labels: no product depends on them.
        name: _,
        material: _,
        bands,
        pixel_pitch_um,
        detectors,
        quantum_efficiency,
        dark_current_e_s,
        dark_temperature,
        read_noise_e,
        well_depth_e,
        gain_e_per_dn,
        bias_dn,
        adc_bits,
        prnu,
        dsnu_e,
        exposure_s,
    } = p;
    (
        PlaneResponse { bands, quantum_efficiency },
        PlanePhoton {
            pixel_pitch_um: *pixel_pitch_um,
            detectors: *detectors,
            dark_current_e_s: *dark_current_e_s,
            dark_temperature: *dark_temperature,
            prnu: *prnu,
            dsnu_e: *dsnu_e,
            well_depth_e: *well_depth_e,
            exposure_s: *exposure_s,
        },
        PlaneElectronics {
            read_noise_e: *read_noise_e,
            gain_e_per_dn: *gain_e_per_dn,
            bias_dn: *bias_dn,
            adc_bits: *adc_bits,
        },
    )
}

/// The geometry an instrument flies (a change re-runs `Geometry` onward).
#[derive(Serialize)]
pub(super) struct Orbit {
    pub altitude_km: f64,
    pub heading_deg: f64,
    pub pixel_pitch_um: f64,
    pub focal_length_mm: f64,
    pub detectors: usize,
    pub lines: usize,
    pub forward_tilt_deg: f64,
    pub across_track_tilt_deg: f64,
    pub decimation: usize,
}

/// The part of an instrument that decides photon and electron counts (a change re-runs the
/// detector model and `Electrons` onward).
#[derive(Serialize)]
pub(super) struct PhotonSide<'a> {
    pub kind: &'a InstrumentKind,
    pub aperture_mm: f64,
    pub pixel_pitch_um: f64,
    pub focal_length_mm: f64,
    pub detectors: usize,
    pub exposure_s: f64,
    pub optical_transmission: f64,
    pub quantum_efficiency: &'a SpectrumSource,
    pub dark_current_e_s: f64,
    pub prnu: f64,
    pub dsnu_e: f64,
    pub well_depth_e: f64,
    pub dark_temperature: Option<DarkTemperature>,
    pub planes: Vec<PlanePhoton>,
    pub noise: bool,
    pub seed: u64,
}

/// The readout electronics (a change re-runs the detector model and `Level0` onward only).
#[derive(Serialize)]
pub(super) struct Electronics {
    pub read_noise_e: f64,
    pub gain_e_per_dn: f64,
    pub bias_dn: f64,
    pub adc_bits: u32,
    pub planes: Vec<PlaneElectronics>,
    pub quantise: bool,
}

/// The measured-SNR patch.
#[derive(Serialize)]
pub(super) struct SnrPatch {
    pub frames: usize,
    pub detectors: usize,
    /// A preview measures on `detectors / decimation` detectors: the typical radiance alone
    /// would not tell two decimations of a uniform scene apart.
    pub decimation: usize,
    pub seed: u64,
}

/// Every keyed field of a run, placed with its stage.
pub(super) struct Inputs<'a> {
    pub response: ResponseInputs<'a>,
    pub orbit: Orbit,
    pub photon: PhotonSide<'a>,
    pub electronics: Electronics,
    pub snr: SnrPatch,
    /// The radiance stage turns the spatial kernel with the ground track; the kernel itself
    /// (offsets and weights, from the aperture, altitude, exposure and GSD and
    /// `spatial_samples_per_gsd`) enters the radiance key by value.
    pub heading_deg: f64,
    /// The optics between pupil and detector: the `Effects` stage applies them to the pupil
    /// radiance and `Level1` corrects them as the processor knows them.
    pub effects: &'a [InstrumentEffect],
    /// Nodes per band of the per-pixel water spectra (the optics stage: 0 = every grid
    /// wavelength).
    pub band_nodes: usize,
    /// The per-pixel water kernel's precision (the optics stage).
    pub water_single_precision: bool,
    /// The correction and calibration stages (decimation and seed, besides their own settings).
    pub decimation: usize,
    pub seed: u64,
}

impl<'a> Inputs<'a> {
    /// Take `config`'s instrument, detector switches and fidelity apart, every field named.
    pub fn of(config: &'a RunConfig) -> Self {
        let InstrumentSpec {
            // Labels: no product depends on them.
            name: _,
            description: _,
            kind,
            altitude_km,
            heading_deg,
            aperture_mm,
            pixel_pitch_um,
            focal_length_mm,
            detectors,
            exposure_s,
            lines,
            forward_tilt_deg,
            across_track_tilt_deg,
            read_noise_e,
            well_depth_e,
            gain_e_per_dn,
            bias_dn,
            adc_bits,
            optical_transmission,
            quantum_efficiency,
            dark_current_e_s,
            prnu,
            dsnu_e,
            dark_temperature,
            // A label: the first plane's numbers are the fields above.
            material: _,
            focal_planes,
            effects,
        } = &config.instrument;
        let (mut plane_response, mut plane_photon, mut plane_electronics) = (Vec::new(), Vec::new(), Vec::new());
        for p in focal_planes {
            let (r, ph, e) = plane_parts(p);
            plane_response.push(r);
            plane_photon.push(ph);
            plane_electronics.push(e);
        }
        let DetectorMode { noise, quantise } = config.detector;
        let Fidelity {
            spectral_step_nm,
            // Enter the radiance key through the spatial kernel's offsets and weights.
            spatial_samples_per_gsd: _,
            band_nodes,
            water_single_precision,
            decimation,
            // Enter the LUT key through the axes they build (`lut_axes`).
            lut_wavelength_step_nm: _,
            lut_view_step_deg: _,
            snr_frames,
            snr_detectors,
        } = config.fidelity;
        let seed = config.seed;
        Self {
            response: ResponseInputs {
                kind,
                quantum_efficiency,
                detectors: *detectors,
                pixel_pitch_um: *pixel_pitch_um,
                focal_length_mm: *focal_length_mm,
                spectral_step_nm,
                planes: plane_response,
                spectral_knowledge: crate::instrument::effects::spectral_knowledge(effects),
            },
            orbit: Orbit {
                altitude_km: *altitude_km,
                heading_deg: *heading_deg,
                pixel_pitch_um: *pixel_pitch_um,
                focal_length_mm: *focal_length_mm,
                detectors: *detectors,
                lines: *lines,
                forward_tilt_deg: *forward_tilt_deg,
                across_track_tilt_deg: *across_track_tilt_deg,
                decimation,
            },
            photon: PhotonSide {
                kind,
                aperture_mm: *aperture_mm,
                pixel_pitch_um: *pixel_pitch_um,
                focal_length_mm: *focal_length_mm,
                detectors: *detectors,
                exposure_s: *exposure_s,
                optical_transmission: *optical_transmission,
                quantum_efficiency,
                dark_current_e_s: *dark_current_e_s,
                prnu: *prnu,
                dsnu_e: *dsnu_e,
                well_depth_e: *well_depth_e,
                dark_temperature: *dark_temperature,
                planes: plane_photon,
                noise,
                seed,
            },
            electronics: Electronics {
                read_noise_e: *read_noise_e,
                gain_e_per_dn: *gain_e_per_dn,
                bias_dn: *bias_dn,
                adc_bits: *adc_bits,
                planes: plane_electronics,
                quantise,
            },
            snr: SnrPatch { frames: snr_frames, detectors: snr_detectors, decimation, seed },
            heading_deg: *heading_deg,
            effects,
            band_nodes,
            water_single_precision,
            decimation,
            seed,
        }
    }
}
