//! The per-node kernel of [`super::BandModel::evaluate_with`] (the equations in the parent
//! module's docs).

use super::{BandModel, ModelScratch, Parameters};
use crate::simd::{Level, mad};
use crate::water::exp_at;

/// The per-node work of [`BandModel::evaluate_with`], as a [`crate::simd::Kernel`] run by
/// [`crate::simd::throughput`] (four nodes per instruction with AVX2, eight with AVX-512 where
/// its units are full width; on AMD Zen 4 AVX-512 measured slower at the 12 to 84 nodes of a
/// retrieval's bands): Rrs at each node and, with the Jacobian, each node's weighted
/// terms of the band gradients. Its multiply-adds, the exponentials' included, are fused where
/// the level has FMA ([`crate::simd::mad`]): AVX2 and AVX-512 give the same bits, the baseline
/// agrees to rounding (`retrieval::levels_test`). Written unfused at every level, the fit ran
/// 12–17 % slower (28 bands, Zen 5).
pub(super) struct Nodes<'a> {
    pub model: &'a BandModel,
    pub p: &'a Parameters,
    pub inv_cos: (f64, f64),
    pub h: f64,
    pub shallow: f64,
    pub with_jacobian: bool,
    pub n: usize,
    pub s: &'a mut ModelScratch,
}

impl crate::simd::Kernel for Nodes<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: crate::simd::Level>(self) {
        // Two loops, so that the one without the Jacobian carries none of its work.
        if self.with_jacobian { self.nodes::<L, true>() } else { self.nodes::<L, false>() }
    }
}

impl Nodes<'_> {
    #[inline(always)]
    fn nodes<L: Level, const JACOBIAN: bool>(self) {
        let mad = mad::<L, f64>;
        let Nodes { model, p, inv_cos, h, shallow, n, s, .. } = self;
        let (mu_w, mu_o) = inv_cos;
        let inv_pi = 1.0 / std::f64::consts::PI;
        let (chl, cdom, nap) = (p.chl, p.cdom, p.nap);
        let (a_w, bb_w, a_ph, a_cdom, a_nap, bb_ph, bb_nap) = (
            &model.a_w[..n],
            &model.bb_w[..n],
            &model.a_ph[..n],
            &model.a_cdom[..n],
            &model.a_nap[..n],
            &model.bb_ph[..n],
            &model.bb_nap[..n],
        );
        let (rb, drb, above) = (&s.rb[..n], &s.drb[..n], &mut s.above[..n]);
        let [g0, g1, g2, g3, g4] = &mut s.grad;
        let (g0, g1, g2, g3, g4) = (&mut g0[..n], &mut g1[..n], &mut g2[..n], &mut g3[..n], &mut g4[..n]);
        let weight = &model.weight[..n];
        for i in 0..n {
            let a = mad(nap, a_nap[i], mad(cdom, a_cdom[i], mad(chl, a_ph[i], a_w[i])));
            let bb = mad(nap, bb_nap[i], mad(chl, bb_ph[i], bb_w[i]));
            let kappa = a + bb;
            let u = bb / kappa;
            let rrs_dp = mad(0.17, u, 0.084) * u;
            let (sc, sb) = (mad(2.4, u, 1.0).sqrt(), mad(5.4, u, 1.0).sqrt());
            let (kc, kb) = (mad(1.03 * sc, mu_o, mu_w), mad(1.04 * sb, mu_o, mu_w));
            // Optically deep: the exponentials are replaced by (e_c, e_b) = (0, 0).
            let ec = shallow * exp_at::<L>(-kc * kappa * h);
            let eb = shallow * exp_at::<L>(-kb * kappa * h);
            let rb_pi = rb[i] * inv_pi;
            let rrs = mad(rb_pi, eb, rrs_dp * (1.0 - ec));
            let denom = mad(-1.7, rrs, 1.0);
            above[i] = 0.52 * rrs / denom;
            if !JACOBIAN {
                continue;
            }
            let d_rrs_dp = mad(0.34, u, 0.084);
            let d_above = 0.52 / (denom * denom);
            let (d_dc, d_db) = (1.236 / sc, 2.808 / sb);
            let d_ec_du = -ec * d_dc * mu_o * kappa * h;
            let d_eb_du = -eb * d_db * mu_o * kappa * h;
            let d_u = d_above * mad(rb_pi, d_eb_du, mad(d_rrs_dp, 1.0 - ec, -(rrs_dp * d_ec_du)));
            let d_k = d_above * mad(rrs_dp * ec, kc * h, -(rb_pi * eb * kb * h));
            let d_h = d_above * mad(rrs_dp * ec, kc * kappa, -(rb_pi * eb * kb * kappa));
            let d_q = d_above * drb[i] * inv_pi * eb;
            // Each node's terms of the band gradients: ∂u/∂C = (a·∂bb − bb·∂a)/κ² and
            // ∂κ/∂C = ∂a + ∂bb, for chl, CDOM (no bb) and NAP; then depth and fraction.
            let w = weight[i];
            let inv_k2 = 1.0 / (kappa * kappa);
            let du = [
                mad(a, bb_ph[i], -(bb * a_ph[i])) * inv_k2,
                -bb * a_cdom[i] * inv_k2,
                mad(a, bb_nap[i], -(bb * a_nap[i])) * inv_k2,
            ];
            let dk = [a_ph[i] + bb_ph[i], a_cdom[i], a_nap[i] + bb_nap[i]];
            g0[i] = w * mad(d_u, du[0], d_k * dk[0]);
            g1[i] = w * mad(d_u, du[1], d_k * dk[1]);
            g2[i] = w * mad(d_u, du[2], d_k * dk[2]);
            g3[i] = w * d_h * shallow;
            g4[i] = w * d_q;
        }
    }
}
