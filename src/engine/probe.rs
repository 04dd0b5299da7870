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
/// (the first such in row order); `None` without water.
#[must_use]
pub fn typical_water_pixel(truth: &Truth) -> Option<(usize, usize)> {
    let mut water: Vec<(f32, usize, usize)> = truth
        .chl_mg_m3
        .indexed_iter()
        .filter(|((r, c), v)| truth.is_water(*r, *c) && v.is_finite())
        .map(|((r, c), v)| (*v, r, c))
        .collect();
    if water.is_empty() {
        return None;
    }
    let mid = water.len() / 2;
    water.select_nth_unstable_by(mid, |a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    Some((water[mid].1, water[mid].2))
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
