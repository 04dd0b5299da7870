//! The instrument's spectral response: its bands on the simulation grid, weighted for photon
//! counting, and the geometry groups (bands that look at the ground from the same direction).
//!
//! A detector counts photons: electrons = t·τ·(πD²/4)·(p/f)²·∫ L(λ) QE(λ) SRF(λ) λ/(hc) dλ
//! (Matthews et al. 2023, §2.1.2; DESIGN §2). With w_b(λ) = SRF·QE·λ/(hc), the band radiance
//! the instrument measures is the response-weighted mean L_b = ∫L w_b/∫w_b, and electrons =
//! K_b·L_b with K_b = t·τ·A·Ω·∫w_b. Calibrating against a diffuser with the same weighting
//! recovers L_b exactly, so L_b is the band radiance Level-1 must return.

use std::ops::Range;

use super::InstrumentError;
use super::effects::{self, SpectralKnowledge};
use super::spec::InstrumentSpec;
use crate::parse::FieldError;
use crate::spectral::{Band, BandAverager, BandSet, Extrapolation, Spectrum, WavelengthGrid};
use crate::units::photon_energy_j;

/// Bands that share a line of sight, and the simulation grid that covers their responses.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometryGroup {
    /// Indices of the bands in this group.
    pub bands: Vec<usize>,
    /// Along- and across-track angles of the group's line of sight relative to the
    /// instrument's, rad (focal-plane position of a filter row; 0 for imagers).
    pub offset_rad: (f64, f64),
    /// The simulation grid over the group's spectral support.
    pub grid: WavelengthGrid,
    /// Per band of the group (same order as `bands`): first grid index and photon weights
    /// w_b(λᵢ)·Δλ in photons J⁻¹ (unnormalised; see the module docs). One set per smile class.
    pub weights: Vec<Vec<(usize, Vec<f64>)>>,
}

/// The instrument's bands and how they respond.
#[derive(Debug, Clone, PartialEq)]
pub struct Response {
    /// Nominal bands (names, centres, FWHM, SRFs).
    pub bands: BandSet,
    /// Geometry groups.
    pub groups: Vec<GeometryGroup>,
    /// Detector → smile class (index into each group's `weights`).
    pub smile_class: Vec<usize>,
    /// Across-track keystone shift of each band, detector pixels.
    pub keystone_px: Vec<f64>,
    /// Each band's focal plane: 0 for the instrument's first, i + 1 for `focal_planes[i]`.
    pub plane_of_band: Vec<usize>,
}

/// Each band's focal plane (0: the first; i + 1: `spec.focal_planes[i]`, the first that claims
/// it). A further plane that claims no band is an error: its numbers would change nothing.
pub fn planes_of(spec: &InstrumentSpec, bands: &BandSet) -> Result<Vec<usize>, InstrumentError> {
    let plane_of: Vec<usize> = bands
        .bands
        .iter()
        .map(|b| spec.focal_planes.iter().position(|p| p.bands.holds(&b.name, b.centre_nm)).map_or(0, |i| i + 1))
        .collect();
    if let Some(i) = (0..spec.focal_planes.len()).find(|i| !plane_of.contains(&(i + 1))) {
        let names: Vec<String> = bands.bands.iter().map(|b| format!("{} ({:.0} nm)", b.name, b.centre_nm)).collect();
        return Err(InstrumentError::Invalid(FieldError {
            field: format!("instrument.focal_planes[{i}].bands"),
            message: format!(
                "selects none of the instrument's bands (allowed: names or centres among {}; an earlier plane takes a band first)",
                names.join(", ")
            ),
        }));
    }
    Ok(plane_of)
}

/// Number of smile classes a swath is split into (smile varies slowly across track).
const SMILE_CLASSES: usize = 32;

impl Response {
    /// The response of `spec` on grids of step `step_nm`, as stated: the bands the processor
    /// believes. Where the instrument states a spectral knowledge error, the grids also cover
    /// the bands it really has ([`Self::sensed`] shares them).
    pub fn new(spec: &InstrumentSpec, step_nm: f64) -> Result<Self, InstrumentError> {
        Self::build(spec, step_nm, false)
    }

    /// The response the instrument really has where it states a spectral knowledge error
    /// ([`super::effects::SpectralKnowledge`]; else the same as [`Self::new`]), on
    /// [`Self::new`]'s grids: each band's SRF stretched about its centre and shifted, the smile
    /// scaled. Its `bands` stay the stated ones (names and centres label the products).
    pub fn sensed(spec: &InstrumentSpec, step_nm: f64) -> Result<Self, InstrumentError> {
        Self::build(spec, step_nm, true)
    }

