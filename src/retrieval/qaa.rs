//! The Quasi-Analytical Algorithm, version 6 (QAA v6): from above-water Rrs to the total
//! absorption a(λ) and particle backscattering b_bp(λ) at every band, split at 443 nm into
//! phytoplankton a_ph(443) and detritus + CDOM a_dg(443), with no assumption about the water's
//! constituents (Lee, Carder & Arnone 2002, Appl. Opt. 41, 5755; v6: Lee et al. 2014, IOCCG,
//! "Update of the Quasi-Analytical Algorithm (QAA_v6)").
//!
//! Steps (λ0 the reference band, aw and bbw pure water's absorption and backscattering at each
//! band, r ratios of Rrs or rrs by the mode, see [`Constants`]):
//! 0. rrs = Rrs / (0.52 + 1.7 Rrs) (Lee et al. 2002, eq. 4);
//! 1. u = (−g0 + √(g0² + 4 g1 rrs)) / (2 g1);
//! 2. λ0 = 555 when Rrs(670) < 0.0015: χ = log10[(r443 + r490) / (r555 + 5 r670² / r490)],
//!    a(λ0) = aw(λ0) + 10^(h0 + h1 χ + h2 χ²); else λ0 = 670:
//!    a(λ0) = aw(λ0) + 0.39 (Rrs670 / (Rrs443 + Rrs490))^1.14;
//! 3. b_bp(λ0) = u(λ0) a(λ0) / (1 − u(λ0)) − bbw(λ0);
//! 4. η = 2 (1 − 1.2 exp(−0.9 r443 / r555));
//! 5. b_bp(λ) = b_bp(λ0) (λ0/λ)^η;
//! 6. a(λ) = (1 − u(λ)) (bbw(λ) + b_bp(λ)) / u(λ);
//! 7. ζ = a_ph(411)/a_ph(443) = 0.74 + 0.2 / (0.8 + r443/r555);
//! 8. S = 0.015 + 0.002 / (0.6 + r443/r555), ξ = a_dg(411)/a_dg(443) = exp(S Δλ);
//! 9. a_dg(443) = [a(412) − ζ a(443)] / (ξ − ζ) − [aw(412) − ζ aw(443)] / (ξ − ζ);
//! 10. a_ph(443) = a(443) − a_dg(443) − aw(443).
//!
//! Shoal scores QAA's chlorophyll-a from a_ph(443) by the global power law of Bricaud et al.
//! (1998, J. Geophys. Res. 103(C13), 31033, Table 2): a_ph(443) = 0.0654 chl^0.728, so
//! chl = (a_ph(443) / 0.0654)^(1/0.728) — an open-ocean relation, which is the point of running
//! it over inland water beside a retrieval that knows the lake's SIOPs. a_dg(443), a_ph(443) and
//! b_bp at the band nearest 555 nm are its extra products, scored against the IOPs the scene's
//! own SIOP set gives the truth's concentrations ([`truth_iops`]).

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use super::band_model::{BandModel, BandResponse};
use super::run::{Product, ProductFlags, RetrievalInputs};
use super::{Mode, RetrievalError};
use crate::control::RunControl;
use crate::correction::RrsFlags;
use crate::parse::FieldError;

/// QAA's settings as a study writes them: `Qaa()` or `Qaa(settings: (mode: Reference))`.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct QaaSettings {
    /// Improved: the v6 document's equations with sub-surface ratios, as NASA's l2gen; Reference:
    /// the IOCCG QAA_v6 spreadsheet's arithmetic, to reproduce its published numbers.
    pub mode: Mode,
}

/// The constants and conventions of a QAA variant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constants {
    /// Gordon's quadratic rrs = g0 u + g1 u² (step 1).
    pub g0: f64,
    /// Its second coefficient.
    pub g1: f64,
    /// log10 a(555) − aw(555) as a quadratic in χ (step 2).
    pub h: [f64; 3],
    /// Ratios in steps 2, 4, 7 and 8 of sub-surface rrs (the document, l2gen) rather than Rrs.
    pub sub_surface_ratios: bool,
    /// Δλ of ξ (step 8), nm; `None`: the difference of the 443 and 412 bands' centres.
    pub xi_span_nm: Option<f64>,
}

