//! The engine thread: previews before full resolution, stale generations dropped, a newer
//! request supersedes the running one.

use std::time::Duration;

use shoal::engine::RunConfig;
use shoal::engine::worker::{EngineHandle, Event, Request};

use super::{small, small_lake};

fn finished(handle: &EngineHandle, timeout: Duration) -> Vec<(u64, usize, bool)> {
    let mut out = Vec::new();
    let deadline = std::time::Instant::now() + timeout;
    while std::time::Instant::now() < deadline {
        match handle.wait(Duration::from_millis(100)) {
            Some(Event::Finished { generation, decimation, result, .. }) => {
                out.push((generation, decimation, result.is_ok()));
                if decimation == 1 {
                    break;
                }
            }
            Some(Event::Progress { .. }) | None => {}
        }
    }
    out
}

#[test]
fn preview_then_full_and_stale_results_dropped() {
    let handle = EngineHandle::spawn(1).unwrap();
    let config = RunConfig::new(small_lake(), small("nominal", 64, 64));
    // Generation 1 is superseded at once by generation 2 (another gain): only 2 is reported.
    assert!(handle.submit(Request { generation: 1, configs: vec![Some(config.clone())], decimations: vec![4, 1] }));
    let mut newer = config;
    newer.instrument.gain_e_per_dn = 2.5;
    assert!(handle.submit(Request { generation: 2, configs: vec![Some(newer)], decimations: vec![4, 1] }));
    let events = finished(&handle, Duration::from_secs(120));
    assert!(events.iter().all(|e| e.0 == 2), "stale results reached the app: {events:?}");
    assert_eq!(events.iter().map(|e| e.1).collect::<Vec<_>>(), vec![4, 1], "preview first, then full");
    assert!(events.iter().all(|e| e.2));
}

#[test]
fn a_failed_run_is_reported_and_the_worker_survives() {
    let handle = EngineHandle::spawn(1).unwrap();
    let mut bad = RunConfig::new(small_lake(), small("nominal", 16, 16));
    bad.instrument.aperture_mm = 0.0;
    assert!(handle.submit(Request { generation: 1, configs: vec![Some(bad)], decimations: vec![1] }));
    let deadline = std::time::Instant::now() + Duration::from_secs(60);
    loop {
        match handle.wait(Duration::from_millis(100)) {
            Some(Event::Finished { result: Err(e), .. }) => {
                assert!(e.to_string().contains("aperture_mm"), "{e}");
                break;
            }
            Some(Event::Finished { result: Ok(_), .. }) => panic!("a zero aperture was accepted"),
            Some(Event::Progress { .. }) | None => {
                assert!(std::time::Instant::now() < deadline, "no answer from the worker")
            }
        }
    }
    let good = RunConfig::new(small_lake(), small("nominal", 16, 16));
    assert!(handle.submit(Request { generation: 2, configs: vec![Some(good)], decimations: vec![1] }));
    let events = finished(&handle, Duration::from_secs(60));
    assert_eq!(events, vec![(2, 1, true)]);
}

#[test]
fn a_and_b_run_at_each_level_before_the_next() {
    let handle = EngineHandle::spawn(1).unwrap();
    let a = RunConfig::new(small_lake(), small("cubesat", 32, 32));
    let b = RunConfig::new(small_lake(), small("smallsat", 32, 32));
    assert!(handle.submit(Request { generation: 1, configs: vec![Some(a), Some(b)], decimations: vec![4, 1] }));
    let mut order = Vec::new();
    let deadline = std::time::Instant::now() + Duration::from_secs(120);
    while order.len() < 4 && std::time::Instant::now() < deadline {
        if let Some(Event::Finished { index, decimation, result, .. }) = handle.wait(Duration::from_millis(100)) {
            assert!(result.is_ok());
            order.push((decimation, index));
        }
    }
    assert_eq!(order, vec![(4, 0), (4, 1), (1, 0), (1, 1)]);
}
