//! The band-pair fit of the image-based correction, pixel by pixel (Gordon & Wang 1994; the
//! steps are in [`super::image`]'s module docs), with the NIR water-leaving iteration of
//! Bailey et al. (2010) around it ([`super::nir_water`]).

use super::CorrectionError;
use super::family::AerosolFamily;
use super::image::{ImageCorrection, Mixture, PackedFamily, Pixel, locate, weighted};
use super::nir_water::{self, NirWater};
use crate::spectral::BandSet;

/// Relative margin beyond the family's ε range before a pixel counts as outside it.
const EDGE: f64 = 0.005;

/// The fit's fixed inputs.
pub(super) struct PairFit<'f> {
    family: &'f AerosolFamily,
    /// The family's terms side by side, for the pixels' mixtures.
    packed: &'f PackedFamily,
    /// Short and long band of the pair.
    pair: (usize, usize),
    /// The NIR water model, when the iteration is on.
    nir: Option<NirWater>,
    /// Every member's aerosol signal at the pair's bands, column by column.
    signals: Signals,
}

/// The aerosol signal L_path(m, τ_k) − L_path(τ = 0) of every model m and AOT node k at the
/// pair's bands, held column by column: what step 1 and 2 of the fit read for a pixel, in one
/// block of memory (read from the family's tables, eighteen members' values at two bands lay in
/// as many places, and those reads took a third of the fit's time).
struct Signals {
    models: usize,
    nodes: usize,
    /// `[(c·models + m)·nodes + k]`: the long band's signal.
    long: Vec<f64>,
    /// The same at the short band.
    short: Vec<f64>,
    /// Per column: the Rayleigh path radiance (τ = 0) at the short and the long band.
    rayleigh: Vec<[f64; 2]>,
}

impl Signals {
    fn new(family: &AerosolFamily, (s, l): (usize, usize)) -> Self {
        let (models, nodes, nb) = (family.models.len(), family.aot550.len(), family.n_bands.max(1));
        let rayleigh_terms = &family.terms[0][0];
        let cols = rayleigh_terms.l_path.len() / nb;
        let (mut long, mut short) =
            (Vec::with_capacity(cols * models * nodes), Vec::with_capacity(cols * models * nodes));
        for c in 0..cols {
            let (il, is) = (c * nb + l, c * nb + s);
            for row in &family.terms {
                for t in row {
                    long.push(t.l_path[il] - rayleigh_terms.l_path[il]);
                    short.push(t.l_path[is] - rayleigh_terms.l_path[is]);
                }
            }
        }
        let rayleigh =
            (0..cols).map(|c| [rayleigh_terms.l_path[c * nb + s], rayleigh_terms.l_path[c * nb + l]]).collect();
        Self { models, nodes, long, short, rayleigh }
    }

    /// Model m's long- and short-band signals over the nodes at column `c`.
    fn of(&self, c: usize, m: usize) -> (&[f64], &[f64]) {
        let at = (c * self.models + m) * self.nodes;
        (&self.long[at..at + self.nodes], &self.short[at..at + self.nodes])
    }
}

/// Per-row working space.
#[derive(Default)]
pub(super) struct Scratch {
    located: Vec<[(usize, f64); 3]>,
    eps: Vec<f64>,
    order: Vec<usize>,
    /// The water's radiance at the pair's bands where the previous pixel of the row converged.
    warm: Option<[f64; 2]>,
}

impl<'f> PairFit<'f> {
    /// The fit for an instrument's bands.
    pub fn new(
        family: &'f AerosolFamily,
        packed: &'f PackedFamily,
        settings: &ImageCorrection,
        bands: &BandSet,
    ) -> Result<Self, CorrectionError> {
        let pair = settings.pair(&bands.centres_nm())?;
        let nir = if settings.nir_iteration { Some(NirWater::new(bands)?) } else { None };
        let signals = Signals::new(family, pair);
        Ok(Self { family, packed, pair, nir, signals })
    }

    /// Every member's ε at column `c` for a pixel whose aerosol signal at the long band is
    /// `long_signal`, as [`Self::fit`] places a pixel's measured ε among them: each model at the
    /// AOT that gives that signal. NaN where the signal is not positive.
    pub fn member_epsilon(&self, c: usize, long_signal: f64) -> Vec<f64> {
        let c = c.min(self.signals.rayleigh.len().saturating_sub(1));
        (0..self.signals.models)
            .map(|m| {
                let (long, short) = self.signals.of(c, m);
                if long_signal > 0.0 {
                    weighted(&locate(long, long_signal), |k| short[k]) / long_signal
                } else {
                    f64::NAN
                }
            })
            .collect()
    }