impl Constants {
    /// The v6 document (Lee et al. 2014): g0 0.089, g1 0.1245, h −1.146, −1.366, −0.469, rrs in
    /// the ratios (as NASA's l2gen after its 2020 correction), ξ over 442.5 − 415.5 = 27 nm.
    pub const DOCUMENT: Self =
        Self { g0: 0.089, g1: 0.1245, h: [-1.146, -1.366, -0.469], sub_surface_ratios: true, xi_span_nm: Some(27.0) };

    /// The IOCCG QAA_v6 spreadsheet (`QAA_v6.xlsm`), whose outputs are the published test
    /// values: g0 0.08945, g1 0.1247 (as l2gen), h at full precision, above-water Rrs in the
    /// ratios, ξ over the bands' own 443 − 412 nm.
    pub const SPREADSHEET: Self = Self {
        g0: 0.08945,
        g1: 0.1247,
        h: [-1.145_902_927_834_08, -1.365_828_264_291_76, -0.469_266_027_944_581],
        sub_surface_ratios: false,
        xi_span_nm: None,
    };

    /// The variant of `mode`.
    #[must_use]
    pub const fn of(mode: Mode) -> Self {
        match mode {
            Mode::Improved => Self::DOCUMENT,
            Mode::Reference => Self::SPREADSHEET,
        }
    }
}

/// The wavelengths QAA reads, nm, and how far a band's centre may be from each.
pub const NEEDED_NM: [f64; 5] = [412.0, 443.0, 490.0, 555.0, 670.0];
/// Largest distance of a band's centre from a wavelength QAA needs, nm (MSI's 560 and 665 nm,
/// OLCI's 665 nm, MODIS's 547 and 667 nm all within it).
pub const MAX_OFFSET_NM: f64 = 15.0;

/// The bands QAA runs on: for each of [`NEEDED_NM`] the nearest band, and pure water's
/// absorption and backscattering at every band.
#[derive(Debug, Clone, PartialEq)]
pub struct QaaBands {
    /// Band centres, nm.
    pub centre_nm: Vec<f64>,
    /// Pure-water absorption per band, m⁻¹.
    pub a_w: Vec<f64>,
    /// Pure-water backscattering per band, m⁻¹.
    pub bb_w: Vec<f64>,
    /// Indices of the bands nearest 412, 443, 490, 555 and 670 nm.
    pub at: [usize; 5],
}

impl QaaBands {
    /// The bands of `centre_nm` nearest each of [`NEEDED_NM`]; an error naming the wavelength
    /// missing when a band is more than [`MAX_OFFSET_NM`] from it.
    pub fn new(centre_nm: Vec<f64>, a_w: Vec<f64>, bb_w: Vec<f64>) -> Result<Self, RetrievalError> {
        let mut at = [0; 5];
        for (k, want) in NEEDED_NM.iter().enumerate() {
            let nearest = (0..centre_nm.len())
                .min_by(|&i, &j| (centre_nm[i] - want).abs().total_cmp(&(centre_nm[j] - want).abs()));
            match nearest {
                Some(i) if (centre_nm[i] - want).abs() <= MAX_OFFSET_NM => at[k] = i,
                other => {
                    return Err(RetrievalError::Invalid(FieldError {
                        field: "retrievals[i].Qaa".into(),
                        message: format!(
                            "QAA needs a band within {MAX_OFFSET_NM} nm of {want} nm; the nearest is {}",
                            other.map_or_else(|| "none".to_string(), |i| format!("at {:.1} nm", centre_nm[i]))
                        ),
                    }));
                }
            }
        }
        Ok(Self { centre_nm, a_w, bb_w, at })
    }
}

/// QAA's result at one pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Iops {
    /// The reference band's centre, nm (near 555 or 670).
    pub lambda0_nm: f64,
    /// Total absorption per band, m⁻¹.
    pub a: Vec<f64>,
    /// Particle backscattering per band, m⁻¹.
    pub bbp: Vec<f64>,
    /// Detritus + CDOM absorption at the 443 band, m⁻¹.
    pub adg443: f64,
    /// Phytoplankton absorption at the 443 band, m⁻¹.
    pub aph443: f64,
}

