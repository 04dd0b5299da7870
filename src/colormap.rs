//! Colour maps for product maps and figures, shared by the study figures and the app.
//!
//! - [`viridis`]: perceptually uniform, readable in greyscale and by colour-blind readers; the
//!   matplotlib default (van der Walt & Smith 2015; Nuñez, Anderton & Renslow 2018). Eight anchor
//!   colours at k/7, linearly interpolated in sRGB.
//! - [`diverging`]: ColorBrewer RdBu reversed (Brewer 2002), blue below zero, red above, for
//!   differences (A − B, retrieved − true).
//! - [`categorical`]: ColorBrewer Set1 (its grey replaced by matplotlib's `tab:cyan`, apart from the
//!   truth's grey) and Dark2 colours for classes (SIOP sets, substrates) and designs.
//!
//! ## References
//! - Nuñez, J. R., Anderton, C. R., Renslow, R. S. (2018) Optimizing colormaps with consideration
//!   for color vision deficiency to enable accurate interpretation of scientific data. PLoS ONE
//!   13, e0199239.
//! - Brewer, C. A. (2002) ColorBrewer, www.ColorBrewer.org (Apache-2.0-style licence).

/// An sRGB colour.
pub type Rgb = [u8; 3];

const VIRIDIS: [Rgb; 8] = [
    [68, 1, 84],
    [70, 50, 127],
    [54, 92, 141],
    [39, 127, 143],
    [31, 162, 136],
    [74, 194, 110],
    [160, 219, 57],
    [254, 232, 37],
];

const RDBU_R: [Rgb; 11] = [
    [5, 48, 97],
    [33, 102, 172],
    [67, 147, 195],
    [146, 197, 222],
    [209, 229, 240],
    [247, 247, 247],
    [253, 219, 199],
    [244, 165, 130],
    [214, 96, 77],
    [178, 24, 43],
    [103, 0, 31],
];

const CLASSES: [Rgb; 12] = [
    [228, 26, 28],
    [55, 126, 184],
    [77, 175, 74],
    [152, 78, 163],
    [255, 127, 0],
    [166, 86, 40],
    [247, 129, 191],
    [23, 190, 207],
    [27, 158, 119],
    [217, 95, 2],
    [117, 112, 179],
    [102, 166, 30],
];

fn interpolate(anchors: &[Rgb], t: f64) -> Rgb {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (anchors.len() - 1) as f64;
    // x ≥ 0, so truncation is its floor (no libm call: a map's every block comes through here).
    let i = (x as usize).min(anchors.len() - 2);
    let f = x - i as f64;
    let (a, b) = (anchors[i], anchors[i + 1]);
    std::array::from_fn(|k| round_channel(f64::from(a[k]) + f * (f64::from(b[k]) - f64::from(a[k]))))
}

/// `v.round() as u8` for `v` in 0–255, without a libm call: half up by truncation, less one where
/// `v + 0.5` rounded up to the next integer in floating point (`v` just below ½).
#[inline]
fn round_channel(v: f64) -> u8 {
    let r = (v + 0.5) as u8;
    if f64::from(r) - v > 0.5 { r - 1 } else { r }
}

/// Viridis at t ∈ [0, 1] (clamped; NaN gives the low end).
#[must_use]
pub fn viridis(t: f64) -> Rgb {
    interpolate(&VIRIDIS, t)
}

/// Diverging blue–white–red at t ∈ [−1, 1] (0 is white).
#[must_use]
pub fn diverging(t: f64) -> Rgb {
    interpolate(&RDBU_R, 0.5 * (t + 1.0))
}

/// The colour of class `i` (cycling after twelve).
#[must_use]
pub fn categorical(i: usize) -> Rgb {
    CLASSES[i % CLASSES.len()]
}

/// A value scale: linear or logarithmic between `lo` and `hi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// Low end.
    pub lo: f64,
    /// High end.
    pub hi: f64,
    /// Logarithmic (both ends > 0).
    pub log: bool,
}

