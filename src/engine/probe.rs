//! Pixels a run is asked, before it starts, to keep the Level-1 radiance and the corrected Rrs
//! of: what a study's spectrum figure shows of each instrument, from a run that does not keep
//! its cubes. The values are the cubes' own, unchanged.

use crate::calibration::Level1;
use crate::correction::Reflectance;
use crate::instrument::{Truth, Viewing};

/// A pixel to keep, named before the run knows its image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Probe {
    /// The run's typical water pixel ([`typical_water_pixel`]).
    TypicalWater,
    /// The run's pixel nearest a ground point, scene frame, m.
    Ground(f64, f64),
}

/// What a run kept of one probed pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Probed {
    /// What was asked.
    pub probe: Probe,
    /// The pixel (row, column); `None`: off the image, or no water for [`Probe::TypicalWater`].
    pub pixel: Option<(usize, usize)>,
    /// Level-1 radiance per band, W m⁻² sr⁻¹ nm⁻¹, and its flags.
    pub level1: Vec<(f32, u8)>,
    /// Corrected Rrs per band, sr⁻¹, and its flags.
    pub rrs: Vec<(f32, u8)>,
}

/// A typical water pixel of `truth`: the one whose true chl-a is the median of the water pixels
/// (the first such in row order); `None` without water. The median is found among the values
/// alone (4 bytes a pixel, where pairs of value and position took 24: 0.4 GB for a 10 m imager's
/// 16 million pixels, beside its cubes), then the pixel by a scan in row order: the one the
/// ordering by (value, row, column) puts in the middle.
#[must_use]
pub fn typical_water_pixel(truth: &Truth) -> Option<(usize, usize)> {
    let water = || truth.chl_mg_m3.indexed_iter().filter(|((r, c), v)| truth.is_water(*r, *c) && v.is_finite());
    let mut values: Vec<f32> = water().map(|(_, v)| *v).collect();
    if values.is_empty() {
        return None;
    }
    let mid = values.len() / 2;
    let median = *values.select_nth_unstable_by(mid, f32::total_cmp).1;
    // The pixels before the middle of that ordering: every smaller value, then the first of the
    // pixels holding the median in row order.
    let smaller = values.iter().filter(|v| v.total_cmp(&median).is_lt()).count();
    drop(values);
    water().filter(|(_, v)| v.total_cmp(&median).is_eq()).nth(mid - smaller).map(|(at, _)| at)
}

impl Probed {
    /// Where `probe` falls on this run's image (nothing read yet).
    pub(super) fn locate(probe: Probe, truth: &Truth, viewing: &Viewing) -> Self {
        let pixel = match probe {
            Probe::TypicalWater => typical_water_pixel(truth),
            Probe::Ground(x, y) => viewing.nearest_pixel(x, y, viewing.track_heading_deg()),
        };
        Self { probe, pixel, level1: Vec::new(), rrs: Vec::new() }
    }

    /// Keep the pixel's Level-1.
    pub(super) fn read_level1(&mut self, level1: &Level1) {
        if let Some((r, c)) = self.pixel {
            let nb = level1.radiance.dim().2;
            self.level1 = (0..nb).map(|b| (level1.radiance[[r, c, b]], level1.flags[[r, c, b]])).collect();
        }
    }

    /// Keep the pixel's Rrs.
    pub(super) fn read_rrs(&mut self, rrs: &Reflectance) {
        if let Some((r, c)) = self.pixel {
            let nb = rrs.rrs.dim().2;
            self.rrs = (0..nb).map(|b| (rrs.rrs[[r, c, b]], rrs.flags[[r, c, b]])).collect();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    /// The pixel the ordering of (value, row, column) puts in the middle, as it was found by
    /// sorting the pairs: the same on fields of many ties, of no ties and with land, NaN and -0.
    #[test]
    fn the_typical_pixel_is_the_middle_of_the_ordering() {
        let middle = |t: &Truth| {
            let mut w: Vec<(f32, usize, usize)> = t
                .chl_mg_m3
                .indexed_iter()
                .filter(|((r, c), v)| t.is_water(*r, *c) && v.is_finite())
                .map(|((r, c), v)| (*v, r, c))
                .collect();
            w.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
            w.get(w.len() / 2).map(|p| (p.1, p.2))
        };
        for (levels, rows, cols) in [(3, 9, 7), (5, 10, 10), (1000, 13, 11), (1, 4, 4)] {
            let chl = Array2::from_shape_fn((rows, cols), |(r, c)| match (r * 7 + c * 3) % 17 {
                0 => f32::NAN,
                1 => -0.0,
                k => (k % levels) as f32,
            });
            let land = Array2::from_shape_fn((rows, cols), |(r, c)| u8::from((r + c) % 5 == 0));
            let truth = Truth {
                chl_mg_m3: chl.clone(),
                nap_g_m3: chl.clone(),
                cdom_per_m: chl,
                depth_m: None,
                substrate_fractions: None,
                substrate_names: Vec::new(),
                surface: crate::instrument::SurfaceMap::from_codes(land),
                aot550: None,
            };
            assert_eq!(typical_water_pixel(&truth), middle(&truth), "{levels} levels, {rows} × {cols}");
        }
    }
}