/// Run QAA v6 (the module's steps 0–10) on above-water `rrs_above` (sr⁻¹, one per band of
/// `bands`); `None` when an Rrs it reads is not positive and finite.
#[must_use]
pub fn qaa_v6(rrs_above: &[f64], bands: &QaaBands, c: &Constants) -> Option<Iops> {
    let [i412, i443, i490, i555, i670] = bands.at;
    if bands.at.iter().any(|&i| !(rrs_above.get(i).is_some_and(|v| v.is_finite() && *v > 0.0))) {
        return None;
    }
    // Step 0 (Lee et al. 2002, eq. 4) and step 1.
    let below: Vec<f64> = rrs_above.iter().map(|r| r / (0.52 + 1.7 * r)).collect();
    let u: Vec<f64> =
        below.iter().map(|r| (-c.g0 + (c.g0 * c.g0 + 4.0 * c.g1 * r).max(0.0).sqrt()) / (2.0 * c.g1)).collect();
    let ratio = if c.sub_surface_ratios { &below } else { rrs_above };
    // Step 2: the reference band and its absorption.
    let (i0, a0) = if rrs_above[i670] < 0.0015 {
        let chi = ((ratio[i443] + ratio[i490]) / (ratio[i555] + 5.0 * ratio[i670] / ratio[i490] * ratio[i670])).log10();
        (i555, bands.a_w[i555] + 10f64.powf(c.h[0] + c.h[1] * chi + c.h[2] * chi * chi))
    } else {
        (i670, bands.a_w[i670] + 0.39 * (rrs_above[i670] / (rrs_above[i443] + rrs_above[i490])).powf(1.14))
    };
    // Steps 3–6.
    let bbp0 = u[i0] * a0 / (1.0 - u[i0]) - bands.bb_w[i0];
    let r = ratio[i443] / ratio[i555];
    let eta = 2.0 * (1.0 - 1.2 * (-0.9 * r).exp());
    let lambda0 = bands.centre_nm[i0];
    let bbp: Vec<f64> = bands.centre_nm.iter().map(|l| bbp0 * (lambda0 / l).powf(eta)).collect();
    let a: Vec<f64> = (0..u.len()).map(|i| (1.0 - u[i]) * (bands.bb_w[i] + bbp[i]) / u[i]).collect();
    // Steps 7–10.
    let zeta = 0.74 + 0.2 / (0.8 + r);
    let s = 0.015 + 0.002 / (0.6 + r);
    let span = c.xi_span_nm.unwrap_or(bands.centre_nm[i443] - bands.centre_nm[i412]);
    let xi = (s * span).exp();
    let adg443 = (a[i412] - zeta * a[i443]) / (xi - zeta) - (bands.a_w[i412] - zeta * bands.a_w[i443]) / (xi - zeta);
    let aph443 = a[i443] - adg443 - bands.a_w[i443];
    Some(Iops { lambda0_nm: lambda0, a, bbp, adg443, aph443 })
}

/// Chlorophyll-a from a_ph(443) (Bricaud et al. 1998, Table 2: a_ph(443) = 0.0654 chl^0.728),
/// mg m⁻³; `None` for a non-positive a_ph.
#[must_use]
pub fn chl_from_aph443(aph443_per_m: f64) -> Option<f64> {
    (aph443_per_m > 0.0 && aph443_per_m.is_finite()).then(|| (aph443_per_m / 0.0654).powf(1.0 / 0.728))
}

/// QAA's model at the instrument's bands: the bands it reads and pure water there, and the scene
/// SIOP set's specific IOPs there (each averaged over the band's response), which turn the
/// truth's concentrations into the IOPs QAA retrieves ([`truth_iops`]).
#[derive(Debug, Clone, PartialEq)]
pub struct QaaModel {
    /// The bands QAA reads, with pure water.
    pub bands: QaaBands,
    /// The scene's SIOP set per band.
    pub scene: crate::retrieval::band_model::BandIops,
}

