//! The scene's spectrum at one ground point, 350–2500 nm, with what each instrument measured
//! there: the figure an engineer reads a band placement from (does the 1610 nm band sit in a
//! window? how much of the 443 nm signal is the atmosphere?).
//!
//! The spectrum is the forward model of the run, evaluated at one point on its own grid:
//! L_TOA = L_path + T_up·Lw + L_glint (+ L_adj), Lw = Rrs·Ed/(1 − S·π·Rrs) (Vermote et al. 1997;
//! see [`crate::toa`]), every [`SPECTRUM_STEP_NM`] nm. Its atmosphere LUT has wavelength nodes
//! every [`LUT_STEP_NM`] nm (the scattering terms are smooth and interpolated log–log between
//! nodes, exact for a power law such as Rayleigh's λ⁻⁴); gas absorption and the solar spectrum
//! are applied at every grid wavelength, so absorption bands keep their depth. The geometry is
//! that of the instrument pixel asked for (its sun and view zenith, relative azimuth).
//!
//! What each instrument measured there comes from its run, unchanged: the Level-1 radiance and
//! the corrected Rrs of its pixel nearest the point, with the band's spectral response.

use std::sync::Arc;

use super::cache::{Key, KeyBuilder};
use super::{EngineError, RunOutput, Stage};
use crate::atmosphere::{AtmosphereLut, LutAxes};
use crate::spectral::WavelengthGrid;
use crate::toa::{SceneOptics, Scratch, Target};

/// First wavelength of the spectrum, nm.
pub const SPECTRUM_START_NM: f64 = 350.0;
/// Last wavelength of the spectrum, nm.
pub const SPECTRUM_END_NM: f64 = 2500.0;
/// Spacing of the spectrum, nm: the 1-nm grid of the solar spectrum and of the run's own
/// simulation, so that a band integrated over it gives the run's band radiance (the Fraunhofer
/// lines matter: a 2.5 nm spacing put the 443 nm band 1.8 % off).
pub const SPECTRUM_STEP_NM: f64 = 1.0;
/// Spacing of the atmosphere LUT's wavelength nodes for the spectrum, nm.
pub const LUT_STEP_NM: f64 = 50.0;

/// The scene at one ground point, seen from one instrument pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSpectrum {
    /// The ground point, scene frame, m.
    pub ground_m: (f64, f64),
    /// The pixel it was seen from (row, column of the run it came from).
    pub pixel: (usize, usize),
    /// Sun zenith, degrees.
    pub sun_zenith_deg: f64,
    /// View zenith, degrees.
    pub view_zenith_deg: f64,
    /// Water (`rrs_per_sr` holds its Rrs) or land (zeros).
    pub water: bool,
    /// Does the scene's atmosphere include gas absorption (`atmosphere.gases`)?
    pub gases: bool,
    /// Wavelengths, nm.
    pub wavelengths_nm: Vec<f64>,
    /// TOA radiance, W m⁻² sr⁻¹ µm⁻¹ (the unit missions state reference radiances in).
    pub l_toa_w_m2_sr_um: Vec<f64>,
    /// Path radiance alone, W m⁻² sr⁻¹ µm⁻¹ (the atmosphere's share of the signal).
    pub l_path_w_m2_sr_um: Vec<f64>,
    /// Above-surface remote-sensing reflectance, sr⁻¹ (the truth; zeros on land).
    pub rrs_per_sr: Vec<f64>,
}

/// One band of an instrument at the point.
#[derive(Debug, Clone, PartialEq)]
pub struct BandAtPoint {
    /// Band name.
    pub name: String,
    /// Centre, nm.
    pub centre_nm: f64,
    /// FWHM, nm.
    pub fwhm_nm: f64,
    /// Spectral response, (nm, response scaled to peak 1).
    pub srf: Vec<(f64, f64)>,
    /// Level-1 radiance of the pixel, W m⁻² sr⁻¹ µm⁻¹ (`None` where flagged).
    pub level1_w_m2_sr_um: Option<f64>,
    /// Corrected Rrs of the pixel, sr⁻¹ (`None` where flagged).
    pub rrs_per_sr: Option<f64>,
}