    /// The stated response (`sensing` false) or the true one.
    fn build(spec: &InstrumentSpec, step_nm: f64, sensing: bool) -> Result<Self, InstrumentError> {
        let kind = spec.kind.model();
        let bands = kind.band_set()?;
        // The bands as the instrument really has them, where they differ from the stated ones.
        let error = effects::spectral_knowledge(&spec.effects);
        let smile_factor = error.map_or(1.0, SpectralKnowledge::smile_factor);
        let true_bands: Option<Vec<Band>> = match error {
            Some(k) => {
                let shifts = k.shifts_nm(bands.len())?;
                let true_band = |(b, d): (&Band, &f64)| shift(&widen(b, k.width_factor())?, *d);
                Some(bands.bands.iter().zip(&shifts).map(true_band).collect::<Result<_, _>>()?)
            }
            None => None,
        };
        // What the weights are built from: the true bands when sensing, the stated otherwise.
        let weighed = match (&true_bands, sensing) {
            (Some(t), true) => t,
            _ => &bands.bands,
        };
        let plane_of_band = planes_of(spec, &bands)?;
        let qe_sources: Vec<&crate::spectral::SpectrumSource> = std::iter::once(&spec.quantum_efficiency)
            .chain(spec.focal_planes.iter().map(|p| &p.quantum_efficiency))
            .collect();
        let (smile_nm, keystone) = kind.distortions();
        let n_classes = if smile_nm == 0.0 { 1 } else { SMILE_CLASSES.min(spec.detectors) };
        let smile_class = (0..spec.detectors).map(|j| j * n_classes / spec.detectors).collect();
        // Smile shift of class c: quadratic in the normalised across-track position.
        let class_shift = |c: usize| -> f64 {
            if n_classes == 1 {
                return 0.0;
            }
            let x = 2.0 * (c as f64 + 0.5) / n_classes as f64 - 1.0;
            smile_nm * x * x * if sensing { smile_factor } else { 1.0 }
        };
        let focal_m = spec.focal_length_mm * 1e-3;
        let group_sets = kind.groups(bands.len(), spec.pixel_pitch_um, focal_m);
        let groups = group_sets
            .into_iter()
            .map(|(members, offset_rad)| {
                let margin = smile_nm.abs() * smile_factor.abs().max(1.0) + step_nm;
                let mut supports: Vec<(f64, f64)> = members.iter().map(|&b| bands.bands[b].srf.range_nm()).collect();
                if let Some(t) = &true_bands {
                    supports.extend(members.iter().map(|&b| t[b].srf.range_nm()));
                }
                let grid = support_grid(&supports, margin, step_nm)?;
                let mut qe_of_plane = Vec::with_capacity(qe_sources.len());
                for (p, source) in qe_sources.iter().enumerate() {
                    let qe = source.sample(&grid, Extrapolation::Clamp, None)?;
                    if let Some(q) = qe.iter().find(|q| !(q.is_finite() && (0.0..=1.0).contains(*q))) {
                        let field = if p == 0 {
                            "quantum_efficiency".to_string()
                        } else {
                            format!("instrument.focal_planes[{}].quantum_efficiency", p - 1)
                        };
                        return Err(InstrumentError::Invalid(FieldError {
                            field,
                            message: format!("value {q} is outside 0 to 1"),
                        }));
                    }
                    qe_of_plane.push(qe);
                }
                let weights = (0..n_classes)
                    .map(|c| {
                        let shifted = BandSet {
                            name: bands.name.clone(),
                            bands: members
                                .iter()
                                .map(|&b| shift(&weighed[b], class_shift(c)))
                                .collect::<Result<_, _>>()?,
                        };
                        let avg = BandAverager::new(&grid, &shifted)?;
                        Ok((0..members.len())
                            .map(|k| {
                                let (first, row) = avg.row(k);
                                let area = avg.srf_area_nm(k);
                                let qe = &qe_of_plane[plane_of_band[members[k]]];
                                let w = row
                                    .iter()
                                    .enumerate()
                                    .map(|(i, a)| {
                                        let wl = grid.wavelength_nm(first + i);
                                        a * area * qe[first + i] / photon_energy_j(wl)
                                    })
                                    .collect();
                                (first, w)
                            })
                            .collect())
                    })
                    .collect::<Result<Vec<_>, InstrumentError>>()?;
                Ok(GeometryGroup { bands: members, offset_rad, grid, weights })
            })
            .collect::<Result<Vec<_>, InstrumentError>>()?;
        let nb = bands.len();
        let keystone_px =
            (0..nb).map(|b| if nb > 1 { keystone * (b as f64 / (nb - 1) as f64 - 0.5) } else { 0.0 }).collect();
        Ok(Self { bands, groups, smile_class, keystone_px, plane_of_band })
    }

