//! The fine wavelength grid on which Shoal simulates spectra.

use serde::{Deserialize, Serialize};

use super::SpectralError;

/// Shortest wavelength of the default simulation grid, nm.
pub const FINE_START_NM: f64 = 350.0;
/// Longest wavelength of the default simulation grid, nm.
pub const FINE_END_NM: f64 = 1000.0;
/// Most wavelengths a grid may hold (0.1 nm over 200–3000 nm is 28 001).
pub const MAX_POINTS: usize = 30_000;

/// A strictly increasing set of wavelengths (nm). Usually uniform (`uniform`, `fine`), but any
/// increasing list is allowed (band centres, a reference code's grid).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WavelengthGrid {
    wavelengths_nm: Vec<f64>,
}

impl WavelengthGrid {
    /// The default fine grid, 350–1000 nm at 1 nm (651 wavelengths).
    ///
    /// ```
    /// let g = shoal::spectral::WavelengthGrid::fine();
    /// assert_eq!(g.len(), 651);
    /// assert_eq!(g.wavelength_nm(0), 350.0);
    /// ```
    #[must_use]
    pub fn fine() -> Self {
        Self::uniform(FINE_START_NM, FINE_END_NM, 1.0).unwrap_or_else(|_| unreachable!())
    }

    /// The fine grid 350–1000 nm at `step_nm` (0.1–50 nm); the last point is the largest
    /// `350 + k·step` not above 1000 nm.
    pub fn fine_with_step(step_nm: f64) -> Result<Self, SpectralError> {
        if !(0.1..=50.0).contains(&step_nm) {
            return Err(SpectralError::Grid { field: "step_nm", value: step_nm, allowed: "0.1 to 50 nm".into() });
        }
        Self::uniform(FINE_START_NM, FINE_END_NM, step_nm)
    }

    /// A uniform grid from `start_nm` to at most `end_nm` with `step_nm`.
    pub fn uniform(start_nm: f64, end_nm: f64, step_nm: f64) -> Result<Self, SpectralError> {
        check_wavelength("start_nm", start_nm)?;
        check_wavelength("end_nm", end_nm)?;
        if !(step_nm.is_finite() && step_nm > 0.0) {
            return Err(SpectralError::Grid {
                field: "step_nm",
                value: step_nm,
                allowed: "a positive number of nm".into(),
            });
        }
        if end_nm < start_nm {
            return Err(SpectralError::Grid {
                field: "end_nm",
                value: end_nm,
                allowed: format!("at least start_nm = {start_nm}"),
            });
        }
        // Rounding guard: 350 + 650·1.0 must land on 1000 exactly.
        let count = ((end_nm - start_nm) / step_nm + 1e-9).floor() + 1.0;
        if count > MAX_POINTS as f64 {
            return Err(SpectralError::Grid {
                field: "step_nm",
                value: step_nm,
                allowed: format!("a step giving at most {MAX_POINTS} wavelengths over {start_nm}–{end_nm} nm"),
            });
        }
        let n = count as usize;
        let wavelengths_nm = (0..n).map(|i| start_nm + i as f64 * step_nm).collect();
        Ok(Self { wavelengths_nm })
    }

    /// An arbitrary strictly increasing list of wavelengths.
    ///
    /// ```
    /// let g = shoal::spectral::WavelengthGrid::from_wavelengths(vec![412.5, 442.5, 490.0]).unwrap();
    /// assert_eq!(g.len(), 3);
    /// assert!(shoal::spectral::WavelengthGrid::from_wavelengths(vec![500.0, 400.0]).is_err());
    /// ```
    pub fn from_wavelengths(wavelengths_nm: Vec<f64>) -> Result<Self, SpectralError> {
        if wavelengths_nm.is_empty() || wavelengths_nm.len() > MAX_POINTS {
            return Err(SpectralError::Grid {
                field: "wavelengths_nm",
                value: wavelengths_nm.len() as f64,
                allowed: format!("1 to {MAX_POINTS} wavelengths"),
            });
        }
        for &w in &wavelengths_nm {
            check_wavelength("wavelengths_nm", w)?;
        }
        if let Some(pair) = wavelengths_nm.windows(2).find(|p| p[1] <= p[0]) {
            return Err(SpectralError::Grid {
                field: "wavelengths_nm",
                value: pair[1],
                allowed: format!("strictly increasing values (it follows {})", pair[0]),
            });
        }
        Ok(Self { wavelengths_nm })
    }

    /// Number of wavelengths.
    #[must_use]
    pub fn len(&self) -> usize {
        self.wavelengths_nm.len()
    }

    /// Always false: a grid has at least one wavelength.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.wavelengths_nm.is_empty()
    }

    /// Wavelength `i`, nm. Panics if `i` is out of range (an internal error).
    #[must_use]
    pub fn wavelength_nm(&self, i: usize) -> f64 {
        self.wavelengths_nm[i]
    }

    /// All wavelengths, nm.
    #[must_use]
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// First and last wavelength, nm.
    #[must_use]
    pub fn range_nm(&self) -> (f64, f64) {
        let first = self.wavelengths_nm.first().copied().unwrap_or(f64::NAN);
        let last = self.wavelengths_nm.last().copied().unwrap_or(f64::NAN);
        (first, last)
    }

    /// Integration weights of the trapezoid rule on this grid (nm): Σ wᵢ f(λᵢ) ≈ ∫ f dλ.
    #[must_use]
    pub fn trapezoid_weights_nm(&self) -> Vec<f64> {
        let w = &self.wavelengths_nm;
        let n = w.len();
        (0..n)
            .map(|i| {
                let left = if i > 0 { w[i] - w[i - 1] } else { 0.0 };
                let right = if i + 1 < n { w[i + 1] - w[i] } else { 0.0 };
                0.5 * (left + right)
            })
            .collect()
    }
}

fn check_wavelength(field: &'static str, value: f64) -> Result<(), SpectralError> {
    if value.is_finite() && (200.0..=3000.0).contains(&value) {
        Ok(())
    } else {
        Err(SpectralError::Grid { field, value, allowed: "200 to 3000 nm".into() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fine_grid_steps_land_on_the_end() {
        assert_eq!(WavelengthGrid::fine_with_step(5.0).unwrap().len(), 131);
        assert_eq!(WavelengthGrid::fine_with_step(0.5).unwrap().range_nm(), (350.0, 1000.0));
        let g = WavelengthGrid::fine_with_step(3.0).unwrap();
        assert_eq!(g.range_nm().1, 998.0);
    }

    #[test]
    fn bad_steps_are_refused_with_the_range() {
        let e = WavelengthGrid::fine_with_step(0.0).unwrap_err();
        assert!(e.to_string().contains("0.1 to 50 nm"), "{e}");
        assert!(WavelengthGrid::fine_with_step(f64::NAN).is_err());
    }

    #[test]
    fn trapezoid_integrates_a_line_exactly() {
        let g = WavelengthGrid::uniform(400.0, 500.0, 10.0).unwrap();
        let w = g.trapezoid_weights_nm();
        let integral: f64 = g.wavelengths_nm().iter().zip(&w).map(|(l, w)| l * w).sum();
        assert!((integral - 0.5 * (500.0f64.powi(2) - 400.0f64.powi(2))).abs() < 1e-9);
    }
}
