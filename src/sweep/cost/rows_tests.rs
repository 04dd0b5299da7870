//! The pairing rule held to synthetic timings: a drift across rounds, one slow run, a real 15 %
//! difference, no difference at all — each case the range rule (a row differs only when its
//! min–max range misses the reference's) got wrong or would get wrong.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use super::*;

/// One run of the simulated table: which row, which round, and the fraction of the table done.
struct Run {
    row: usize,
    round: usize,
    at: f64,
}

/// Rows timed the way `cost_of_accuracy` times them — `rounds` rounds of every row in order,
/// then a closing reference run — where row i's run takes `true_s[i]`, times the machine's
/// slowness `machine(at)` (`at` the fraction of the table done), times `spell(run)` (a slow
/// spell during one run), times uniform noise of ± `noise`. CPU time is twice the wall time.
/// `errors[i]` is the row's chl error.
fn simulate(
    true_s: &[f64],
    errors: &[Option<f64>],
    rounds: usize,
    noise: f64,
    machine: impl Fn(f64) -> f64,
    spell: impl Fn(&Run) -> f64,
) -> Vec<CostRow> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut rows: Vec<CostRow> = true_s
        .iter()
        .zip(errors)
        .enumerate()
        .map(|(i, (_, e))| CostRow {
            errors: PerPixel { chl_pct: *e, ..PerPixel::default() },
            ..CostRow::untimed(&format!("row {i}"), 30.0, 0.0)
        })
        .collect();
    let total = (rounds * true_s.len() + 1) as f64;
    let mut order: Vec<(usize, usize)> = (0..rounds).flat_map(|k| (0..true_s.len()).map(move |i| (i, k))).collect();
    order.push((0, rounds));
    for (j, (row, round)) in order.into_iter().enumerate() {
        let run = Run { row, round, at: j as f64 / total };
        let wall_s = true_s[row] * machine(run.at) * spell(&run) * (1.0 + noise * (2.0 * rng.random::<f64>() - 1.0));
        rows[row].samples.push(Sample { wall_s, cpu_s: Some(2.0 * wall_s) });
        rows[row].time = Summary::of(&rows[row].samples);
        pair_with_reference(&mut rows);
    }
    rows
}

fn ranges_overlap(a: &CostRow, b: &CostRow) -> bool {
    let (a, b) = (a.time.wall_range_s, b.time.wall_range_s);
    a.0 <= b.1 && b.0 <= a.1
}

/// Is `r` within the noise of `expected`? A ratio of two runs of ± 3 % noise each is within
/// ± 6 % of the true one, and so is the median of such ratios.
fn near(r: f64, expected: f64) -> bool {
    (r / expected - 1.0).abs() <= 0.062
}

fn ratio(c: Comparison) -> f64 {
    match c {
        Comparison::Ratio(p) => p.ratio,
        Comparison::NoMeasurableDifference(p) => panic!("no claim: {p:?}"),
    }
}

#[test]
fn a_drift_across_rounds_cancels_and_a_15_pct_difference_is_told_apart() {
    // The machine slows steadily by 60 % from the first run to the last (a job starting, a
    // throttled CPU); ± 3 % noise per run.
    let none = [None; 4];
    let rows = simulate(&[4.0, 4.0, 3.4, 4.6], &none, 5, 0.03, |at| 1.0 + 0.6 * at, |_| 1.0);
    for r in &rows[1..] {
        assert!(ranges_overlap(r, &rows[0]), "{}: the range rule would see no difference", r.label);
    }
    assert_eq!(rows[0].samples.len(), 6, "5 rounds and the closing reference run");
    assert!(matches!(rows[1].comparison, Comparison::NoMeasurableDifference(Some(_))), "{:?}", rows[1].comparison);
    let (faster, slower) = (ratio(rows[2].comparison), ratio(rows[3].comparison));
    assert!(near(faster, 0.85) && near(slower, 1.15), "{faster} {slower}");
    assert!((ratio(rows[2].cpu_comparison.expect("cpu")) - faster).abs() < 1e-9, "CPU paired alike");
    // Rows against each other, through their normalised times.
    assert!(rows[2].measurably_faster_than(&rows[1]) && rows[1].measurably_faster_than(&rows[3]));
    assert!(!rows[1].measurably_faster_than(&rows[0]) && !rows[0].measurably_faster_than(&rows[1]));
    // Without noise the drift alone is left: the interpolation between the bracketing reference
    // runs cancels it to within 1 % (the smoothing's end rule and the geometric interpolation
    // follow a straight line in log time; this slowdown is straight in time), where the round's
    // own reference alone would leave the last row 60 %/5 × ¾ ≈ 9 % slow.
    let still = simulate(&[4.0; 4], &none, 5, 0.0, |at| 1.0 + 0.6 * at, |_| 1.0);
    for r in &still {
        assert!(r.wall_vs_reference.iter().all(|x| (x - 1.0).abs() < 0.01), "{}: {:?}", r.label, r.wall_vs_reference);
        assert!(matches!(r.comparison, Comparison::NoMeasurableDifference(_)));
    }
}

