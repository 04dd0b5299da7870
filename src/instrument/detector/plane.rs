//! Each focal plane's electronics and its sampling of the image grid ([`crate::instrument::focal`]),
//! as the detector model reads them per band.

use super::super::focal::Sampling;
use super::super::spec::InstrumentSpec;

/// One focal plane's numbers, as the detector model uses them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneElectronics {
    /// How its pixels tile the image grid.
    pub sampling: Sampling,
    /// Dark current at the operating temperature, e⁻ s⁻¹ per pixel.
    pub dark_current_e_s: f64,
    /// Photo-response non-uniformity of a grid pixel, relative rms (÷ m when m × m pixels are
    /// binned into it).
    pub prnu: f64,
    /// Dark-signal non-uniformity of a grid pixel, e⁻ rms (÷ m likewise).
    pub dsnu_e: f64,
    /// Étendue of one of its pixels, m² sr.
    pub etendue_m2_sr: f64,
    /// Its integration time over the instrument's nominal exposure.
    pub exposure_ratio: f64,
    /// Full well, e⁻ (in `f32` precision: see [`super::Detector::new`]).
    pub well_e: f64,
    /// Read noise of a grid pixel's value, e⁻ rms: σ/m when m × m pixels are averaged.
    pub read_noise_e: f64,
    /// Conversion gain, e⁻/DN.
    pub gain_e_per_dn: f64,
    /// 1/gain.
    pub dn_per_e: f64,
    /// Bias, DN.
    pub bias_dn: f64,
    /// Largest DN, 2^bits − 1.
    pub dn_max: f64,
    /// Reads averaged into one value (digital TDI's N; 1 otherwise).
    pub reads: f64,
}

impl PlaneElectronics {
    /// Every plane of `spec`: its first (the instrument's own fields), then `focal_planes`.
    #[must_use]
    pub fn of(spec: &InstrumentSpec) -> Vec<Self> {
        let d = spec.aperture_mm * 1e-3;
        let etendue = |pitch_um: f64| {
            let ifov = pitch_um * 1e-6 / (spec.focal_length_mm * 1e-3);
            std::f64::consts::PI * d * d / 4.0 * ifov * ifov
        };
        let first = Self {
            sampling: Sampling::Same,
            dark_current_e_s: spec.dark_current_at_operating_e_s(),
            prnu: spec.prnu,
            dsnu_e: spec.dsnu_e,
            etendue_m2_sr: spec.etendue_m2_sr(),
            exposure_ratio: 1.0,
            well_e: f64::from(spec.well_depth_e as f32),
            read_noise_e: spec.read_noise_e,
            gain_e_per_dn: spec.gain_e_per_dn,
            dn_per_e: 1.0 / spec.gain_e_per_dn,
            bias_dn: spec.bias_dn,
            dn_max: spec.dn_max(),
            reads: 1.0,
        };
        std::iter::once(first)
            .chain(spec.focal_planes.iter().map(|p| {
                // Validation refused pitches that do not tile the grid; a plane reaching here
                // untested is sampled like the first.
                let sampling = Sampling::of(p.pixel_pitch_um, spec.pixel_pitch_um).unwrap_or(Sampling::Same);
                let m = (sampling.binned() as f64).sqrt();
                Self {
                    sampling,
                    dark_current_e_s: p.dark_current_at_operating_e_s(),
                    prnu: p.prnu / m,
                    dsnu_e: p.dsnu_e / m,
                    etendue_m2_sr: etendue(p.pixel_pitch_um),
                    exposure_ratio: p.exposure_on(spec.pixel_pitch_um, spec.exposure_s) / spec.exposure_s,
                    well_e: f64::from(p.well_depth_e as f32),
                    read_noise_e: p.read_noise_e / m,
                    gain_e_per_dn: p.gain_e_per_dn,
                    dn_per_e: 1.0 / p.gain_e_per_dn,
                    bias_dn: p.bias_dn,
                    dn_max: p.dn_max(),
                    reads: 1.0,
                }
            }))
            .map(|plane| match crate::instrument::effects::tdi(&spec.effects) {
                Some(tdi) => plane.integrated(tdi),
                None => plane,
            })
            .collect()
    }

    /// The plane integrating over `tdi`'s N stages ([`crate::instrument::effects::tdi`]):
    /// charge-domain, N times the signal and dark signal in one read (the integration time N
    /// times one row's), DSNU·√N and PRNU/√N of N pooled pixels; digital, N reads averaged
    /// (shot and read noise, PRNU and DSNU all over √N).
    #[must_use]
    pub fn integrated(self, tdi: &crate::instrument::effects::Tdi) -> Self {
        let n = tdi.n();
        if tdi.digital {
            Self {
                prnu: self.prnu / n.sqrt(),
                dsnu_e: self.dsnu_e / n.sqrt(),
                read_noise_e: self.read_noise_e / n.sqrt(),
                reads: self.reads * n,
                ..self
            }
        } else {
            Self {
                prnu: self.prnu / n.sqrt(),
                dsnu_e: self.dsnu_e * n.sqrt(),
                exposure_ratio: self.exposure_ratio * n,
                ..self
            }
        }
    }

    /// Values averaged into one grid pixel's (m² pixels of a finer plane, times digital TDI's
    /// reads; 1 otherwise).
    #[must_use]
    pub fn binned(&self) -> f64 {
        self.sampling.binned() as f64 * self.reads
    }

    /// Grid pixels per plane pixel along a side (k for a coarser plane, 1 otherwise).
    #[must_use]
    pub fn block(&self) -> usize {
        self.sampling.block()
    }
}