/// [`QaaModel`] at `inputs.bands`.
pub fn qaa_model(inputs: &RetrievalInputs<'_>) -> Result<QaaModel, RetrievalError> {
    let (siop, dir) = &inputs.scene_siop;
    let model =
        BandModel::new(siop, dir.as_deref(), &crate::water::SubstrateLibrary::embedded()?, &[], &inputs.bands, 5)?;
    let scene = model.band_iops();
    let bands = QaaBands::new(
        inputs.bands.iter().map(BandResponse::centroid_nm).collect(),
        scene.a_w.clone(),
        scene.bb_w.clone(),
    )?;
    Ok(QaaModel { bands, scene })
}

/// The true values of QAA's extra products, from the truth's concentrations and the scene's SIOP
/// set at the bands QAA reads (the forward model's own IOPs, Lee et al. 1999 as in
/// [`crate::water`]): a_dg(443) = CDOM·a*_CDOM(443) + NAP·a*_NAP(443), a_ph(443) =
/// chl·a*_ph(443), b_bp(555) = chl·b*_bph(555) + NAP·b*_bNAP(555), at the bands nearest 443 and
/// 555 nm; by key of [`crate::variable::EXTRAS`].
#[must_use]
pub fn truth_iops(model: &QaaModel, truth: &crate::instrument::Truth) -> Vec<(String, ndarray::Array2<f32>)> {
    let (i443, i555, s) = (model.bands.at[1], model.bands.at[3], &model.scene);
    let (chl, nap, cdom) = (&truth.chl_mg_m3, &truth.nap_g_m3, &truth.cdom_per_m);
    let at = |f: &dyn Fn(usize) -> f64| {
        ndarray::Array2::from_shape_fn(chl.dim(), |(r, c)| {
            if truth.is_water(r, c) { f(r * chl.ncols() + c) as f32 } else { 0.0 }
        })
    };
    let v = |m: &ndarray::Array2<f32>, k: usize| f64::from(m.as_slice().map_or(0.0, |x| x[k]));
    let adg = at(&|k| v(cdom, k) * s.a_cdom[i443] + v(nap, k) * s.a_nap[i443]);
    let aph = at(&|k| v(chl, k) * s.a_ph[i443]);
    let bbp = at(&|k| v(chl, k) * s.bb_ph[i555] + v(nap, k) * s.bb_nap[i555]);
    crate::variable::EXTRAS.iter().map(|x| x.key.to_string()).zip([adg, aph, bbp]).collect()
}

