//! SAMBUCA's reference mode against the CSIRO package's own results on 160 pixels in three
//! set-ups (`tests/data/retrieval_reference/sambuca`, see PROVENANCE.md and the reference's README
//! §2): the forward model, band sums and objective to rounding; SLSQP's behaviour — success, the
//! stall, the pair kept — as the package shows it.
//!
//! Tolerances and why:
//! - Deterministic quantities (f at the start and at the truth, band rrs at the truth and at the
//!   package's result): 1e-10 relative (f: relative to |f| + 1e-5, since f at the truth of a
//!   noise-free pixel is pure rounding, 0 to 4e-8). The same f64 formulas summed in another order differ by
//!   ~1e-15; 1e-10 leaves room for libm's `exp`/`powf` against numpy's (≤ 1 ulp each).
//! - The fits: the package's x is not reproducible to rounding by any other SLSQP — SciPy 1.15.3
//!   (Fortran) and 1.17.1 (C) agree on no x bit for bit, and keep different pairs in 7 of 90
//!   pixels (README §2.8). The test therefore pins behaviour:
//!   - exact where the package is exact: every fit's success flag; the Shoal-bounds set-up (every
//!     fit stalls at depth 14.95 and q 0.5 bit for bit, pair 0 kept; its summed SLSQP iterations
//!     equal the package's, 1518); no stall in the ALOS set-up;
//!   - the iteration count summed per set-up within 5 % of the package's (measured: 0.5 %, 0 %,
//!     2.5 %): the same algorithm, step for step, not merely another optimiser;
//!   - in the wide set-up, where the quasi-Newton matrix reaches condition numbers of 1e12 and
//!     fits diverge chaotically, bands from this port's measured agreement (Shoal port vs SciPy
//!     1.17.1 / vs 1.15.3 / the two SciPys with each other): stall flag 243 / 241 / 262 of 270
//!     fits (band ≥ 88 %); kept pair 78 of 90 (band ≥ 85 %); x within 1e-2 in 215 / 214 / 225
//!     (band ≥ 72 %, the ALOS set-up's 30 of 40 being the lowest); stalled kept pairs 64 against
//!     71 (band ± 10). These are looser than the two SciPys' agreement, and the disagreement has
//!     a direction — the port leaves the start depth in ~7 fits where the package stalls, never
//!     the reverse in more than 1 — whose cause is not found (candidate: the QP step in those
//!     ill-conditioned matrices, which SciPy solves through LDP/NNLS and Shoal by an active set
//!     on the same factor). They are regression guards, not a claim of agreement.

use serde_json::Value;
use shoal::retrieval::sambuca_reference::{
    ReferenceModel, ReferenceScratch, ReferenceSpectra, distance_f, invert, start,
};
use shoal::spectral::Table;

use super::data;

fn table(name: &str) -> Table {
    Table::from_file(&data(&format!("retrieval_reference/sambuca/{name}"))).unwrap()
}

fn numbers(t: &Table, column: &str) -> Vec<f64> {
    t.column_str(column).unwrap().iter().map(|s| if s.is_empty() { f64::NAN } else { s.parse().unwrap() }).collect()
}

fn strings(t: &Table, column: &str) -> Vec<String> {
    t.column_str(column).unwrap().iter().map(|s| (*s).to_string()).collect()
}

fn array5(v: &Value) -> [f64; 5] {
    let a: Vec<f64> = v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    [a[0], a[1], a[2], a[3], a[4]]
}

/// One set-up: the model, bounds, NEDR.
struct Setup {
    name: String,
    model: ReferenceModel,
    p_min: [f64; 5],
    p_max: [f64; 5],
    nedr: Vec<f64>,
}

/// In-water inverse cosines of the package's defaults: sun 30° in air, view 0°, n = 1.33784.
fn inv_cos() -> (f64, f64) {
    let theta_w = (30f64.to_radians().sin() / 1.337_84).asin();
    (1.0 / theta_w.cos(), 1.0)
}

