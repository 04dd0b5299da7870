//! One trait per instrument kind: what the chain asks of a kind — its bands (which
//! [`super::Response`] lowers to band weights), its spectral distortions, where each band looks
//! on the focal plane, its own fields' checks, and what it can do ([`Capabilities`]) — so the
//! stages ask a question of the kind rather than which kind it is. A new kind is a variant of
//! [`InstrumentKind`] (its fields as a preset writes them), a type implementing [`Kind`] and an
//! arm of [`InstrumentKind::model`].

use super::InstrumentError;
use super::spec::InstrumentKind;
use crate::parse::FieldError;
use crate::spectral::{Band, BandSet, BandSetSpec, GaussianBand};

/// What an instrument kind can do, asked instead of its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capabilities {
    /// Its detector adds noise, quantises and saturates (false: an ideal radiometer for
    /// reference runs, whatever the run's detector switches say).
    pub real_detector: bool,
    /// Its bands see the ground from different along-track angles (a filter imager's bands lie
    /// along the focal plane).
    pub bands_along_track: bool,
}

/// One instrument kind.
pub trait Kind {
    /// Its bands, as band responses (the response lowers them to weights per detector).
    fn band_set(&self) -> Result<BandSet, InstrumentError>;

    /// How many bands it will have, without reading band files (for the memory plan).
    fn band_count(&self) -> usize;

    /// Smile (shift of the band centres at the swath edges, nm) and keystone (misregistration
    /// between the first and last band, pixels); zero for band-pass imagers.
    fn distortions(&self) -> (f64, f64) {
        (0.0, 0.0)
    }

    /// The bands grouped by where they look: per group its bands and (along-track, across-track)
    /// offset angle of its line of sight, rad, for `n_bands` bands, a `pitch_um` detector and a
    /// `focal_m` focal length. One group at nadir for kinds whose bands share the ground pixel.
    fn groups(&self, n_bands: usize, _pitch_um: f64, _focal_m: f64) -> Vec<(Vec<usize>, (f64, f64))> {
        vec![((0..n_bands).collect(), (0.0, 0.0))]
    }

    /// Check its own fields against [`crate::ranges`].
    fn validate(&self) -> Result<(), InstrumentError> {
        Ok(())
    }

    /// What it can do.
    fn capabilities(&self) -> Capabilities {
        Capabilities { real_detector: true, bands_along_track: false }
    }
}

/// Bands of a band-set spec, without reading band files.
fn set_count(b: &BandSetSpec) -> usize {
    match b {
        BandSetSpec::Olci { bands, .. } => bands.as_ref().map_or(19, Vec::len),
        BandSetSpec::Msi { bands, .. } => bands.as_ref().map_or(9, Vec::len),
        BandSetSpec::Gaussian(g) => g.len(),
        BandSetSpec::Combined(parts) => parts.iter().map(set_count).sum(),
    }
}

/// A band-pass multispectral imager: every band sees the same ground pixel through its SRF.
struct Multispectral<'a>(&'a BandSetSpec);

impl Kind for Multispectral<'_> {
    fn band_set(&self) -> Result<BandSet, InstrumentError> {
        Ok(BandSet::from_spec(self.0)?)
    }
    fn band_count(&self) -> usize {
        set_count(self.0)
    }
}

/// An ideal radiometer: the same bands, no noise, no quantisation, no saturation.
struct IdealRadiometer<'a>(&'a BandSetSpec);

impl Kind for IdealRadiometer<'_> {
    fn band_set(&self) -> Result<BandSet, InstrumentError> {
        Ok(BandSet::from_spec(self.0)?)
    }
    fn band_count(&self) -> usize {
        set_count(self.0)
    }
    fn capabilities(&self) -> Capabilities {
        Capabilities { real_detector: false, bands_along_track: false }
    }
}

/// A long-slit dispersive spectrograph's fields (start, end, sampling, resolution, smile,
/// keystone).
struct Spectrograph {
    start_nm: f64,
    end_nm: f64,
    sampling_nm: f64,
    resolution_nm: f64,
    smile_nm: f64,
    keystone_px: f64,
    channels_summed: usize,
}

impl Spectrograph {
    /// Spectral samples from `start_nm` to `end_nm`.
    fn channels(&self) -> usize {
        let n = ((self.end_nm - self.start_nm) / self.sampling_nm + 1e-9).floor();
        if n.is_finite() && n >= 0.0 { n as usize + 1 } else { 1 }
    }
}

