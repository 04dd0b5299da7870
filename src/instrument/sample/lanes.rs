//! A block of rows, column by column, a few pixels of a column at once: [`PixelSampler::column`],
//! [`PixelSampler::pixels`] and its band-sum kernel.
//!
//! The band sums at the nodes (L_b += ω·(L_path + G + Σ Cₙ fₙ), Rrs_b += ω·Σ Dₙ Rrsₙ, see
//! [`super::sample_radiance`]) add each pixel's terms in node order, so a pixel's sum is a chain
//! of dependent additions that cannot be split across vector lanes without changing its bits.
//! Pixels of one column share the weights, though: [`LANES`] pixels of consecutive rows, one per
//! vector lane, each add the same terms in the same order as alone — the same bits, a vector
//! instruction for what took one per pixel.

use super::{AotNodes, BandAtmosphere, InstrumentError, PixelSampler, PixelWork, truth_at};
use crate::control::RunControl;
use crate::scene::Sky;
use crate::toa::Target;

/// Pixels (consecutive rows of one column) sampled together.
pub(super) const LANES: usize = 8;

/// Where a run of up to [`LANES`] pixels of one column writes: pixel `l` of the run (row
/// `first_row + l`) at `at + l·stride` in `radiance` and `truth`, `n_bands` values each.
struct Run<'o> {
    /// The run's first row (of the image), its pixels and its column.
    first_row: usize,
    lanes: usize,
    column: usize,
    /// The first pixel's offset in the block's buffers, and a row's.
    at: usize,
    stride: usize,
    /// The block's band radiance and true band Rrs.
    radiance: &'o mut [f32],
    truth: &'o mut [f32],
}

impl Run<'_> {
    /// Pixel `l`'s radiance and truth.
    fn pixel(&mut self, l: usize, nb: usize) -> (&mut [f32], &mut [f32]) {
        let at = self.at + l * self.stride;
        (&mut self.radiance[at..at + nb], &mut self.truth[at..at + nb])
    }
}

/// A block of rows' outputs, each row-major within the block (see [`super::sample_radiance`]).
pub(super) struct Block<'o> {
    /// The block's first row and its number of rows.
    pub first_row: usize,
    pub rows: usize,
    /// Band radiance and true band Rrs, (row, column, band); zero on entry.
    pub radiance: &'o mut [f32],
    pub truth_rrs: &'o mut [f32],
    /// chl, NAP, CDOM, (row, column), and depth ((row, column) with a bottom, one float a row
    /// without).
    pub maps: [&'o mut [f32]; 4],
    /// Surface classes, (row, column).
    pub land: &'o mut [u8],
    /// Substrate fractions, (row, column, substrate) with a bottom (one float a row without),
    /// and a row's length there.
    pub fractions: &'o mut [f32],
    pub frac_stride: usize,
    /// AOT(550) under each pixel centre, (row, column) with an aerosol map (one float a row
    /// without).
    pub aot: &'o mut [f32],
}

