//! A pixel's atmosphere as the image-based correction finds it: weighted entries of the aerosol
//! family's tables ([`super::family`]), and the exact inversion through them.

use super::family::BandTerms;

/// A pixel's atmosphere: up to six weighted table entries (two models, three AOT nodes each),
/// its AOT(550) and Ångström exponent.
#[derive(Default)]
pub(super) struct Mixture<'f> {
    /// (band terms, weight).
    pub entries: Vec<(&'f BandTerms, f64)>,
    /// AOT(550).
    pub aot550: f64,
    /// Ångström exponent 443–865 nm.
    pub angstrom: f64,
    /// The measured ε lay outside the family's range.
    pub outside: bool,
    /// Passes of the NIR iteration.
    pub passes: usize,
}

impl Mixture<'_> {
    /// (L_path, T·Ed, S) at index `i` (column·bands + band).
    #[inline]
    pub fn terms(&self, i: usize) -> (f64, f64, f64) {
        let (mut lp, mut te, mut s) = (0.0, 0.0, 0.0);
        for &(t, w) in &self.entries {
            lp += w * t.l_path[i];
            te += w * t.t_ed[i];
            s += w * t.spherical_albedo[i];
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
            let (tl, tt, ts) = (&t.l_path[span.clone()], &t.t_ed[span.clone()], &t.spherical_albedo[span.clone()]);
            for b in 0..lp.len() {
                lp[b] += w * tl[b];
                te[b] += w * tt[b];
                sa[b] += w * ts[b];
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