/// What one instrument measured at the point.
#[derive(Debug, Clone, PartialEq)]
pub struct InstrumentAtPoint {
    /// The instrument's label.
    pub label: String,
    /// Its pixel nearest the point (`None`: the point is off its image).
    pub pixel: Option<(usize, usize)>,
    /// Its bands.
    pub bands: Vec<BandAtPoint>,
}

/// Computes point spectra, keeping the atmosphere LUT and the scene optics between calls on
/// the same scene and atmosphere (a second click costs the water model only).
#[derive(Default)]
pub struct SpectrumMaker {
    cached: Option<(Key, Arc<SceneOptics>)>,
}

impl SpectrumMaker {
    /// The scene of `out` at its pixel (row, column), 350–2500 nm.
    ///
    /// # Errors
    /// A pixel outside the run, or a failure of the atmosphere or water model (named).
    pub fn at(&mut self, out: &RunOutput, row: usize, column: usize) -> Result<PointSpectrum, EngineError> {
        let fail = |message: String| EngineError::Failed { stage: Stage::Optics, message };
        let viewing = &out.viewing;
        if row >= viewing.lines() || column >= viewing.columns() {
            return Err(fail(format!(
                "pixel ({row}, {column}) is outside the image ({} × {})",
                viewing.lines(),
                viewing.columns()
            )));
        }
        let look = viewing.looks[0][column];
        let g = look.geometry;
        let ground_m = viewing.ground_m(0, row, column);
        let optics = self.optics(out)?;
        let path = optics.path_spectrum(&g).map_err(|e| fail(e.to_string()))?;
        let n = optics.grid().len();
        let (mut l_toa, mut rrs) = (vec![0.0; n], vec![0.0; n]);
        let sky = out.scene.sky_at(ground_m.0, ground_m.1, g.view_zenith_rad, look.view_azimuth_rad);
        let surface = optics
            .radiance(&out.scene, ground_m.0, ground_m.1, &g, sky, &path, &mut Scratch::default(), &mut l_toa, &mut rrs)
            .map_err(|e| fail(e.to_string()))?;
        let per_um = |v: &[f64]| v.iter().map(|x| x * 1000.0).collect::<Vec<_>>();
        Ok(PointSpectrum {
            ground_m,
            pixel: (row, column),
            sun_zenith_deg: g.sun_zenith_rad.to_degrees(),
            view_zenith_deg: g.view_zenith_rad.to_degrees(),
            water: surface == Target::Water,
            gases: out.config.scene.atmosphere.gases,
            wavelengths_nm: optics.grid().wavelengths_nm().to_vec(),
            l_toa_w_m2_sr_um: per_um(&l_toa),
            l_path_w_m2_sr_um: per_um(&path.l_path),
            rrs_per_sr: rrs,
        })
    }

    /// The scene optics on the spectrum's grid, built once per scene and atmosphere.
    fn optics(&mut self, out: &RunOutput) -> Result<Arc<SceneOptics>, EngineError> {
        let fail = |stage: Stage| move |e: String| EngineError::Failed { stage, message: e };
        let step = (SPECTRUM_END_NM - SPECTRUM_START_NM) / LUT_STEP_NM;
        let nodes: Vec<f64> = (0..=step.round() as usize).map(|i| SPECTRUM_START_NM + LUT_STEP_NM * i as f64).collect();
        let sun = out.config.scene.sun.zenith_deg;
        // View nodes every 10° up to the run's widest view: one LUT serves every pixel.
        let max_vza = (out.viewing.max_view_zenith_deg / 10.0).ceil().max(1.0) * 10.0;
        let axes = LutAxes::covering(
            nodes,
            (sun, sun),
            max_vza.min(crate::ranges::GEOMETRY_VIEW_ZENITH_DEG.hi),
            (1.0, 10.0, 30.0),
        );
        let mut spec = out.config.scene.atmosphere.clone();
        spec.day_of_year = out.scene.day_of_year;
        let key =
            KeyBuilder::new(Stage::Lut).with(&spec).with(&axes).with(&(Arc::as_ptr(&out.scene) as usize)).finish();
        if let Some((k, optics)) = &self.cached
            && *k == key
        {
            return Ok(optics.clone());
        }
        let atmosphere = spec.build().map_err(|e| fail(Stage::Lut)(e.to_string()))?;
        let lut = AtmosphereLut::build(&atmosphere, axes).map_err(|e| fail(Stage::Lut)(e.to_string()))?;
        let grid = WavelengthGrid::uniform(SPECTRUM_START_NM, SPECTRUM_END_NM, SPECTRUM_STEP_NM)
            .map_err(|e| fail(Stage::Optics)(e.to_string()))?;
        let optics = Arc::new(
            SceneOptics::new(&out.scene, &grid, Arc::new(lut)).map_err(|e| fail(Stage::Optics)(e.to_string()))?,
        );
        self.cached = Some((key, optics.clone()));
        Ok(optics)
    }
}

