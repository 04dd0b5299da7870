//! aLMI with the SIOP sets in SIMD lanes: the same arithmetic as [`super::almi::invert`], laid
//! out so the compiler vectorises it.
//!
//! The per-pixel work of aLMI is, for each SIOP set, two weighted normal-equation builds (ten
//! sums over the bands), two 3-unknown NNLS solves and a forward-model cost. The sums and the
//! cost are the same operations for every set with other coefficients: with the coefficients
//! stored band by band with the sets side by side (`[band][set]`, [`PackedSets`]), the inner
//! loops run over up to [`LANES`] sets at once. Only the NNLS solves stay per set.
//!
//! Every lane performs exactly the operations, in the same order, that the scalar
//! [`super::almi::invert`] performs for that set, so the two give bit-identical pixels (tested
//! below); the scalar one stays as the readable statement of the method.

use super::almi::{AlmiFlags, AlmiPixel, AlmiSet, AlmiSettings, MAX_BANDS, Prepared};
use super::nnls::{MIN_DET, column_scale, finite, nnls3};

/// Sets per chunk (one chunk of eight covers the built-in sets).
pub const LANES: usize = 8;

/// One chunk's coefficients at one band, a lane per set.
#[derive(Debug, Clone, Copy, Default)]
struct BandLanes {
    a_w: [f64; LANES],
    bb_w: [f64; LANES],
    a_ph: [f64; LANES],
    bb_ph: [f64; LANES],
    a_cdom: [f64; LANES],
    a_nap: [f64; LANES],
    bb_nap: [f64; LANES],
}

/// The SIOP sets' band IOPs, band by band with the sets side by side, in chunks of [`LANES`].
#[derive(Debug, Clone)]
pub struct PackedSets {
    /// `chunks[c][k]`: chunk `c` at band `k`.
    chunks: Vec<Vec<BandLanes>>,
    /// Sets in each chunk.
    lanes: Vec<usize>,
}

impl PackedSets {
    /// Pack `sets` (all with the same bands). Unused lanes of the last chunk hold zeros and are
    /// never read back.
    #[must_use]
    pub fn new(sets: &[AlmiSet]) -> Self {
        let n_bands = sets.first().map_or(0, |s| s.iops.a_w.len());
        let mut chunks = Vec::new();
        let mut lanes = Vec::new();
        for chunk in sets.chunks(LANES) {
            let mut bands = vec![BandLanes::default(); n_bands];
            for (s, set) in chunk.iter().enumerate() {
                let o = &set.iops;
                for (k, b) in bands.iter_mut().enumerate() {
                    b.a_w[s] = o.a_w[k];
                    b.bb_w[s] = o.bb_w[k];
                    b.a_ph[s] = o.a_ph[k];
                    b.bb_ph[s] = o.bb_ph[k];
                    b.a_cdom[s] = o.a_cdom[k];
                    b.a_nap[s] = o.a_nap[k];
                    b.bb_nap[s] = o.bb_nap[k];
                }
            }
            chunks.push(bands);
            lanes.push(chunk.len());
        }
        Self { chunks, lanes }
    }
}

/// Per-thread work space of [`invert_packed`]: the rows and weights of every band and the
/// pixel's per-band quantities (23 kB, so reused from pixel to pixel rather than zeroed for
/// each).
#[derive(Clone)]
pub struct Scratch {
    rows: Vec<Rows>,
    w2: Vec<[f64; LANES]>,
    pixel: Box<Prepared>,
}

impl Default for Scratch {
    fn default() -> Self {
        Self { rows: vec![Rows::default(); MAX_BANDS], w2: vec![[1.0; LANES]; MAX_BANDS], pixel: Box::default() }
    }
}

/// One set's NNLS answer: (x, unconstrained x), or `None` (see [`nnls3`]; its residual is not
/// needed here, so the lanes do not carry it).
type Solution = Option<([f64; 3], [f64; 3])>;

/// The weighted normal equations of every lane: G (six sums, symmetric), b and yᵀy.
#[derive(Clone, Copy)]
struct Normal {
    g: [[f64; LANES]; 6],
    b: [[f64; LANES]; 3],
    yy: [f64; LANES],
}

/// One value per lane.
type Lanes = [f64; LANES];

mod ops;

use ops::{cramer, det3_lanes, feasible, lanewise, mask, select};

/// Index of (i, j) among the six stored entries of a symmetric 3 × 3 matrix.
const AT: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];

