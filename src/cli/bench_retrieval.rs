//! `shoal bench` rows for the retrievals, side by side with the reference codes measured on this
//! machine class ([`super::bench_reference`]: where and when each figure was measured).
//! Single-threaded, on synthetic pixels drawn from the same ranges as the scenes, timed with the
//! instrument-like noise the study runs see (1 % of Rrs, Gaussian) and for at least a second
//! per row (0.3 s with `--quick`), so a row is not a few milliseconds of jitter; closure is
//! checked on the same pixels without noise. And the full Lake Hume study end to end.

use std::fmt::Write as _;
use std::time::Instant;

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use super::CliError;
use crate::control::RunControl;
use crate::retrieval::almi::{AlmiSet, AlmiSettings};
use crate::retrieval::almi_lanes::{PackedSets, Scratch, invert_packed};
use crate::retrieval::sambuca::{
    self, Observation, SambucaSettings, invert as sambuca_invert, invert_in, objective_value,
};
use crate::retrieval::sets::ALMI_SETS;
use crate::retrieval::{BandModel, BandResponse, Parameters};
use crate::study::{StudySpec, run_study};
use crate::timing::{Summary, measure};
use crate::water::{SiopSpec, SubstrateLibrary, rrs_above_from_below};

fn gaussian_bands(centres_fwhm: &[(f64, f64)]) -> Vec<BandResponse> {
    centres_fwhm
        .iter()
        .map(|&(c, w)| {
            let s = w / 2.354_820_045;
            let x: Vec<f64> =
                (0..=(6.0 * s).ceil() as i32 * 2).map(|i| (c - 3.0 * s).round() + f64::from(i) * 0.5).collect();
            let weights = x.iter().map(|x| (-0.5 * ((x - c) / s).powi(2)).exp()).collect();
            BandResponse { name: format!("B{c:.0}"), wavelengths_nm: x, weights }
        })
        .collect()
}

fn err<E: std::fmt::Display>(e: E) -> CliError {
    CliError::Run(e.to_string())
}

/// Pixels per second of `invert` over `pixels`, cycling through them until at least `min_s`
/// seconds and one full pass have gone by.
fn timed_rate(min_s: f64, pixels: usize, mut invert: impl FnMut(usize)) -> f64 {
    let start = Instant::now();
    let mut done = 0usize;
    loop {
        invert(done % pixels);
        done += 1;
        // The clock is read every 256 pixels (and at the end of a pass), not after every pixel:
        // at millions of pixels a second its ~20 ns would be counted as the kernel's (5 % of
        // aLMI's samples in perf).
        let check = done.is_multiple_of(256) || done.is_multiple_of(pixels);
        if done >= pixels && check && start.elapsed().as_secs_f64() >= min_s {
            break;
        }
    }
    done as f64 / start.elapsed().as_secs_f64()
}

fn min_seconds(quick: bool) -> f64 {
    if quick { 0.3 } else { 1.0 }
}

/// aLMI pixels per second on one core, (noise-weighted, unweighted as the reference), and QAA
/// v6 on the same pixels.
fn almi_rate(quick: bool) -> Result<(f64, f64, f64, usize), CliError> {
    // The 8 MODIS-like bands of the reference's configuration, as 10 nm Gaussians.
    let bands = gaussian_bands(&[
        (411.5, 10.0),
        (441.5, 10.0),
        (486.5, 10.0),
        (528.5, 10.0),
        (551.0, 10.0),
        (665.5, 10.0),
        (676.5, 10.0),
        (746.5, 10.0),
    ]);
    let lib = SubstrateLibrary::embedded().map_err(err)?;
    let sets: Vec<AlmiSet> = ALMI_SETS
        .iter()
        .map(|n| {
            let spec = SiopSpec::preset(n).map_err(err)?;
            Ok(AlmiSet {
                name: (*n).into(),
                iops: BandModel::new(&spec, None, &lib, &[], &bands, 3).map_err(err)?.band_iops(),
            })
        })
        .collect::<Result<_, CliError>>()?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let n = if quick { 20_000 } else { 100_000 };
    let o = &sets[4].iops;
    let pixels: Vec<Vec<f64>> = (0..n)
        .map(|_| {
            let chl = 10f64.powf(rng.random_range(0.0..2.0));
            (0..bands.len())
                .map(|k| {
                    let a = o.a_w[k] + chl * o.a_ph[k] + o.a_cdom[k] + 10.0 * o.a_nap[k];
                    let bb = o.bb_w[k] + chl * o.bb_ph[k] + 10.0 * o.bb_nap[k];
                    let u = bb / (a + bb);
                    rrs_above_from_below((0.084 + 0.17 * u) * u) * (1.0 + 0.02 * (rng.random::<f64>() - 0.5))
                })
                .collect()
        })
        .collect();
    let valid = vec![true; bands.len()];
    let nedr = vec![1e-4; bands.len()];
    let packed = PackedSets::new(&sets);
    let rate = |weighting: bool| {
        let settings = AlmiSettings { noise_weighting: weighting, ..AlmiSettings::default() };
        let mut sink = 0.0;
        let mut scratch = Scratch::default();
        let r = timed_rate(min_seconds(quick), pixels.len(), |i| {
            sink += invert_packed(&mut scratch, &packed, &settings, &pixels[i], &valid, &nedr).chl;
        });
        std::hint::black_box(sink);
        r
    };
    // QAA v6 on the same pixels and bands, with the sets' pure water (the bands nearest 412, 443,
    // 490, 555 and 670 nm of these eight).
    let qaa_bands = crate::retrieval::qaa::QaaBands::new(
        bands.iter().map(BandResponse::centroid_nm).collect(),
        o.a_w.clone(),
        o.bb_w.clone(),
    )
    .map_err(err)?;
    let constants = crate::retrieval::qaa::Constants::DOCUMENT;
    let mut sink = 0.0;
    let qaa = timed_rate(min_seconds(quick), pixels.len(), |i| {
        sink += crate::retrieval::qaa::qaa_v6(&pixels[i], &qaa_bands, &constants).map_or(0.0, |x| x.aph443);
    });
    std::hint::black_box(sink);
    Ok((rate(true), rate(false), qaa, bands.len()))
}

