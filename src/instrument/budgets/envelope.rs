//! Where the instrument goes: its optical envelope, the smallest CubeSat form factor or
//! SmallSat envelope it fits, and its mass and power scaled from a reference instrument.
//!
//! ## Formulas
//! - Optical length L = t · f + back, with t the telephoto ratio (overall length over effective
//!   focal length; Smith 2008, §8.4: below 1 for a telephoto or folded Cassegrain design) and
//!   `back` the focal-plane and electronics depth behind the image.
//! - Cross-section = D + 2 · wall (baffle and barrel around the aperture).
//! - A box of sides (a, b, c) holds the instrument if, with the optical axis along one side,
//!   L fits the payload's share of that side and the cross-section fits the smaller of the
//!   other two. CubeSat sizes are the CubeSat Design Specification's outer dimensions (Cal Poly
//!   CDS rev. 14.1, 2022: 1U 100 × 100 × 113.5 mm, 3U 340.5 mm long; 6U and 12U from the
//!   6U CDS rev. 1.0, 2018: 100 × 226.3 × 366 and 226.3 × 226.3 × 366 mm).
//! - Mass and power by analogy with a reference instrument (Wertz & Larson 1999, §9.5,
//!   eqs. 9-16 to 9-18): R = D / D_ref, W = K R³ W_ref, P = K R³ P_ref, with K = 2 when
//!   R < 0.5 (small instruments carry relatively more structure) and 1 otherwise. The scaling
//!   is only as good as the reference's likeness; SMAD advises R between 0.5 and 2.
//!
//! ## References
//! - Smith, W. J. (2008) Modern Optical Engineering, 4th ed. McGraw-Hill.
//! - Wertz, J. R., Larson, W. J. (eds.) (1999) Space Mission Analysis and Design, 3rd ed.
//!   Microcosm / Kluwer.
//! - California Polytechnic State University (2022) CubeSat Design Specification, rev. 14.1;
//!   (2018) 6U CubeSat Design Specification, rev. 1.0.

use serde::{Deserialize, Serialize};

use crate::parse::FieldError;

/// How the optics are packaged.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Packaging {
    /// Overall length over focal length.
    pub telephoto_ratio: f64,
    /// Depth behind the image (focal plane, proximity electronics), mm.
    pub back_mm: f64,
    /// Barrel and baffle wall around the aperture, mm.
    pub wall_mm: f64,
    /// Share of a box's length the payload may take (the rest is the bus).
    pub payload_length_share: f64,
}

/// A box an instrument may fly in: a CubeSat form factor or a SmallSat payload bay.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormFactor {
    /// Name (`"6U"`).
    pub name: String,
    /// Outer sides, mm.
    pub sides_mm: (f64, f64, f64),
}

/// A reference instrument to scale mass and power from (SMAD §9.5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Its name and the source of its figures.
    pub name: String,
    /// Aperture, mm.
    pub aperture_mm: f64,
    /// Mass, kg.
    pub mass_kg: f64,
    /// Power, W.
    pub power_w: f64,
}

/// The envelope of a design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Envelope {
    /// Optical length, mm.
    pub length_mm: f64,
    /// Cross-section, mm.
    pub cross_section_mm: f64,
    /// The smallest form factor (by volume) it fits; `None`: none of them.
    pub fits: Option<String>,
    /// Mass scaled from the reference, kg (`None`: no reference given).
    pub mass_kg: Option<f64>,
    /// Power scaled from the reference, W.
    pub power_w: Option<f64>,
}

impl Packaging {
    /// Every figure in range.
    pub fn validate(&self) -> Result<(), FieldError> {
        check("budgets.packaging.telephoto_ratio", self.telephoto_ratio, 0.05, 3.0)?;
        check("budgets.packaging.back_mm", self.back_mm, 0.0, 2000.0)?;
        check("budgets.packaging.wall_mm", self.wall_mm, 0.0, 500.0)?;
        check("budgets.packaging.payload_length_share", self.payload_length_share, 0.05, 1.0)
    }

    /// Optical length and cross-section of a telescope of `aperture_mm` and `focal_length_mm`.
    #[must_use]
    pub fn size_mm(&self, aperture_mm: f64, focal_length_mm: f64) -> (f64, f64) {
        (self.telephoto_ratio * focal_length_mm + self.back_mm, aperture_mm + 2.0 * self.wall_mm)
    }

    /// Does a telescope of `length_mm` × `cross_mm` fit `box_`? Any of the three sides may hold
    /// the optical axis.
    #[must_use]
    pub fn fits(&self, length_mm: f64, cross_mm: f64, box_: &FormFactor) -> bool {
        self.fit_ratio(length_mm, cross_mm, box_) <= 1.0
    }