/// The column-scaled normal equations of every lane, as [`nnls3`] scales them.
struct Scaled {
    /// The scaled Gram matrix's six entries (symmetric bit for bit: the scales are powers of two,
    /// so g_ij·s_i·s_j is exact in either order).
    gs: [Lanes; 6],
    bs: [Lanes; 3],
    yy: Lanes,
}

impl Scaled {
    #[inline(always)]
    fn at(&self, i: usize, j: usize) -> &Lanes {
        &self.gs[AT[i][j]]
    }

    /// The residual ‖A·x − y‖² in lane `s` of scaled x with its non-zeros in `support`, as
    /// `nnls3` writes it but without the terms of the zeros outside the support. In a lane that
    /// can win (x finite, G finite) each such term is ±0, and adding ±0 leaves r as it was (at
    /// most the sign of a zero r changes, and r only enters comparisons), so the kept terms,
    /// added in `nnls3`'s order, give its residual. A support of one or two columns then costs
    /// a third of the full support's 12 terms, or less.
    #[inline(always)]
    fn residual_lane(&self, x: &[f64; 3], support: &[usize], s: usize) -> f64 {
        let mut r = self.yy[s];
        for &i in support {
            r -= 2.0 * x[i] * self.bs[i][s];
            for &j in support {
                r += x[i] * self.at(i, j)[s] * x[j];
            }
        }
        r.max(0.0)
    }
}

/// The enumeration of supports, on the scaled normal equations of every lane.
impl Scaled {
    /// Enumerate the supports of one or two columns in the lanes of `quad`, in `nnls3`'s order
    /// (its masks 0 to 6: bit j, column j; the empty one is where each lane starts), and keep
    /// each lane's first feasible solution of smallest residual. One pass over the lanes runs
    /// all six supports, the lane's best so far held in registers and stored once: with a pass
    /// per support, the compiler turned each conditional update of the stored best into masked
    /// stores (`vmaskmovpd`), slow on AMD (perf put 14 % of aLMI's time on them and their
    /// masks). Each support is spelled out so that its indices are constants once inlined.
    #[inline(always)]
    fn enumerate(&self, quad: usize, x: &mut [Lanes; 3]) {
        for s in quad * QUAD..(quad + 1) * QUAD {
            // The empty support first (x = 0, the residual yᵀy), always feasible: a later
            // support is kept exactly when it is feasible and strictly better, as in `nnls3`.
            let mut best = ([0.0; 3], self.residual_lane(&[0.0; 3], &[], s));
            self.consider(&[0], s, &mut best);
            self.consider(&[1], s, &mut best);
            self.consider(&[0, 1], s, &mut best);
            self.consider(&[2], s, &mut best);
            self.consider(&[0, 2], s, &mut best);
            self.consider(&[1, 2], s, &mut best);
            for j in 0..3 {
                x[j][s] = best.0[j];
            }
        }
    }

    /// Solve lane `s` on `support` (one or two columns) as [`nnls3`] does, and take the solution
    /// into `best` (x, residual) where it is feasible and strictly better.
    #[inline(always)]
    fn consider(&self, support: &[usize], s: usize, best: &mut ([f64; 3], f64)) {
        let mut x = [0.0; 3];
        let ok = match *support {
            [j] => {
                x[j] = self.bs[j][s] / self.at(j, j)[s];
                true
            }
            [p, q, ..] => {
                let (gpp, gqq, gpq, gqp) = (self.at(p, p)[s], self.at(q, q)[s], self.at(p, q)[s], self.at(q, p)[s]);
                let det = gpp * gqq - gpq * gqp;
                let inv = 1.0 / det;
                x[p] = (self.bs[p][s] * gqq - gpq * self.bs[q][s]) * inv;
                x[q] = (gpp * self.bs[q][s] - gqp * self.bs[p][s]) * inv;
                det.abs() > MIN_DET * (gpp * gqq)
            }
            _ => unreachable!("the enumeration considers supports of one or two columns"),
        };
        let r = self.residual_lane(&x, support, s);
        let take = mask(ok & feasible(&x) & (r < best.1));
        best.1 = select(take, r, best.1);
        for (b, v) in best.0.iter_mut().zip(x) {
            *b = select(take, v, *b);
        }
    }
}