/// SAMBUCA pixels per second on one core, and closure: share of noise-free pixels fitted at least
/// as well as the truth, and share within 1 % of the true depth.
fn sambuca_rate(
    bands: &[BandResponse],
    substrates: &[&str],
    n: usize,
    quick: bool,
) -> Result<(f64, f64, f64), CliError> {
    let spec = SiopSpec::preset("heron_island").map_err(err)?;
    let lib = SubstrateLibrary::embedded().map_err(err)?;
    let names: Vec<String> = substrates.iter().map(|s| (*s).to_string()).collect();
    let settings = SambucaSettings::default();
    let model = BandModel::new(&spec, None, &lib, &names, bands, settings.nodes_per_band).map_err(err)?;
    let nb = model.n_bands();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let inv = (1.0 / 0.95, 1.0 / 0.999);
    let pairs: Vec<(usize, usize)> = if names.len() > 1 {
        (0..names.len()).flat_map(|i| (i + 1..names.len()).map(move |j| (i, j))).collect()
    } else {
        vec![(0, usize::MAX)]
    };
    let truths: Vec<Parameters> = (0..n)
        .map(|_| Parameters {
            chl: 10f64.powf(rng.random_range(-1.5..0.5)),
            cdom: 10f64.powf(rng.random_range(-3.0..-1.0)),
            nap: 10f64.powf(rng.random_range(-0.5..0.7)),
            depth_m: Some(rng.random_range(0.5..8.0)),
            substrates: {
                let (i, j) = pairs[rng.random_range(0..pairs.len())];
                (i, j, rng.random_range(0.0..1.0))
            },
        })
        .collect();
    // NEΔRrs of the nominal instrument over bright reef water: ~1 % of Rrs.
    let observed: Vec<Vec<f64>> = truths
        .iter()
        .map(|p| {
            let mut m = vec![0.0; nb];
            model.evaluate(p, inv, &mut m, None);
            m
        })
        .collect();
    let valid = vec![true; nb];
    let nedr_of = |o: &[f64]| -> Vec<f64> { o.iter().map(|v| (0.01 * v).max(1e-5)).collect() };
    // Timed on noisy pixels (the noise the NEΔRrs describes), as the study's pixels are.
    let noisy = with_noise(&observed, &mut rng);
    let mut sink = 0.0;
    // Working arrays kept from pixel to pixel, as the study's rows keep them.
    let mut scratch = sambuca::Scratch::default();
    let rate = timed_rate(min_seconds(quick), n, |i| {
        let nedr = nedr_of(&noisy[i]);
        let obs = Observation { rrs: &noisy[i], valid: &valid, nedr: &nedr, inv_cos: inv };
        sink += invert_in(&mut scratch, &model, &settings, &obs).depth_m;
    });
    std::hint::black_box(sink);
    let results: Vec<_> = observed
        .iter()
        .map(|o| {
            let nedr = nedr_of(o);
            let obs = Observation { rrs: o, valid: &valid, nedr: &nedr, inv_cos: inv };
            (sambuca_invert(&model, &settings, &obs), nedr)
        })
        .collect();
    let (mut no_worse, mut depth_ok) = (0usize, 0usize);
    for ((res, nedr), (truth, o)) in results.iter().zip(truths.iter().zip(&observed)) {
        let weights: Vec<f64> = nedr.iter().map(|v| 1.0 / v).collect();
        let obs = Observation { rrs: o, valid: &valid, nedr, inv_cos: inv };
        let mut m = vec![0.0; nb];
        model.evaluate(truth, inv, &mut m, None);
        let at_truth = objective_value(settings.objective, &obs, &weights, &m);
        no_worse += usize::from(res.objective <= at_truth * (1.0 + 1e-9) + 1e-12);
        depth_ok += usize::from((res.depth_m / truth.depth_m.unwrap_or(1.0) - 1.0).abs() < 0.01);
    }
    Ok((rate, 100.0 * no_worse as f64 / n as f64, 100.0 * depth_ok as f64 / n as f64))
}