fn setups() -> Vec<Setup> {
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(data("retrieval_reference/sambuca/setups.json")).unwrap())
            .unwrap();
    let inputs = table("inputs_1nm.csv");
    let filters = table("filters_1nm.csv");
    let wavelengths = numbers(&inputs, "wavelength_nm");
    assert_eq!(numbers(&filters, "wavelength_nm"), wavelengths);
    ["CASI28_HI3_wide", "CASI28_HI3_shoalbounds", "ALOS4_MB_notebook"]
        .iter()
        .map(|&name| {
            let s = &json[name];
            let substrates: Vec<String> =
                s["substrates"].as_array().unwrap().iter().map(|v| v.as_str().unwrap().to_string()).collect();
            let bands = s["bands"].as_array().unwrap();
            let filter_columns: Vec<Vec<f64>> = bands
                .iter()
                .map(|b| {
                    let k = b["band"].as_u64().unwrap();
                    let column =
                        if name.starts_with("CASI") { format!("CASI04_b{k:02}") } else { format!("ALOS_b{k}") };
                    numbers(&filters, &column)
                })
                .collect();
            let spectra = ReferenceSpectra::sambuca_core_defaults(
                wavelengths.clone(),
                numbers(&inputs, "a_water"),
                numbers(&inputs, "a_ph_star"),
                substrates.clone(),
                substrates.iter().map(|n| numbers(&inputs, &n.replace(' ', "_"))).collect(),
            );
            Setup {
                name: name.to_string(),
                model: ReferenceModel::new(spectra, &filter_columns).unwrap(),
                p_min: array5(&s["p_min"]),
                p_max: array5(&s["p_max"]),
                nedr: bands.iter().map(|b| b["nedr"].as_f64().unwrap()).collect(),
            }
        })
        .collect()
}