impl Normal {
    /// Every lane's NNLS, lane-wise: [`nnls3`]'s column scaling, Cramer solves, residuals and
    /// unscaling, the same operations in the same order, so the same bits. When the
    /// unconstrained solution is feasible it is the answer (most lanes); otherwise the seven
    /// other supports are enumerated as [`nnls3`] does — in its order, keeping the first
    /// smallest residual — for all lanes at once, which costs less than solving the few
    /// infeasible lanes one by one with branches. A lane with a zero or non-finite column, or
    /// non-finite data, is left to the scalar [`nnls3`] (it then drops that column from every
    /// support).
    #[inline(always)]
    fn solve_all(&self, lanes: usize) -> [Solution; LANES] {
        let norm2 = |j: usize| &self.g[AT[j][j]];
        let col = |j: usize| lanewise(|s| column_scale(norm2(j)[s]));
        let sc: [Lanes; 3] = [col(0), col(1), col(2)];
        let scale = |i: usize, j: usize| lanewise(|s| self.g[AT[i][j]][s] * sc[i][s] * sc[j][s]);
        let gs: [Lanes; 6] = [scale(0, 0), scale(0, 1), scale(0, 2), scale(1, 1), scale(1, 2), scale(2, 2)];
        let rhs = |j: usize| lanewise(|s| self.b[j][s] * sc[j][s]);
        let scaled = Scaled { gs, bs: [rhs(0), rhs(1), rhs(2)], yy: self.yy };
        let at = |i: usize, j: usize| scaled.at(i, j);
        // Lanes the lane-wise arithmetic holds for: every column present, the data finite.
        // (`&` rather than `&&` and `all`, here and below: no short circuits, so no branches per
        // lane, and the lanes are tested side by side.)
        let regular: [bool; LANES] = lanewise(|s| {
            (0..3)
                .fold(finite(self.yy[s]), |ok, j| ok & (norm2(j)[s] > 0.0) & finite(norm2(j)[s]) & finite(self.b[j][s]))
        });
        // The full support by Cramer's rule.
        let rows = [[at(0, 0), at(0, 1), at(0, 2)], [at(1, 0), at(1, 1), at(1, 2)], [at(2, 0), at(2, 1), at(2, 2)]];
        let det = det3_lanes(&rows);
        let inv_det = lanewise(|s| 1.0 / det[s]);
        let full: [Lanes; 3] = [
            cramer(&rows, &scaled.bs, &inv_det, 0),
            cramer(&rows, &scaled.bs, &inv_det, 1),
            cramer(&rows, &scaled.bs, &inv_det, 2),
        ];
        let solvable: [bool; LANES] = lanewise(|s| det[s].abs() > MIN_DET * (at(0, 0)[s] * at(1, 1)[s] * at(2, 2)[s]));
        let fast: [bool; LANES] =
            lanewise(|s| regular[s] && solvable[s] && feasible(&[full[0][s], full[1][s], full[2][s]]));
        let unscale =
            |x: &[Lanes; 3], s: usize| -> [f64; 3] { [x[0][s] * sc[0][s], x[1][s] * sc[1][s], x[2][s] * sc[2][s]] };
        // The other supports, in the quads (four lanes, one AVX2 vector) with a lane that needs
        // them.
        let mut best = [[0.0; LANES]; 3];
        for quad in 0..LANES / QUAD {
            let need =
                (quad * QUAD..((quad + 1) * QUAD).min(lanes)).fold(false, |any, s| any | (regular[s] & !fast[s]));
            if need {
                scaled.enumerate(quad, &mut best);
            }
        }
        let mut out: [Solution; LANES] = [None; LANES];
        for (s, slot) in out.iter_mut().enumerate().take(lanes) {
            // Which of the full and the enumerated solution a lane takes is data, unpredictable
            // lane to lane: chosen by bit masks rather than a branch (perf put 12 % of aLMI's
            // time on this loop; the selects gained 2–4 %). Irregular lanes are rare and take
            // the branch.
            *slot = if regular[s] {
                let (full, best) = (unscale(&full, s), unscale(&best, s));
                let fast = mask(fast[s]);
                // `nnls3` returns the unconstrained x only when it was solvable (zeros otherwise).
                let solvable = mask(solvable[s]);
                Some((
                    std::array::from_fn(|j| select(fast, full[j], best[j])),
                    std::array::from_fn(|j| select(solvable, full[j], 0.0)),
                ))
            } else {
                self.solve(s)
            };
        }
        out
    }

    fn solve(&self, s: usize) -> Solution {
        let g = |j: usize| self.g[j][s];
        nnls3(
            &[[g(0), g(1), g(2)], [g(1), g(3), g(4)], [g(2), g(4), g(5)]],
            &[self.b[0][s], self.b[1][s], self.b[2][s]],
            self.yy[s],
        )
        .map(|(x, _, unconstrained)| (x, unconstrained))
    }
}

/// The rows of one band in every lane: r (three columns) and y.
#[derive(Clone, Copy, Default)]
struct Rows {
    r: [[f64; LANES]; 3],
    y: [f64; LANES],
}

