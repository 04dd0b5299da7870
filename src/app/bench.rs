//! `shoal bench`'s app rows: the latency from a slider change to the updated preview on screen,
//! and the UI thread's frame time while the engine works.
//!
//! Headless: the app draws into an egui context with no window, exactly as the eframe loop calls
//! it (`draw`, then tessellation); what the GPU does with the triangles is not counted (the glow
//! back end uploads a few textures and draws one mesh list, well under a millisecond). Frames are
//! paced as on a 60 Hz display, so a result waits up to one refresh (16.7 ms) to be drawn, as it
//! would on screen.
//!
//! "Updated preview on screen" means: both instruments show a result of the new generation and
//! the map textures built from those results are loaded (the frame that draws them is the one
//! timed last).

use std::time::{Duration, Instant};

use super::model::AppState;
use super::{AppOptions, ShoalApp};

/// Display refresh interval, ms (60 Hz).
const REFRESH_MS: f64 = 1000.0 / 60.0;

/// One frame: run the UI and tessellate its shapes. Returns the time taken, ms.
fn frame(ctx: &egui::Context, app: &mut ShoalApp) -> f64 {
    let input = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1500.0, 960.0))),
        ..Default::default()
    };
    let start = Instant::now();
    let out = ctx.run_ui(input, |ui| {
        app.tick(ui.ctx());
        app.draw(ui);
    });
    let _ = ctx.tessellate(out.shapes, out.pixels_per_point);
    start.elapsed().as_secs_f64() * 1e3
}

/// Is the current generation's result at decimation `level` or finer on screen for every design?
fn on_screen(app: &ShoalApp, level: usize) -> bool {
    let generation = app.link.generation();
    !app.link.shown.is_empty()
        && app
            .link
            .shown
            .iter()
            .all(|s| s.as_ref().is_some_and(|s| s.generation == generation && s.decimation <= level))
        && app.images.ready()
}

/// Draw frames until `done(app)` or `timeout`; returns the frame times, ms.
fn frames_until(
    ctx: &egui::Context,
    app: &mut ShoalApp,
    timeout: Duration,
    done: impl Fn(&ShoalApp) -> bool,
) -> Result<Vec<f64>, String> {
    let deadline = Instant::now() + timeout;
    let mut times = Vec::new();
    loop {
        times.push(frame(ctx, app));
        if done(app) {
            return Ok(times);
        }
        if let Some(e) = app.link.errors.iter().flatten().next() {
            return Err(format!("the engine failed: {e}"));
        }
        if Instant::now() > deadline {
            return Err(format!("no result within {} s", timeout.as_secs()));
        }
        // Paced like a 60 Hz display: the next frame starts one refresh after this one did.
        std::thread::sleep(Duration::from_secs_f64((REFRESH_MS - times.last().copied().unwrap_or(0.0)).max(0.0) / 1e3));
    }
}

fn percentile(mut v: Vec<f64>, q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i]
}

/// One parameter moved like a slider: `steps` distinct values (so no run is served from the cache).
struct Sweep {
    label: &'static str,
    set: fn(&mut AppState, usize),
}

const SWEEPS: [Sweep; 2] = [
    Sweep { label: "aperture", set: |s, k| s.designs[0].spec.aperture_mm *= 1.0 + 0.02 * (k as f64 + 1.0) },
    Sweep { label: "pixel pitch", set: |s, k| s.designs[0].spec.pixel_pitch_um *= 1.0 + 0.02 * (k as f64 + 1.0) },
];