/// SAMBUCA's reference mode (the CSIRO package's fit) on the same kind of pixels: pixels per
/// second on one core, the share of noise-free pixels fitted at least as well as the truth, and
/// the share within 1 % of the true depth. Bounds of the reference data's wide set-up (start
/// depth 14.95 m).
fn sambuca_reference_rate(
    bands: &[BandResponse],
    substrates: &[&str],
    n: usize,
    quick: bool,
) -> Result<(f64, f64, f64), CliError> {
    use crate::retrieval::sambuca_reference::{self as reference, ReferenceModel, ReferenceScratch, distance_f};
    let spec = SiopSpec::preset("heron_island").map_err(err)?;
    let lib = SubstrateLibrary::embedded().map_err(err)?;
    let names: Vec<String> = substrates.iter().map(|s| (*s).to_string()).collect();
    let model = ReferenceModel::from_siop(&spec, None, &lib, &names, bands).map_err(err)?;
    let (p_min, p_max) = ([0.01, 0.0005, 0.01, 0.1, 0.0], [10.0, 1.0, 30.0, 30.0, 1.0]);
    let nb = model.n_bands();
    let inv = (1.0 / 0.95, 1.0 / 0.999);
    let pairs = model.pairs().to_vec();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let mut scratch = ReferenceScratch::default();
    let truths: Vec<([f64; 5], (usize, usize))> = (0..n)
        .map(|_| {
            let x = [
                10f64.powf(rng.random_range(-1.5..0.5)),
                10f64.powf(rng.random_range(-3.0..-1.0)),
                10f64.powf(rng.random_range(-0.5..0.7)),
                rng.random_range(0.5..8.0),
                rng.random_range(0.0..1.0),
            ];
            (x, pairs[rng.random_range(0..pairs.len())])
        })
        .collect();
    let observed: Vec<Vec<f64>> = truths
        .iter()
        .map(|(x, pair)| {
            let mut m = vec![0.0; nb];
            model.closed_rrs(x, *pair, inv, &mut m, None, &mut scratch);
            m
        })
        .collect();
    let nedr_of = |o: &[f64]| -> Vec<f64> { o.iter().map(|v| (0.01 * v).max(1e-5)).collect() };
    let noisy = with_noise(&observed, &mut rng);
    let mut sink = 0.0;
    let rate = timed_rate(min_seconds(quick), n, |i| {
        sink += reference::invert(&model, &p_min, &p_max, &noisy[i], &nedr_of(&noisy[i]), inv).fun;
    });
    std::hint::black_box(sink);
    let results: Vec<_> = observed
        .iter()
        .map(|o| {
            let nedr = nedr_of(o);
            (reference::invert(&model, &p_min, &p_max, o, &nedr, inv), nedr)
        })
        .collect();
    let (mut no_worse, mut depth_ok) = (0usize, 0usize);
    for ((res, nedr), ((x, pair), o)) in results.iter().zip(truths.iter().zip(&observed)) {
        let mut m = vec![0.0; nb];
        model.closed_rrs(x, *pair, inv, &mut m, None, &mut scratch);
        let at_truth = distance_f(o, &m, nedr);
        no_worse += usize::from(res.fun <= at_truth * (1.0 + 1e-9) + 1e-12);
        depth_ok += usize::from((res.x[3] / x[3] - 1.0).abs() < 0.01);
    }
    Ok((rate, 100.0 * no_worse as f64 / n as f64, 100.0 * depth_ok as f64 / n as f64))
}

/// `observed` with Gaussian noise of 1 % of each value (the NEΔRrs the fits are given).
fn with_noise(observed: &[Vec<f64>], rng: &mut Xoshiro256PlusPlus) -> Vec<Vec<f64>> {
    observed
        .iter()
        .map(|o| {
            o.iter()
                .map(|v| {
                    let z: f64 = rng.sample(rand_distr::StandardNormal);
                    v + z * (0.01 * v).max(1e-5)
                })
                .collect()
        })
        .collect()
}

