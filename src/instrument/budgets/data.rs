//! What the instrument downlinks: its data rate while imaging, the volume of a day's images,
//! and the share of a stated downlink that takes.
//!
//! ## Formulas
//! - A pushbroom plane reads `detectors` pixels in each of its bands every line period
//!   t = GSD / v_ground (Schowengerdt 2007, §3.4); its rate is detectors · bands · bits / t.
//!   A plane with a finer pitch than the first has a shorter line period in the same ratio.
//! - An image is the instrument's `lines` lines of its first plane: duration lines · t₀.
//! - Daily volume = images per day · image volume / compression ratio (Wertz & Larson 1999,
//!   §13.2: data volume against link capacity); a design whose coder holds a rate target
//!   (`instrument::effects::Compression`) sends that many bits per sample instead of the ADC's.
//! - Downlink capacity per day = link rate · contact time per day.
//!
//! ## References
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd ed.
//! - Wertz, J. R., Larson, W. J. (eds.) (1999) Space Mission Analysis and Design, 3rd ed.

use serde::{Deserialize, Serialize};

use super::envelope::check;
use crate::instrument::effects::Compression;
use crate::parse::FieldError;

/// How the instrument is operated and what the ground segment takes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Operations {
    /// Images (of the instrument's `lines`) taken per day.
    pub images_per_day: f64,
    /// Lossless compression ratio applied on board (1: none).
    pub compression_ratio: f64,
    /// Downlink rate, Mbit/s.
    pub downlink_mbit_s: f64,
    /// Ground-station contact time per day, minutes.
    pub contact_min_per_day: f64,
}

/// One focal plane's readout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneReadout {
    /// Bands on the plane.
    pub bands: usize,
    /// Detectors across track.
    pub detectors: usize,
    /// ADC bits.
    pub bits: u32,
    /// Its line period, s.
    pub line_period_s: f64,
}

/// The data budget of a design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataBudget {
    /// Rate while imaging, Mbit/s.
    pub rate_mbit_s: f64,
    /// One image (the instrument's lines), Gbit.
    pub image_gbit: f64,
    /// A day's images after compression, Gbit.
    pub daily_gbit: f64,
    /// What the link downlinks in a day, Gbit.
    pub downlink_gbit_day: f64,
}

impl DataBudget {
    /// Share of the daily downlink the images take (above 1: they do not fit).
    #[must_use]
    pub fn downlink_share(&self) -> f64 {
        if self.downlink_gbit_day > 0.0 { self.daily_gbit / self.downlink_gbit_day } else { f64::INFINITY }
    }
}

impl Operations {
    /// Every figure in range.
    pub fn validate(&self) -> Result<(), FieldError> {
        check("budgets.operations.images_per_day", self.images_per_day, 0.0, 1e4)?;
        check("budgets.operations.compression_ratio", self.compression_ratio, 1.0, 100.0)?;
        check("budgets.operations.downlink_mbit_s", self.downlink_mbit_s, 0.0, 1e5)?;
        check("budgets.operations.contact_min_per_day", self.contact_min_per_day, 0.0, 1440.0)
    }

    /// [`Self::budget`] for a design whose on-board coder the instrument states: a rate target
    /// replaces the stated ratio (the coder holds every band to that many bits per sample); a
    /// coder without one keeps the stated ratio (its real rate depends on the scene: a study
    /// reports it, `CompressionReport`).
    #[must_use]
    pub fn budget_with(&self, planes: &[PlaneReadout], lines: usize, coder: Option<&Compression>) -> DataBudget {
        let rate = coder.map_or(0.0, |c| c.bits_per_sample);
        if rate <= 0.0 {
            return self.budget(planes, lines);
        }
        let mut budget = Self { compression_ratio: 1.0, ..self.clone() }.budget(planes, lines);
        // Bits a second raw and coded, each plane at its own line rate.
        let per_second = |bits: &dyn Fn(&PlaneReadout) -> f64| -> f64 {
            let timed = planes.iter().filter(|p| p.line_period_s > 0.0);
            timed.map(|p| (p.detectors * p.bands) as f64 * bits(p) / p.line_period_s).sum()
        };
        let raw_bits = per_second(&|p| f64::from(p.bits));
        let coded_bits = per_second(&|p| rate.min(f64::from(p.bits)));
        if raw_bits > 0.0 {
            budget.daily_gbit *= coded_bits / raw_bits;
        }
        budget
    }

    /// The data budget of planes read out as `planes`, an image being `lines` lines of the first.
    #[must_use]
    pub fn budget(&self, planes: &[PlaneReadout], lines: usize) -> DataBudget {
        let rate_bit_s: f64 = planes
            .iter()
            .filter(|p| p.line_period_s > 0.0)
            .map(|p| (p.detectors * p.bands) as f64 * f64::from(p.bits) / p.line_period_s)
            .sum();
        let duration_s = planes.first().map_or(0.0, |p| lines as f64 * p.line_period_s);
        let image_gbit = rate_bit_s * duration_s * 1e-9;
        DataBudget {
            rate_mbit_s: rate_bit_s * 1e-6,
            image_gbit,
            daily_gbit: self.images_per_day * image_gbit / self.compression_ratio,
            downlink_gbit_day: self.downlink_mbit_s * self.contact_min_per_day * 60.0 * 1e-3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_volume_and_link_by_hand() {
        let ops = Operations {
            images_per_day: 10.0,
            compression_ratio: 2.0,
            downlink_mbit_s: 50.0,
            contact_min_per_day: 20.0,
        };
        // 1024 detectors × 8 bands × 12 bits every 2 ms = 49.152 Mbit/s; a SWIR plane at half
        // the resolution (4 ms) with 512 × 2 × 14 bits adds 3.584 Mbit/s.
        let planes = [
            PlaneReadout { bands: 8, detectors: 1024, bits: 12, line_period_s: 0.002 },
            PlaneReadout { bands: 2, detectors: 512, bits: 14, line_period_s: 0.004 },
        ];
        let d = ops.budget(&planes, 2000);
        assert!((d.rate_mbit_s - 52.736).abs() < 1e-9);
        // 2000 lines × 2 ms = 4 s: 0.210944 Gbit; 10 a day halved: 1.05472 Gbit.
        assert!((d.image_gbit - 0.210_944).abs() < 1e-12);
        // A coder held to 3 bits per sample: the first plane sends 3 of 12 bits, the SWIR plane
        // 3 of 14; (1024·8·3/0.002 + 512·2·3/0.004)/(52.736e6) of 10 uncompressed images.
        let coder = Compression { max_error_dn: 0, bits_per_sample: 3.0 };
        let coded = ops.budget_with(&planes, 2000, Some(&coder));
        let share = (1024.0 * 8.0 * 3.0 / 0.002 + 512.0 * 2.0 * 3.0 / 0.004) / 52.736e6;
        assert!((coded.daily_gbit - 10.0 * 0.210_944 * share).abs() < 1e-12, "{coded:?}");
        assert_eq!(ops.budget_with(&planes, 2000, Some(&Compression::default())), d);
        assert!((d.daily_gbit - 1.054_72).abs() < 1e-12);
        // 50 Mbit/s × 20 min = 60 Gbit a day.
        assert!((d.downlink_gbit_day - 60.0).abs() < 1e-12);
        assert!((d.downlink_share() - 1.054_72 / 60.0).abs() < 1e-15);
    }
}