impl Kind for Spectrograph {
    /// One Gaussian band per spectral sample; binned, each band is the sum of `channels_summed`
    /// adjacent samples' Gaussians (tabulated every FWHM/20 over ±2.5 FWHM of its ends), its
    /// centre their mean and its area theirs summed (so it collects their light).
    fn band_set(&self) -> Result<BandSet, InstrumentError> {
        let m = self.channels_summed.max(1);
        let at = |i: usize| self.start_nm + i as f64 * self.sampling_nm;
        let list = (0..self.band_count())
            .map(|i| {
                if m == 1 {
                    let c = at(i);
                    return Band::gaussian(&GaussianBand {
                        name: Some(format!("S{c:.1}")),
                        centre_nm: c,
                        fwhm_nm: self.resolution_nm,
                    });
                }
                let (first, last) = (at(i * m), at(i * m + m - 1));
                let w = self.resolution_nm;
                let step = w / 20.0;
                let nodes = ((last - first + 5.0 * w) / step).ceil() as usize + 1;
                let wavelengths: Vec<f64> = (0..nodes).map(|k| first - 2.5 * w + k as f64 * step).collect();
                let values = wavelengths
                    .iter()
                    .map(|x| {
                        (0..m).map(|j| (-4.0 * std::f64::consts::LN_2 * ((x - at(i * m + j)) / w).powi(2)).exp()).sum()
                    })
                    .collect();
                let c = 0.5 * (first + last);
                let srf = crate::spectral::Spectrum::new(format!("S{c:.1}"), wavelengths, values)?;
                Band::from_srf(&format!("S{c:.1}"), srf)
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(BandSet { name: "spectrograph".into(), bands: list })
    }
    fn band_count(&self) -> usize {
        (self.channels() / self.channels_summed.max(1)).max(1)
    }
    fn distortions(&self) -> (f64, f64) {
        (self.smile_nm, self.keystone_px)
    }
    fn validate(&self) -> Result<(), InstrumentError> {
        use crate::ranges as r;
        let check = |range: &r::Range, v: f64| {
            range.check(v).map_err(|message| FieldError { field: range.field("instrument.").into(), message })
        };
        let Self { start_nm, end_nm, sampling_nm, resolution_nm, smile_nm, keystone_px, channels_summed } = *self;
        // Each field checked as `InstrumentSpec::validate` checks the common ones.
        check(&r::SPECTROGRAPH_START_NM, start_nm)?;
        check(&r::SPECTROGRAPH_END_NM, end_nm)?;
        check(&r::SPECTROGRAPH_SAMPLING_NM, sampling_nm)?;
        check(&r::SPECTROGRAPH_RESOLUTION_NM, resolution_nm)?;
        check(&r::SPECTROGRAPH_SMILE_NM, smile_nm)?;
        check(&r::SPECTROGRAPH_KEYSTONE_PX, keystone_px)?;
        check(&r::SPECTROGRAPH_CHANNELS_SUMMED, channels_summed as f64)?;
        let fail = |range: &r::Range, message: String| {
            InstrumentError::Invalid(FieldError { field: range.field("instrument.").into(), message })
        };
        if end_nm < start_nm {
            return Err(fail(
                &r::SPECTROGRAPH_END_NM,
                format!("{end_nm} is below start_nm = {start_nm} (allowed: start_nm to {} nm)", r::MAX_SIMULATED_NM),
            ));
        }
        // Each band's Gaussian response is tabulated over centre ± 2.5 FWHM (Band::gaussian),
        // shifted by up to |smile|; it must lie where Shoal has atmospheric data.
        let reach = 2.5 * resolution_nm + smile_nm.abs();
        if end_nm + reach > r::MAX_SIMULATED_NM {
            return Err(fail(
                &r::SPECTROGRAPH_END_NM,
                format!(
                    "{end_nm} with resolution_nm = {resolution_nm} and smile_nm = {smile_nm} puts the last band's \
                     response at {:.1} nm (allowed: end_nm + 2.5·resolution_nm + |smile_nm| ≤ {} nm, the end \
                     of Shoal's atmospheric data)",
                    end_nm + reach,
                    r::MAX_SIMULATED_NM
                ),
            ));
        }
        if start_nm - reach < r::MIN_SIMULATED_NM {
            return Err(fail(
                &r::SPECTROGRAPH_START_NM,
                format!(
                    "{start_nm} with resolution_nm = {resolution_nm} and smile_nm = {smile_nm} puts the first \
                     band's response at {:.1} nm (allowed: start_nm − 2.5·resolution_nm − |smile_nm| ≥ {} nm)",
                    start_nm - reach,
                    r::MIN_SIMULATED_NM
                ),
            ));
        }
        if channels_summed > self.channels() {
            return Err(fail(
                &r::SPECTROGRAPH_CHANNELS_SUMMED,
                format!(
                    "{channels_summed} with {} spectral samples (allowed: 1 to {})",
                    self.channels(),
                    self.channels()
                ),
            ));
        }
        let samples = (end_nm - start_nm) / sampling_nm;
        if samples > 2000.0 {
            return Err(fail(
                &r::SPECTROGRAPH_SAMPLING_NM,
                format!(
                    "{sampling_nm} gives {samples:.0} spectral samples from start_nm to end_nm (allowed: at most 2000)"
                ),
            ));
        }
        Ok(())
    }
}

/// A gradient / linear-variable-filter imager: the pass band changes along track across the
/// focal plane, so each band looks at the ground from its own along-track angle.
struct FilterImager<'a> {
    bands: &'a BandSetSpec,
    rows_per_band: usize,
}

impl Kind for FilterImager<'_> {
    fn band_set(&self) -> Result<BandSet, InstrumentError> {
        Ok(BandSet::from_spec(self.bands)?)
    }
    fn band_count(&self) -> usize {
        set_count(self.bands)
    }
    /// Band b's rows sit (b − (n − 1)/2)·rows_per_band·pitch from the focal plane's centre: it
    /// looks along track at atan(y / f).
    fn groups(&self, n_bands: usize, pitch_um: f64, focal_m: f64) -> Vec<(Vec<usize>, (f64, f64))> {
        (0..n_bands)
            .map(|b| {
                let y = (b as f64 - 0.5 * (n_bands as f64 - 1.0)) * self.rows_per_band as f64 * pitch_um * 1e-6;
                (vec![b], ((y / focal_m).atan(), 0.0))
            })
            .collect()
    }
    fn validate(&self) -> Result<(), InstrumentError> {
        let r = &crate::ranges::FILTER_ROWS_PER_BAND;
        r.check(self.rows_per_band as f64)
            .map_err(|message| InstrumentError::Invalid(FieldError { field: r.field("instrument.").into(), message }))
    }
    fn capabilities(&self) -> Capabilities {
        Capabilities { real_detector: true, bands_along_track: true }
    }
}

