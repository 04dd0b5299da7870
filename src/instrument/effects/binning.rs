//! On-board spatial binning: k × k detector pixels summed into one before the downlink, trading
//! ground sampling for signal-to-noise and data volume (a CubeSat decision: bin 2 × 2 and meet
//! the SNR, or keep the GSD).
//!
//! A binned pixel is k² pixels' signal: electrons S_k = k²·S (k pixels across track, k
//! successive lines along it, each exposed t). Its noise depends on where the sum is made
//! (Janesick 2001, §4.3 on-chip binning; Holst & Lomheim 2011, §6.5):
//! - **charge** (`digital: false`, a CCD's serial register and summing well): the charge is
//!   summed before the one read, σ² = k²S + k²·D·t + σ_r² — read noise once;
//! - **digital** (`digital: true`, a CMOS plane, or summing in the electronics): k² reads, each
//!   quantised, averaged: σ² = k²S + k²·D·t + k²(σ_r² + g²/12), with g the gain (e⁻/DN).
//!
//! Shoal simulates the binned instrument directly rather than k² times as many pixels: the
//! instrument as flown ([`Binning::flown`]) has the pitch k·p (so its pixel collects k² the
//! light through the same optics and its footprint is k GSDs), ⌊N/k⌋ detectors and lines, a well
//! of k²·W (the summing well must hold it), the dark current k²·D, DSNU k·σ_D and PRNU σ_P/k
//! (sums of k² independent elements), and an ADC whose gain is k²·g at the same bits (the
//! downlinked value is the k² pixels' mean in the original DN, so the data per pixel stay the
//! same); the digital sum's k² reads and roundings enter as the read noise k·√(σ_r² + g²/12).
//! The signal, the noise and the pixel's footprint (k·p box; the smear of each line, t/T of a
//! native pixel, is t/(kT) of the binned one) are those of the sum. SNR, GSD and the data budget
//! follow from the instrument as flown.
//!
//! ## References
//! - Janesick, J. R. (2001) Scientific Charge-Coupled Devices. SPIE Press, §4.3.
//! - Holst, G. C., Lomheim, T. S. (2011) CMOS/CCD Sensors and Camera Systems, 2nd ed. SPIE
//!   Press, §6.5.

use serde::{Deserialize, Serialize};

use super::{Effect, InstrumentEffect, InstrumentError, check};
use crate::instrument::{InstrumentKind, InstrumentSpec};
use crate::parse::FieldError;
use crate::ranges as r;

/// On-board binning as an instrument file states it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Binning {
    /// Pixels summed along and across track: k × k make one.
    #[serde(default = "one")]
    pub factor: u32,
    /// A spectrograph's adjacent spectral samples summed: m make one band.
    #[serde(default = "one")]
    pub spectral: u32,
    /// Summed after digitisation (k² reads) rather than as charge (one read).
    #[serde(default)]
    pub digital: bool,
}

fn one() -> u32 {
    1
}

impl Binning {
    /// A short statement for tables ("2 × 2 charge", "1 × 1 × 3 spectral, digital").
    #[must_use]
    pub fn describe(&self) -> String {
        let spectral = if self.spectral > 1 { format!(" × {} spectral", self.spectral) } else { String::new() };
        let how = if self.digital { "digital" } else { "charge" };
        if spectral.is_empty() {
            format!("{0} × {0} {how}", self.factor)
        } else {
            format!("{0} × {0}{spectral}, {how}", self.factor)
        }
    }

    /// Pixels summed into one binned value, k²·m.
    #[must_use]
    pub fn summed(&self) -> f64 {
        f64::from(self.factor.max(1)).powi(2) * f64::from(self.spectral.max(1))
    }

    /// One focal plane's numbers as binned, in place: well, read noise, gain, dark current,
    /// DSNU and PRNU (the module docs), for the k²·m elements in one binned value.
    fn bin_electronics(&self, [well_e, read_e, gain_e_per_dn, dark_e_s, dsnu_e, prnu]: [&mut f64; 6]) {
        let summed = self.summed();
        if self.digital {
            *read_e = (summed * (*read_e * *read_e + *gain_e_per_dn * *gain_e_per_dn / 12.0)).sqrt();
        }
        *well_e *= summed;
        *gain_e_per_dn *= summed;
        *dark_e_s *= summed;
        *dsnu_e *= summed.sqrt();
        *prnu /= summed.sqrt();
    }