impl PixelSampler<'_> {
    /// Column `c` of `block`: every pixel's band radiance (its aerosol exchanged where the
    /// scene's AOT is a map) and its truth. Checks `control` at every pixel, after its run's
    /// sums (a fault injected at a pixel fires there; a panic while a run of pixels is summed
    /// is placed at the run's first pixel).
    pub(super) fn column(
        &self,
        work: &mut PixelWork,
        block: &mut Block<'_>,
        c: usize,
        (aerosol_map, control): (Option<&AotNodes>, &RunControl),
    ) -> Result<(), InstrumentError> {
        let (scene, viewing) = (self.scene, self.viewing);
        let cols = viewing.columns();
        let nb = self.response.n_bands();
        let pixel = cols * nb;
        let shallow = scene.depth.is_some();
        let (n_sub, frac_stride) = (scene.substrates.len(), block.frac_stride);
        for rr0 in (0..block.rows).step_by(LANES) {
            let n_lanes = LANES.min(block.rows - rr0);
            // The run's sums are placed at its first pixel; each pixel is visited after them.
            let mut at = control.row(block.first_row + rr0);
            at.column(c);
            let mut run = Run {
                first_row: block.first_row + rr0,
                lanes: n_lanes,
                column: c,
                at: rr0 * pixel + c * nb,
                stride: pixel,
                radiance: block.radiance,
                truth: block.truth_rrs,
            };
            self.pixels(work, &mut run)?;
            drop(at);
            for rr in rr0..rr0 + n_lanes {
                let r = block.first_row + rr;
                let mut at = control.row(r);
                at.column(c);
                let (x, y) = viewing.ground_m(0, r, c);
                if let Some(nodes) = aerosol_map {
                    let tau = scene.aot550_at(x, y);
                    let at = rr * pixel + c * nb;
                    nodes.exchange(self.atmosphere, c, tau, &mut block.radiance[at..at + nb]);
                    block.aot[rr * cols + c] = tau as f32;
                }
                let at = rr * cols + c;
                let fractions = shallow
                    .then(|| &mut block.fractions[rr * frac_stride + c * n_sub..rr * frac_stride + (c + 1) * n_sub]);
                let look = &viewing.looks[0][c];
                let sky = scene.sky_at(x, y, look.geometry.view_zenith_rad, look.view_azimuth_rad);
                let values = truth_at(scene, x, y, sky, &mut block.land[at], fractions);
                let [chl, nap, cdom, depth] = &mut block.maps;
                (chl[at], nap[at], cdom[at]) = (values[0], values[1], values[2]);
                if shallow {
                    depth[at] = values[3];
                }
            }
        }
        Ok(())
    }

    /// Add the run's pixels' band radiance and true band Rrs (both zero on entry), over every
    /// group and spatial quadrature point: at the band nodes where the optics has them and the
    /// point is water ([`LANES`] pixels at once), on the full grid otherwise (pixel by pixel).
    /// Each pixel's sums take their terms in the order they would alone (group by group, point
    /// by point, from +0.0), in `work.sums` (a band's lanes side by side), then go to the run.
    fn pixels(&self, work: &mut PixelWork, run: &mut Run<'_>) -> Result<(), InstrumentError> {
        let (atmosphere, kernel, c) = (self.atmosphere, self.kernel, run.column);
        let nb = self.response.n_bands();
        work.sums.clear();
        work.sums.resize(nb, [[0.0; LANES]; 2]);
        for (gi, group) in self.response.groups.iter().enumerate() {
            let optics = &self.optics[gi];
            let look = &self.viewing.looks[gi][c];
            let n_nodes = work.nodes[gi];
            work.lane_rrs.resize(LANES * n_nodes, 0.0);
            for (k, &(dx, dy)) in self.offsets.iter().enumerate() {
                // The lanes whose point is water at the band nodes, with their Rrs there (lane
                // after lane; zero in the others).
                let mut water = [false; LANES];
                for l in 0..run.lanes {
                    let (x0, y0) = self.viewing.ground_m(gi, run.first_row + l, c);
                    let (x, y) = (x0 + dx, y0 + dy);
                    let sky = self.scene.sky_at(x, y, look.geometry.view_zenith_rad, look.view_azimuth_rad);
                    let rrs = &mut work.lane_rrs[l * n_nodes..(l + 1) * n_nodes];
                    water[l] = sky == Sky::Clear
                        && atmosphere.has_nodes(gi)
                        && optics.water_at_nodes(self.scene, x, y, &look.geometry, &mut work.scratch, rrs)?;
                    if !water[l] {
                        rrs.fill(0.0);
                        self.on_grid(work, (gi, k), c, (x, y, sky), l)?;
                    }
                }
                if water.contains(&true) {
                    let weight = |b: usize| kernel.weights[b][k];
                    crate::simd::avx2(AtNodes {
                        atmosphere,
                        truth_atmosphere: self.truth_atmosphere,
                        gi,
                        c,
                        bands: &group.bands,
                        weight,
                        node_rrs: &work.lane_rrs[..LANES * n_nodes],
                        water,
                        f: &mut work.lane_f,
                        sums: &mut work.sums,
                    });
                }
            }
        }
        for l in 0..run.lanes {
            let (out, truth) = run.pixel(l, nb);
            for (b, [radiance, t]) in work.sums.iter().enumerate() {
                (out[b], truth[b]) = (radiance[l], t[l]);
            }
        }
        Ok(())
    }

    /// One point's band radiance and truth on the full grid (land, cloud, shadow, or optics
    /// without band nodes), added to lane `l` of `work.sums`.
    fn on_grid(
        &self,
        work: &mut PixelWork,
        (gi, k): (usize, usize),
        c: usize,
        (x, y, sky): (f64, f64, Sky),
        l: usize,
    ) -> Result<(), InstrumentError> {
        let optics = &self.optics[gi];
        let look = &self.viewing.looks[gi][c];
        let path = &self.atmosphere.paths[gi][c];
        let j = self.viewing.detector_index[c];
        let (l_toa, rrs) = &mut work.spectra[gi];
        let surface = optics.radiance(self.scene, x, y, &look.geometry, sky, path, &mut work.scratch, l_toa, rrs)?;
        for (kb, &b) in self.response.groups[gi].bands.iter().enumerate() {
            let (first, w) = self.response.weights(gi, kb, j);
            let (num, den) =
                w.iter().zip(&l_toa[first..first + w.len()]).fold((0.0, 0.0), |(n, d), (wi, v)| (n + wi * v, d + wi));
            let weight = self.kernel.weights[b][k];
            work.sums[b][0][l] += (weight * num / den) as f32;
            if surface == Target::Water {
                let (tf, tw) = &self.truth_atmosphere.truth_weights[gi][c][kb];
                let t: f64 = tw.iter().zip(&rrs[*tf..*tf + tw.len()]).map(|(a, v)| a * v).sum();
                work.sums[b][1][l] += (weight * t) as f32;
            }
        }
        Ok(())
    }
}