/// Lanes per accumulation pass of [`normal`]: ten sums of four lanes fit the sixteen AVX2
/// registers (all eight lanes at once would spill them to the stack at every band).
const QUAD: usize = 4;
const _: () = assert!(LANES.is_multiple_of(QUAD));

/// Accumulate the normal equations from `rows` with per-band, per-lane weights (`None`: 1).
/// Each lane's sums run over the bands in order, whatever the pass, so the bits are the scalar
/// code's.
#[inline(always)]
fn normal(rows: &[Rows], w2: Option<&[[f64; LANES]]>) -> Normal {
    let mut n = Normal { g: [[0.0; LANES]; 6], b: [[0.0; LANES]; 3], yy: [0.0; LANES] };
    for q in (0..LANES).step_by(QUAD) {
        let mut g = [[0.0; QUAD]; 6];
        let mut b = [[0.0; QUAD]; 3];
        let mut yy = [0.0; QUAD];
        for (i, row) in rows.iter().enumerate() {
            for l in 0..QUAD {
                let s = q + l;
                let w = match w2 {
                    Some(w) => w[i][s],
                    None => 1.0,
                };
                let (r0, r1, r2, y) = (row.r[0][s], row.r[1][s], row.r[2][s], row.y[s]);
                let (wr0, wr1, wr2, wy) = (w * r0, w * r1, w * r2, w * y);
                g[0][l] += wr0 * r0;
                g[1][l] += wr0 * r1;
                g[2][l] += wr0 * r2;
                g[3][l] += wr1 * r1;
                g[4][l] += wr1 * r2;
                g[5][l] += wr2 * r2;
                b[0][l] += wr0 * y;
                b[1][l] += wr1 * y;
                b[2][l] += wr2 * y;
                yy[l] += wy * y;
            }
        }
        for l in 0..QUAD {
            for j in 0..6 {
                n.g[j][q + l] = g[j][l];
            }
            for j in 0..3 {
                n.b[j][q + l] = b[j][l];
            }
            n.yy[q + l] = yy[l];
        }
    }
    n
}

/// a and bb of every lane at band `c` for concentrations `x` (lane-wise).
#[inline(always)]
fn kappa(c: &BandLanes, x: &[[f64; LANES]; 3], s: usize) -> (f64, f64) {
    let a = c.a_w[s] + x[0][s] * c.a_ph[s] + x[1][s] * c.a_cdom[s] + x[2][s] * c.a_nap[s];
    let bb = c.bb_w[s] + x[0][s] * c.bb_ph[s] + x[2][s] * c.bb_nap[s];
    (a, bb)
}

/// [`super::almi::invert`] over packed sets: the same inputs, the same pixel, bit for bit.
/// On a CPU with AVX2 the lanes run four sets per instruction (two otherwise); not AVX-512,
/// which measured 0–3 % slower on AMD Zen 4 and 25 % slower on Zen 5 (see [`crate::simd`]).
/// What was tried on Zen 5 before keeping AVX2: at AVX-512 the lane-by-lane selects of
/// `Scaled::enumerate` compile to k-masked scalar moves (`vmovsd {k}`, the hottest
/// instructions in perf); written support by support over a quad's lanes, that build recovered
/// to about 5 % behind AVX2, and AVX2 itself moved within the noise; accumulating the sums of
/// all eight lanes at once (one zmm per sum) left AVX-512 about 35 % behind AVX2.
#[must_use]
pub fn invert_packed(
    scratch: &mut Scratch,
    sets: &PackedSets,
    settings: &AlmiSettings,
    rrs_above: &[f64],
    valid: &[bool],
    nedr: &[f64],
) -> AlmiPixel {
    crate::simd::avx2(Invert { scratch, sets, settings, rrs_above, valid, nedr })
}

/// [`invert_lanes`]'s arguments, to run it through [`crate::simd::avx2`].
struct Invert<'a> {
    scratch: &'a mut Scratch,
    sets: &'a PackedSets,
    settings: &'a AlmiSettings,
    rrs_above: &'a [f64],
    valid: &'a [bool],
    nedr: &'a [f64],
}

impl crate::simd::Kernel for Invert<'_> {
    type Output = AlmiPixel;

    #[inline(always)]
    fn run<L: crate::simd::Level>(self) -> AlmiPixel {
        invert_lanes(self.scratch, self.sets, self.settings, self.rrs_above, self.valid, self.nedr)
    }
}

