//! Sampling the scene: the band radiance every pixel sees, the band-effective atmosphere, and
//! the truth the retrievals are scored against.
//!
//! For pixel (row, column) and band b of geometry group g, with photon weights w_b(λ) of the
//! pixel's detector (see [`super::response`]) normalised to Σw = 1, and spatial quadrature
//! points k with weights ω_{b,k} (see [`super::spatial`]; one point without spatial response):
//!
//! L_b = Σ_k ω_{b,k} Σ_λ w_b(λ) L_TOA(λ; x_k, y_k)
//!
//! The band-effective atmosphere of a detector uses the same weights:
//! L_path,b = Σ w L_path, G_b = Σ w L_glint, (T·Ed)_b = Σ w T_up Ed, S_b = Σ w T_up Ed S / (T·Ed)_b,
//! and the true band reflectance is the one this band integrates through the atmosphere,
//! Rrs_b = Σ w T_up Ed Rrs / (T·Ed)_b: inverting L_b = L_path,b + G_b + (T·Ed)_b·Rrs_b/(1 − S_b π Rrs_b)
//! returns it up to within-band covariance terms of order S·π·Rrs·var(Rrs)/Rrs² (< 10⁻⁴).
//!
//! A spectrograph's keystone shifts each band's image across track by a fraction of a pixel;
//! it is applied to the sampled band radiance by linear interpolation across detectors (the
//! pixel-integrated radiance of box pixels), and not to the truth, so it shows as error.

use std::sync::Arc;

use ndarray::{Array2, Array3};
use rayon::prelude::*;

use super::InstrumentError;
use super::geometry::Viewing;
use super::response::Response;
use super::spatial::SpatialKernel;
use super::truth::{SurfaceClass, SurfaceMap, Truth};
use crate::control::RunControl;
use crate::parse::FieldError;
use crate::scene::{Scene, Sky};
use crate::toa::{SceneOptics, Scratch};

pub use super::aerosol_map::AotNodes;
pub use super::band_atmosphere::{BandAtmosphere, BandWeights, NodeWeights};

mod lanes;

/// Rows per work block of [`sample_radiance`].
const BLOCK_ROWS: usize = 32;

/// Options of the sampling stage.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleOptions {
    /// The spatial response quadrature ([`SpatialKernel::point`] without spatial response).
    pub kernel: SpatialKernel,
    /// Heading of the ground track, degrees clockwise from north (rotates the kernel).
    pub heading_deg: f64,
}

/// What the sampling stage produces: the radiance each pixel sees and the truth under it.
#[derive(Debug, Clone)]
pub struct RadianceCube {
    /// Band radiance at the entrance pupil, W m⁻² sr⁻¹ nm⁻¹, (row, column, band).
    pub radiance: Array3<f32>,
    /// The scene's truth under each pixel (its maps).
    pub truth: Arc<Truth>,
    /// True band remote-sensing reflectance above the surface, Rrs(0+), sr⁻¹ (0 on land),
    /// (row, column, band), weighted by each band's response as the radiance is (the water
    /// model's `rrs` is below the surface, rrs(0−)). A cube: kept apart from the truth's maps,
    /// so that a run that does not keep its cubes keeps the maps alone; such a run empties it once
    /// it has taken the pixels its comparisons read (`correction::TruthRrsSample`), where nothing
    /// else holds this product.
    pub truth_rrs: Arc<Array3<f32>>,
    /// Depth bins and substrate shares of the truth's water pixels, counted once per cube (runs
    /// that reuse the cube from the cache reuse them).
    pub truth_shares: super::shares::SceneShares,
    /// Water-model evaluations.
    pub water_evaluations: u64,
    /// Water-model evaluations that included the bottom term.
    pub bottom_evaluations: u64,
    /// Brightest band radiance over the water pixels (what the plausibility guard checks the
    /// detector's full scale against), W m⁻² sr⁻¹ nm⁻¹.
    pub brightest_water_w_m2_sr_nm: Vec<f64>,
    /// Median band radiance over the water pixels (the SNR stage's typical radiance), W m⁻²
    /// sr⁻¹ nm⁻¹: computed with the cube, so a run that reuses the cube does not recompute it
    /// (it was 5 % of an electronics preview's time).
    pub typical_water_w_m2_sr_nm: Vec<f64>,
}

