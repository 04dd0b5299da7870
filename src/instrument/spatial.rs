//! The instrument's spatial response: the PSF quadrature the scene is sampled with, used when the
//! instrument states an MTF budget (`effects: [SpatialResponse(...)]`) or, for designs that state
//! none, when the scene asks for `SpatialResponse` (an ideal optic: [`MtfBudget::default`]).
//!
//! The system point-spread function on the ground is the one whose transfer function is the MTF
//! budget's product of parts ([`super::effects::mtf`]: diffraction of the annular pupil, wavefront
//! error, the pixel's aperture, diffusion, crosstalk, jitter and the smear over the exposure;
//! Schowengerdt 2007, §3.4.3; Fiete 2010, ch. 4).
//!
//! The pixel's band radiance is the PSF-weighted mean of the scene radiance. Shoal evaluates it
//! with a product quadrature: sample points every GSD/`samples_per_gsd` along and across track,
//! each weighted by the 1-D line-spread function integrated over its sub-cell
//! ([`MtfBudget::cell_weights`]); tails holding less than 0.5 % at either end are dropped and the
//! weights renormalised, so a uniform scene keeps its radiance exactly. Diffraction depends on λ,
//! so each band has its own weights on shared points. The image is simulated on the first focal
//! plane's grid; a coarser plane's block average adds its larger pixel ([`super::focal`]).
//!
//! ## References
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd ed.
//! - Fiete, R. D. (2010) Modeling the Imaging Chain of Digital Cameras. SPIE Tutorial Texts TT92.

use super::InstrumentError;
use super::effects::{
    self,
    mtf::{Axis, MtfBudget, MtfGeometry, Part},
};
use super::response::planes_of;
use super::spec::{InstrumentSpec, ground_speed_m_s};

/// Quadrature of the system PSF: sample offsets and per-band weights.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialKernel {
    /// Sample offsets from the pixel centre (along track, across track), m.
    pub offsets_m: Vec<(f64, f64)>,
    /// Per band: the weight of each offset (summing to 1).
    pub weights: Vec<Vec<f64>>,
}

/// Fraction of the PSF dropped at each tail of each axis.
const TAIL: f64 = 0.005;

/// Most sub-cells on either side of the centre along an axis before trimming (at most
/// (2·48 + 1)² points per pixel).
const MAX_HALF_CELLS: usize = 48;

/// The MTF geometry of `spec`'s first focal plane (the image's grid), at nadir.
#[must_use]
pub fn first_plane_geometry(spec: &InstrumentSpec) -> MtfGeometry {
    let tdi = crate::instrument::effects::tdi(&spec.effects).copied().unwrap_or_default();
    MtfGeometry {
        aperture_m: spec.aperture_mm * 1e-3,
        altitude_m: spec.altitude_km * 1e3,
        focal_length_m: spec.focal_length_mm * 1e-3,
        pitch_ground_m: spec.gsd_m(),
        smear_m: ground_speed_m_s(spec.altitude_km) * spec.exposure_s,
        tdi_slip_m: tdi.slip_m(spec.gsd_m()),
        tdi_transfer_loss: tdi.transfer_loss(),
    }
}

impl SpatialKernel {
    /// A point sample at the pixel centre (no spatial response).
    #[must_use]
    pub fn point(n_bands: usize) -> Self {
        Self { offsets_m: vec![(0.0, 0.0)], weights: vec![vec![1.0]; n_bands] }
    }