    /// How much of `box_` the telescope needs: over the three orientations of its optical axis,
    /// the least of max(length / room along the axis, cross-section / room across). At most 1:
    /// it fits; 1.2: it is 20 % too large in its tightest dimension.
    #[must_use]
    pub fn fit_ratio(&self, length_mm: f64, cross_mm: f64, box_: &FormFactor) -> f64 {
        let (a, b, c) = box_.sides_mm;
        [(a, b.min(c)), (b, a.min(c)), (c, a.min(b))]
            .iter()
            .map(|&(axis, face)| (length_mm / (self.payload_length_share * axis)).max(cross_mm / face))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Check that `value` of `field` is finite and within `lo..=hi`.
pub(super) fn check(field: &str, value: f64, lo: f64, hi: f64) -> Result<(), FieldError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(FieldError { field: field.into(), message: format!("{value} is out of range (allowed: {lo} to {hi})") })
    }
}

impl Reference {
    /// Every figure positive.
    pub fn validate(&self) -> Result<(), FieldError> {
        check("budgets.reference.aperture_mm", self.aperture_mm, 1.0, 20_000.0)?;
        check("budgets.reference.mass_kg", self.mass_kg, 1e-3, 1e5)?;
        check("budgets.reference.power_w", self.power_w, 0.0, 1e5)
    }

    /// Mass (kg) and power (W) of an instrument of `aperture_mm` (SMAD eqs. 9-17, 9-18).
    #[must_use]
    pub fn scale(&self, aperture_mm: f64) -> (f64, f64) {
        let r = aperture_mm / self.aperture_mm;
        let k = if r < 0.5 { 2.0 } else { 1.0 };
        (k * r.powi(3) * self.mass_kg, k * r.powi(3) * self.power_w)
    }
}

/// The envelope of a telescope against `boxes` (tried in order of volume).
#[must_use]
pub fn envelope(
    packaging: &Packaging,
    boxes: &[FormFactor],
    reference: Option<&Reference>,
    aperture_mm: f64,
    focal_length_mm: f64,
) -> Envelope {
    let (length_mm, cross_section_mm) = packaging.size_mm(aperture_mm, focal_length_mm);
    let mut sorted: Vec<&FormFactor> = boxes.iter().collect();
    sorted.sort_by(|x, y| volume(x).total_cmp(&volume(y)));
    let fits = sorted.into_iter().find(|b| packaging.fits(length_mm, cross_section_mm, b)).map(|b| b.name.clone());
    let (mass_kg, power_w) = reference.map(|r| r.scale(aperture_mm)).unzip();
    Envelope { length_mm, cross_section_mm, fits, mass_kg, power_w }
}

fn volume(b: &FormFactor) -> f64 {
    b.sides_mm.0 * b.sides_mm.1 * b.sides_mm.2
}

#[cfg(test)]
mod tests {
    use super::*;

    fn packaging() -> Packaging {
        Packaging { telephoto_ratio: 0.5, back_mm: 40.0, wall_mm: 5.0, payload_length_share: 0.5 }
    }

    fn cubesats() -> Vec<FormFactor> {
        vec![
            FormFactor { name: "12U".into(), sides_mm: (226.3, 226.3, 366.0) },
            FormFactor { name: "3U".into(), sides_mm: (100.0, 100.0, 340.5) },
            FormFactor { name: "6U".into(), sides_mm: (100.0, 226.3, 366.0) },
        ]
    }

    #[test]
    fn the_smallest_box_that_holds_the_telescope_by_hand() {
        // 60 mm, f = 165 mm: L = 0.5·165 + 40 = 122.5 mm, cross-section 70 mm. A 3U's half
        // length is 170.25 mm and its face 100 mm: it fits a 3U.
        let e = envelope(&packaging(), &cubesats(), None, 60.0, 165.0);
        assert_eq!((e.length_mm, e.cross_section_mm), (122.5, 70.0));
        assert_eq!(e.fits.as_deref(), Some("3U"));
        // 120 mm: cross-section 130 mm > 100 mm, so only a 12U face (226.3 mm) holds it.
        assert_eq!(envelope(&packaging(), &cubesats(), None, 120.0, 165.0).fits.as_deref(), Some("12U"));
        // f = 600 mm: L = 340 mm > 183 mm (half of 366): nothing fits.
        assert_eq!(envelope(&packaging(), &cubesats(), None, 60.0, 600.0).fits, None);
    }

    #[test]
    fn smad_analogy_scaling_by_hand() {
        let r = Reference { name: "ref".into(), aperture_mm: 100.0, mass_kg: 10.0, power_w: 20.0 };
        // R = 0.8: K = 1, 0.512 × 10 kg, 0.512 × 20 W.
        let (m, p) = r.scale(80.0);
        assert!((m - 5.12).abs() < 1e-12 && (p - 10.24).abs() < 1e-12);
        // R = 0.4 < 0.5: K = 2, 2 × 0.064 × 10 kg.
        assert!((r.scale(40.0).0 - 1.28).abs() < 1e-12);
    }
}