#[inline(always)]
fn invert_lanes(
    scratch: &mut Scratch,
    sets: &PackedSets,
    settings: &AlmiSettings,
    rrs_above: &[f64],
    valid: &[bool],
    nedr: &[f64],
) -> AlmiPixel {
    let (g0, g1) = (settings.g0, settings.g1);
    let Scratch { rows, w2, pixel } = scratch;
    if !pixel.prepare(settings, rrs_above, valid, nedr) {
        return AlmiPixel::FAILED;
    }
    let Prepared { ref used, m, ref rrs, ref u, ref sigma_u, ref inv_sigma_rrs, mean_rrs, .. } = **pixel;
    let used = &used[..m];
    let mut best = AlmiPixel::FAILED;
    for (chunk, (bands, &lanes)) in sets.chunks.iter().zip(&sets.lanes).enumerate() {
        for (i, &k) in used.iter().enumerate() {
            let c = &bands[k];
            let (uu, v) = (u[i], 1.0 - u[i]);
            // Built in a local and stored whole: stores into the scratch (heap) might alias the
            // coefficients (heap too) as far as the compiler knows, which kept it from computing
            // the lanes side by side.
            let mut row = Rows::default();
            for s in 0..LANES {
                row.r[0][s] = c.a_ph[s] * uu - c.bb_ph[s] * v;
                row.r[1][s] = c.a_cdom[s] * uu;
                row.r[2][s] = c.a_nap[s] * uu - c.bb_nap[s] * v;
                row.y[s] = c.bb_w[s] * v - c.a_w[s] * uu;
            }
            rows[i] = row;
        }
        let first = normal(&rows[..m], None);
        let mut sol = first.solve_all(lanes);
        let x_of = |sol: &[Solution; LANES]| -> [[f64; LANES]; 3] {
            let mut x = [[0.0; LANES]; 3];
            for (s, p) in sol.iter().enumerate() {
                if let Some((xs, _)) = p {
                    for j in 0..3 {
                        x[j][s] = xs[j];
                    }
                }
            }
            x
        };
        if settings.noise_weighting {
            // One reweighting pass, as in the scalar code: weights from each lane's own solution.
            let x = x_of(&sol);
            for (i, &k) in used.iter().enumerate() {
                let c = &bands[k];
                // A local, stored whole, as for the rows above (the divisions then run four lanes
                // per instruction; they were scalar: 10 % of aLMI's time in perf).
                let mut w = [0.0; LANES];
                for (s, w) in w.iter_mut().enumerate() {
                    let (a, bb) = kappa(c, &x, s);
                    let w1 = 1.0 / ((a + bb) * sigma_u[i]).max(1e-300);
                    *w = w1 * w1;
                }
                w2[i] = w;
            }
            let second = normal(&rows[..m], Some(&w2[..m])).solve_all(lanes);
            for (slot, next) in sol.iter_mut().zip(second).take(lanes) {
                if slot.is_some()
                    && let Some(next) = next
                {
                    *slot = Some(next);
                }
            }
        }
        // Cost in rrs space, every lane at once.
        let x = x_of(&sol);
        let mut sq = [0.0; LANES];
        let weighting = settings.noise_weighting;
        for (i, &k) in used.iter().enumerate() {
            let c = &bands[k];
            let (target, inv_sigma) = (rrs[i], inv_sigma_rrs[i]);
            for s in 0..LANES {
                let (a, bb) = kappa(c, &x, s);
                let up = bb / (a + bb);
                let d = (g0 + g1 * up) * up - target;
                sq[s] += if weighting { (d * inv_sigma).powi(2) } else { d * d };
            }
        }
        // Every lane's cost at once: the square roots and divisions run side by side (inside the
        // loop below, after its `continue`, they ran lane by lane).
        let costs: Lanes = lanewise(|s| {
            let rms = (sq[s] / m as f64).sqrt();
            if weighting { rms } else { rms / mean_rrs }
        });
        for (s, p) in sol.iter().enumerate().take(lanes) {
            let Some((xs, unconstrained)) = p else { continue };
            let cost = costs[s];
            if cost.is_finite() && cost < best.cost {
                let physical = unconstrained.iter().all(|v| *v >= 0.0);
                let at_bound = xs.contains(&0.0);
                best = AlmiPixel {
                    chl: xs[0],
                    cdom: xs[1],
                    nap: xs[2],
                    set: u8::try_from(chunk * LANES + s).ok(),
                    cost,
                    flags: if physical { AlmiFlags::PHYSICAL } else { 0 }
                        | if at_bound { AlmiFlags::AT_BOUND } else { 0 },
                };
            }
        }
    }
    best
}

#[cfg(test)]
mod tests;
