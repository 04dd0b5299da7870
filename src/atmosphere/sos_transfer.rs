//! The formal solution of the transfer equation through the layers of a plane-parallel column,
//! for one order of scattering in [`super::sos`]: given the source J of an order at the level
//! boundaries, the radiance of that order at every level and direction.
//!
//! With J linear in τ between levels, I(τ_b) = I(τ_a)e^{−x} + J_a·c_a(x) + J_b·c_b(x),
//! x = Δτ/|μ|, c_a = (1 − e^{−x}(1 + x))/x, c_b = 1 − e^{−x} − c_a. The first-order (solar)
//! source a(τ)·e^{−τ/μ₀} is integrated exactly for its exponential factor, with a(τ) linear
//! between levels, through φ(x) = (eˣ − 1)/x and ψ(x) = (eˣ(x − 1) + 1)/x².
//!
//! ## References
//! - Lenoble, J. et al. (2007) J. Quant. Spectrosc. Radiat. Transfer 107, 479–507 (SOS).
//! - Chami, M. et al. (2015) OSOAA. Opt. Express 23, 27829 (linear source between levels).

use super::profile::Layering;

pub(super) type Block<const S: usize> = [[f64; S]; S];

#[inline]
pub(super) fn mat_vec<const S: usize>(m: &Block<S>, v: &[f64; S]) -> [f64; S] {
    let mut out = [0.0; S];
    for (o, row) in out.iter_mut().zip(m) {
        *o = row.iter().zip(v).map(|(a, b)| a * b).sum();
    }
    out
}

/// Transfer coefficients (e, c_far, c_near) of a layer of thickness `dtau` along cosine `mu`.
#[inline]
pub(super) fn transfer_coefficients(dtau: f64, mu: f64) -> (f64, f64, f64) {
    let x = dtau / mu;
    let e = (-x).exp();
    let c_far =
        if x < 1e-3 { x * (0.5 - x * (1.0 / 3.0 - x * (1.0 / 8.0 - x / 30.0))) } else { (1.0 - e * (1.0 + x)) / x };
    (e, c_far, (1.0 - e) - c_far)
}

/// φ(x) = (eˣ − 1)/x and ψ(x) = ∫₀¹ t eˣᵗ dt = (eˣ(x − 1) + 1)/x², with series near 0.
#[inline]
pub(super) fn phi_psi(x: f64) -> (f64, f64) {
    if x.abs() < 1e-3 {
        (1.0 + x * (0.5 + x * (1.0 / 6.0 + x / 24.0)), 0.5 + x * (1.0 / 3.0 + x * (0.125 + x / 30.0)))
    } else {
        let e = x.exp();
        ((e - 1.0) / x, (e * (x - 1.0) + 1.0) / (x * x))
    }
}

/// Per-layer transfer coefficients for a list of cosines.
pub(super) struct Transfer {
    /// [layer k (1..=K) − 1][stream] → (e, c_far, c_near)
    pub(super) coef: Vec<Vec<(f64, f64, f64)>>,
}

impl Transfer {
    pub(super) fn new(layering: &Layering, mus: &[f64]) -> Self {
        let coef = layering
            .tau
            .windows(2)
            .map(|w| mus.iter().map(|&mu| transfer_coefficients(w[1] - w[0], mu)).collect())
            .collect();
        Self { coef }
    }
}

pub(super) type Field<const S: usize> = Vec<Vec<[f64; S]>>;

