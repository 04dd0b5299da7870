//! The engine thread: previews before full resolution, a stale result dropped (told apart from a
//! cancelled run by the worker's counters, [`WorkerStats`]), a newer request cancelling the
//! running one.

use std::time::{Duration, Instant};

use shoal::engine::RunConfig;
use shoal::engine::worker::{EngineHandle, Event, Request, WorkerStats};

use super::{small, small_lake};

fn finished(handle: &EngineHandle, timeout: Duration) -> Vec<(u64, usize, bool)> {
    let mut out = Vec::new();
    let deadline = Instant::now() + timeout;
    while Instant::now() < deadline {
        match handle.wait(Duration::from_millis(100)) {
            Some(Event::Finished { generation, decimation, result, .. }) => {
                out.push((generation, decimation, result.is_ok()));
                if decimation == 1 {
                    break;
                }
            }
            Some(Event::Progress { .. } | Event::Kept { .. }) | None => {}
        }
    }
    out
}

/// Wait, without reading any event, until `done(stats)` holds.
fn until(handle: &EngineHandle, timeout: Duration, done: impl Fn(&WorkerStats) -> bool) -> WorkerStats {
    let deadline = Instant::now() + timeout;
    loop {
        let s = handle.stats();
        if done(&s) {
            return s;
        }
        assert!(Instant::now() < deadline, "worker stuck: {s:?}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn preview_then_full_for_the_newest_generation() {
    let handle = EngineHandle::spawn(1).unwrap();
    let config = RunConfig::new(small_lake(), small("nominal", 64, 64));
    // Generation 1 is superseded at once by generation 2 (another gain).
    assert!(handle.submit(Request {
        generation: 1,
        configs: vec![Some(config.clone())],
        finest_only: vec![],
        decimations: vec![4, 1]
    }));
    let mut newer = config;
    newer.instrument.gain_e_per_dn = 2.5;
    assert!(handle.submit(Request {
        generation: 2,
        configs: vec![Some(newer)],
        finest_only: vec![],
        decimations: vec![4, 1]
    }));
    let events = finished(&handle, Duration::from_secs(120));
    assert_eq!(events, vec![(2, 4, true), (2, 1, true)], "preview first, then full, of generation 2 only");
    // Generation 1 went one of three ways, and the counters say which: skipped before it ran,
    // cancelled while running its preview, or its preview finished and was dropped as stale
    // (then its full run was cancelled or never started). Every result sent either reached the
    // app (the two above) or was dropped: the channel is FIFO and generation 1's events all
    // precede generation 2's final one, so none is still queued.
    let s = handle.stats();
    assert_eq!(s.results_sent, 2 + s.stale_results_dropped, "{s:?}");
    assert!(s.runs_cancelled <= 1 && s.stale_results_dropped <= 1, "{s:?}");
    assert_eq!(s.requests_skipped + u64::from(s.runs_cancelled + s.stale_results_dropped > 0), 1, "{s:?}");
}

#[test]
fn a_stale_result_is_dropped_not_cancelled() {
    // Generation 1 runs to the end before generation 2 is submitted: its result sits in the
    // event queue, stale, and `wait` must drop it (counted), while no run was cancelled.
    let handle = EngineHandle::spawn(1).unwrap();
    let config = RunConfig::new(small_lake(), small("nominal", 16, 16));
    assert!(handle.submit(Request {
        generation: 1,
        configs: vec![Some(config.clone())],
        finest_only: vec![],
        decimations: vec![1]
    }));
    let s = until(&handle, Duration::from_secs(120), |s| s.results_sent == 1);
    assert_eq!(s, WorkerStats { results_sent: 1, ..WorkerStats::default() });
    let mut newer = config;
    newer.instrument.gain_e_per_dn = 2.5;
    assert!(handle.submit(Request {
        generation: 2,
        configs: vec![Some(newer)],
        finest_only: vec![],
        decimations: vec![1]
    }));
    assert_eq!(finished(&handle, Duration::from_secs(120)), vec![(2, 1, true)]);
    assert_eq!(
        handle.stats(),
        WorkerStats { results_sent: 2, runs_cancelled: 0, requests_skipped: 0, stale_results_dropped: 1 }
    );
}

#[test]
fn a_newer_request_cancels_the_running_one_which_reports_nothing() {
    // Generation 1 is a full-resolution run of the nominal instrument's whole 1024-detector swath
    // over 512 lines (428 × 642 pixels cropped to the lake, 3.2 s on two threads, longer on the
    // worker's one); generation 2 arrives once it is under way (a progress event with rows
    // done, reported every 50 ms). Generation 1 must be cancelled: no result sent, none dropped.
    let handle = EngineHandle::spawn(1).unwrap();
    let big = RunConfig::new(small_lake(), small("nominal", 1024, 512));
    assert!(handle.submit(Request {
        generation: 1,
        configs: vec![Some(big)],
        finest_only: vec![],
        decimations: vec![1]
    }));
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        assert!(Instant::now() < deadline, "generation 1 never reported progress");
        if let Some(Event::Progress { generation: 1, done, .. }) = handle.wait(Duration::from_millis(100))
            && done > 0
        {
            break;
        }
    }
    assert_eq!(handle.stats(), WorkerStats::default(), "generation 1 finished before it could be cancelled");
    let light = RunConfig::new(small_lake(), small("nominal", 16, 16));
    assert!(handle.submit(Request {
        generation: 2,
        configs: vec![Some(light)],
        finest_only: vec![],
        decimations: vec![1]
    }));
    assert_eq!(finished(&handle, Duration::from_secs(120)), vec![(2, 1, true)]);
    assert_eq!(
        handle.stats(),
        WorkerStats { results_sent: 1, runs_cancelled: 1, requests_skipped: 0, stale_results_dropped: 0 }
    );
}

#[test]
fn a_failed_run_is_reported_and_the_worker_survives() {
    let handle = EngineHandle::spawn(1).unwrap();
    let mut bad = RunConfig::new(small_lake(), small("nominal", 16, 16));
    bad.instrument.aperture_mm = 0.0;
    assert!(handle.submit(Request {
        generation: 1,
        configs: vec![Some(bad)],
        finest_only: vec![],
        decimations: vec![1]
    }));
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        match handle.wait(Duration::from_millis(100)) {
            Some(Event::Finished { result: Err(e), .. }) => {
                assert!(e.to_string().contains("aperture_mm"), "{e}");
                break;
            }
            Some(Event::Finished { result: Ok(_), .. }) => panic!("a zero aperture was accepted"),
            Some(Event::Progress { .. } | Event::Kept { .. }) | None => {
                assert!(Instant::now() < deadline, "no answer from the worker")
            }
        }
    }
    let good = RunConfig::new(small_lake(), small("nominal", 16, 16));
    assert!(handle.submit(Request {
        generation: 2,
        configs: vec![Some(good)],
        finest_only: vec![],
        decimations: vec![1]
    }));
    let events = finished(&handle, Duration::from_secs(60));
    assert_eq!(events, vec![(2, 1, true)]);
}