/// Per (set-up, pixel): the observed and the noise-free sub-surface band rrs.
fn band_values(setup: &str, column: &str) -> std::collections::BTreeMap<usize, Vec<f64>> {
    let t = table("pixel_bands.csv");
    let (names, ids, values) = (strings(&t, "setup"), numbers(&t, "pixel_id"), numbers(&t, column));
    let mut out = std::collections::BTreeMap::<usize, Vec<f64>>::new();
    for i in 0..t.len() {
        if names[i] == setup {
            out.entry(ids[i] as usize).or_default().push(values[i]);
        }
    }
    out
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

#[test]
fn forward_model_band_sums_and_objective_match_the_package() {
    let per_pair = table("per_pair.csv");
    let pixels = table("pixels.csv");
    let (pp_setup, pp_pixel, pp_pair) =
        (strings(&per_pair, "setup"), numbers(&per_pair, "pixel_id"), numbers(&per_pair, "pair"));
    let (f_p0, f_truth) = (numbers(&per_pair, "f_at_p0"), numbers(&per_pair, "f_at_truth_params"));
    let truth: Vec<Vec<f64>> =
        ["chl_true", "cdom_true", "nap_true", "depth_true", "q_true"].iter().map(|c| numbers(&pixels, c)).collect();
    let fit: Vec<Vec<f64>> =
        ["fit_chl", "fit_cdom", "fit_nap", "fit_depth", "fit_q"].iter().map(|c| numbers(&pixels, c)).collect();
    let (px_setup, px_id, kept) =
        (strings(&pixels, "setup"), numbers(&pixels, "pixel_id"), numbers(&pixels, "kept_pair"));
    let pair_true = numbers(&pixels, "pair_true");
    let mut scratch = ReferenceScratch::default();
    let (mut worst_f, mut worst_rrs, mut checked) = (0.0f64, 0.0f64, 0);
    for setup in setups() {
        let observed = band_values(&setup.name, "obs_rrs_sub");
        let clean = band_values(&setup.name, "clean_rrs_sub");
        let fitted = band_values(&setup.name, "fit_rrs_sub");
        let nb = setup.model.n_bands();
        let mut m = vec![0.0; nb];
        let p0 = start(&setup.p_min, &setup.p_max);
        let row_of =
            |id: usize| (0..pixels.len()).find(|&i| px_setup[i] == setup.name && px_id[i] as usize == id).unwrap();
        for i in (0..per_pair.len()).filter(|&i| pp_setup[i] == setup.name) {
            let id = pp_pixel[i] as usize;
            let pair = setup.model.pairs()[pp_pair[i] as usize];
            let r = row_of(id);
            let x_truth = [truth[0][r], truth[1][r], truth[2][r], truth[3][r], truth[4][r]];
            for (x, want) in [(p0, f_p0[i]), (x_truth, f_truth[i])] {
                setup.model.closed_rrs(&x, pair, inv_cos(), &mut m, None, &mut scratch);
                let got = distance_f(&observed[&id], &m, &setup.nedr);
                // f at the truth of a noise-free pixel is rounding (~1e-8 or 0): an absolute floor
                // of 1e-15 on top of the relative 1e-10.
                let err = (got - want).abs() / (want.abs() + 1e-5);
                assert!(err < 1e-10, "{} pixel {id} pair {pair:?}: f {got} vs the package's {want}", setup.name);
                worst_f = worst_f.max(err);
                checked += 1;
            }
        }
        for (&id, want) in &clean {
            let r = row_of(id);
            let x_truth = [truth[0][r], truth[1][r], truth[2][r], truth[3][r], truth[4][r]];
            let x_fit = [fit[0][r], fit[1][r], fit[2][r], fit[3][r], fit[4][r]];
            for (x, pair, want) in [
                (x_truth, setup.model.pairs()[pair_true[r] as usize], want),
                (x_fit, setup.model.pairs()[kept[r] as usize], &fitted[&id]),
            ] {
                setup.model.closed_rrs(&x, pair, inv_cos(), &mut m, None, &mut scratch);
                for b in 0..nb {
                    let err = relative(m[b], want[b]);
                    assert!(err < 1e-10, "{} pixel {id} band {}: rrs {} vs {}", setup.name, b + 1, m[b], want[b]);
                    worst_rrs = worst_rrs.max(err);
                }
            }
        }
    }
    assert_eq!(checked, 800, "f at the start and at the truth for all 400 pair fits");
    println!("worst relative error: f {worst_f:.1e}, band rrs {worst_rrs:.1e}");
}

/// What the package reported for one set-up, and what the port gives.
#[derive(Default, Debug)]
struct Tally {
    fits: usize,
    success_same: usize,
    stall_same: usize,
    x_close: usize,
    pixels: usize,
    kept_same: usize,
    kept_stalled_package: usize,
    kept_stalled_port: usize,
    exact_stall_at_start: usize,
    stall_same_scipy115: usize,
    x_close_scipy115: usize,
    nit_port: u32,
    nit_package: f64,
}

#[test]
fn fits_behave_as_the_package_reports() {
    let per_pair = table("per_pair.csv");
    let pixels = table("pixels.csv");
    let (pp_setup, pp_pixel, pp_pair) =
        (strings(&per_pair, "setup"), numbers(&per_pair, "pixel_id"), numbers(&per_pair, "pair"));
    let (pp_success, pp_stalled) = (numbers(&per_pair, "success"), numbers(&per_pair, "stalled"));
    let pp_x: Vec<Vec<f64>> =
        ["x_chl", "x_cdom", "x_nap", "x_depth", "x_q"].iter().map(|c| numbers(&per_pair, c)).collect();
    let (px_setup, px_id) = (strings(&pixels, "setup"), numbers(&pixels, "pixel_id"));
    let old = table("per_pair_scipy1.15.3.csv");
    let (old_setup, old_pixel, old_pair, old_stalled) =
        (strings(&old, "setup"), numbers(&old, "pixel_id"), numbers(&old, "pair"), numbers(&old, "stalled"));
    let old_x: Vec<Vec<f64>> =
        ["x_chl", "x_cdom", "x_nap", "x_depth", "x_q"].iter().map(|c| numbers(&old, c)).collect();
    let pp_nit = numbers(&per_pair, "nit");
    let (kept, kept_stalled, success) =
        (numbers(&pixels, "kept_pair"), numbers(&pixels, "kept_pair_stalled"), numbers(&pixels, "success"));
    let mut report = Vec::new();
    for setup in setups() {
        let observed = band_values(&setup.name, "obs_rrs_sub");
        let p0 = start(&setup.p_min, &setup.p_max);
        let mut t = Tally::default();
        for (&id, obs) in &observed {
            let got = invert(&setup.model, &setup.p_min, &setup.p_max, obs, &setup.nedr, inv_cos());
            let r = (0..pixels.len()).find(|&i| px_setup[i] == setup.name && px_id[i] as usize == id).unwrap();
            t.pixels += 1;
            assert_eq!(got.success, success[r] == 1.0, "{} pixel {id}: success", setup.name);
            t.kept_same += usize::from(got.kept == Some(kept[r] as usize));
            t.kept_stalled_package += usize::from(kept_stalled[r] == 1.0);
            t.kept_stalled_port += usize::from(got.stalled);
            for fit in &got.fits {
                let k = setup.model.pairs().iter().position(|p| *p == fit.pair).unwrap();
                let i = (0..per_pair.len())
                    .find(|&i| pp_setup[i] == setup.name && pp_pixel[i] as usize == id && pp_pair[i] as usize == k)
                    .unwrap();
                let o = (0..old.len())
                    .find(|&o| old_setup[o] == setup.name && old_pixel[o] as usize == id && old_pair[o] as usize == k)
                    .unwrap();
                t.fits += 1;
                t.success_same += usize::from(fit.success() == (pp_success[i] == 1.0));
                t.stall_same += usize::from(fit.stalled == (pp_stalled[i] == 1.0));
                t.stall_same_scipy115 += usize::from(fit.stalled == (old_stalled[o] == 1.0));
                let close = |x: &[Vec<f64>], i: usize| {
                    (0..5).all(|j| {
                        let (a, b) = (fit.x[j], x[j][i]);
                        (a - b).abs() <= 1e-2 * b.abs().max(1e-2 * (setup.p_max[j] - setup.p_min[j]))
                    })
                };
                t.x_close += usize::from(close(&pp_x, i));
                t.x_close_scipy115 += usize::from(close(&old_x, o));
                t.nit_port += fit.nit;
                t.nit_package += pp_nit[i];
                t.exact_stall_at_start += usize::from(fit.x[3] == p0[3] && fit.x[4] == p0[4]);
            }
        }
        report.push(format!("{}: {t:?}", setup.name));
        let share = |n: usize, of: usize| n as f64 / of as f64;
        assert_eq!(t.success_same, t.fits, "{}: every fit's success flag", setup.name);
        assert!(share(t.stall_same, t.fits) >= 0.88, "{}: stall flags {}/{}", setup.name, t.stall_same, t.fits);
        assert!(share(t.kept_same, t.pixels) >= 0.85, "{}: kept pair {}/{}", setup.name, t.kept_same, t.pixels);
        assert!(share(t.x_close, t.fits) >= 0.72, "{}: x within 1e-2 in {}/{}", setup.name, t.x_close, t.fits);
        let iterations = f64::from(t.nit_port) / t.nit_package;
        assert!((0.95..=1.05).contains(&iterations), "{}: SLSQP iterations {iterations:.3}× the package's", setup.name);
        assert!(
            t.kept_stalled_port.abs_diff(t.kept_stalled_package) <= 10,
            "{}: {} stalled kept pairs against the package's {}",
            setup.name,
            t.kept_stalled_port,
            t.kept_stalled_package
        );
        match setup.name.as_str() {
            "CASI28_HI3_shoalbounds" => {
                assert_eq!(t.exact_stall_at_start, t.fits, "every fit ends exactly at depth 14.95, q 0.5");
                assert_eq!(t.kept_same, t.pixels, "pair 0 kept everywhere (all pairs give the same f)");
                assert_eq!(f64::from(t.nit_port), t.nit_package, "the same iterations, fit for fit");
            }
            "ALOS4_MB_notebook" => assert_eq!(t.kept_stalled_port, 0, "the 3.45 m start sees the bottom: no stall"),
            _ => {}
        }
    }
    println!("{}", report.join("\n"));
}