impl Scale {
    /// Where `v` falls on the scale, 0–1 (not clamped).
    #[must_use]
    pub fn position(&self, v: f64) -> f64 {
        if self.log {
            let (a, b) = (self.lo.max(f64::MIN_POSITIVE).ln(), self.hi.max(f64::MIN_POSITIVE).ln());
            if b > a { (v.max(f64::MIN_POSITIVE).ln() - a) / (b - a) } else { 0.5 }
        } else if self.hi > self.lo {
            (v - self.lo) / (self.hi - self.lo)
        } else {
            0.5
        }
    }

    /// The value at position `t` (0–1).
    #[must_use]
    pub fn value(&self, t: f64) -> f64 {
        if self.log {
            (self.lo.ln() + t * (self.hi.ln() - self.lo.ln())).exp()
        } else {
            self.lo + t * (self.hi - self.lo)
        }
    }

    /// Round tick values inside the scale, for colour bars and axes: 1-2-5 per decade on a log
    /// scale (1-3 when it spans more than 1.5 decades, decades alone beyond 3), about five
    /// 1-2-5 steps on a linear one. A scale of zero width gets its one value.
    #[must_use]
    pub fn nice_ticks(&self) -> Vec<f64> {
        if !(self.lo.is_finite() && self.hi.is_finite()) {
            return Vec::new();
        }
        let (lo, hi) = (self.lo.min(self.hi), self.hi.max(self.lo));
        if hi <= lo {
            return vec![lo];
        }
        let inside = |v: &f64| *v >= lo - 1e-9 * lo.abs() && *v <= hi + 1e-9 * hi.abs();
        if self.log && lo > 0.0 {
            let decades = (hi / lo).log10();
            let mults: &[f64] = if decades > 3.0 {
                &[1.0]
            } else if decades > 1.5 {
                &[1.0, 3.0]
            } else {
                &[1.0, 2.0, 5.0]
            };
            let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
            (d0..=d1).flat_map(|d| mults.iter().map(move |m| m * 10f64.powi(d))).filter(inside).collect()
        } else {
            let raw = (hi - lo) / 5.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|s| *s >= raw).unwrap_or(raw);
            let first = (lo / step).ceil() as i64;
            (first..).map(|k| k as f64 * step).take_while(|v| inside(v)).collect()
        }
    }

    /// The mean of [`Scale::position`] over a set of values, from their mean `mean_value` and the
    /// mean `mean_ln` of their `ln(max(v, f64::MIN_POSITIVE))`: the position is affine in `v` on
    /// a linear scale and in `ln v` on a log scale, so the mean of positions is the position of
    /// the mean (up to rounding). Lets a map keep block sums and be recoloured without revisiting
    /// its pixels.
    #[must_use]
    pub fn position_of_mean(&self, mean_value: f64, mean_ln: f64) -> f64 {
        self.position_of_mean_fn()(mean_value, mean_ln)
    }

    /// [`Self::position_of_mean`] with the scale's logarithms taken once, for a whole image (the
    /// same values: a map of 720 × 480 blocks took two logarithms per block).
    pub fn position_of_mean_fn(&self) -> impl Fn(f64, f64) -> f64 + Copy + use<> {
        let (log, lo, hi) = (self.log, self.lo, self.hi);
        let (a, b) = if log { (lo.max(f64::MIN_POSITIVE).ln(), hi.max(f64::MIN_POSITIVE).ln()) } else { (lo, hi) };
        move |mean_value: f64, mean_ln: f64| {
            if log {
                if b > a { (mean_ln - a) / (b - a) } else { 0.5 }
            } else if hi > lo {
                (mean_value - lo) / (hi - lo)
            } else {
                0.5
            }
        }
    }

    /// A scale covering the 1st–99th percentiles of the finite (and, for log, positive) values,
    /// logarithmic when they span more than a decade and are all positive.
    #[must_use]
    pub fn robust(values: impl IntoIterator<Item = f64>) -> Self {
        let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
        v.sort_unstable_by(f64::total_cmp);
        Self::robust_sorted(&[&v])
    }

    /// [`Scale::robust`] of the union of several ascending slices of finite values (each map's
    /// sorted sample, kept between redraws), without merging them.
    #[must_use]
    pub fn robust_sorted(sorted: &[&[f64]]) -> Self {
        let n: usize = sorted.iter().map(|s| s.len()).sum();
        if n == 0 {
            return Self { lo: 0.0, hi: 1.0, log: false };
        }
        let at = |q: f64| kth_smallest(sorted, ((n - 1) as f64 * q).round() as usize).unwrap_or(f64::NAN);
        let (lo, hi) = (at(0.01), at(0.99));
        let positive = at(0.0) > 0.0;
        let log = positive && hi > 10.0 * lo;
        let (lo, hi) =
            if hi > lo { (lo, hi) } else { (lo - 0.5 * lo.abs().max(1e-12), hi + 0.5 * hi.abs().max(1e-12)) };
        Self { lo, hi, log }
    }
}