impl InstrumentKind {
    /// The kind's model: the one place that says which type each kind is.
    #[must_use]
    pub fn model(&self) -> Box<dyn Kind + '_> {
        match self {
            Self::Multispectral { bands } => Box::new(Multispectral(bands)),
            Self::IdealRadiometer { bands } => Box::new(IdealRadiometer(bands)),
            Self::Spectrograph {
                start_nm,
                end_nm,
                sampling_nm,
                resolution_nm,
                smile_nm,
                keystone_px,
                channels_summed,
            } => Box::new(Spectrograph {
                start_nm: *start_nm,
                end_nm: *end_nm,
                sampling_nm: *sampling_nm,
                resolution_nm: *resolution_nm,
                smile_nm: *smile_nm,
                keystone_px: *keystone_px,
                channels_summed: *channels_summed,
            }),
            Self::FilterImager { bands, rows_per_band } => {
                Box::new(FilterImager { bands, rows_per_band: *rows_per_band })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::InstrumentSpec;

    #[test]
    fn every_preset_is_within_the_ranges_a_user_is_held_to() {
        for name in InstrumentSpec::preset_names() {
            let spec = InstrumentSpec::preset(&name).unwrap_or_else(|e| panic!("{name}: {e}"));
            spec.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            spec.as_flown().validate().unwrap_or_else(|e| panic!("{name} as flown: {e}"));
        }
    }

    #[test]
    fn every_preset_kind_counts_the_bands_it_builds_and_says_what_it_can_do() {
        for name in InstrumentSpec::preset_names() {
            let spec = InstrumentSpec::preset(&name).unwrap_or_else(|e| panic!("{name}: {e}"));
            let kind = spec.kind.model();
            let built = kind.band_set().unwrap_or_else(|e| panic!("{name}: {e}")).len();
            assert_eq!(kind.band_count(), built, "{name}: the memory plan's count is the built one");
            let groups = kind.groups(built, spec.pixel_pitch_um, spec.focal_length_mm * 1e-3);
            assert_eq!(groups.iter().map(|g| g.0.len()).sum::<usize>(), built, "{name}: every band in one group");
            let c = kind.capabilities();
            assert_eq!(c.bands_along_track, groups.len() > 1, "{name}");
            assert_eq!(c.real_detector, !matches!(spec.kind, InstrumentKind::IdealRadiometer { .. }), "{name}");
        }
    }
}