/// What instrument `label` of run `out` measured at ground point `ground_m` (its nearest pixel;
/// for a run that kept views of its cubes, the kept pixel of that pixel's block).
#[must_use]
pub fn instrument_at(out: &RunOutput, label: &str, ground_m: (f64, f64)) -> InstrumentAtPoint {
    let heading = out.viewing.track_heading_deg();
    let pixel = out.viewing.nearest_pixel(ground_m.0, ground_m.1, heading);
    let pixel = match (&out.cubes, &out.views) {
        (None, Some(v)) => pixel.map(|p| v.kept(p)),
        _ => pixel,
    };
    let bands = out
        .response
        .bands
        .bands
        .iter()
        .enumerate()
        .map(|(b, band)| {
            let peak = band.srf.values.iter().copied().fold(0.0_f64, f64::max).max(f64::MIN_POSITIVE);
            let srf = band.srf.wavelength_nm.iter().zip(&band.srf.values).map(|(&w, &v)| (w, v / peak)).collect();
            let (level1, rrs) = pixel.map_or((None, None), |(r, c)| measured_at(out, (r, c), b));
            BandAtPoint {
                name: band.name.clone(),
                centre_nm: band.centre_nm,
                fwhm_nm: band.fwhm_nm,
                srf,
                level1_w_m2_sr_um: level1,
                rrs_per_sr: rrs,
            }
        })
        .collect();
    InstrumentAtPoint { label: label.to_string(), pixel, bands }
}

/// Band `b`'s Level-1 radiance (W m⁻² sr⁻¹ µm⁻¹) and corrected Rrs (sr⁻¹) at `pixel` of `out`,
/// each `None` where flagged: from the run's cubes when it kept them, else from its views (at the
/// kept pixel of `pixel`'s block), else from a pixel it was asked to keep ([`super::Probe`]);
/// `None` where it has none of them.
fn measured_at(out: &RunOutput, (r, c): (usize, usize), b: usize) -> (Option<f64>, Option<f64>) {
    let good = |(v, flag): (f32, u8)| (flag == 0).then_some(f64::from(v));
    if let Some(cubes) = &out.cubes {
        let l1 = good((cubes.level1.radiance[[r, c, b]], cubes.level1.flags[[r, c, b]])).map(|v| v * 1000.0);
        return (l1, good((cubes.rrs.rrs[[r, c, b]], cubes.rrs.flags[[r, c, b]])));
    }
    if let Some(views) = &out.views {
        let l1 = views.at(super::ViewOf::Level1, (r, c), b).and_then(good).map(|v| v * 1000.0);
        return (l1, views.at(super::ViewOf::Rrs, (r, c), b).and_then(good));
    }
    out.probes.iter().find(|p| p.pixel == Some((r, c))).map_or((None, None), |p| {
        let l1 = p.level1.get(b).copied().and_then(good).map(|v| v * 1000.0);
        (l1, p.rrs.get(b).copied().and_then(good))
    })
}
