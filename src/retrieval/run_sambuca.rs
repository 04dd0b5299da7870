//! The SAMBUCA retrieval over a whole Rrs image, as Shoal improves it and as the CSIRO package
//! runs it (`mode: Reference`): per-pixel fits through the row executor, and the product maps.

use ndarray::{Array2, Array3};

use super::Mode;
use super::RetrievalError;
use super::band_model::BandModel;
use super::run::{Product, ProductFlags, RetrievalInputs};
use super::sambuca::{Observation, SambucaSettings, Scratch, invert_in};
use super::sambuca_reference::{self as reference, ReferenceModel};
use crate::control::RunControl;
use crate::correction::RrsFlags;
use crate::parse::FieldError;
use crate::water::{SiopSource, SubstrateLibrary, rrs_below_from_above};

/// One SAMBUCA pixel as stored: (chl, cdom, nap, depth, q, pair, objective, sdi, iterations, flags).
type SambucaRow = (f32, f32, f32, f32, f32, (u8, u8), f32, f32, u16, u8);

/// Per-substrate fractions from each pixel's pair and fraction.
fn substrate_fractions(results: &[Vec<SambucaRow>], n_sub: usize) -> Array3<f32> {
    let (rows, cols) = (results.len(), results.first().map_or(0, Vec::len));
    let mut fractions = Array3::<f32>::zeros((rows, cols, n_sub));
    for r in 0..rows {
        for c in 0..cols {
            let p = &results[r][c];
            if p.9 & ProductFlags::RETURNED == 0 {
                continue;
            }
            let (i, j) = (usize::from(p.5.0), usize::from(p.5.1));
            if i < n_sub {
                fractions[[r, c, i]] = if j < n_sub { p.4 } else { 1.0 };
            }
            if j < n_sub {
                fractions[[r, c, j]] = 1.0 - p.4;
            }
        }
    }
    fractions
}

/// SAMBUCA's model at the instrument's bands: the SIOP set and the substrates integrated over the
/// band responses (Gauss nodes for Shoal's fit, the package's band sums for the reference).
/// Depends only on the spec, the scene's SIOP and substrates, and the bands.
#[derive(Debug, Clone)]
pub struct SambucaModel {
    /// The SIOP set's name.
    siop_name: String,
    /// The substrates, in the product's order.
    names: Vec<String>,
    /// The model of the mode asked for.
    kind: ModelKind,
}

#[derive(Debug, Clone)]
enum ModelKind {
    Improved(BandModel),
    Reference { model: ReferenceModel, refractive_index: f64 },
}

/// Build [`SambucaModel`] at `inputs.bands`.
pub(super) fn sambuca_model(
    siop: Option<&SiopSource>,
    substrates: Option<&[String]>,
    settings: &SambucaSettings,
    inputs: &RetrievalInputs<'_>,
) -> Result<SambucaModel, RetrievalError> {
    let (spec, dir) = match siop {
        Some(src) => src.load(inputs.base_dir)?,
        None => inputs.scene_siop.clone(),
    };
    let names: Vec<String> = substrates.map_or_else(|| inputs.scene_substrates.clone(), <[String]>::to_vec);
    if names.is_empty() {
        return Err(RetrievalError::Invalid(FieldError {
            field: "substrates".into(),
            message: "SAMBUCA needs at least one substrate".into(),
        }));
    }
    let library = SubstrateLibrary::embedded()?;
    let kind = if settings.mode == Mode::Reference {
        let model = ReferenceModel::from_siop(&spec, dir.as_deref(), &library, &names, &inputs.bands)?;
        ModelKind::Reference { model, refractive_index: spec.water_refractive_index }
    } else {
        ModelKind::Improved(BandModel::new(
            &spec,
            dir.as_deref(),
            &library,
            &names,
            &inputs.bands,
            settings.nodes_per_band,
        )?)
    };
    Ok(SambucaModel { siop_name: spec.name, names, kind })
}