    /// The PSF quadrature of `spec` with its MTF `budget`, for bands centred at `centres_nm`.
    #[must_use]
    pub fn new(spec: &InstrumentSpec, budget: &MtfBudget, centres_nm: &[f64], samples_per_gsd: usize) -> Self {
        let g = first_plane_geometry(spec);
        // Every band shares the positions: the widest band's reach sets them.
        let reach = |axis: Axis| centres_nm.iter().map(|&w| budget.reach_m(&g, w, axis)).fold(0.0, f64::max);
        let widest = reach(Axis::Along).max(reach(Axis::Across));
        // Sub-cells of GSD/samples, widened where the PSF would need more than MAX_HALF_CELLS on
        // a side (a tiny aperture's blur many pixels wide): the quadrature coarsens rather than
        // the run exploding.
        let h = (g.pitch_ground_m / samples_per_gsd.max(1) as f64).max(widest / MAX_HALF_CELLS as f64);
        let cells = |axis: Axis| ((reach(axis) / h + 0.5).ceil() as usize).min(MAX_HALF_CELLS + 1);
        let (k_along, k_across) = (cells(Axis::Along), cells(Axis::Across));
        let along: Vec<Vec<f64>> =
            centres_nm.iter().map(|&w| budget.cell_weights(&g, w, Axis::Along, h, k_along)).collect();
        let across: Vec<Vec<f64>> =
            centres_nm.iter().map(|&w| budget.cell_weights(&g, w, Axis::Across, h, k_across)).collect();
        let keep = |all: &[Vec<f64>]| -> (usize, usize) {
            let n = all[0].len();
            let mut lo = n;
            let mut hi = 0;
            for w in all {
                let (a, b) = trim(w);
                lo = lo.min(a);
                hi = hi.max(b);
            }
            (lo, hi)
        };
        let (a0, a1) = keep(&along);
        let (c0, c1) = keep(&across);
        let mut offsets_m = Vec::new();
        for i in a0..=a1 {
            for k in c0..=c1 {
                offsets_m.push(((i as f64 - k_along as f64) * h, (k as f64 - k_across as f64) * h));
            }
        }
        let weights = along
            .iter()
            .zip(&across)
            .map(|(wa, wc)| {
                let mut w = Vec::with_capacity(offsets_m.len());
                for i in a0..=a1 {
                    for k in c0..=c1 {
                        w.push(wa[i] * wc[k]);
                    }
                }
                let total: f64 = w.iter().sum();
                w.iter().map(|v| v / total).collect()
            })
            .collect();
        Self { offsets_m, weights }
    }

    /// Number of sample points per pixel.
    #[must_use]
    pub fn len(&self) -> usize {
        self.offsets_m.len()
    }

    /// Is this empty? (Never, for a built kernel.)
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.offsets_m.is_empty()
    }
}

/// The MTF at Nyquist of one band on its focal plane, with the budget's parts along track.
#[derive(Debug, Clone, PartialEq)]
pub struct NyquistRow {
    /// Band name.
    pub band: String,
    /// Its focal plane's name (`"main"` for the instrument's own).
    pub plane: String,
    /// Band centre, nm.
    pub centre_nm: f64,
    /// The plane's ground pitch, m.
    pub gsd_m: f64,
    /// System MTF at the plane's Nyquist frequency along track.
    pub along: f64,
    /// System MTF at the plane's Nyquist frequency across track.
    pub across: f64,
    /// Each part's transfer function at Nyquist along track.
    pub parts_along: [Part; 9],
}