    /// The instrument as flown: `spec` with every focal plane binned (the module docs), the
    /// binning entry itself removed and a misregistration's shifts in binned pixels.
    #[must_use]
    pub fn flown(&self, spec: &InstrumentSpec) -> InstrumentSpec {
        let k = f64::from(self.factor.max(1));
        let n = self.factor.max(1) as usize;
        let mut out = spec.clone();
        out.pixel_pitch_um *= k;
        out.detectors = (spec.detectors / n).max(1);
        out.lines = (spec.lines / n).max(1);
        self.bin_electronics([
            &mut out.well_depth_e,
            &mut out.read_noise_e,
            &mut out.gain_e_per_dn,
            &mut out.dark_current_e_s,
            &mut out.dsnu_e,
            &mut out.prnu,
        ]);
        if let InstrumentKind::Spectrograph { channels_summed, .. } = &mut out.kind {
            *channels_summed *= self.spectral.max(1) as usize;
        }
        for p in &mut out.focal_planes {
            p.pixel_pitch_um *= k;
            // Rounded up: a coarser plane still covers the first plane's binned swath.
            p.detectors = p.detectors.div_ceil(n).max(1);
            self.bin_electronics([
                &mut p.well_depth_e,
                &mut p.read_noise_e,
                &mut p.gain_e_per_dn,
                &mut p.dark_current_e_s,
                &mut p.dsnu_e,
                &mut p.prnu,
            ]);
        }
        out.effects.retain(|e| !matches!(e, InstrumentEffect::Binning(_)));
        for e in &mut out.effects {
            if let InstrumentEffect::Misregistration(m) = e {
                m.sigma_px /= k;
                for s in &mut m.per_band {
                    *s = (s.0 / k, s.1 / k);
                }
            }
        }
        out
    }
}

impl Effect for Binning {
    fn name(&self) -> &'static str {
        "Binning"
    }

    fn role(&self) -> super::Role {
        super::Role::Design
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::BINNING_FACTOR, f64::from(self.factor), &format!("{at}.factor"))?;
        check(&r::BINNING_SPECTRAL, f64::from(self.spectral), &format!("{at}.spectral"))
    }

    /// It changes the instrument (its pixels), not the cube.
    fn on_the_cube(&self) -> bool {
        false
    }
}

