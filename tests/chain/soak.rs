//! Engine soak: 1,000 random edits of instruments A and B through the worker, at random
//! intervals (many land mid-stage), as a slider-happy user makes them. Checked against oracles
//! kept by the test itself, not by the worker:
//! - no deadlock: the whole soak and the final results finish within a watchdog's time;
//! - every result the app would display carries the configuration submitted with its generation
//!   (the test's own record), and every result the worker sent was displayed or dropped as stale,
//!   none lost;
//! - the final results equal, bit for bit, what a fresh engine returns for the final configurations;
//! - the cache stays within its capacity (the sum of the stages' capacities);
//! - cancellation stops work: rows finished after a cancel are at most the rows already started
//!   (one block per pool thread per heavy stage).

use crate::common::Kept;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use rand::{RngExt, SeedableRng};
use shoal::control::RunControl;
use shoal::engine::worker::{EngineHandle, Event, Request};
use shoal::engine::{Engine, RunConfig, Stage};
use shoal::instrument::InstrumentSpec;

use super::small_lake;

const EDITS: usize = 1000;
const THREADS: usize = 2;

fn base(name: &str) -> RunConfig {
    let mut instrument = InstrumentSpec::preset(name).unwrap();
    instrument.detectors = 48;
    instrument.lines = 32;
    let mut c = RunConfig::new(small_lake(), instrument);
    c.retrievals = vec![ron::from_str("Almi()").unwrap()];
    c
}

/// One random edit of the kind a user makes with the sliders.
fn edit(c: &mut RunConfig, rng: &mut rand::rngs::Xoshiro256PlusPlus) -> &'static str {
    let i = &mut c.instrument;
    match rng.random_range(0..8) {
        0 => {
            i.aperture_mm = rng.random_range(20.0..200.0);
            "aperture"
        }
        1 => {
            i.exposure_s = rng.random_range(0.0005..0.003);
            "exposure"
        }
        2 => {
            i.read_noise_e = rng.random_range(0.0..60.0);
            "read noise"
        }
        3 => {
            i.gain_e_per_dn = rng.random_range(0.5..10.0);
            "gain"
        }
        4 => {
            i.well_depth_e = rng.random_range(2e4..2e5);
            "well"
        }
        5 => {
            i.adc_bits = rng.random_range(10..=16);
            "ADC bits"
        }
        6 => {
            c.seed = rng.random_range(1..5);
            "seed"
        }
        _ => {
            i.pixel_pitch_um = rng.random_range(4.0..8.0);
            "pixel pitch (geometry)"
        }
    }
}

/// The worker's run `a` (views of its cubes, as the app keeps them) against a fresh run `b` that
/// kept its cubes: the views hold the cubes' own bits at every kept pixel, and the products are
/// the same.
fn same_products(a: &shoal::engine::RunOutput, b: &shoal::engine::RunOutput) -> bool {
    let views = a.views.as_ref().expect("the app's engine keeps views");
    let every = views.stride as isize;
    let kept = |cube: &ndarray::Array3<f32>| cube.slice(ndarray::s![..;every, ..;every, ..]).to_owned();
    let bits = |x: &ndarray::Array3<f32>, y: &ndarray::Array3<f32>| {
        x.dim() == y.dim() && x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits())
    };
    bits(&views.level1, &kept(&b.kept().level1.radiance))
        && bits(&views.rrs, &kept(&b.kept().rrs.rrs))
        && bits(&views.toa, &kept(&b.kept().radiance.radiance))
        && a.retrievals.len() == b.retrievals.len()
        && a.retrievals.iter().zip(&b.retrievals).all(|(x, y)| {
            x.product
                .chl_mg_m3
                .iter()
                .flatten()
                .zip(y.product.chl_mg_m3.iter().flatten())
                .all(|(p, q)| p.to_bits() == q.to_bits())
                && format!("{:?}", x.metrics) == format!("{:?}", y.metrics)
        })
}

/// Resident and peak memory of this process, kB (Linux `/proc/self/status`).
fn memory_kb() -> (u64, u64) {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        status
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse().ok())
            .unwrap_or(0)
    };
    (field("VmRSS:"), field("VmHWM:"))
}

struct Soak {
    generations: u64,
    displayed: usize,
    finals: [Option<std::sync::Arc<shoal::engine::RunOutput>>; 2],
    configs: [RunConfig; 2],
    seconds: f64,
    memory: Vec<u64>,
}