/// Sample the scene through every pixel of `viewing`: `optics[g]` is the scene bound to group
/// g's grid, the atmosphere from [`BandAtmosphere::new`] with, where the scene's AOT is a map,
/// its terms at AOT nodes ([`super::aerosol_map`]), and the truth's band Rrs through the
/// `truth` atmosphere's weights (the same atmosphere, or the stated bands' where the instrument
/// has others: [`Response::sensed`]). Checks `control` between rows.
pub fn sample_radiance(
    scene: &Scene,
    optics: &[SceneOptics],
    viewing: &Viewing,
    response: &Response,
    (atmosphere, aerosol_map, truth_atmosphere): (&BandAtmosphere, Option<&AotNodes>, &BandAtmosphere),
    options: &SampleOptions,
    control: &RunControl,
) -> Result<RadianceCube, InstrumentError> {
    let (rows, cols, nb) = (viewing.lines(), viewing.columns(), response.n_bands());
    let n_sub = scene.substrates.len();
    let shallow = scene.depth.is_some();
    let pixel = cols * nb;
    let mut radiance = vec![0.0f32; rows * pixel];
    let mut rrs_truth = vec![0.0f32; rows * pixel];
    // The truth's maps, each a plane (chl, NAP, CDOM, and depth where there is a bottom: one
    // unused float per row without), written as the truth keeps them.
    let depth_stride = if shallow { cols } else { 1 };
    let (mut chl, mut nap, mut cdom) =
        (vec![0.0f32; rows * cols], vec![0.0f32; rows * cols], vec![0.0f32; rows * cols]);
    let mut depth = vec![0.0f32; rows * depth_stride];
    // Without a bottom the fraction rows are one unused float each (keeps the row zip simple).
    let frac_stride = if shallow { (cols * n_sub).max(1) } else { 1 };
    let mut fractions = vec![0.0f32; rows * frac_stride];
    let mut land = vec![0u8; rows * cols];
    // The aerosol map under each pixel centre (one unused float per row without a map).
    let aot_stride = if aerosol_map.is_some() { cols } else { 1 };
    let mut aot = vec![0.0f32; rows * aot_stride];
    let (along, right) = {
        let h = options.heading_deg.to_radians();
        ((h.sin(), h.cos()), (h.cos(), -h.sin()))
    };
    let kernel = &options.kernel;
    let offsets: Vec<(f64, f64)> =
        kernel.offsets_m.iter().map(|&(a, c)| (a * along.0 + c * right.0, a * along.1 + c * right.1)).collect();
    control.add_total(rows as u64);
    // Blocks of rows, walked column by column: each column's atmosphere (a few kB per group)
    // then stays in cache for the whole block instead of streaming from memory for every pixel.
    let block = BLOCK_ROWS.min(rows.max(1));
    let counters: Vec<(u64, u64)> = radiance
        .par_chunks_mut((pixel * block).max(1))
        .zip(rrs_truth.par_chunks_mut((pixel * block).max(1)))
        .zip(chl.par_chunks_mut(cols * block).zip(nap.par_chunks_mut(cols * block)))
        .zip(cdom.par_chunks_mut(cols * block).zip(depth.par_chunks_mut(depth_stride * block)))
        .zip(land.par_chunks_mut(cols * block))
        .zip(fractions.par_chunks_mut(frac_stride * block))
        .zip(aot.par_chunks_mut(aot_stride * block))
        .enumerate()
        .map(
            |(
                bi,
                ((((((rad_block, rrs_block), (chl_b, nap_b)), (cdom_b, depth_b)), land_block), frac_block), aot_block),
            )| {
                if control.cancelled() {
                    return Err(InstrumentError::Cancelled);
                }
                // Written before it is read: the zeroed allocation is still unmapped, so this first
                // touch maps fresh pages. Read first (the band sums' `+=`), each page would map the
                // kernel's shared zero page and then be copied on the first write, with a TLB flush
                // sent to every core (an inter-processor interrupt, a VM exit here): 8 % of the
                // default study's CPU time, measured with perf.
                rad_block.fill(0.0);
                rrs_block.fill(0.0);
                let first_row = bi * block;
                let n_rows = land_block.len() / cols.max(1);
                let sampler = PixelSampler {
                    scene,
                    optics,
                    viewing,
                    response,
                    atmosphere,
                    truth_atmosphere,
                    kernel,
                    offsets: &offsets,
                };
                let mut work = PixelWork::new(optics);
                let mut block = lanes::Block {
                    first_row,
                    rows: n_rows,
                    radiance: rad_block,
                    truth_rrs: rrs_block,
                    maps: [chl_b, nap_b, cdom_b, depth_b],
                    land: land_block,
                    fractions: frac_block,
                    frac_stride,
                    aot: aot_block,
                };
                for c in 0..cols {
                    sampler.column(&mut work, &mut block, c, (aerosol_map, control))?;
                    if control.cancelled() {
                        return Err(InstrumentError::Cancelled);
                    }
                }
                control.tick(n_rows as u64);
                Ok((work.scratch.water_evaluations, work.scratch.bottom_evaluations))
            },
        )
        .collect::<Result<Vec<_>, InstrumentError>>()?;
    apply_keystone(&mut radiance, cols, nb, &response.keystone_px, viewing.decimation);
    let bad =
        |e: ndarray::ShapeError| InstrumentError::Invalid(FieldError { field: "cube".into(), message: e.to_string() });
    let radiance = Array3::from_shape_vec((rows, cols, nb), radiance).map_err(bad)?;
    let aot = aerosol_map.is_some().then_some(aot);
    let (truth, truth_rrs) = TruthBuffers { rrs: rrs_truth, maps: [chl, nap, cdom, depth], fractions, land, aot }
        .into_truth(scene, (rows, cols, nb))?;
    Ok(RadianceCube {
        brightest_water_w_m2_sr_nm: super::plausibility::brightest_water(&radiance, &truth.surface),
        typical_water_w_m2_sr_nm: super::plausibility::typical_water(&radiance, &truth.surface),
        radiance,
        truth_shares: super::shares::SceneShares::of(&truth),
        truth: Arc::new(truth),
        truth_rrs: Arc::new(truth_rrs),
        water_evaluations: counters.iter().map(|c| c.0).sum(),
        bottom_evaluations: counters.iter().map(|c| c.1).sum(),
    })
}