/// The `k`-th smallest value (0-based) of the union of ascending slices of non-NaN values, without
/// merging them: `None` when they hold `k` values or fewer. For each slice in turn, a binary
/// search for the element whose rank in the union brackets `k` (ranks counted with
/// `partition_point`, so ties are handled): O(m² log² n) for m slices.
#[must_use]
pub fn kth_smallest(sorted: &[&[f64]], k: usize) -> Option<f64> {
    let below = |x: f64| sorted.iter().map(|s| s.partition_point(|v| *v < x)).sum::<usize>();
    let up_to = |x: f64| sorted.iter().map(|s| s.partition_point(|v| *v <= x)).sum::<usize>();
    for s in sorted {
        let (mut lo, mut hi) = (0, s.len());
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            let x = s[mid];
            if up_to(x) <= k {
                lo = mid + 1;
            } else if below(x) > k {
                hi = mid;
            } else {
                return Some(x);
            }
        }
    }
    None
}

/// The 8 × 8 Bayer matrix (Bayer 1973, "An optimum method for two-level rendition of
/// continuous-tone pictures"): thresholds 0–63 spread so that any 8 × 8 tile lights 64 f of its
/// cells (rounded) for a grey level f.
const BAYER8: [[u8; 8]; 8] = [
    [0, 32, 8, 40, 2, 34, 10, 42],
    [48, 16, 56, 24, 50, 18, 58, 26],
    [12, 44, 4, 36, 14, 46, 6, 38],
    [60, 28, 52, 20, 62, 30, 54, 22],
    [3, 35, 11, 43, 1, 33, 9, 41],
    [51, 19, 59, 27, 49, 17, 57, 25],
    [15, 47, 7, 39, 13, 45, 5, 37],
    [63, 31, 55, 23, 61, 29, 53, 21],
];

/// Is a cell at (`x`, `y`) of which a share `share` (0–1) is data drawn as data? Ordered
/// dithering against [`BAYER8`]: over any 8 × 8 cells a share f lights 64 f of them, so a map
/// drawn smaller than its pixels shows as much "not returned" grey as there is, wherever it is
/// looked at (one cell coloured by any returned pixel made a 22 % return look ~90 % coloured).
#[must_use]
pub fn dithered(share: f64, x: usize, y: usize) -> bool {
    share > (f64::from(BAYER8[y % 8][x % 8]) + 0.5) / 64.0
}