#[test]
fn one_slow_run_of_the_reference_moves_no_verdict() {
    // The reference's third run takes three times as long (a backup starting, a page cache
    // flushed): two rounds lean on it, and the smoothed reference sets it aside. The same noise
    // with and without the slow run gives the same verdicts and ratios within 2 %.
    let times = [4.0, 4.0, 3.4, 4.6];
    let calm = simulate(&times, &[None; 4], 5, 0.03, |_| 1.0, |_| 1.0);
    let spell = simulate(&times, &[None; 4], 5, 0.03, |_| 1.0, |r| if r.row == 0 && r.round == 2 { 3.0 } else { 1.0 });
    for (a, b) in calm.iter().zip(&spell).skip(1) {
        assert_eq!(a.comparison.ratio().is_some(), b.comparison.ratio().is_some(), "{}", a.label);
        let (x, y) = (Paired::of(&a.wall_vs_reference).expect("runs"), Paired::of(&b.wall_vs_reference).expect("runs"));
        assert!((x.ratio / y.ratio - 1.0).abs() < 0.02, "{}: {x:?} {y:?}", a.label);
    }
    assert!(near(ratio(spell[2].comparison), 0.85));
    assert!(near(ratio(spell[3].comparison), 1.15), "{:?}", spell[3].comparison);
    // The reference's median time is its own: the slow run is one of six.
    assert!((spell[0].seconds() - 4.0).abs() < 0.15, "{}", spell[0].seconds());
}

#[test]
fn one_slow_run_of_a_setting_is_one_order_statistic_from_8_rounds() {
    let slow = |rounds| {
        simulate(&[4.0, 3.4], &[None; 2], rounds, 0.03, |_| 1.0, |r| if r.row == 1 && r.round == 1 { 1.5 } else { 1.0 })
    };
    // From 8 rounds the interval is the 2nd to the 7th ratio (1 − 2·9/256 = 93.0 %): the slow round is left out.
    let rows = slow(8);
    let Comparison::Ratio(p) = rows[1].comparison else { panic!("{:?}", rows[1].comparison) };
    assert!(near(p.ratio, 0.85) && p.hi < 1.0 && (p.level_pct - 92.97).abs() < 0.01, "{p:?}");
    // With 5, every round must agree (the interval is the whole range, 93.75 %): no claim, and
    // the text says what the runs could not tell.
    let rows = slow(5);
    assert!(matches!(rows[1].comparison, Comparison::NoMeasurableDifference(Some(_))));
    assert!(rows[1].comparison.text().starts_with("no measurable difference (0."), "{}", rows[1].comparison.text());
}

#[test]
fn without_a_difference_nothing_is_claimed_and_the_reference_is_the_cheapest() {
    // Nine rows of the same true time, ± 10 % noise, 9 rounds: every verdict holds 1.
    let rows = simulate(&[2.0; 9], &[Some(0.0); 9], 9, 0.10, |_| 1.0, |_| 1.0);
    for r in &rows[1..] {
        assert!(matches!(r.comparison, Comparison::NoMeasurableDifference(Some(_))), "{}: {:?}", r.label, r.comparison);
        assert!(!rows.iter().any(|o| o.measurably_faster_than(r)), "{}", r.label);
    }
    assert_eq!(cheapest_within(&rows, ErrorOf::Chl, 1.0).map(|r| r.label.as_str()), Some("row 0"));
    assert_eq!(pareto_front(&rows, ErrorOf::Chl).len(), 1, "all tie in time and error: the first stands for them");
}

#[test]
fn too_few_rounds_claim_nothing() {
    let rows = simulate(&[4.0, 2.0], &[None; 2], 3, 0.0, |_| 1.0, |_| 1.0);
    assert_eq!(rows[1].comparison.text(), "no measurable difference (3 rounds; 5 needed)");
}

#[test]
fn the_front_and_the_cheapest_use_the_same_pairing() {
    // Times 4.0 (reference), 4.0, 3.0, 3.05, 2.0, 0.8 s with chl errors 0, 0, 0.5, 0.9, 3 %
    // and a preview (no per-pixel error); ± 10 % noise and a 30 % drift over 6 rounds.
    let errors = [Some(0.0), Some(0.0), Some(0.5), Some(0.9), Some(3.0), None];
    let rows = simulate(&[4.0, 4.0, 3.0, 3.05, 2.0, 0.8], &errors, 6, 0.10, |at| 1.0 + 0.3 * at, |_| 1.0);
    let front: Vec<&str> = pareto_front(&rows, ErrorOf::Chl).iter().map(|r| r.label.as_str()).collect();
    // Row 1 ties the reference and is no more accurate; row 3 ties row 2 in time and is worse;
    // the preview has other pixels.
    assert_eq!(front, ["row 4", "row 2", "row 0"]);
    assert_eq!(cheapest_within(&rows, ErrorOf::Chl, 1.0).map(|r| r.label.as_str()), Some("row 2"));
    assert_eq!(cheapest_within(&rows, ErrorOf::Chl, 5.0).map(|r| r.label.as_str()), Some("row 4"));
    assert_eq!(cheapest_within(&rows, ErrorOf::Chl, 0.1).map(|r| r.label.as_str()), Some("row 0"));
    // Of candidates the timings cannot tell apart, the most accurate: rows 2 and 3 tie in time.
    assert!(!rows[2].measurably_faster_than(&rows[3]) && !rows[3].measurably_faster_than(&rows[2]));
}

#[test]
fn smoothing_keeps_a_trend_and_drops_one_outlier() {
    let trend = [1.0, 2.0, 3.0, 4.0, 5.0];
    assert_eq!(smooth(&trend), trend);
    assert_eq!(smooth(&[1.0, 1.0, 9.0, 1.0, 1.0]), [1.0; 5]);
    assert_eq!(smooth(&[9.0, 1.0, 1.0, 1.0]), [1.0; 4], "an outlying end");
    assert_eq!(smooth(&[1.0, 5.0, 2.0]), [1.0, 5.0, 2.0], "three values are left as they are");
}