    /// Number of bands.
    #[must_use]
    pub fn n_bands(&self) -> usize {
        self.bands.len()
    }

    /// The band-`k` weights of group `g` for detector `detector` (its smile class).
    #[must_use]
    pub fn weights(&self, g: usize, k: usize, detector: usize) -> (usize, &[f64]) {
        let (first, w) = &self.groups[g].weights[self.smile_class_of(g, detector)][k];
        (*first, w)
    }

    /// The index of detector `detector`'s weights in group `g` (its smile class).
    #[must_use]
    pub fn smile_class_of(&self, g: usize, detector: usize) -> usize {
        self.smile_class.get(detector).copied().unwrap_or(0).min(self.groups[g].weights.len() - 1)
    }

    /// Photon response ∫w_b dλ of band `b` (photons J⁻¹), at the swath centre.
    #[must_use]
    pub fn photon_response(&self, b: usize) -> f64 {
        for (gi, g) in self.groups.iter().enumerate() {
            if let Some(k) = g.bands.iter().position(|&x| x == b) {
                let centre = self.smile_class.len() / 2;
                return self.weights(gi, k, centre).1.iter().sum();
            }
        }
        0.0
    }

    /// Response-weighted band means of a spectrum on group `g`'s grid, for detector `detector`.
    pub fn band_means(&self, g: usize, detector: usize, spectrum: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate().take(self.groups[g].bands.len()) {
            let (first, w) = self.weights(g, k, detector);
            let (mut num, mut den) = (0.0, 0.0);
            for (wi, v) in w.iter().zip(&spectrum[first..first + w.len()]) {
                num += wi * v;
                den += wi;
            }
            *o = if den > 0.0 { num / den } else { 0.0 };
        }
    }

