//! aLMI's reference mode against the DEA code's own outputs on 302 pixels
//! (`tests/data/retrieval_reference/almi`, see PROVENANCE.md): the set chosen (or the pixel
//! dropped, and why) for every pixel, the float32 concentrations and the cost; and the per-set
//! least-squares solutions before any set is dropped.
//!
//! Tolerances (from the reference's README): concentrations 1e-6 relative — DEA stores float32
//! (6e-8) and solves through LAPACK's SVD where Shoal uses Jacobi on the normal matrix (condition
//! number of A ≤ 130 here, so ~1e-12 in f64 before the float32 rounding, which the two share
//! except within one float32 ulp); cost 1e-7 absolute (DEA's noise-free cost is ~1e-8 from the
//! float32 rounding of the solution).

use shoal::retrieval::almi::AlmiSet;
use shoal::retrieval::almi_reference::{NotReturned, invert_reference, not_returned};
use shoal::retrieval::band_model::BandIops;
use shoal::spectral::Table;

use super::data;

const BANDS: [&str; 8] = ["412", "442", "490", "510", "560", "620", "665", "709"];

fn table(name: &str) -> Table {
    Table::from_file(&data(&format!("retrieval_reference/almi/{name}"))).unwrap()
}

fn numbers(t: &Table, column: &str) -> Vec<f64> {
    t.column_str(column).unwrap().iter().map(|s| if s.is_empty() { f64::NAN } else { s.parse().unwrap() }).collect()
}

/// The eight sets at the band centres, in file order (index k is almi_{k+1}).
fn sets() -> Vec<AlmiSet> {
    let t = table("siop_sets_bands.csv");
    let index = numbers(&t, "set_index");
    let names = t.column_str("set_name").unwrap();
    let col = |c: &str| numbers(&t, c);
    let (a_w, bb_w, a_ph, bb_ph, a_cdom, a_nap, bb_nap) = (
        col("a_w"),
        col("bb_w"),
        col("a_ph_star"),
        col("bb_ph_star"),
        col("a_cdom_star"),
        col("a_nap_star"),
        col("bb_nap_star"),
    );
    (0..8)
        .map(|s| {
            let rows: Vec<usize> = (0..index.len()).filter(|&i| index[i] == s as f64).collect();
            assert_eq!(rows.len(), 8);
            let pick = |v: &[f64]| rows.iter().map(|&i| v[i]).collect::<Vec<_>>();
            AlmiSet {
                name: names[rows[0]].to_string(),
                iops: BandIops {
                    a_w: pick(&a_w),
                    bb_w: pick(&bb_w),
                    a_ph: pick(&a_ph),
                    a_cdom: pick(&a_cdom),
                    a_nap: pick(&a_nap),
                    bb_ph: pick(&bb_ph),
                    bb_nap: pick(&bb_nap),
                },
            }
        })
        .collect()
}

#[test]
fn every_pixel_gets_the_dea_set_concentrations_and_cost() {
    let sets = sets();
    let t = table("pixels.csv");
    let rrs: Vec<Vec<f64>> = BANDS.iter().map(|b| numbers(&t, &format!("Rrs_in_{b}"))).collect();
    let (index, chl, cdom, nap, cost) = (
        numbers(&t, "dea_siop_index"),
        numbers(&t, "dea_chl"),
        numbers(&t, "dea_cdom"),
        numbers(&t, "dea_nap"),
        numbers(&t, "dea_cost_rmse"),
    );
    let (mut returned, mut no_set, mut screened) = (0, 0, 0);
    for p in 0..t.len() {
        let obs: Vec<f64> = rrs.iter().map(|b| b[p]).collect();
        let got = invert_reference(&sets, 0.084, 0.17, &obs, &[true; 8]);
        match index[p] as i64 {
            -999 => {
                assert_eq!(not_returned(&got), Some(NotReturned::Screened), "pixel {p}");
                screened += 1;
            }
            -1 => {
                assert_eq!(not_returned(&got), Some(NotReturned::NoValidSet), "pixel {p}");
                no_set += 1;
            }
            k => {
                assert_eq!(got.set, Some(k as u8), "pixel {p}: set");
                for (name, g, want) in [("chl", got.chl, chl[p]), ("cdom", got.cdom, cdom[p]), ("nap", got.nap, nap[p])]
                {
                    assert!((g / want - 1.0).abs() < 1e-6, "pixel {p} {name}: {g} vs DEA {want}");
                }
                assert!((got.cost - cost[p]).abs() < 1e-7, "pixel {p} cost: {} vs DEA {}", got.cost, cost[p]);
                returned += 1;
            }
        }
    }
    // The reference README's counts: 277 returned, 19 with no valid set, 6 screened out.
    assert_eq!((returned, no_set, screened), (277, 19, 6));
}

#[test]
fn the_per_set_least_squares_solutions_match_before_any_set_is_dropped() {
    // One set at a time: a pixel inverted with only set k reports set k's solution if it is valid;
    // compare with DEA's f64 lstsq where DEA kept it (valid_conc = 1), to 1e-6 relative.
    let sets = sets();
    let pixels = table("pixels.csv");
    let rrs: Vec<Vec<f64>> = BANDS.iter().map(|b| numbers(&pixels, &format!("Rrs_in_{b}"))).collect();
    let t = table("per_set.csv");
    let (pixel, set, valid) = (numbers(&t, "pixel_id"), numbers(&t, "set_index"), numbers(&t, "valid_conc"));
    let below = numbers(&t, "cost_below_threshold");
    let (chl, cdom, nap) = (numbers(&t, "chl_f32"), numbers(&t, "cdom_f32"), numbers(&t, "nap_f32"));
    let mut compared = 0;
    for i in 0..t.len() {
        let p = pixel[i] as usize;
        let s = set[i] as usize;
        let obs: Vec<f64> = rrs.iter().map(|b| b[p]).collect();
        // Set s alone, with the first set's water (the reference reuses set 0's right-hand side;
        // all eight sets share one water here).
        let got = invert_reference(&sets[s..=s], 0.084, 0.17, &obs, &[true; 8]);
        if valid[i] == 1.0 && below[i] == 1.0 {
            for (g, want) in [(got.chl, chl[i]), (got.cdom, cdom[i]), (got.nap, nap[i])] {
                assert!((g / want - 1.0).abs() < 1e-6, "pixel {p} set {s}: {g} vs DEA {want}");
            }
            compared += 1;
        } else {
            assert_eq!(not_returned(&got), Some(NotReturned::NoValidSet), "pixel {p} set {s}: DEA dropped it");
        }
    }
    // 296 processed pixels × 8 sets; DEA kept 1335 of those solutions (valid and cost < 100).
    assert_eq!((t.len(), compared), (2368, 1335));
}