/// SAMBUCA over the image with `model` (from [`sambuca_model`] of the same settings and bands).
pub(super) fn retrieve_sambuca(
    model: &SambucaModel,
    settings: &SambucaSettings,
    inputs: &RetrievalInputs<'_>,
    control: &RunControl,
) -> Result<Product, RetrievalError> {
    let b = &settings.bounds;
    let SambucaModel { siop_name, names, kind } = model;
    let model = match kind {
        ModelKind::Reference { model, refractive_index } => {
            return retrieve_sambuca_reference(
                model,
                (siop_name, *refractive_index),
                names.clone(),
                settings,
                inputs,
                control,
            );
        }
        ModelKind::Improved(model) => model,
    };
    let (rows, cols, nb) = inputs.rrs.dim();
    let inv_cos: Vec<(f64, f64)> =
        inputs.geometry.iter().map(|g| g.inverse_cosines_in_water(model.refractive_index)).collect();
    let results: Vec<Vec<SambucaRow>> = control.map_rows(rows, |at| {
        let r = at.index();
        let mut obs = vec![0.0; nb];
        let mut valid = vec![false; nb];
        let mut scratch = Scratch::default();
        let row = (0..cols)
            .map(|c| {
                at.column(c);
                let failed = (0.0, 0.0, 0.0, 0.0, 0.0, (0, 0), 0.0, 0.0, 0, ProductFlags::FAILED);
                if !inputs.surface.is_water(r, c) {
                    return (0.0, 0.0, 0.0, 0.0, 0.0, (0, 0), 0.0, 0.0, 0, ProductFlags::LAND);
                }
                for k in 0..nb {
                    obs[k] = f64::from(inputs.rrs[[r, c, k]]);
                    valid[k] = inputs.flags[[r, c, k]] & (RrsFlags::INVALID | RrsFlags::SATURATED) == 0;
                }
                let o = Observation { rrs: &obs, valid: &valid, nedr: &inputs.nedr, inv_cos: inv_cos[c] };
                let p = invert_in(&mut scratch, model, settings, &o);
                if !p.ok {
                    return failed;
                }
                let mut flags = ProductFlags::RETURNED;
                if p.converged {
                    flags |= ProductFlags::CONVERGED;
                }
                if p.sdi >= 1.0 {
                    flags |= ProductFlags::BOTTOM_VISIBLE;
                }
                let near = |v: f64, (lo, hi): (f64, f64)| v <= lo * (1.0 + 1e-9) || v >= hi * (1.0 - 1e-9);
                if near(p.chl, b.chl_mg_m3)
                    || near(p.cdom, b.cdom_per_m)
                    || near(p.nap, b.nap_g_m3)
                    || near(p.depth_m, b.depth_m)
                {
                    flags |= ProductFlags::AT_BOUND;
                }
                (
                    p.chl as f32,
                    p.cdom as f32,
                    p.nap as f32,
                    p.depth_m as f32,
                    p.fraction as f32,
                    p.pair,
                    p.objective as f32,
                    p.sdi as f32,
                    u16::try_from(p.iterations).unwrap_or(u16::MAX),
                    flags,
                )
            })
            .collect();
        Ok::<_, RetrievalError>(row)
    })?;
    Ok(sambuca_product(&results, names.clone(), siop_name))
}

/// The SAMBUCA product from its per-pixel rows.
fn sambuca_product(results: &[Vec<SambucaRow>], names: Vec<String>, siop_name: &str) -> Product {
    let (rows, cols) = (results.len(), results.first().map_or(0, Vec::len));
    let fractions = substrate_fractions(results, names.len());
    let plane = |k: fn(&SambucaRow) -> f32| Array2::from_shape_fn((rows, cols), |(r, c)| k(&results[r][c]));
    Product {
        name: super::algorithm::SAMBUCA.title.into(),
        chl_mg_m3: Some(plane(|p| p.0)),
        cdom_per_m: Some(plane(|p| p.1)),
        nap_g_m3: Some(plane(|p| p.2)),
        depth_m: Some(plane(|p| p.3)),
        substrate_names: names,
        substrate_fractions: Some(fractions),
        siop_set_names: vec![siop_name.to_string()],
        siop_set: None,
        cost: plane(|p| p.6),
        sdi: Some(plane(|p| p.7)),
        iterations: Some(Array2::from_shape_fn((rows, cols), |(r, c)| results[r][c].8)),
        extras: Vec::new(),
        flags: Array2::from_shape_fn((rows, cols), |(r, c)| results[r][c].9),
    }
}