/// Latency and frame times of `steps` changes of `sweep` at the preview 1/`preview`, with B
/// on screen at the final resolution as in use.
///
/// After each change the engine refines A; the next change comes once A's 1/`settle` is on
/// screen (the engine then cancels the finer levels, as when a user keeps moving a slider), so
/// the frames counted are frames while the engine works.
fn sweep_row(
    ctx: &egui::Context,
    app: &mut ShoalApp,
    sweep: &Sweep,
    steps: usize,
    preview: usize,
    settle: usize,
) -> Result<String, String> {
    let mut latencies = Vec::new();
    let mut engine = Vec::new();
    let mut stages: std::collections::BTreeMap<String, Vec<f64>> = std::collections::BTreeMap::new();
    let mut busy_frames = Vec::new();
    for k in 0..steps {
        (sweep.set)(&mut app.state, k);
        let start = Instant::now();
        let first = frames_until(ctx, app, Duration::from_secs(120), |a| on_screen(a, preview))?;
        latencies.push(start.elapsed().as_secs_f64() * 1e3);
        // The engine's share: A's run (only A changed).
        if let Some(shown) = app.link.shown[0].as_ref() {
            let report = &shown.output.report;
            engine.push(report.total_seconds * 1e3);
            for s in report.stages.iter().filter(|s| s.status == crate::engine::StageStatus::Ran) {
                stages.entry(s.stage.to_string()).or_default().push(s.seconds * 1e3);
            }
        }
        busy_frames.extend(first);
        busy_frames.extend(frames_until(ctx, app, Duration::from_secs(600), |a| on_screen(a, settle))?);
    }
    let lat_min = latencies.iter().copied().fold(f64::INFINITY, f64::min);
    let lat_max = latencies.iter().copied().fold(0.0, f64::max);
    let n = busy_frames.len();
    Ok(format!(
        "| {} | 1/{preview} | {steps} | {:.0} ({lat_min:.0}–{lat_max:.0}) | {:.0}: {} | ≤ 40 / 60 | {:.1} / {:.1} / {:.1} | {n} |\n",
        sweep.label,
        percentile(latencies.clone(), 0.5),
        percentile(engine, 0.5),
        largest_stages(stages, steps),
        percentile(busy_frames.clone(), 0.5),
        percentile(busy_frames.clone(), 0.95),
        percentile(busy_frames, 1.0),
    ))
}

/// The engine's three largest stages by median time, ms ("correction 2.8, retrieval 1.9, …"):
/// what a change reruns and where its time goes. A stage that ran in only some of the `steps`
/// runs counts as 0 in the others.
fn largest_stages(stages: std::collections::BTreeMap<String, Vec<f64>>, steps: usize) -> String {
    let mut by_time: Vec<(f64, String)> = stages
        .into_iter()
        .map(|(name, mut t)| {
            t.resize(steps.max(t.len()), 0.0);
            (percentile(t, 0.5), name)
        })
        .collect();
    by_time.sort_by(|a, b| b.0.total_cmp(&a.0));
    by_time.iter().take(3).map(|(t, name)| format!("{name} {t:.1}")).collect::<Vec<_>>().join(", ")
}

/// The app rows of `shoal bench` (Markdown, with a heading).
///
/// The app starts on the default study and refines to full resolution (1/4 in the quick run);
/// then each parameter of A is moved `steps` times at the default preview (1/24) and at 1/16,
/// with B shown at the final resolution (what the maps, palette and plots then redraw).
pub fn rows(quick: bool) -> Result<String, String> {
    let ctx = egui::Context::default();
    let mut state = AppState::default();
    if quick {
        state.decimations.retain(|&d| d >= 4);
    }
    let preview = state.decimations()[0];
    let finest = state.decimations().last().copied().unwrap_or(1);
    let steps = if quick { 3 } else { 7 };
    let mut app = ShoalApp::with_state(state, &ctx, AppOptions::default());
    let cold = Instant::now();
    frames_until(&ctx, &mut app, Duration::from_secs(600), |a| on_screen(a, preview))?;
    let cold_preview_s = cold.elapsed().as_secs_f64();
    frames_until(&ctx, &mut app, Duration::from_secs(600), |a| on_screen(a, finest) && !a.link.busy())?;
    let cold_final_s = cold.elapsed().as_secs_f64();

    let mut out = String::new();
    out.push_str("\n## App (headless egui frames, default study: CubeSat vs SmallSat over Lake Hume)\n\n");
    out.push_str(&format!(
        "Engine threads {}. From start: first preview (1/{preview}) on screen {cold_preview_s:.2} s, final (1/{finest}) {cold_final_s:.1} s.\n\n",
        super::link::engine_threads(0)
    ));
    out.push_str("| change to A | preview | changes | slider → preview on screen, median (min–max) ms | of which engine, median ms: its largest stages | target median / max | frame ms while engine runs, median / p95 / max | frames |\n|---|---|---|---|---|---|---|---|\n");
    let previews: &[usize] = if quick { &[24] } else { &[24, 16] };
    for &p in previews {
        app.state.decimations = vec![p, 4, finest];
        app.state.decimations.dedup();
        frames_until(&ctx, &mut app, Duration::from_secs(600), |a| on_screen(a, finest) && !a.link.busy())?;
        for sweep in &SWEEPS {
            out.push_str(&sweep_row(&ctx, &mut app, sweep, steps, p, 4)?);
        }
    }
    out.push_str(&format!("\nFrame target 16 ms. Latency counts from the state change (the slider's value) to the end of the frame that draws the new maps; frames are paced at 60 Hz. Only A changes, so only A re-runs; B's result at 1/{finest} is kept, and its maps and plots are redrawn with A's. The next change comes once A's 1/4 is on screen (the finer levels are then cancelled, as when a slider keeps moving).\n"));
    Ok(out)
}