/// What every pixel of [`sample_radiance`] reads.
struct PixelSampler<'a> {
    scene: &'a Scene,
    optics: &'a [SceneOptics],
    viewing: &'a Viewing,
    response: &'a Response,
    atmosphere: &'a BandAtmosphere,
    /// Whose weights the truth's band Rrs is taken with.
    truth_atmosphere: &'a BandAtmosphere,
    kernel: &'a SpatialKernel,
    /// The kernel's offsets turned with the ground track, m (east, north).
    offsets: &'a [(f64, f64)],
}

/// A worker's buffers for [`PixelSampler::pixels`].
struct PixelWork {
    scratch: Scratch,
    /// Per group: TOA radiance and Rrs on the grid.
    spectra: Vec<(Vec<f64>, Vec<f64>)>,
    /// Per group: the number of band nodes (0 without them).
    nodes: Vec<usize>,
    /// Rrs at the band nodes of each lane of a run ([`lanes::LANES`] × nodes).
    lane_rrs: Vec<f64>,
    /// f and Rrs at each node for the lanes ([`lanes`]'s kernel).
    lane_f: Vec<[[f64; lanes::LANES]; 2]>,
    /// Per band: the lanes' radiance and truth sums.
    sums: Vec<[[f32; lanes::LANES]; 2]>,
}

impl PixelWork {
    fn new(optics: &[SceneOptics]) -> Self {
        let pair = |n: usize| (vec![0.0; n], vec![0.0; n]);
        Self {
            scratch: Scratch::default(),
            spectra: optics.iter().map(|o| pair(o.grid().len())).collect(),
            nodes: optics.iter().map(|o| o.band_nodes().map_or(0, <[usize]>::len)).collect(),
            lane_rrs: Vec::new(),
            lane_f: Vec::new(),
            sums: Vec::new(),
        }
    }
}

/// The truth as the sampling loop writes it: flat row-major buffers.
struct TruthBuffers {
    /// Band Rrs(0+), (row, column, band).
    rrs: Vec<f32>,
    /// chl, NAP, CDOM and depth, each (row, column) (depth one unused float per row without a
    /// bottom).
    maps: [Vec<f32>; 4],
    /// Substrate fractions, (row, column, substrate) when the scene is shallow.
    fractions: Vec<f32>,
    /// Land flags, (row, column).
    land: Vec<u8>,
    /// AOT(550) at each pixel centre, (row, column), when the scene has an aerosol map.
    aot: Option<Vec<f32>>,
}