/// SAMBUCA's reference mode over the image: every water pixel fitted as the CSIRO package fits
/// it ([`super::sambuca_reference`]). The package works in sub-surface rrs: each band's corrected
/// Rrs is taken below the surface with rrs = Rrs/(0.52 + 1.7·Rrs) (Lee et al. 2002) and its
/// noise-equivalent ΔRrs with the same map's slope, 0.52/(0.52 + 1.7·Rrs)². A pixel with an
/// invalid, saturated or non-finite band, or Σ(rrs/NEDR) ≤ 0, is not fitted (the package would
/// carry the NaN or a negative f through); every other pixel is returned, as the package writes
/// every pixel's x, with `CONVERGED` where it reported success and `STALLED` where that success
/// left the depth at its start.
fn retrieve_sambuca_reference(
    model: &ReferenceModel,
    (siop_name, refractive_index): (&str, f64),
    names: Vec<String>,
    settings: &SambucaSettings,
    inputs: &RetrievalInputs<'_>,
    control: &RunControl,
) -> Result<Product, RetrievalError> {
    let bnd = &settings.bounds;
    let p_min = [bnd.chl_mg_m3.0, bnd.cdom_per_m.0, bnd.nap_g_m3.0, bnd.depth_m.0, 0.0];
    let p_max = [bnd.chl_mg_m3.1, bnd.cdom_per_m.1, bnd.nap_g_m3.1, bnd.depth_m.1, 1.0];
    let (rows, cols, nb) = inputs.rrs.dim();
    let inv_cos: Vec<(f64, f64)> =
        inputs.geometry.iter().map(|g| g.inverse_cosines_in_water(refractive_index)).collect();
    let pairs = model.pairs().to_vec();
    let results: Vec<Vec<SambucaRow>> = control.map_rows(rows, |at| {
        let r = at.index();
        let (mut obs, mut nedr) = (vec![0.0; nb], vec![0.0; nb]);
        let row = (0..cols)
            .map(|c| {
                at.column(c);
                let failed = (0.0, 0.0, 0.0, 0.0, 0.0, (0, 0), 0.0, 0.0, 0, ProductFlags::FAILED);
                if !inputs.surface.is_water(r, c) {
                    return (0.0, 0.0, 0.0, 0.0, 0.0, (0, 0), 0.0, 0.0, 0, ProductFlags::LAND);
                }
                let mut usable = true;
                for k in 0..nb {
                    let above = f64::from(inputs.rrs[[r, c, k]]);
                    let flagged = inputs.flags[[r, c, k]] & (RrsFlags::INVALID | RrsFlags::SATURATED) != 0;
                    let denominator = 0.52 + 1.7 * above;
                    usable &= !flagged && above.is_finite() && denominator > 0.0 && inputs.nedr[k] > 0.0;
                    obs[k] = rrs_below_from_above(above);
                    nedr[k] = inputs.nedr[k] * 0.52 / (denominator * denominator);
                }
                let weighted: f64 = obs.iter().zip(&nedr).map(|(o, e)| o / e).sum();
                if !usable || !(weighted > 0.0) {
                    return failed;
                }
                let p = reference::invert(model, &p_min, &p_max, &obs, &nedr, inv_cos[c]);
                if !p.fun.is_finite() {
                    return failed;
                }
                let pair = pairs[p.kept.unwrap_or(pairs.len() - 1)];
                let sdi = reference::sdi(model, &p.x, pair, &nedr, inv_cos[c]);
                let mut flags = ProductFlags::RETURNED;
                if p.success {
                    flags |= ProductFlags::CONVERGED;
                }
                if p.stalled {
                    flags |= ProductFlags::STALLED;
                }
                if sdi >= 1.0 {
                    flags |= ProductFlags::BOTTOM_VISIBLE;
                }
                let near = |v: f64, k: usize| v <= p_min[k] * (1.0 + 1e-9) || v >= p_max[k] * (1.0 - 1e-9);
                if (0..4).any(|k| near(p.x[k], k)) {
                    flags |= ProductFlags::AT_BOUND;
                }
                let narrow = |i: usize| u8::try_from(i).unwrap_or(u8::MAX);
                // One substrate: the package's single-substrate model, stored as (0, none).
                let stored = if pair.0 == pair.1 { (0, u8::MAX) } else { (narrow(pair.0), narrow(pair.1)) };
                (
                    p.x[0] as f32,
                    p.x[1] as f32,
                    p.x[2] as f32,
                    p.x[3] as f32,
                    p.x[4] as f32,
                    stored,
                    p.fun as f32,
                    sdi as f32,
                    u16::try_from(p.nit).unwrap_or(u16::MAX),
                    flags,
                )
            })
            .collect();
        Ok::<_, RetrievalError>(row)
    })?;
    Ok(sambuca_product(&results, names, siop_name))
}
