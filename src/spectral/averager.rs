//! The `band_from_fine` averaging matrix: a fine-grid spectrum averaged over each band's SRF.

use super::bands::{Band, BandSet};
use super::{Extrapolation, SpectralError, WavelengthGrid};

/// `band_from_fine`: the matrix that averages a fine-grid spectrum over each band's SRF.
///
/// Row *b* holds wᵢ = ∫ SRF_b(λ) hᵢ(λ) dλ / ∫ SRF_b(λ) dλ, where hᵢ is the hat function of grid
/// node *i* (the basis of linear interpolation). The band value is then exactly the SRF-weighted
/// mean of the linearly interpolated fine spectrum, whatever the grid step. Integration is exact:
/// on every interval between SRF samples and grid nodes both factors are linear, so Simpson's
/// rule integrates their product without error.
#[derive(Debug, Clone, PartialEq)]
pub struct BandAverager {
    rows: Vec<(usize, Vec<f64>)>,
    areas_nm: Vec<f64>,
    n_fine: usize,
}

impl BandAverager {
    /// Build the matrix for `bands` on `grid`. A band whose SRF reaches outside the grid by more
    /// than 0.1 % of its area is refused.
    ///
    /// ```
    /// use shoal::spectral::{BandAverager, BandSet, BandSetSpec, WavelengthGrid};
    /// let bands = BandSet::from_spec(&BandSetSpec::parse_cli("gauss:500/10").unwrap()).unwrap();
    /// let m = BandAverager::new(&WavelengthGrid::fine(), &bands).unwrap();
    /// let flat = vec![2.0; 651];
    /// assert!((m.apply(&flat)[0] - 2.0).abs() < 1e-12);
    /// ```
    pub fn new(grid: &WavelengthGrid, bands: &BandSet) -> Result<Self, SpectralError> {
        let rows: Vec<(usize, Vec<f64>, f64)> =
            bands.bands.iter().map(|b| Self::build_row(grid, b)).collect::<Result<_, _>>()?;
        Ok(Self {
            areas_nm: rows.iter().map(|r| r.2).collect(),
            rows: rows.into_iter().map(|(first, w, _)| (first, w)).collect(),
            n_fine: grid.len(),
        })
    }

    fn build_row(grid: &WavelengthGrid, band: &Band) -> Result<(usize, Vec<f64>, f64), SpectralError> {
        let g = grid.wavelengths_nm();
        let (g_lo, g_hi) = grid.range_nm();
        let (s_lo, s_hi) = band.srf.range_nm();
        let srf = |x: f64| band.srf.value_at(x, Extrapolation::Zero).unwrap_or(0.0);
        let total = integrate_linear(&band.srf.wavelength_nm, &band.srf.values);
        // Breakpoints: SRF samples and grid nodes inside the overlap.
        let (a, b) = (s_lo.max(g_lo), s_hi.min(g_hi));
        let mut xs: Vec<f64> = band.srf.wavelength_nm.iter().copied().filter(|x| (a..=b).contains(x)).collect();
        xs.extend(g.iter().copied().filter(|x| (a..=b).contains(x)));
        xs.push(a);
        xs.push(b);
        xs.sort_by(f64::total_cmp);
        xs.dedup_by(|p, q| (*p - *q).abs() < 1e-12);
        // The SRF at every breakpoint, read once (each is an end of two intervals).
        let at_breakpoints: Vec<f64> = xs.iter().map(|&x| srf(x)).collect();
        let mut weights = vec![0.0; g.len()];
        let mut inside = 0.0;
        for (w, s) in xs.windows(2).zip(at_breakpoints.windows(2)) {
            let (x0, x1, s0, s1) = (w[0], w[1], s[0], s[1]);
            if x1 <= x0 {
                continue;
            }
            let xm = 0.5 * (x0 + x1);
            let sm = srf(xm);
            let simpson = |f0: f64, fm: f64, f1: f64| (x1 - x0) / 6.0 * (f0 + 4.0 * fm + f1);
            // Grid interval [g[j-1], g[j]] that contains this sub-interval.
            let j = g.partition_point(|&v| v <= xm).clamp(1, g.len().max(2) - 1);
            if g.len() == 1 {
                let seg = simpson(s0, sm, s1);
                weights[0] += seg;
                inside += seg;
                continue;
            }
            let (gl, gr) = (g[j - 1], g[j]);
            let hat_r = |x: f64| (x - gl) / (gr - gl);
            let right = simpson(s0 * hat_r(x0), sm * hat_r(xm), s1 * hat_r(x1));
            let left = simpson(s0 * (1.0 - hat_r(x0)), sm * (1.0 - hat_r(xm)), s1 * (1.0 - hat_r(x1)));
            weights[j - 1] += left;
            weights[j] += right;
            inside += left + right;
        }
        if !(total > 0.0) || inside < 0.999 * total {
            return Err(SpectralError::Bands(format!(
                "band `{}` ({:.1}–{:.1} nm) reaches outside the simulation grid {:.0}–{:.0} nm",
                band.name, s_lo, s_hi, g_lo, g_hi
            )));
        }
        let first = weights.iter().position(|&w| w != 0.0).unwrap_or(0);
        let last = weights.iter().rposition(|&w| w != 0.0).unwrap_or(0);
        let row = weights[first..=last].iter().map(|w| w / inside).collect();
        Ok((first, row, inside))
    }

    /// Row `b`: index of its first non-zero weight and the weights (summing to 1).
    #[must_use]
    pub fn row(&self, b: usize) -> (usize, &[f64]) {
        let (first, w) = &self.rows[b];
        (*first, w)
    }

    /// ∫ SRF dλ of band `b` over the grid, nm (the equivalent width of a peak-normalised SRF).
    #[must_use]
    pub fn srf_area_nm(&self, b: usize) -> f64 {
        self.areas_nm[b]
    }

    /// Number of bands (rows).
    #[must_use]
    pub fn n_bands(&self) -> usize {
        self.rows.len()
    }

    /// Number of fine-grid wavelengths (columns).
    #[must_use]
    pub fn n_fine(&self) -> usize {
        self.n_fine
    }

    /// Band averages of a fine-grid spectrum.
    #[must_use]
    pub fn apply(&self, fine: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.rows.len()];
        self.apply_into(fine, &mut out);
        out
    }

    /// Band averages into `out` (length = number of bands).
    pub fn apply_into(&self, fine: &[f64], out: &mut [f64]) {
        debug_assert_eq!(fine.len(), self.n_fine);
        for ((first, w), o) in self.rows.iter().zip(out.iter_mut()) {
            *o = w.iter().zip(&fine[*first..*first + w.len()]).map(|(a, b)| a * b).sum();
        }
    }

    /// The dense matrix (bands × fine wavelengths), for export and inspection.
    #[must_use]
    pub fn to_dense(&self) -> ndarray::Array2<f64> {
        let mut m = ndarray::Array2::zeros((self.rows.len(), self.n_fine));
        for (b, (first, w)) in self.rows.iter().enumerate() {
            for (k, v) in w.iter().enumerate() {
                m[[b, first + k]] = *v;
            }
        }
        m
    }
}

fn integrate_linear(x: &[f64], y: &[f64]) -> f64 {
    x.windows(2).zip(y.windows(2)).map(|(x, y)| 0.5 * (x[1] - x[0]) * (y[0] + y[1])).sum()
}