#[test]
fn a_and_b_run_at_each_level_before_the_next() {
    let handle = EngineHandle::spawn(1).unwrap();
    let a = RunConfig::new(small_lake(), small("cubesat", 32, 32));
    let b = RunConfig::new(small_lake(), small("smallsat", 32, 32));
    assert!(handle.submit(Request {
        generation: 1,
        configs: vec![Some(a), Some(b)],
        finest_only: vec![],
        decimations: vec![4, 1]
    }));
    let mut order = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(120);
    while order.len() < 4 && Instant::now() < deadline {
        if let Some(Event::Finished { index, decimation, result, .. }) = handle.wait(Duration::from_millis(100)) {
            assert!(result.is_ok());
            order.push((decimation, index));
        }
    }
    assert_eq!(order, vec![(4, 0), (4, 1), (1, 0), (1, 1)]);
}

/// The first event of `handle` that is a finished run, within `timeout`.
fn next_finished(handle: &EngineHandle, timeout: Duration) -> Option<(u64, usize)> {
    let deadline = Instant::now() + timeout;
    while Instant::now() < deadline {
        if let Some(Event::Finished { generation, decimation, .. }) = handle.wait(Duration::from_millis(100)) {
            return Some((generation, decimation));
        }
    }
    None
}

#[test]
fn after_a_preview_the_engine_waits_until_it_is_on_screen() {
    // With a pause far longer than the test's timeouts, the finer level can only come because
    // the owner said the preview is shown, or because a newer request ended the wait.
    let handle = EngineHandle::spawn(1).unwrap();
    handle.set_preview_pause(Duration::from_secs(600));
    let config = RunConfig::new(small_lake(), small("nominal", 32, 24));
    let request = |generation, gain| {
        let mut c = config.clone();
        c.instrument.gain_e_per_dn = gain;
        Request { generation, configs: vec![Some(c)], finest_only: vec![], decimations: vec![4, 1] }
    };
    assert!(handle.submit(request(1, 3.0)));
    assert_eq!(next_finished(&handle, Duration::from_secs(60)), Some((1, 4)));
    let shown = Instant::now();
    handle.preview_shown(1);
    assert_eq!(next_finished(&handle, Duration::from_secs(60)), Some((1, 1)), "shown: refined");
    let full = shown.elapsed();

    assert!(handle.submit(request(2, 2.5)));
    assert_eq!(next_finished(&handle, Duration::from_secs(60)), Some((2, 4)));
    // Not shown: nothing comes in three times what the finer level took once it was shown.
    assert_eq!(next_finished(&handle, 3 * full + Duration::from_millis(500)), None, "paused ({full:?})");
    // A newer request ends the wait and runs at once.
    assert!(handle.submit(request(3, 2.0)));
    assert_eq!(next_finished(&handle, Duration::from_secs(60)), Some((3, 4)), "the newer preview");
    handle.preview_shown(3);
    assert_eq!(next_finished(&handle, Duration::from_secs(60)), Some((3, 1)));
}

