//! The app's engine restarts a run at its retrievals from the kept Rrs, even when the cache
//! has let that run's earlier cubes go, and gives what a fresh engine gives.

use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, RunOutput, Stage, StageStatus};

use super::{small, small_lake};

/// Everything a run's output says, part by part, but how long its stages took and which ran.
fn said(out: &RunOutput) -> Vec<(&'static str, String)> {
    let mut report = out.report.clone();
    report.stages.clear();
    report.total_seconds = 0.0;
    let retrievals: Vec<String> = out.retrievals.iter().map(|r| format!("{:?} {:?}", r.product, r.metrics)).collect();
    vec![
        ("truth", format!("{:?}", out.truth)),
        ("views", format!("{:?}", out.views)),
        ("calibration", format!("{:?}", out.calibration)),
        ("correction", format!("{:?}", out.correction)),
        ("snr", format!("{:?}", out.snr)),
        ("feasibility", format!("{:?}", out.feasibility)),
        ("config", format!("{:?}", out.config)),
        ("retrievals", format!("{retrievals:?}")),
        ("report", format!("{report:?}")),
    ]
}

/// `a` and `b` say the same, part by part (`but` left out).
fn same(a: &RunOutput, b: &RunOutput, what: &str, but: &[&str]) {
    for ((part, x), (_, y)) in said(a).into_iter().zip(said(b)) {
        assert!(x == y || but.contains(&part), "{what}: the {part} differs");
    }
}

#[test]
fn a_retrieval_change_restarts_at_the_retrievals_after_the_cubes_are_gone() {
    let mut config = RunConfig::new(small_lake(), small("nominal", 48, 40));
    config.retrievals = vec![ron::from_str("Almi()").unwrap()];
    let mut engine = Engine::for_app(usize::MAX, 2).with_view_bytes(16 << 10);
    engine.run(&config, &RunControl::new()).unwrap();
    // Half the cache goes, least recently used first: the scene maps, the pupil radiance and
    // the Level-0 counts, not the Rrs and what the run kept beside it (the newest).
    let held = engine.cached_bytes();
    engine.set_cache_budget(held / 2);
    config.retrievals = vec![ron::from_str("Almi(settings: (noise_weighting: false))").unwrap()];
    let ran = |e: &Engine| {
        [Stage::Radiance, Stage::Level0, Stage::Level1, Stage::Correction, Stage::Snr].map(|s| e.executions(s))
    };
    let before = ran(&engine);
    let warm = engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(ran(&engine), before, "nothing before the retrieval ran again");
    assert_eq!(engine.executions(Stage::Retrieval), 2);
    let fresh = Engine::for_app(usize::MAX, 2).with_view_bytes(16 << 10).run(&config, &RunControl::new()).unwrap();
    same(&warm, &fresh, "the restart from the Rrs", &[]);
    // Its report lists the same stages, those before the retrievals as served from the cache.
    let stages = |o: &RunOutput| o.report.stages.iter().map(|s| s.stage).collect::<Vec<_>>();
    assert_eq!(stages(&warm), stages(&fresh));
    let radiance = warm.report.stages.iter().find(|s| s.stage == Stage::Radiance).unwrap();
    assert_eq!(radiance.status, StageStatus::Cached);
    // A change before the Rrs is not served from it.
    config.instrument.gain_e_per_dn *= 1.5;
    let changed = engine.run(&config, &RunControl::new()).unwrap();
    assert!(engine.executions(Stage::Level0) > before[1], "the gain reruns the digitisation");
    let fresh = Engine::for_app(usize::MAX, 2).with_view_bytes(16 << 10).run(&config, &RunControl::new()).unwrap();
    // (A run through the stage cache reports what it computed, the water model's evaluations
    // among them, so its report is not a fresh run's; the restart's is.)
    same(&changed, &fresh, "after a gain change", &["report"]);
}

#[test]
fn an_engine_that_keeps_cubes_hands_them_back_after_a_retrieval_change() {
    let mut config = RunConfig::new(small_lake(), small("nominal", 32, 24));
    config.retrievals = vec![ron::from_str("Almi()").unwrap()];
    // The default engine hands back cubes: a retrieval change finds them all in the cache, and
    // its output carries them (a restart from the Rrs could not).
    let mut engine = Engine::new();
    engine.run(&config, &RunControl::new()).unwrap();
    config.retrievals = vec![ron::from_str("Almi(settings: (noise_weighting: false))").unwrap()];
    let out = engine.run(&config, &RunControl::new()).unwrap();
    assert!(out.cubes.is_some(), "the cubes are handed back");
    assert_eq!(engine.executions(Stage::Radiance), 1);
}

#[test]
fn a_smaller_share_of_the_views_restarts_at_the_retrievals_and_cuts_the_views() {
    use shoal::engine::footprint::Footprint;
    let mut config = RunConfig::new(small_lake(), small("nominal", 48, 40));
    config.retrievals = vec![ron::from_str("Almi()").unwrap()];
    // The views of 40 × 48 pixels and 19 bands take 18 bytes per kept pixel and band: every
    // other pixel is 164,160 bytes, every third 76,608, every fourth 41,040.
    let mut engine = Engine::for_app(usize::MAX, 2).with_view_bytes(170 << 10);
    let first = engine.run(&config, &RunControl::new()).unwrap();
    let wide = first.views.clone().unwrap();
    assert_eq!((wide.stride, wide.bytes()), (2, 164_160));
    let ran = |e: &Engine| {
        [Stage::Radiance, Stage::Level0, Stage::Level1, Stage::Correction, Stage::Retrieval].map(|s| e.executions(s))
    };
    let before = ran(&engine);
    // More designs in the app: a smaller share, in which a new run would keep every third
    // pixel. The same configuration restarts from its kept Rrs; nothing runs (its retrieval
    // comes from the cache), and its views are cut from every other pixel to every fourth.
    let share = 80 << 10;
    engine.set_view_bytes(share);
    let cut = engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(ran(&engine), before, "nothing ran again");
    let views = cut.views.clone().unwrap();
    assert_eq!((views.stride, views.bytes()), (4, 41_040));
    assert_eq!(Some(&*views), wide.within(share).as_ref());
    // They are the views a run at every fourth pixel keeps, value for value.
    let own = Engine::for_app(usize::MAX, 2).with_view_bytes(48 << 10).run(&config, &RunControl::new()).unwrap();
    assert_eq!(own.views.as_deref(), Some(&*views));
    same(&cut, &first, "the restart under a smaller share", &["views"]);
    // The engine keeps the cut views, not the wide ones: the next restart hands back the same.
    let again = engine.run(&config, &RunControl::new()).unwrap();
    assert!(std::sync::Arc::ptr_eq(again.views.as_ref().unwrap(), cut.views.as_ref().unwrap()));
    // A larger share again keeps the cut views (a run made again would take finer ones).
    engine.set_view_bytes(170 << 10);
    let wider = engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(wider.views.as_ref().unwrap().stride, 4);
    assert_eq!(ran(&engine), before);
}