/// The water points' band sums at the band nodes, [`LANES`] pixels a vector, as a
/// [`crate::simd::Kernel`]: f = Rrs/(1 − S·π·Rrs) at every node, then per band
/// L_b += ω·(L_path + G + Σ Cₙ fₙ) and Rrs_b += ω·Σ Dₙ Rrsₙ. Nothing is fused and each lane adds
/// its terms in node order, from −0.0 as `Iterator::sum` does: every level, and every lane, gives
/// the bits of a pixel summed alone. Lanes that are not water add +0.0 (which changes no sum:
/// one that starts at +0.0 is never −0.0).
struct AtNodes<'s, 'b, W> {
    /// The atmosphere the radiance is summed with, and the one the truth's weights come from.
    atmosphere: &'s BandAtmosphere,
    truth_atmosphere: &'s BandAtmosphere,
    /// Group and column.
    gi: usize,
    c: usize,
    bands: &'b [usize],
    /// The point's spatial weight in band b.
    weight: W,
    /// Rrs at the nodes of each lane, lane after lane (zero where not water).
    node_rrs: &'b [f64],
    /// Which lanes are water.
    water: [bool; LANES],
    /// Work space: f and Rrs, node by node, [`LANES`] values a node.
    f: &'b mut Vec<[[f64; LANES]; 2]>,
    /// The lanes' band radiance and truth, band by band.
    sums: &'b mut [[[f32; LANES]; 2]],
}

impl<W: Fn(usize) -> f64> crate::simd::Kernel for AtNodes<'_, '_, W> {
    type Output = ();

