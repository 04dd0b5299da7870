//! The SAMBUCA-style fit's warm pair starts (`SambucaSettings::warm_pairs`) against a cold start
//! for every pair, on the kind of pixels `shoal bench` times: 28 Gaussian bands (430–835 nm,
//! 10 nm FWHM), three reef substrates (three pairs), the Heron Island SIOPs, 1 % noise; and
//! the working arrays a loop over pixels keeps (`invert_in`) against fresh ones.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use shoal::retrieval::sambuca::{Observation, SambucaPixel, Scratch, invert, invert_in, objective_value};
use shoal::retrieval::{BandModel, BandResponse, Objective, Parameters, SambucaSettings, Starts};
use shoal::water::{SiopSpec, SubstrateLibrary};

const INV_COS: (f64, f64) = (1.0 / 0.95, 1.0 / 0.999);

fn model() -> BandModel {
    model_of(28)
}

/// The bench's model with its first `n_bands` bands.
fn model_of(n_bands: i32) -> BandModel {
    let bands: Vec<BandResponse> = (0..n_bands)
        .map(|i| {
            let (c, s): (f64, f64) = (430.0 + 15.0 * f64::from(i), 10.0 / 2.354_820_045);
            let x: Vec<f64> =
                (0..=(6.0 * s).ceil() as i32 * 2).map(|i| (c - 3.0 * s).round() + f64::from(i) * 0.5).collect();
            let weights = x.iter().map(|x| (-0.5 * ((x - c) / s).powi(2)).exp()).collect();
            BandResponse { name: format!("B{c:.0}"), wavelengths_nm: x, weights }
        })
        .collect();
    let names: Vec<String> = ["acropora", "sand", "turf_algae"].iter().map(|s| (*s).to_string()).collect();
    let spec = SiopSpec::preset("heron_island").unwrap();
    BandModel::new(&spec, None, &SubstrateLibrary::embedded().unwrap(), &names, &bands, 3).unwrap()
}

/// `n` truths drawn as the bench draws them, and their modelled band Rrs.
fn pixels(model: &BandModel, n: usize, seed: u64) -> Vec<(Parameters, Vec<f64>)> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let pairs = [(0, 1), (0, 2), (1, 2)];
    (0..n)
        .map(|_| {
            let p = Parameters {
                chl: 10f64.powf(rng.random_range(-1.5..0.5)),
                cdom: 10f64.powf(rng.random_range(-3.0..-1.0)),
                nap: 10f64.powf(rng.random_range(-0.5..0.7)),
                depth_m: Some(rng.random_range(0.5..8.0)),
                substrates: {
                    let (i, j) = pairs[rng.random_range(0..pairs.len())];
                    (i, j, rng.random_range(0.0..1.0))
                },
            };
            let mut m = vec![0.0; model.n_bands()];
            model.evaluate(&p, INV_COS, &mut m, None);
            (p, m)
        })
        .collect()
}

fn nedr(rrs: &[f64]) -> Vec<f64> {
    rrs.iter().map(|v| (0.01 * v).max(1e-5)).collect()
}

fn fit(model: &BandModel, settings: &SambucaSettings, rrs: &[f64], nedr: &[f64]) -> SambucaPixel {
    let valid = vec![true; rrs.len()];
    invert(model, settings, &Observation { rrs, valid: &valid, nedr, inv_cos: INV_COS })
}