    /// Grid indices of group `g` at which per-pixel spectra are evaluated with `per_band` nodes
    /// per band: each band's response quantiles (k + ½)/n, k = 0…n−1, of the swath centre's
    /// weights (one node is the band's median wavelength, two bracket it at the quartiles), and
    /// the two ends of its response's support (so its tails are interpolated, not held flat),
    /// merged over the group's bands, sorted, distinct.
    #[must_use]
    pub fn band_nodes(&self, g: usize, per_band: usize) -> Vec<usize> {
        let centre = self.smile_class.len() / 2;
        let mut nodes = Vec::new();
        for k in 0..self.groups[g].bands.len() {
            let (first, w) = self.weights(g, k, centre);
            let total: f64 = w.iter().sum();
            if w.is_empty() || total <= 0.0 {
                continue;
            }
            nodes.extend([first, first + w.len() - 1]);
            for q in 0..per_band {
                let target = (q as f64 + 0.5) / per_band as f64 * total;
                let mut cum = 0.0;
                let i = w
                    .iter()
                    .position(|v| {
                        cum += v;
                        cum >= target
                    })
                    .unwrap_or(w.len() - 1);
                nodes.push(first + i);
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        nodes
    }

    /// Wavelength ranges of the groups' grids (for reports).
    #[must_use]
    pub fn spans_nm(&self) -> Vec<Range<f64>> {
        self.groups.iter().map(|g| g.grid.range_nm().0..g.grid.range_nm().1).collect()
    }
}

pub use crate::ranges::{MAX_SIMULATED_NM, MIN_SIMULATED_NM};

/// The simulation grid of a group: every multiple of `step_nm` within `margin_nm` of a band's
/// SRF support. Gaps between disjoint bands are left out (nothing there is seen), so a
/// 19-band imager costs its bands' width, not the 400–900 nm span.
fn support_grid(supports: &[(f64, f64)], margin_nm: f64, step_nm: f64) -> Result<WavelengthGrid, InstrumentError> {
    let mut nodes: Vec<i64> = Vec::new();
    for &(lo, hi) in supports {
        let (mut a, mut b) = (((lo - margin_nm) / step_nm).floor() as i64, ((hi + margin_nm) / step_nm).ceil() as i64);
        let (from, to) = ((a as f64) * step_nm, (b as f64) * step_nm);
        // The margin may be cut where the data end; the response itself may not.
        if lo < MIN_SIMULATED_NM || hi > MAX_SIMULATED_NM {
            return Err(InstrumentError::Invalid(FieldError {
                field: "bands".into(),
                message: format!(
                    "spectral responses span {lo:.1}–{hi:.1} nm, simulated over {from:.1}–{to:.1} nm with the \
                     grid's margin; Shoal simulates {MIN_SIMULATED_NM}–{MAX_SIMULATED_NM} nm (the atmospheric data)"
                ),
            }));
        }
        a = a.max((MIN_SIMULATED_NM / step_nm).ceil() as i64);
        b = b.min((MAX_SIMULATED_NM / step_nm).floor() as i64);
        nodes.extend(a..=b);
    }
    nodes.sort_unstable();
    nodes.dedup();
    Ok(WavelengthGrid::from_wavelengths(nodes.into_iter().map(|k| k as f64 * step_nm).collect())?)
}

/// A band with its SRF stretched about its centre by `factor` (its FWHM with it).
fn widen(b: &Band, factor: f64) -> Result<Band, InstrumentError> {
    if factor == 1.0 {
        return Ok(b.clone());
    }
    let c = b.centre_nm;
    let wavelengths = b.srf.wavelength_nm.iter().map(|w| c + (w - c) * factor).collect();
    let srf = Spectrum::new(b.srf.name.clone(), wavelengths, b.srf.values.clone())?;
    Ok(Band { srf, fwhm_nm: b.fwhm_nm * factor, ..b.clone() })
}

/// A band with its SRF shifted by `d` nm (smile, a centre error).
fn shift(b: &Band, d: f64) -> Result<Band, InstrumentError> {
    if d == 0.0 {
        return Ok(b.clone());
    }
    let srf =
        Spectrum::new(b.srf.name.clone(), b.srf.wavelength_nm.iter().map(|w| w + d).collect(), b.srf.values.clone())?;
    Ok(Band { srf, centre_nm: b.centre_nm + d, ..b.clone() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::InstrumentKind;
    use crate::spectral::{BandSetSpec, GaussianBand};

    fn spec_with(kind: InstrumentKind) -> InstrumentSpec {
        let mut s = InstrumentSpec::preset("nominal").unwrap();
        s.kind = kind;
        s
    }

    #[test]
    fn photon_response_of_a_gaussian_band() {
        // ∫ SRF·QE·λ/(hc) dλ ≈ QE·λc/(hc)·1.0645·FWHM for a narrow Gaussian band.
        let bands = BandSetSpec::Gaussian(vec![GaussianBand { name: None, centre_nm: 500.0, fwhm_nm: 10.0 }]);
        let r = Response::new(&spec_with(InstrumentKind::Multispectral { bands }), 0.5).unwrap();
        let expected = 0.7 / photon_energy_j(500.0) * 1.064_467 * 10.0;
        assert!((r.photon_response(0) / expected - 1.0).abs() < 5e-3, "{} vs {expected}", r.photon_response(0));
    }

    #[test]
    fn olci_grid_covers_only_the_bands() {
        let r = Response::new(&InstrumentSpec::preset("nominal").unwrap(), 1.0).unwrap();
        assert_eq!(r.n_bands(), 19);
        assert_eq!(r.groups.len(), 1);
        // Gaps between bands are left out: fewer points than the 400–910 nm span.
        let g = &r.groups[0].grid;
        assert!(g.len() < 450 && g.len() > 200, "{}", g.len());
    }

    #[test]
    fn spectrograph_bands_smile_and_keystone() {
        let kind = InstrumentKind::Spectrograph {
            start_nm: 400.0,
            end_nm: 900.0,
            sampling_nm: 5.0,
            resolution_nm: 7.0,
            smile_nm: 1.0,
            keystone_px: 0.4,
            channels_summed: 1,
        };
        let r = Response::new(&spec_with(kind), 0.5).unwrap();
        assert_eq!(r.n_bands(), 101);
        assert!((r.keystone_px[0] + 0.2).abs() < 1e-12 && (r.keystone_px[100] - 0.2).abs() < 1e-12);
        // Smile: the edge detector's band 0 is centred 1 nm (×(31/32)²) redder than the centre's.
        let centroid = |j: usize| {
            let (first, w) = r.weights(0, 0, j);
            let grid = &r.groups[0].grid;
            let (num, den) =
                w.iter().enumerate().fold((0.0, 0.0), |(n, d), (i, v)| (n + v * grid.wavelength_nm(first + i), d + v));
            num / den
        };
        let shift = centroid(0) - centroid(512);
        let x: f64 = 2.0 * 0.5 / 32.0 - 1.0;
        let expected = 1.0 * x * x - 1.0 * (2.0 * 16.5 / 32.0 - 1.0_f64).powi(2);
        assert!((shift - expected).abs() < 0.02, "{shift} vs {expected}");
    }

    #[test]
    fn filter_imager_bands_look_from_their_own_angles() {
        let r = Response::new(&InstrumentSpec::preset("filter_imager").unwrap(), 1.0).unwrap();
        assert_eq!(r.groups.len(), 10);
        let offsets: Vec<f64> = r.groups.iter().map(|g| g.offset_rad.0).collect();
        // 64 rows of 5.5 µm at 165 mm between bands, symmetric about the boresight.
        let step = (64.0 * 5.5e-6 / 0.165_f64).atan();
        assert!((offsets[1] - offsets[0] - step).abs() < 1e-6);
        assert!((offsets[0] + offsets[9]).abs() < 1e-12);
    }
}

#[cfg(test)]
mod knowledge_tests {
    use super::*;
    use crate::instrument::InstrumentKind;
    use crate::instrument::effects::{InstrumentEffect, SpectralKnowledge};
    use crate::spectral::{BandSetSpec, GaussianBand};

    /// Band `k`'s photon-weighted centroid and rms width, nm.
    fn moments(r: &Response, k: usize) -> (f64, f64) {
        let (first, w) = r.weights(0, k, 0);
        let grid = &r.groups[0].grid;
        let total: f64 = w.iter().sum();
        let mean = w.iter().enumerate().map(|(i, v)| v * grid.wavelength_nm(first + i)).sum::<f64>() / total;
        let var =
            w.iter().enumerate().map(|(i, v)| v * (grid.wavelength_nm(first + i) - mean).powi(2)).sum::<f64>() / total;
        (mean, var.sqrt())
    }

    #[test]
    fn a_band_shift_and_width_error_move_the_band_integral() {
        let bands = BandSetSpec::Gaussian(vec![
            GaussianBand { name: None, centre_nm: 490.0, fwhm_nm: 10.0 },
            GaussianBand { name: None, centre_nm: 665.0, fwhm_nm: 15.0 },
        ]);
        let mut spec = InstrumentSpec::preset("nominal").unwrap();
        spec.kind = InstrumentKind::Multispectral { bands };
        // A flat QE: the photon weighting λ/(hc) is then the only slope under the bands.
        spec.quantum_efficiency = crate::spectral::SpectrumSource::Constant(0.7);
        spec.effects = vec![InstrumentEffect::SpectralKnowledge(SpectralKnowledge {
            centre_nm: 0.0,
            sigma_nm: 0.0,
            per_band_nm: vec![1.5, -0.7],
            draw: 0,
            width_pct: 10.0,
            smile_pct: 0.0,
        })];
        let (believed, sensed) = (Response::new(&spec, 0.1).unwrap(), Response::sensed(&spec, 0.1).unwrap());
        // One grid for both, covering the true bands.
        assert_eq!(believed.groups[0].grid, sensed.groups[0].grid);
        for (k, centre, shift) in [(0, 490.0, 1.5), (1, 665.0, -0.7)] {
            let ((m0, s0), (m1, s1)) = (moments(&believed, k), moments(&sensed, k));
            // The photon weighting λ moves a symmetric band's centroid from its centre c by
            // σ²/c: the true band's centroid is c + d + σ₁²/c, the believed one's c + σ₀²/c
            // (to 1e-4 nm: terms in σ⁴/c³ and the 0.1 nm grid).
            let expected = shift + (s1 * s1 - s0 * s0) / centre;
            assert!((m1 - m0 - expected).abs() < 1e-3, "band {k}: {m1} − {m0} against {expected}");
            // Stretched 10 % about its centre: the rms width grows by 10 % (less the λ weighting's
            // skew, σ²/c² relative; the 0.1 nm grid).
            assert!((s1 / s0 - 1.1).abs() < 1e-3, "band {k}: {s1} / {s0}");
            // And the band collects 10 % more photons (its SRF's area grows with its width), each
            // of energy hc/λ at its centre: ∫SRF·λ is the area times the centre.
            let area = |r: &Response| r.weights(0, k, 0).1.iter().sum::<f64>();
            let expected = 1.1 * (centre + shift) / centre;
            assert!((area(&sensed) / area(&believed) / expected - 1.0).abs() < 1e-4, "band {k}");
        }
        // Without the effect, the sensed response is the stated one.
        spec.effects.clear();
        assert_eq!(Response::sensed(&spec, 0.1).unwrap(), Response::new(&spec, 0.1).unwrap());
    }
}