/// Formal solution for one order with sources linear in τ: given `j[k][d]` on the 2m directions
/// of one set of streams (down 0..m, up m..2m), fill radiance `out[k][d]`; `surface[d]` reflects
/// downward into upward radiance at the bottom.
pub(super) fn transfer<const S: usize>(
    t: &Transfer,
    surface: &[Block<S>],
    j: &[Vec<[f64; S]>],
    out: &mut [Vec<[f64; S]>],
) {
    let k_max = j.len() - 1;
    let m = surface.len();
    for d in 0..m {
        out[0][d] = [0.0; S];
    }
    for k in 1..=k_max {
        for d in 0..m {
            let (e, c_far, c_near) = t.coef[k - 1][d];
            let mut v = [0.0; S];
            for s in 0..S {
                v[s] = out[k - 1][d][s] * e + j[k - 1][d][s] * c_far + j[k][d][s] * c_near;
            }
            out[k][d] = v;
        }
    }
    for d in 0..m {
        out[k_max][m + d] = mat_vec(&surface[d], &out[k_max][d]);
    }
    for k in (0..k_max).rev() {
        for d in 0..m {
            let (e, c_far, c_near) = t.coef[k][d];
            let mut v = [0.0; S];
            for s in 0..S {
                v[s] = out[k + 1][m + d][s] * e + j[k + 1][m + d][s] * c_far + j[k][m + d][s] * c_near;
            }
            out[k][m + d] = v;
        }
    }
}

/// First-order radiance from the solar source J(τ) = a(τ)e^{−τ/μ₀} + b(τ)e^{−(2τ*−τ)/μ₀}
/// (direct beam, and the beam reflected at the surface), with the amplitudes a, b linear in τ
/// between levels and the exponentials integrated exactly. `a[k][d]`, `b[k][d]` on the 2m
/// directions of `mus` (down 0..m, up m..2m).
#[allow(clippy::too_many_arguments)]
pub(super) fn transfer_solar<const S: usize>(
    layering: &Layering,
    mus: &[f64],
    mu0: f64,
    surface: &[Block<S>],
    a: &[Vec<[f64; S]>],
    b: &[Vec<[f64; S]>],
    out: &mut [Vec<[f64; S]>],
) {
    let tau = &layering.tau;
    let k_max = tau.len() - 1;
    let total = tau[k_max];
    let m = mus.len();
    // Layer integral ∫ (α + βs) e^{−c(τ_top + s)} w(s) ds/μ over s ∈ [0, Δ] for the two source
    // terms (c = 1/μ₀ with amplitude a; c = −1/μ₀ with amplitude b·e^{−2τ*/μ₀}), w the path
    // attenuation to the end of the layer.
    let layer = |k_top: usize, d: usize, mu: f64, down: bool, s: usize| -> f64 {
        let (t0, t1) = (tau[k_top], tau[k_top + 1]);
        let delta = t1 - t0;
        let mut sum = 0.0;
        for (amp, c, scale) in [(a, 1.0 / mu0, 1.0), (b, -1.0 / mu0, (-2.0 * total / mu0).exp())] {
            let alpha = amp[k_top][d][s];
            let beta = amp[k_top + 1][d][s] - alpha;
            if alpha == 0.0 && beta == 0.0 {
                continue;
            }
            let (x, attenuation) = if down {
                // Down: w(s) = e^{−(Δ−s)/μ}; ∫ (α+β s/Δ) e^{(1/μ − c)s} ds · e^{−Δ/μ}
                ((1.0 / mu - c) * delta, (-delta / mu).exp())
            } else {
                // Up (towards τ_top): w(s) = e^{−s/μ}; ∫ (α+β s/Δ) e^{−(c + 1/μ)s} ds
                (-(c + 1.0 / mu) * delta, 1.0)
            };
            let (f0, f1) = phi_psi(x);
            sum += scale * (-c * t0).exp() * attenuation * delta / mu * (alpha * f0 + beta * f1);
        }
        sum
    };
    for d in 0..m {
        out[0][d] = [0.0; S];
    }
    for k in 1..=k_max {
        for d in 0..m {
            let e = (-(tau[k] - tau[k - 1]) / mus[d]).exp();
            for s in 0..S {
                out[k][d][s] = out[k - 1][d][s] * e + layer(k - 1, d, mus[d], true, s);
            }
        }
    }
    for d in 0..m {
        out[k_max][m + d] = mat_vec(&surface[d], &out[k_max][d]);
    }
    for k in (0..k_max).rev() {
        for d in 0..m {
            let e = (-(tau[k + 1] - tau[k]) / mus[d]).exp();
            for s in 0..S {
                out[k][m + d][s] = out[k + 1][m + d][s] * e + layer(k, m + d, mus[d], false, s);
            }
        }
    }
}