/// A binning the instrument cannot make: fewer detectors or lines than one binned pixel needs,
/// or spectral binning on an instrument without a spectrum on its detector.
pub(crate) fn check_fits(b: &Binning, spec: &InstrumentSpec) -> Result<(), InstrumentError> {
    if b.spectral > 1 && !matches!(spec.kind, InstrumentKind::Spectrograph { .. }) {
        return Err(InstrumentError::Invalid(FieldError {
            field: "instrument.effects[].Binning.spectral".into(),
            message: format!(
                "{} on an instrument whose bands are filters (allowed: 1; a Spectrograph sums adjacent samples)",
                b.spectral
            ),
        }));
    }
    let k = b.factor as usize;
    let short = [("detectors", spec.detectors), ("lines", spec.lines)].into_iter().find(|(_, n)| *n < k);
    match short {
        Some((what, n)) => Err(InstrumentError::Invalid(FieldError {
            field: "instrument.effects[].Binning.factor".into(),
            message: format!("{k} × {k} binning with {n} {what} (allowed: 1 to {n})"),
        })),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flown_instrument_is_the_sum_of_k_squared_pixels() {
        let spec = InstrumentSpec::preset("cubesat").unwrap();
        let charge = Binning { factor: 2, spectral: 1, digital: false }.flown(&spec);
        assert_eq!(charge.pixel_pitch_um, 2.0 * spec.pixel_pitch_um);
        assert_eq!(charge.detectors, spec.detectors / 2);
        assert_eq!(charge.lines, spec.lines / 2);
        assert!((charge.gsd_m() / spec.gsd_m() - 2.0).abs() < 1e-12);
        assert_eq!(charge.well_depth_e, 4.0 * spec.well_depth_e);
        assert_eq!(charge.read_noise_e, spec.read_noise_e, "charge: one read");
        assert_eq!(charge.gain_e_per_dn, 4.0 * spec.gain_e_per_dn);
        assert_eq!(charge.adc_bits, spec.adc_bits);
        let digital = Binning { factor: 2, spectral: 1, digital: true }.flown(&spec);
        let g = spec.gain_e_per_dn;
        let expected = 2.0 * (spec.read_noise_e.powi(2) + g * g / 12.0).sqrt();
        assert!((digital.read_noise_e - expected).abs() < 1e-12, "digital: four reads and roundings");
        assert!(digital.effects.iter().all(|e| !matches!(e, InstrumentEffect::Binning(_))));
    }

    #[test]
    fn binned_noise_is_the_analytic_sum_of_k_squared_pixels() {
        use crate::instrument::{Detector, DetectorMode, Response, analytic_snr, measured_snr};
        let mut spec = InstrumentSpec::preset("cubesat").unwrap();
        spec.dark_current_e_s = 2000.0;
        let of = |s: &InstrumentSpec| {
            let r = Response::new(s, 1.0).unwrap();
            Detector::new(s, &r, DetectorMode::default(), 5)
        };
        let native = of(&spec);
        let (j, b, radiance) = (spec.detectors / 2, 5, 0.02);
        let t = native.exposure_s();
        let (signal, dark) = (native.responsivity(j, b) * radiance, native.dark_mean_e(j, b, t));
        let (read, g) = (spec.read_noise_e, spec.gain_e_per_dn);
        for (k, digital) in [(2u32, false), (2, true), (3, false)] {
            let flown = Binning { factor: k, spectral: 1, digital }.flown(&spec);
            let binned = of(&flown);
            let (kk, jb) = (f64::from(k * k), flown.detectors / 2);
            // The binned pixel collects k² times the light and the dark current.
            assert!((binned.responsivity(jb, b) / native.responsivity(j, b) / kk - 1.0).abs() < 1e-12);
            assert!((binned.dark_mean_e(jb, b, t) / dark / kk - 1.0).abs() < 1e-12);
            // σ² = k²(S + D) + reads + one rounding of the sum at the gain k²·g (module docs).
            let reads = if digital { kk * (read * read + g * g / 12.0) } else { read * read };
            let expected = kk * signal / (kk * (signal + dark) + reads + (kk * g).powi(2) / 12.0).sqrt();
            let analytic = analytic_snr(&binned, jb, b, radiance);
            assert!((analytic / expected - 1.0).abs() < 1e-9, "{k} {digital}: {analytic} against {expected}");
            // And the frames the detector draws agree: 400 frames, the SNR's standard error
            // 1/√800 = 3.5 %; 4σ.
            let mut radiances = vec![0.0; binned.n_bands()];
            radiances[b] = radiance;
            let measured = measured_snr(&binned, &radiances, &[jb], 400, 11)[b];
            assert!((measured / expected - 1.0).abs() < 0.14, "{k} {digital}: measured {measured}, {expected}");
        }
        // Shot-limited, 2 × 2 gains 2 in SNR; in charge, the one read makes it more than 2
        // exactly where the read noise outweighs the coarser rounding, σ_r > g/√3 (from the
        // variances above: 4(S + D + σ_r² + g²/12) against S + D + σ_r²/4 + g²/3).
        let flown = Binning { factor: 2, spectral: 1, digital: false }.flown(&spec);
        let gain = analytic_snr(&of(&flown), flown.detectors / 2, b, radiance) / analytic_snr(&native, j, b, radiance);
        assert_eq!(gain > 2.0, read > g / 3f64.sqrt(), "{gain}");
        assert!(gain > 1.5, "{gain}");
    }

    #[test]
    fn spectral_binning_sums_adjacent_samples() {
        use crate::instrument::{Detector, DetectorMode, Response};
        let mut spec = InstrumentSpec::preset("hyperspectral").unwrap();
        // No PRNU: each element's own draw would hide the sum.
        spec.prnu = 0.0;
        let flown = Binning { factor: 1, spectral: 2, digital: true }.flown(&spec);
        let of = |s: &InstrumentSpec| {
            let r = Response::new(s, 0.5).unwrap();
            (Detector::new(s, &r, DetectorMode::default(), 5), r)
        };
        let ((native, nr), (binned, br)) = (of(&spec), of(&flown));
        // 101 samples 400–900 nm every 5 nm: 50 bands of two, the first centred at 402.5 nm.
        assert_eq!(br.n_bands(), nr.n_bands() / 2);
        assert!((br.bands.bands[0].centre_nm - 402.5).abs() < 0.05, "{}", br.bands.bands[0].centre_nm);
        // Each band collects its two samples' light: the responsivities add (to the tabulation
        // of the summed Gaussians, 1e-3).
        let j = spec.detectors / 2;
        for i in [0, 10, 49] {
            let sum = native.responsivity(j, 2 * i) + native.responsivity(j, 2 * i + 1);
            assert!(
                (binned.responsivity(j, i) / sum - 1.0).abs() < 1e-3,
                "band {i}: {} against {sum}",
                binned.responsivity(j, i)
            );
        }
        // Two reads and roundings summed: the read noise of the pair.
        let g = spec.gain_e_per_dn;
        let expected = (2.0 * (spec.read_noise_e.powi(2) + g * g / 12.0)).sqrt();
        assert!((flown.read_noise_e - expected).abs() < 1e-12);
        // On filters there is nothing to sum.
        let cubesat = InstrumentSpec::preset("cubesat").unwrap();
        let e = check_fits(&Binning { factor: 1, spectral: 2, digital: false }, &cubesat).unwrap_err().to_string();
        assert!(e.contains("Binning.spectral"), "{e}");
    }

    #[test]
    fn a_binning_larger_than_the_array_is_refused_by_name() {
        let mut spec = InstrumentSpec::preset("cubesat").unwrap();
        spec.lines = 3;
        let e = check_fits(&Binning { factor: 4, spectral: 1, digital: false }, &spec).unwrap_err().to_string();
        assert!(e.contains("Binning.factor") && e.contains("3 lines"), "{e}");
        let e = Binning { factor: 0, spectral: 1, digital: false }.validate("b").unwrap_err().to_string();
        assert!(e.contains("b.factor"), "{e}");
    }
}