#[test]
fn a_design_asked_at_the_finest_level_only_restarts_from_its_rrs_or_is_kept() {
    let handle = EngineHandle::spawn(1).unwrap();
    let a = RunConfig::new(small_lake(), small("nominal", 24, 24));
    let mut b = a.clone();
    b.instrument.gain_e_per_dn = 2.5;
    let mut c = a.clone();
    c.instrument.read_noise_e = 20.0;
    let request = |generation, configs: Vec<&RunConfig>, finest_only| Request {
        generation,
        configs: configs.into_iter().cloned().map(Some).collect(),
        finest_only,
        decimations: vec![4, 2, 1],
    };
    // What the worker reports, (index, decimation) or (index, 0) for a design kept as it is.
    let events = |n: usize| {
        let mut seen = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(120);
        while seen.len() < n && Instant::now() < deadline {
            match handle.wait(Duration::from_millis(100)) {
                Some(Event::Finished { index, decimation, result, .. }) => {
                    assert!(result.is_ok());
                    seen.push((index, decimation));
                }
                Some(Event::Kept { index, .. }) => seen.push((index, 0)),
                Some(Event::Progress { .. }) | None => {}
            }
        }
        seen
    };
    assert!(handle.submit(request(1, vec![&a], vec![])));
    assert_eq!(events(3), vec![(0, 4), (0, 2), (0, 1)]);
    // A again at the finest level only, beside a new B: B at every level, then A, restarted
    // from the Rrs its first run left; C, never run, is not run but kept as it is.
    assert!(handle.submit(request(2, vec![&a, &b, &c], vec![true, false, true])));
    assert_eq!(events(5), vec![(1, 4), (1, 2), (1, 1), (0, 1), (2, 0)]);
    // And nothing else: the worker is idle after them.
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(handle.stats().results_sent, 3 + 5);
}