fn soak() -> Soak {
    let start = Instant::now();
    let handle = EngineHandle::spawn(THREADS).unwrap();
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(1000);
    let mut configs = [base("cubesat"), base("smallsat")];
    // What was submitted with each generation: the oracle for what may be displayed.
    let mut submitted: Vec<[RunConfig; 2]> = Vec::new();
    let decimations = vec![4, 1];
    let mut displayed = 0;
    let mut memory = Vec::new();
    // `wait` hands over only the newest generation's events; what is checked here is that such a
    // result carries the configuration submitted with that generation.
    let check = |event: Event, submitted: &[[RunConfig; 2]], displayed: &mut usize| {
        if let Event::Finished { generation, index, decimation, result } = event {
            *displayed += 1;
            let Ok(out) = result else { panic!("generation {generation}: run failed") };
            let mut expected = submitted[generation as usize - 1][index].clone();
            expected.fidelity.decimation = decimation;
            assert_eq!(out.config, expected, "generation {generation}, instrument {index}: not the submitted config");
        }
    };
    for n in 0..EDITS {
        let which = rng.random_range(0..2);
        edit(&mut configs[which], &mut rng);
        submitted.push(configs.clone());
        let generation = submitted.len() as u64;
        assert!(handle.submit(Request {
            generation,
            configs: configs.iter().cloned().map(Some).collect(),
            finest_only: Vec::new(),
            decimations: decimations.clone(),
        }));
        // Random intervals: mostly shorter than a preview (edits pile up and cancel runs
        // mid-stage), sometimes long enough for a preview or a full run to land.
        let pause = match rng.random_range(0..10) {
            0..=6 => Duration::from_micros(rng.random_range(0..2000)),
            7 | 8 => Duration::from_millis(rng.random_range(2..30)),
            _ => Duration::from_millis(rng.random_range(30..150)),
        };
        let until = Instant::now() + pause;
        while Instant::now() < until {
            if let Some(e) = handle.wait(until.saturating_duration_since(Instant::now())) {
                check(e, &submitted, &mut displayed);
            }
        }
        if n % 250 == 0 {
            memory.push(memory_kb().0);
        }
    }
    // The final results: both instruments at full resolution for the last generation.
    let last = submitted.len() as u64;
    let mut finals: [Option<std::sync::Arc<shoal::engine::RunOutput>>; 2] = [None, None];
    let deadline = Instant::now() + Duration::from_secs(300);
    while finals.iter().any(Option::is_none) {
        assert!(Instant::now() < deadline, "no final results within 300 s");
        if let Some(e) = handle.wait(Duration::from_millis(100)) {
            if let Event::Finished { generation, index, decimation: 1, result: Ok(out) } = &e {
                assert_eq!(*generation, last);
                finals[*index] = Some(out.clone());
            }
            check(e, &submitted, &mut displayed);
        }
    }
    memory.push(memory_kb().0);
    let stats = handle.stats();
    let load = handle.load();
    // Accounting across the two threads: the finals are the last events sent and the channel is
    // first in, first out, so every result the worker sent has been either displayed or dropped
    // as stale by the handle — none lost, none shown twice.
    assert_eq!(stats.results_sent, displayed as u64 + stats.stale_results_dropped, "{stats:?}, {displayed} displayed");
    // The app engine keeps one large cube per design and decimation (`Engine::for_app`).
    let large = shoal::engine::APP_LEVELS * shoal::engine::worker::MAX_DESIGNS;
    let capacity: usize =
        Stage::ALL.iter().map(|s| if s.capacity() < Stage::Scene.capacity() { large } else { s.capacity() }).sum();
    assert!(load.max_cached_products <= capacity as u64, "{} cached products > {capacity}", load.max_cached_products);
    assert!(
        stats.runs_cancelled > 100,
        "only {} runs were cancelled: the soak did not interrupt",
        stats.runs_cancelled
    );
    // A cancel is seen at the next row check: rows already started finish. The heavy stages tick
    // per row (Level-0, retrieval) or per block of rows (radiance: at most 48 lines / 2 threads);
    // so at most one block per pool thread may finish after a cancel.
    let bound = stats.runs_cancelled * THREADS as u64 * 32;
    assert!(load.rows_after_cancel <= bound, "{} rows after {} cancels", load.rows_after_cancel, stats.runs_cancelled);
    eprintln!(
        "soak: {EDITS} edits, {last} generations, {} results sent ({} stale dropped), {} requests skipped, \
         {} runs cancelled ({} rows done after a cancel), {displayed} results displayed, cache peak {} of \
         {capacity} products, RSS {:?} kB (peak {} kB), {:.1} s",
        stats.results_sent,
        stats.stale_results_dropped,
        stats.requests_skipped,
        stats.runs_cancelled,
        load.rows_after_cancel,
        load.max_cached_products,
        memory,
        memory_kb().1,
        start.elapsed().as_secs_f64()
    );
    Soak { generations: last, displayed, finals, configs, seconds: start.elapsed().as_secs_f64(), memory }
}

#[test]
fn a_thousand_random_edits_through_the_worker() {
    // Watchdog: a deadlock fails the test instead of hanging CI.
    let (tx, rx) = mpsc::sync_channel(1);
    std::thread::Builder::new()
        .name("soak".into())
        .spawn(move || {
            let _ = tx.send(soak());
        })
        .unwrap();
    let s = rx.recv_timeout(Duration::from_secs(900)).expect("the soak did not finish in 900 s: deadlock?");
    assert_eq!(s.generations, EDITS as u64);
    assert!(s.displayed >= 2);
    for (i, out) in s.finals.iter().enumerate() {
        let out = out.as_ref().unwrap();
        let mut config = s.configs[i].clone();
        config.fidelity.decimation = 1;
        let fresh = Engine::new().run(&config, &RunControl::new()).unwrap();
        assert!(same_products(out, &fresh), "instrument {i}: the final result differs from a fresh run");
    }
    // Memory: the cache is bounded, so resident memory at the end is within 2× of a quarter in.
    let (first, last) = (s.memory[1], *s.memory.last().unwrap());
    assert!(last < 2 * first.max(1) + 200_000, "RSS grew from {first} kB to {last} kB over the soak");
    assert!(s.seconds > 0.0);
}