    #[inline(always)]
    fn run<L: crate::simd::Level>(self) {
        let AtNodes { atmosphere, truth_atmosphere, gi, c, bands, weight, node_rrs, water: is_water, f, sums } = self;
        let s_pi = &atmosphere.node_s_pi[gi][c];
        // A lane's nodes lie `stride` apart in `node_rrs`.
        let stride = node_rrs.len() / LANES;
        let n = stride.min(s_pi.len());
        f.resize(n, [[0.0; LANES]; 2]);
        // Node-major: a node's lanes side by side.
        for (i, (fi, &s)) in f.iter_mut().zip(s_pi).enumerate() {
            let rrs: [f64; LANES] = std::array::from_fn(|l| node_rrs[l * stride + i]);
            for l in 0..LANES {
                fi[0][l] = rrs[l] / (1.0 - s * rrs[l]);
            }
            fi[1] = rrs;
        }
        for (kb, &b) in bands.iter().enumerate() {
            let nw = &atmosphere.node_weights[gi][c][kb];
            let tw = &truth_atmosphere.node_weights[gi][c][kb];
            let (mut water, mut t) = ([-0.0; LANES], [-0.0; LANES]);
            if tw.first == nw.first && tw.truth.len() == nw.radiance.len() {
                // One loop, two independent sums (the truth's weights are usually the radiance's).
                let terms = nw.radiance.iter().zip(&tw.truth).zip(&f[nw.first..]);
                for ((&cn, &dn), [fn_, rn]) in terms {
                    for l in 0..LANES {
                        water[l] += cn * fn_[l];
                        t[l] += dn * rn[l];
                    }
                }
            } else {
                for (&cn, [fn_, _]) in nw.radiance.iter().zip(&f[nw.first..]) {
                    for l in 0..LANES {
                        water[l] += cn * fn_[l];
                    }
                }
                for (&dn, [_, rn]) in tw.truth.iter().zip(&f[tw.first..]) {
                    for l in 0..LANES {
                        t[l] += dn * rn[l];
                    }
                }
            }
            let i = atmosphere.at(c, b);
            let (weight, base) = (weight(b), atmosphere.l_path[i] + atmosphere.glint[i]);
            let [radiance, truth] = &mut sums[b];
            for l in 0..LANES {
                radiance[l] += if is_water[l] { (weight * (base + water[l])) as f32 } else { 0.0 };
                truth[l] += if is_water[l] { (weight * t[l]) as f32 } else { 0.0 };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::NodeWeights;
    use super::*;

    /// Every lane's sums are, to the bit, those of its pixel summed alone in node order (the
    /// scalar loop the lanes replaced), whichever lanes are water, at every vector level; a lane
    /// that is not water keeps its sums. Band 2's truth weights start at another node than its
    /// radiance weights (the kernel's second branch).
    #[test]
    fn each_lane_sums_as_its_pixel_alone() {
        let (n, nb, c) = (12, 3, 1);
        let value = |i: usize| 0.5 + ((i * 7919) % 1013) as f64 / 997.0;
        let weights = |first: usize, len: usize, shift: usize, scale: f64| NodeWeights {
            first,
            radiance: (0..len).map(|j| scale * value(j + shift)).collect(),
            truth: (0..len).map(|j| value(j + shift + 5) / len as f64).collect(),
        };
        let radiance_weights = vec![weights(0, 5, 0, 80.0), weights(3, 6, 2, 95.0), weights(7, 5, 4, 60.0)];
        let mut truth_weights = radiance_weights.clone();
        truth_weights[2] = weights(6, 6, 9, 60.0);
        let atmosphere = |node_weights: &Vec<NodeWeights>| BandAtmosphere {
            n_bands: nb,
            paths: Vec::new(),
            l_path: (0..2 * nb).map(|i| 30.0 + value(i)).collect(),
            glint: (0..2 * nb).map(|i| 0.1 * value(i + 3)).collect(),
            ed: Vec::new(),
            t_ed: Vec::new(),
            spherical_albedo: Vec::new(),
            truth_weights: Vec::new(),
            node_weights: vec![vec![Vec::new(), node_weights.clone()]],
            node_s_pi: vec![vec![Vec::new(), (0..n).map(|i| 0.3 + 0.01 * value(i)).collect()]],
        };
        let (radiance_atm, truth_atm) = (atmosphere(&radiance_weights), atmosphere(&truth_weights));
        let rrs = |l: usize, i: usize| 0.002 + 1e-4 * value(l * 31 + i * 3);
        let node_rrs: Vec<f64> = (0..LANES).flat_map(|l| (0..n).map(move |i| rrs(l, i))).collect();
        let water: [bool; LANES] = std::array::from_fn(|l| l % 3 != 1);
        let weight = |b: usize| 0.25 + 0.1 * b as f64;
        for tier in [crate::simd::Tier::Avx512, crate::simd::Tier::Avx2, crate::simd::Tier::Baseline] {
            let mut sums = vec![[[0.0f32; LANES]; 2]; nb];
            sums[1][0][1] = 7.0;
            let mut f = Vec::new();
            crate::simd::capped(tier, || {
                crate::simd::avx2(AtNodes {
                    atmosphere: &radiance_atm,
                    truth_atmosphere: &truth_atm,
                    gi: 0,
                    c,
                    bands: &[0, 1, 2],
                    weight,
                    node_rrs: &node_rrs,
                    water,
                    f: &mut f,
                    sums: &mut sums,
                });
            });
            for l in 0..LANES {
                let f_alone: Vec<f64> =
                    (0..n).map(|i| rrs(l, i) / (1.0 - radiance_atm.node_s_pi[0][c][i] * rrs(l, i))).collect();
                for b in 0..nb {
                    let (nw, tw) = (&radiance_weights[b], &truth_weights[b]);
                    let water_sum: f64 = nw.radiance.iter().zip(&f_alone[nw.first..]).map(|(a, v)| a * v).sum();
                    let t: f64 = tw.truth.iter().zip((tw.first..).map(|i| rrs(l, i))).map(|(a, v)| a * v).sum();
                    let i = radiance_atm.at(c, b);
                    let start = if (b, l) == (1, 1) { 7.0f32 } else { 0.0 };
                    let (want_l, want_t) = if water[l] {
                        let l_b = weight(b) * (radiance_atm.l_path[i] + radiance_atm.glint[i] + water_sum);
                        (start + l_b as f32, 0.0f32 + (weight(b) * t) as f32)
                    } else {
                        (start, 0.0)
                    };
                    assert_eq!(sums[b][0][l].to_bits(), want_l.to_bits(), "{tier:?}: lane {l}, band {b}, radiance");
                    assert_eq!(sums[b][1][l].to_bits(), want_t.to_bits(), "{tier:?}: lane {l}, band {b}, truth");
                }
            }
        }
    }
}