#[test]
fn warm_pair_starts_reach_the_cold_starts_minima_in_fewer_iterations() {
    let model = model();
    let cold = SambucaSettings { warm_pairs: false, ..SambucaSettings::default() };
    let warm = SambucaSettings::default();
    assert!(warm.warm_pairs, "warm pair starts are the default");
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let (mut same, mut worse, mut iterations) = (0, 0, (0u64, 0u64));
    let n = 300;
    for (_, m) in pixels(&model, n, 17) {
        let noisy: Vec<f64> =
            m.iter().map(|v| v + (0.01 * v).max(1e-5) * rng.sample::<f64, _>(rand_distr::StandardNormal)).collect();
        let nedr = nedr(&noisy);
        let (c, w) = (fit(&model, &cold, &noisy, &nedr), fit(&model, &warm, &noisy, &nedr));
        iterations.0 += u64::from(c.iterations);
        iterations.1 += u64::from(w.iterations);
        // The same minimum: objectives equal to the optimiser's stopping tolerance (a relative
        // decrease of 1e-10 a step, far below 1e-6); a pure substrate (fraction 0 or 1) is the
        // same fit under two pairs, so the pair itself may differ.
        if (w.objective / c.objective - 1.0).abs() <= 1e-6 {
            same += 1;
        } else if w.objective > c.objective {
            worse += 1;
        }
    }
    // Measured: all 300 the same minimum, 25 % fewer iterations. A warm start may find another
    // basin; more than 1 % of pixels ending worse would make it a worse default.
    assert!(worse * 100 <= n, "{worse} of {n} pixels ended worse warm than cold ({same} the same)");
    let ratio = iterations.1 as f64 / iterations.0 as f64;
    eprintln!(
        "warm pairs: {same} of {n} the cold minimum, {worse} worse; iterations {:.1} → {:.1} a pixel ({ratio:.3}×)",
        iterations.0 as f64 / n as f64,
        iterations.1 as f64 / n as f64
    );
    assert!(ratio < 0.85, "warm pairs took {ratio:.3}× the cold starts' iterations");
}

#[test]
fn warm_pair_starts_keep_noise_free_closure() {
    // Noise-free pixels: every fit at least as good as the truth (to 1e-9 relative, the
    // objective's rounding), as `shoal bench` counts it for the cold starts.
    let model = model();
    let settings = SambucaSettings::default();
    let n = 200;
    let mut worse = 0;
    for (truth, m) in pixels(&model, n, 23) {
        let nedr = nedr(&m);
        let got = fit(&model, &settings, &m, &nedr);
        let weights: Vec<f64> = nedr.iter().map(|v| 1.0 / v).collect();
        let valid = vec![true; m.len()];
        let obs = Observation { rrs: &m, valid: &valid, nedr: &nedr, inv_cos: INV_COS };
        let mut at = vec![0.0; m.len()];
        model.evaluate(&truth, INV_COS, &mut at, None);
        let at_truth = objective_value(settings.objective, &obs, &weights, &at);
        worse += usize::from(got.objective > at_truth * (1.0 + 1e-9) + 1e-12);
    }
    assert_eq!(worse, 0, "{worse} of {n} noise-free pixels fitted worse than the truth");
}

/// `invert_in` keeps its working arrays from pixel to pixel: whatever the scratch held (another
/// model's band count, another objective, a failed pixel), each pixel is the one a fresh
/// `invert` returns, to the bit.
#[test]
fn a_reused_scratch_gives_each_pixel_as_a_fresh_one_does() {
    let models = [model(), model_of(5)];
    let settings = [
        SambucaSettings::default(),
        SambucaSettings { objective: Objective::AlphaF, ..SambucaSettings::default() },
        SambucaSettings { noise_weighting: false, starts: Starts::ShallowAndDeep, ..SambucaSettings::default() },
    ];
    let mut scratch = Scratch::default();
    let mut compared = 0;
    for (k, (_, m)) in pixels(&models[0], 12, 23).into_iter().enumerate() {
        for model in &models {
            let rrs = &m[..model.n_bands()];
            let nedr = nedr(rrs);
            // Every third pixel with two valid bands only: refused, its arrays half written.
            let valid: Vec<bool> = (0..rrs.len()).map(|b| k % 3 != 2 || b < 2).collect();
            let obs = Observation { rrs, valid: &valid, nedr: &nedr, inv_cos: INV_COS };
            for s in &settings {
                let (fresh, reused) = (invert(model, s, &obs), invert_in(&mut scratch, model, s, &obs));
                assert_eq!(format!("{reused:?}"), format!("{fresh:?}"), "pixel {k}, {} bands", model.n_bands());
                compared += usize::from(fresh.ok);
            }
        }
    }
    // Most pixels are fitted (not only refused ones compared).
    assert!(compared >= 40, "{compared}");
}