/// Append the retrieval rows to `out`.
pub fn retrieval_rows(out: &mut String, quick: bool) -> Result<(), CliError> {
    let _ = writeln!(out, "## Retrievals, one core (synthetic pixels)");
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "| retrieval | bands | pixels/s per core (noisy pixels) | reference (Python), pixels/s | × reference | closure (noise-free) |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    let (weighted, unweighted, qaa, nb) = almi_rate(quick)?;
    let dea = super::bench_reference::DEA_ALMI;
    for (label, rate) in [("noise-weighted", weighted), ("unweighted (as DEA)", unweighted)] {
        let _ = writeln!(
            out,
            "| aLMI, 8 SIOP sets, {label} | {nb} | {rate:.0} | {} | {} | 1e-6 (test) |",
            dea.text(),
            dea.ratio_here(rate)
        );
    }
    let _ = writeln!(
        out,
        "| QAA v6 (document), the same pixels | {nb} | {qaa:.0} | – | – | IOCCG sheet to 1e-9 m⁻¹ (test) |"
    );
    let casi: Vec<(f64, f64)> = (0..28).map(|i| (430.0 + 15.0 * f64::from(i), 10.0)).collect();
    let alos = [(460.0, 70.0), (560.0, 70.0), (650.0, 60.0), (825.0, 120.0)];
    let n = if quick { 200 } else { 1000 };
    for (label, bands, subs, reference) in [
        (
            "SAMBUCA-style, 3 substrate pairs",
            gaussian_bands(&casi),
            vec!["acropora", "sand", "turf_algae"],
            super::bench_reference::SAMBUCA_FIT_28,
        ),
        (
            "SAMBUCA-style, 1 substrate pair",
            gaussian_bands(&alos),
            vec!["sand", "seagrass"],
            super::bench_reference::SAMBUCA_FIT_4,
        ),
    ] {
        let (rate, no_worse, depth_ok) = sambuca_rate(&bands, &subs, n, quick)?;
        let _ = writeln!(
            out,
            "| {label} | {} | {rate:.0} | {} | {} | {no_worse:.1} % no worse than truth; depth within 1 % in {depth_ok:.1} % |",
            bands.len(),
            reference.text(),
            reference.ratio_here(rate)
        );
        let (rate, no_worse, depth_ok) = sambuca_reference_rate(&bands, &subs, n / 4, quick)?;
        let _ = writeln!(
            out,
            "| {label}, reference mode (SLSQP from (max − min)/2) | {} | {rate:.0} | {} | {} | {no_worse:.1} % no worse than truth; depth within 1 % in {depth_ok:.1} % |",
            bands.len(),
            reference.text(),
            reference.ratio_here(rate)
        );
    }
    let _ = writeln!(out);
    let _ = writeln!(out, "{}", super::bench_reference::SIDE_BY_SIDE);
    if let Some(w) = super::bench_reference::other_machine(super::bench::cpu_model()) {
        let _ = writeln!(out);
        let _ = writeln!(out, "{w}");
    }
    let _ = writeln!(out);
    let _ = writeln!(out, "{}", super::bench_reference::SUPERSEDED);
    let _ = writeln!(out);
    // The whole default study.
    let spec = StudySpec::default_study().map_err(err)?;
    let mut resolved = spec.resolve(None).map_err(err)?;
    if quick {
        for (_, _, c) in &mut resolved.runs {
            c.fidelity.decimation = 4;
        }
    }
    // Three runs (one with --quick): the median and range, wall and CPU.
    let mut samples = Vec::new();
    let mut result = None;
    for _ in 0..if quick { 1 } else { 3 } {
        let (r, sample) = measure(|| run_study(&resolved, &RunControl::new(), false, |_, _| Ok(())));
        result = Some(r.map_err(err)?);
        samples.push(sample);
    }
    let time = Summary::of(&samples);
    let runs = result.as_ref().map_or(0, |r| r.runs.len());
    let pixels: usize = result.iter().flat_map(|r| &r.runs).map(|r| r.report.shape.0 * r.report.shape.1).sum();
    let _ = writeln!(
        out,
        "Full study `{}` ({runs} runs, {pixels} pixels{}), chain and aLMI, without writing files, on {} threads: wall {}, CPU {}.",
        spec.name,
        if quick { ", decimation 4" } else { "" },
        rayon::current_num_threads(),
        time.wall_text(),
        time.cpu_text()
    );
    let _ = writeln!(out);
    Ok(())
}