/// The MTF at Nyquist of every band of `spec` on its own focal plane (its pitch and its
/// exposure's smear), with the MTF budget it states or, if none, an ideal optic's.
pub fn nyquist_table(spec: &InstrumentSpec) -> Result<Vec<NyquistRow>, InstrumentError> {
    let bands = spec.kind.model().band_set()?;
    let plane_of = planes_of(spec, &bands)?;
    let ideal = MtfBudget::default();
    let budget = effects::spatial_response(&spec.effects).unwrap_or(&ideal);
    let first = first_plane_geometry(spec);
    let speed = ground_speed_m_s(spec.altitude_km);
    Ok(bands
        .bands
        .iter()
        .zip(&plane_of)
        .map(|(b, &p)| {
            let (plane, g) = match p.checked_sub(1).map(|i| &spec.focal_planes[i]) {
                None => ("main".to_string(), first),
                Some(fp) => {
                    let ratio = fp.pixel_pitch_um / spec.pixel_pitch_um;
                    let g = MtfGeometry {
                        pitch_ground_m: first.pitch_ground_m * ratio,
                        tdi_slip_m: first.tdi_slip_m * ratio,
                        smear_m: speed * fp.exposure_on(spec.pixel_pitch_um, spec.exposure_s),
                        ..first
                    };
                    (fp.name.clone(), g)
                }
            };
            let nu = g.nyquist_per_m();
            NyquistRow {
                band: b.name.clone(),
                plane,
                centre_nm: b.centre_nm,
                gsd_m: g.pitch_ground_m,
                along: budget.at_nyquist(&g, b.centre_nm, Axis::Along),
                across: budget.at_nyquist(&g, b.centre_nm, Axis::Across),
                parts_along: budget.parts(&g, b.centre_nm, nu, Axis::Along),
            }
        })
        .collect())
}

/// Indices of the first and last cells kept after dropping `TAIL` at each end.
fn trim(w: &[f64]) -> (usize, usize) {
    let tail = TAIL * w.iter().sum::<f64>();
    let mut acc = 0.0;
    let mut lo = 0;
    for (i, v) in w.iter().enumerate() {
        acc += v;
        if acc > tail {
            lo = i;
            break;
        }
    }
    acc = 0.0;
    let mut hi = w.len() - 1;
    for (i, v) in w.iter().enumerate().rev() {
        acc += v;
        if acc > tail {
            hi = i;
            break;
        }
    }
    (lo, hi.max(lo))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_is_normalised_and_centred() {
        let spec = InstrumentSpec::preset("cubesat").unwrap();
        let k = SpatialKernel::new(&spec, &MtfBudget::default(), &[400.0, 865.0], 2);
        for w in &k.weights {
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let mean_along: f64 = w.iter().zip(&k.offsets_m).map(|(w, o)| w * o.0).sum();
            assert!(mean_along.abs() < 1e-9);
        }
        // The smear makes the kernel longer along track than across.
        let span = |f: fn(&(f64, f64)) -> f64| k.offsets_m.iter().map(f).fold(0.0, f64::max);
        assert!(span(|o| o.0) >= span(|o| o.1));
    }

    #[test]
    fn a_pinhole_aperture_coarsens_the_quadrature_rather_than_exploding() {
        // 1 mm at 1500 km: the Airy core is kilometres wide on a 0.15 m pixel.
        let mut spec = InstrumentSpec::preset("cubesat").unwrap();
        spec.aperture_mm = 1.0;
        spec.altitude_km = 1500.0;
        spec.pixel_pitch_um = 1.0;
        spec.focal_length_mm = 10_000.0;
        let k = SpatialKernel::new(&spec, &MtfBudget::default(), &[400.0, 2500.0], 8);
        assert!(k.len() <= 97 * 97, "{} points", k.len());
        for w in &k.weights {
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-9 && w.iter().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn a_full_fill_pixel_alone_is_the_trapezoid_rule() {
        // A huge aperture and no smear: the PSF is the pixel's box; sampled at GSD/2 its cells
        // hold ¼, ½, ¼ (diffraction's residue and Simpson's rule: 2 %).
        let mut spec = InstrumentSpec::preset("cubesat").unwrap();
        spec.aperture_mm = 2000.0;
        spec.exposure_s = 1e-9;
        let k = SpatialKernel::new(&spec, &MtfBudget::default(), &[550.0], 2);
        let across: Vec<f64> =
            k.offsets_m.iter().zip(&k.weights[0]).filter(|(o, _)| o.0 == 0.0).map(|(_, w)| *w).collect();
        let total: f64 = across.iter().sum();
        let mid = across.len() / 2;
        assert!((across[mid] / total - 0.5).abs() < 0.02, "{across:?}");
        assert!((across[mid - 1] / total - 0.25).abs() < 0.02, "{across:?}");
    }
}
