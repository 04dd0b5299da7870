//! A pixel's atmosphere as the image-based correction finds it: weighted entries of the aerosol
//! family's tables ([`super::family`]), and the exact inversion through them.

use super::family::AerosolFamily;

/// One family member's band terms with the three a pixel's inversion reads side by side:
/// `[L_path, T·Ed, S]` at index column·bands + band.
pub(super) type Packed = [[f64; 3]];

/// The family's members as [`Packed`] tables, `terms[m][k]` as in [`AerosolFamily::terms`].
///
/// A pixel's mixture reads up to six members at a few bands each. Held as the family holds them
/// (three arrays per member), those reads went to eighteen places in memory per band, too many
/// streams for the CPU's prefetcher: perf put a third of the band-pair fit's time on them. Side
/// by side, one member's terms at a column are one contiguous block.
pub(super) struct PackedFamily {
    /// `terms[m][k]`: model m at AOT node k.
    pub terms: Vec<Vec<Vec<[f64; 3]>>>,
}

impl PackedFamily {
    /// The family's terms side by side (the same values: the inversion's bits do not change).
    pub fn new(family: &AerosolFamily) -> Self {
        let pack = |t: &super::family::BandTerms| -> Vec<[f64; 3]> {
            t.l_path.iter().zip(&t.t_ed).zip(&t.spherical_albedo).map(|((l, e), s)| [*l, *e, *s]).collect()
        };
        Self { terms: family.terms.iter().map(|row| row.iter().map(pack).collect()).collect() }
    }
}

/// A pixel's atmosphere: up to six weighted table entries (two models, three AOT nodes each),
/// its AOT(550) and Ångström exponent.
#[derive(Default)]
pub(super) struct Mixture<'f> {
    /// (a member's packed terms, weight).
    pub entries: Vec<(&'f Packed, f64)>,
    /// AOT(550).
    pub aot550: f64,
    /// Ångström exponent 443–865 nm.
    pub angstrom: f64,
    /// The measured ε lay outside the family's range.
    pub outside: bool,
    /// Passes of the NIR iteration.
    pub passes: usize,
    /// The measured ε at the pair (the band-pair fit; NaN otherwise or where not measured).
    pub epsilon: f64,
    /// The measured aerosol signal at the pair's long band, W m⁻² sr⁻¹ nm⁻¹ (with `epsilon`).
    pub long_signal: f64,
}

impl Mixture<'_> {
    /// (L_path, T·Ed, S) at index `i` (column·bands + band).
    #[inline]
    pub fn terms(&self, i: usize) -> (f64, f64, f64) {
        let (mut lp, mut te, mut s) = (0.0, 0.0, 0.0);
        for &(t, w) in &self.entries {
            let [l, e, a] = t[i];
            lp += w * l;
            te += w * e;
            s += w * a;
        }
        (lp, te, s)
    }

    /// The terms of every band of a column at once (`span`: its indices), into `lp`, `te` and
    /// `sa` (contiguous per column, so the loop vectorises).
    #[inline]
    pub fn column_terms(&self, span: std::ops::Range<usize>, lp: &mut [f64], te: &mut [f64], sa: &mut [f64]) {
        lp.fill(0.0);
        te.fill(0.0);
        sa.fill(0.0);
        for &(t, w) in &self.entries {
            for (b, [l, e, a]) in t[span.clone()].iter().enumerate().take(lp.len()) {
                lp[b] += w * l;
                te[b] += w * e;
                sa[b] += w * a;
            }
        }
    }

    /// Rrs from radiance `l1` at index `i`.
    #[inline]
    pub fn rrs(&self, i: usize, l1: f64) -> f64 {
        let (lp, te, s) = self.terms(i);
        invert(l1, lp, te, s)
    }

    /// The water's part of the TOA radiance at index `i` for above-surface `rrs`: the inverse
    /// of [`Self::rrs`], (T·Ed)·Rrs/(1 − S·π·Rrs).
    #[inline]
    pub fn water_radiance(&self, i: usize, rrs: f64) -> f64 {
        let (_, te, s) = self.terms(i);
        te * rrs / (1.0 - s * std::f64::consts::PI * rrs)
    }
}

/// The exact inversion with a band's terms: y = (L1 − L_path)/(T·Ed), Rrs = y/(1 + S·π·y).
#[inline]
pub(super) fn invert(l1: f64, l_path: f64, t_ed: f64, spherical_albedo: f64) -> f64 {
    let y = (l1 - l_path) / t_ed;
    y / (1.0 + spherical_albedo * std::f64::consts::PI * y)
}