impl TruthBuffers {
    /// Shape the buffers into a [`Truth`] and the true Rrs cube.
    fn into_truth(
        self,
        scene: &Scene,
        (rows, cols, nb): (usize, usize, usize),
    ) -> Result<(Truth, Array3<f32>), InstrumentError> {
        let bad = |e: ndarray::ShapeError| {
            InstrumentError::Invalid(FieldError { field: "truth".into(), message: e.to_string() })
        };
        let shallow = scene.depth.is_some();
        let [chl, nap, cdom, depth] = self.maps;
        let plane = |v: Vec<f32>| Array2::from_shape_vec((rows, cols), v).map_err(bad);
        let rrs = Array3::from_shape_vec((rows, cols, nb), self.rrs).map_err(bad)?;
        let truth = Truth {
            chl_mg_m3: plane(chl)?,
            nap_g_m3: plane(nap)?,
            cdom_per_m: plane(cdom)?,
            depth_m: shallow.then(|| plane(depth)).transpose()?,
            substrate_fractions: if shallow {
                Some(Array3::from_shape_vec((rows, cols, scene.substrates.len()), self.fractions).map_err(bad)?)
            } else {
                None
            },
            surface: SurfaceMap::from_codes(Array2::from_shape_vec((rows, cols), self.land).map_err(bad)?),
            aot550: self.aot.map(|a| Array2::from_shape_vec((rows, cols), a)).transpose().map_err(bad)?,
            substrate_names: scene.substrates.iter().map(|(n, _)| n.clone()).collect(),
        };
        Ok((truth, rrs))
    }
}

/// The truth maps at scene point (x, y): chl, NAP, CDOM and depth (0 without a bottom), the surface class
/// as the sensor sees it under `sky` (cloud over anything; water in a cloud's shadow), and the
/// normalised substrate fractions.
fn truth_at(scene: &Scene, x: f64, y: f64, sky: Sky, class: &mut u8, fractions: Option<&mut [f32]>) -> [f32; 4] {
    let maps = [
        scene.chl.value_at(x, y) as f32,
        scene.nap.value_at(x, y) as f32,
        scene.cdom.value_at(x, y) as f32,
        scene.depth.as_ref().map_or(0.0, |d| d.value_at(x, y)) as f32,
    ];
    *class = match (sky, scene.is_land(x, y)) {
        (Sky::Cloud, _) => SurfaceClass::Cloud,
        (_, true) => SurfaceClass::Land,
        (Sky::Shadow, false) => SurfaceClass::CloudShadow,
        (Sky::Clear, false) => SurfaceClass::Water,
    } as u8;
    if let Some(f) = fractions {
        let n = f.len();
        let values: Vec<f64> = scene.substrates.iter().map(|(_, m)| m.value_at(x, y).max(0.0)).collect();
        let total: f64 = values.iter().sum();
        for (s, v) in values.iter().enumerate().take(n) {
            f[s] = if total > 0.0 { (v / total) as f32 } else { 1.0 / n as f32 };
        }
    }
    maps
}

/// Shift band b of every row by `keystone_px[b] / decimation` columns (linear interpolation,
/// edges clamped).
fn apply_keystone(cube: &mut [f32], cols: usize, nb: usize, keystone_px: &[f64], decimation: usize) {
    if keystone_px.iter().all(|k| *k == 0.0) || cols < 2 {
        return;
    }
    cube.par_chunks_mut(cols * nb).for_each(|row| {
        let original = row.to_vec();
        for (b, &k) in keystone_px.iter().enumerate() {
            let shift = k / decimation as f64;
            for c in 0..cols {
                let pos = (c as f64 + shift).clamp(0.0, (cols - 1) as f64);
                let c0 = pos.floor() as usize;
                let c1 = (c0 + 1).min(cols - 1);
                let f = (pos - c0 as f64) as f32;
                row[c * nb + b] = original[c0 * nb + b] * (1.0 - f) + original[c1 * nb + b] * f;
            }
        }
    });
}