/// Run QAA over the image: per water pixel whose five bands are valid, the IOPs, the chl they
/// give and the flags (returned where a_ph(443), a_dg(443) and b_bp are positive).
pub fn retrieve_qaa(
    model: &QaaModel,
    settings: &QaaSettings,
    inputs: &RetrievalInputs<'_>,
    control: &RunControl,
) -> Result<Product, RetrievalError> {
    let constants = Constants::of(settings.mode);
    let bands = &model.bands;
    let (rows, cols, nb) = inputs.rrs.dim();
    // Per pixel: chl, adg443, aph443, bbp near 555; and the flags. Rows in parallel.
    let i555 = bands.at[3];
    let rows_out: Vec<Vec<([f32; 4], u8)>> = control.map_rows(rows, |at| {
        let r = at.index();
        let mut rrs = vec![0.0; nb];
        let row = (0..cols)
            .map(|c| {
                at.column(c);
                if !inputs.surface.is_water(r, c) {
                    return ([0.0; 4], ProductFlags::LAND);
                }
                let bad = RrsFlags::INVALID | RrsFlags::SATURATED;
                let valid = bands.at.iter().all(|&b| inputs.flags[[r, c, b]] & bad == 0);
                for (b, v) in rrs.iter_mut().enumerate() {
                    *v = f64::from(inputs.rrs[[r, c, b]]);
                }
                // Physical IOPs only: a_dg(443) positive, and b_bp positive (b_bp(λ) has b_bp(λ0)'s
                // sign at every band; over very clear water u·a/(1 − u) may fall below b_bw).
                let iops = valid
                    .then(|| qaa_v6(&rrs, bands, &constants))
                    .flatten()
                    .filter(|x| x.adg443 > 0.0 && x.bbp.first().is_some_and(|b| *b > 0.0));
                match iops.as_ref().and_then(|x| Some((x, chl_from_aph443(x.aph443)?))) {
                    Some((x, chl)) => (
                        [chl as f32, x.adg443 as f32, x.aph443 as f32, x.bbp[i555] as f32],
                        ProductFlags::RETURNED | ProductFlags::PHYSICAL,
                    ),
                    None => ([0.0; 4], ProductFlags::FAILED),
                }
            })
            .collect();
        Ok::<_, RetrievalError>(row)
    })?;
    let out = Array2::from_shape_fn((rows, cols), |(r, c)| rows_out[r][c].0);
    let flags = Array2::from_shape_fn((rows, cols), |(r, c)| rows_out[r][c].1);
    let plane = |k: usize| out.mapv(|v| v[k]);
    // a_dg(443), a_ph(443), b_bp(555): the order of `crate::variable::EXTRAS`.
    let extras = crate::variable::EXTRAS.iter().enumerate().map(|(k, v)| (v.key.to_string(), plane(k + 1))).collect();
    Ok(Product { chl_mg_m3: Some(plane(0)), extras, ..Product::bare(super::algorithm::QAA.title.into(), flags) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bands(centres: [f64; 6]) -> QaaBands {
        // The IOCCG spreadsheet's pure water (Pope & Fry 1997; Morel 1974).
        let a_w = vec![0.00473, 0.00635, 0.015, 0.0325, 0.0596, 0.439];
        let bb_w = vec![0.0034, 0.0025, 0.00158, 0.00133, 0.0009, 0.00034];
        QaaBands::new(centres.to_vec(), a_w, bb_w).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_band_set_without_443_is_refused_by_name() {
        let e = QaaBands::new(vec![412.0, 490.0, 555.0, 670.0], vec![0.0; 4], vec![0.0; 4]).unwrap_err();
        assert!(e.to_string().contains("443 nm") && e.to_string().contains("nearest is at 412.0 nm"), "{e}");
    }

    #[test]
    fn the_iops_returned_give_back_the_rrs_they_came_from() {
        // Closure of steps 0, 1 and 6: Gordon's quadratic forward model (rrs = g0 u + g1 u²,
        // u = bb/(a + bb), Rrs = 0.52 rrs/(1 − 1.7 rrs)) on QAA's a and bb = bbw + bbp gives back
        // every band's Rrs, whatever λ0 and η were.
        let b = bands([412.0, 443.0, 489.0, 510.0, 555.0, 670.0]);
        for (c, rrs) in [
            (Constants::DOCUMENT, [0.0012, 0.00169, 0.00329, 0.00404, 0.00748, 0.00346]),
            (Constants::SPREADSHEET, [0.0045, 0.0041, 0.00402, 0.00295, 0.00169, 0.00018]),
        ] {
            let x = qaa_v6(&rrs, &b, &c).unwrap_or_else(|| panic!("no result"));
            for i in 0..6 {
                let bb = b.bb_w[i] + x.bbp[i];
                let u = bb / (x.a[i] + bb);
                let below = c.g0 * u + c.g1 * u * u;
                let back = 0.52 * below / (1.0 - 1.7 * below);
                assert!((back / rrs[i] - 1.0).abs() < 1e-12, "band {i}: {back} vs {}", rrs[i]);
            }
        }
    }

    #[test]
    fn a_pixel_without_a_positive_rrs_where_qaa_reads_returns_nothing() {
        let b = bands([412.0, 443.0, 489.0, 510.0, 555.0, 670.0]);
        assert!(qaa_v6(&[0.001, 0.001, 0.001, 0.001, 0.0, 0.001], &b, &Constants::DOCUMENT).is_none());
        assert!(qaa_v6(&[0.001, f64::NAN, 0.001, 0.001, 0.001, 0.001], &b, &Constants::DOCUMENT).is_none());
        assert_eq!(chl_from_aph443(-0.01), None);
        // Bricaud et al. (1998): a_ph(443) = 0.0654 at 1 mg m⁻³.
        assert!((chl_from_aph443(0.0654).unwrap_or(0.0) - 1.0).abs() < 1e-12);
    }
}