    /// Fill `mix` with the pixel's atmosphere; false where the pair's bands are flagged.
    ///
    /// Each pass follows l2gen's `atmocor2.c`: the NIR water radiance the model gives is damped
    /// against the previous pass's, and the ramp then scales the damped value, so that where
    /// OC4 gives 0.7 mg m⁻³ or less the water is black whatever the previous pass held. A pass
    /// whose OC4 fails (a blue or green Rrs not positive: the black-pixel fit over-corrected a
    /// turbid pixel) is taken for turbid water, as l2gen reseeds it: chl 10 mg m⁻³ and the red
    /// band's whole Rayleigh-corrected radiance the water's; a second failure reseeds once more
    /// and ends the passes.
    pub fn fit(&self, p: &Pixel<'_>, mix: &mut Mixture<'f>, scratch: &mut Scratch) -> bool {
        let (s, l) = self.pair;
        let usable = !p.land && p.flags[l] == 0 && p.flags[s] == 0;
        // The water's part of the TOA radiance at the pair's bands, from the previous pass; the
        // first pass starts where the row's previous water pixel ended (l2gen starts every pixel
        // black: the iteration contracts to the same fixed point, reached in fewer passes).
        let mut water = if usable && self.nir.is_some() { scratch.warm.unwrap_or([0.0; 2]) } else { [0.0; 2] };
        let mut previous_red = f64::INFINITY;
        let mut reseeds = 0;
        for pass in 1..=nir_water::MAX_PASSES + 1 {
            self.select(p, water, mix, scratch);
            mix.passes = pass;
            let Some(nir) = self.nir.as_ref().filter(|_| usable) else { break };
            let rrs = |b: usize| mix.rrs(p.at(b), f64::from(p.l1[b]));
            let red = rrs(nir.red);
            if red < 0.0 && pass == 1 && water != [0.0; 2] {
                // The previous pixel's water leaves this one's red band negative: start again
                // black, where l2gen starts every pixel.
                water = [0.0; 2];
                continue;
            }
            if red < 0.0
                || (red - previous_red).abs() < nir_water::CONVERGED * red.abs()
                || pass > nir_water::MAX_PASSES
                || reseeds > 1
            {
                scratch.warm = Some(water);
                break;
            }
            previous_red = red;
            let (chl, red_as_water) = match nir.chl_oc4(rrs) {
                Some(chl) => (chl, None),
                None if pass < nir_water::MAX_PASSES => {
                    reseeds += 1;
                    // The red band with the Rayleigh atmosphere alone: all its aerosol signal
                    // counted as the water's.
                    let [l_path, t_ed, albedo] = self.packed.terms[0][0][p.at(nir.red)];
                    let all = super::mixture::invert(f64::from(p.l1[nir.red]), l_path, t_ed, albedo);
                    (nir_water::TURBID_SEED_CHL, Some(all))
                }
                None => (0.0, None),
            };
            let ramp = NirWater::ramp(chl);
            let model_rrs = |b: usize| if b == nir.red { red_as_water.unwrap_or(red) } else { rrs(b) };
            let estimate = if ramp > 0.0 { nir.estimate(model_rrs, chl, [s, l]).unwrap_or([0.0; 2]) } else { [0.0; 2] };
            for (j, b) in [s, l].into_iter().enumerate() {
                let new = mix.water_radiance(p.at(b), estimate[j]);
                water[j] = ramp * ((1.0 - nir_water::DAMPING) * new + nir_water::DAMPING * water[j]);
            }
        }
        usable
    }

    /// Two-band model selection with the water's radiance `water` taken from the pair's bands.
    fn select(&self, p: &Pixel<'_>, water: [f64; 2], mix: &mut Mixture<'f>, scratch: &mut Scratch) {
        let family = self.family;
        let (s_band, l_band) = self.pair;
        let nm = family.models.len();
        let Scratch { located, eps, order, .. } = scratch;
        located.resize(nm, [(0, 1.0), (0, 0.0), (0, 0.0)]);
        eps.resize(nm, 0.0);
        let [rayleigh_s, rayleigh_l] = self.signals.rayleigh[p.col];
        let a_l = f64::from(p.l1[l_band]) - rayleigh_l - water[1];
        let a_s = f64::from(p.l1[s_band]) - rayleigh_s - water[0];
        // Each model's τ and ε for this pixel.
        for m in 0..nm {
            let (a_long, a_short) = self.signals.of(p.col, m);
            located[m] = locate(a_long, a_l);
            let short = weighted(&located[m], |k| a_short[k]);
            eps[m] = if a_l > 0.0 { short / a_l } else { 0.0 };
        }
        let measured = if a_l > 0.0 { a_s / a_l } else { 0.0 };
        (mix.epsilon, mix.long_signal) = if a_l > 0.0 { (measured, a_l) } else { (f64::NAN, f64::NAN) };
        // The bracketing pair (by ε), or the nearest model outside the family's range.
        order.clear();
        order.extend(0..nm);
        // Stable insertion sort, as `sort_by` orders them: a family has a handful of members,
        // and per pass of every pixel the library sort's set-up cost more than the sorting.
        for i in 1..nm {
            let mut j = i;
            while j > 0 && eps[order[j - 1]].total_cmp(&eps[order[j]]).is_gt() {
                order.swap(j - 1, j);
                j -= 1;
            }
        }
        let (m1, m2, w, out) = match order.windows(2).find(|q| eps[q[0]] <= measured && measured <= eps[q[1]]) {
            Some(q) => {
                let d = eps[q[1]] - eps[q[0]];
                (q[0], q[1], if d > 0.0 { (measured - eps[q[0]]) / d } else { 0.0 }, false)
            }
            None if nm == 1 || measured < eps[order[0]] => (order[0], order[0], 0.0, nm > 1),
            None => (order[nm - 1], order[nm - 1], 0.0, true),
        };
        // Counted as outside only beyond half a per cent of the family's range: a member's own
        // pixels sit on its edge and the water's NIR signal moves them across it.
        let (lo, hi) = (eps[order[0]], eps[order[nm - 1]]);
        mix.outside = out && a_l > 0.0 && (measured < lo * (1.0 - EDGE) || measured > hi * (1.0 + EDGE));
        mix.entries.clear();
        for (m, share) in [(m1, 1.0 - w), (m2, w)] {
            for &(k, weight) in &located[m] {
                if share * weight != 0.0 {
                    mix.entries.push((&self.packed.terms[m][k][..], share * weight));
                }
            }
        }
        let tau = |m: usize| weighted(&located[m], |k| family.aot550[k]).max(0.0);
        mix.aot550 = (1.0 - w) * tau(m1) + w * tau(m2);
        mix.angstrom = (1.0 - w) * family.angstrom[m1] + w * family.angstrom[m2];
    }
}