/// A tick or axis value as people write it: `digits` significant digits without trailing zeros
/// (211.151 → "211" at 3 digits; 0.30000000000000004 → "0.3"), and e-notation outside
/// 0.001–10⁶ ("2e-5"). Colour bars, axes and crossings in the app and on the review slide.
#[must_use]
pub fn significant(v: f64, digits: i32) -> String {
    let a = v.abs();
    if a == 0.0 || !v.is_finite() {
        return if a == 0.0 { "0".into() } else { format!("{v}") };
    }
    if !(1e-3..1e6).contains(&a) {
        return format!("{v:.0e}");
    }
    let decimals = (digits - 1 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kth_of_sorted_slices_is_the_kth_of_their_union() {
        let a = [0.5, 1.0, 1.0, 4.0];
        let b = [1.0, 2.0, 3.0];
        let c: [f64; 0] = [];
        let mut all: Vec<f64> = a.iter().chain(&b).copied().collect();
        all.sort_by(f64::total_cmp);
        for (k, want) in all.iter().enumerate() {
            assert_eq!(kth_smallest(&[&a, &b, &c], k), Some(*want), "k = {k}");
        }
        assert_eq!(kth_smallest(&[&a, &b], all.len()), None);
        // The same scale as from the values themselves.
        let v: Vec<f64> = (0..997).map(|i| f64::from(i).mul_add(0.37, 1.0).sin().abs() * 50.0 + 0.01).collect();
        let (x, y) = v.split_at(400);
        let (mut x, mut y) = (x.to_vec(), y.to_vec());
        x.sort_by(f64::total_cmp);
        y.sort_by(f64::total_cmp);
        assert_eq!(Scale::robust(v.iter().copied()), Scale::robust_sorted(&[&x, &y]));
    }

    #[test]
    fn ends_and_middle() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [254, 232, 37]);
        assert_eq!(viridis(f64::NAN), [68, 1, 84]);
        assert_eq!(diverging(0.0), [247, 247, 247]);
        let s = Scale { lo: 1.0, hi: 100.0, log: true };
        assert!((s.position(10.0) - 0.5).abs() < 1e-12);
        assert!((s.value(0.5) - 10.0).abs() < 1e-9);
        let r = Scale::robust((1..=1000).map(f64::from));
        assert!(r.log && (r.lo - 11.0).abs() < 1.0 && (r.hi - 990.0).abs() < 2.0);
    }

    #[test]
    fn values_print_as_people_write_them() {
        let t: Vec<String> = [100.0, 30.0, 3.0, 0.3, 0.05, -0.5, 0.0, 2e-5].map(|v| significant(v, 4)).to_vec();
        assert_eq!(t, ["100", "30", "3", "0.3", "0.05", "-0.5", "0", "2e-5"]);
        let t: Vec<String> = [211.151, 0.0012345, 1500.0, 2.5].map(|v| significant(v, 3)).to_vec();
        assert_eq!(t, ["211", "0.00123", "1500", "2.5"]);
    }

    #[test]
    fn nice_ticks_are_round_and_inside() {
        // The colour bar: 0.97 to 31 mg m⁻³ (1.5 decades) → 1, 3, 10, 30.
        let chl = Scale { lo: 0.9689, hi: 31.37, log: true };
        assert_eq!(chl.nice_ticks(), vec![1.0, 3.0, 10.0, 30.0]);
        assert_eq!(Scale { lo: 2.0, hi: 9.0, log: true }.nice_ticks(), vec![2.0, 5.0]);
        assert_eq!(Scale { lo: 0.01, hi: 100.0, log: true }.nice_ticks(), vec![0.01, 0.1, 1.0, 10.0, 100.0]);
        assert_eq!(Scale { lo: 0.0, hi: 9.84, log: false }.nice_ticks(), vec![0.0, 2.0, 4.0, 6.0, 8.0]);
        assert_eq!(Scale { lo: -1.0, hi: 1.0, log: false }.nice_ticks(), vec![-1.0, -0.5, 0.0, 0.5, 1.0]);
        // Degenerate scales end, with their one value or none.
        assert_eq!(Scale { lo: 5.0, hi: 5.0, log: false }.nice_ticks(), vec![5.0]);
        assert!(Scale { lo: f64::NAN, hi: 1.0, log: false }.nice_ticks().is_empty());
    }

    #[test]
    fn the_dither_lights_a_tile_in_proportion() {
        let mut all: Vec<u8> = BAYER8.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(all, (0..64).collect::<Vec<u8>>(), "every threshold once");
        for f in [0.0, 0.22, 0.5, 0.9, 1.0] {
            let lit = (0..8).flat_map(|y| (0..8).map(move |x| (x, y))).filter(|&(x, y)| dithered(f, x, y)).count();
            assert_eq!(lit as f64, (64.0 * f).round(), "share {f}");
        }
    }
}
