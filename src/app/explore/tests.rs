use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

use super::*;
use crate::app::model::AppState;
use crate::app::{AppOptions, ShoalApp};
use crate::timing::{Comparison, Paired};

#[test]
fn the_cost_window_shows_the_95th_percentile_at_1280x720_and_marks_rows_of_an_older_a_stale() {
    let mut h = Harness::builder().with_size(egui::vec2(1280.0, 720.0)).build_eframe(|cc| {
        let state = AppState { decimations: vec![24], ..AppState::default() };
        let mut app =
            ShoalApp::with_state(state, &cc.egui_ctx, AppOptions { engine_threads: 1, ..AppOptions::default() });
        let e = &mut app.ui.explore;
        e.cost_open = true;
        e.cost_rows = vec![
            CostRow::timed(
                "reference (full fidelity)",
                &[4.47, 4.32, 4.49],
                Comparison::NoMeasurableDifference(None),
                Some(0.0),
                Some(0.0),
            ),
            // The longest label of the aLMI table, so that the grid is as wide as in use.
            CostRow::timed(
                "the defaults (band nodes 4, single precision)",
                &[3.63, 3.59, 3.70],
                Comparison::Ratio(Paired::exact(0.81)),
                Some(1.683),
                Some(5.312),
            ),
            CostRow::timed(
                "band nodes 3 per band",
                &[4.1, 4.2, 4.3],
                Comparison::NoMeasurableDifference(Some(Paired {
                    ratio: 0.97,
                    lo: 0.91,
                    hi: 1.04,
                    n: 5,
                    level_pct: 93.75,
                })),
                Some(0.2),
                Some(0.9),
            ),
            CostRow::timed("preview 1/4", &[0.49, 0.45, 0.51], Comparison::Ratio(Paired::exact(0.11)), None, None),
        ];
        e.cost_status = "done: 3 settings × 3 rounds".into();
        e.cost_config = app.state.configs().into_iter().next().map(at_full_fidelity);
        app
    });
    h.run_steps(4);
    for text in ["chl p95 %", "5.312", "1.683", "other grid", "0.81×", "no measurable difference (0.91–1.04×)"] {
        assert!(h.query_by_label(text).is_some(), "the cost window does not show {text:?}");
    }
    // The p95 column is in view: at 640 px wide the window showed it only after a
    // horizontal scroll. The window's description wraps at the content's width, so its
    // right edge is the window's; the column's header and a value must end left of it.
    let content_right = h.get_by_label_contains("Time of the whole chain").rect().right();
    for text in ["chl p95 %", "5.312"] {
        let right = h.get_by_label(text).rect().right();
        assert!(
            right <= content_right + 1.0 && right < 1280.0,
            "{text:?} ends at x = {right}, the window's content at {content_right}"
        );
    }
    assert!(h.query_by_label_contains("Stale").is_none(), "rows of the current A are not stale");
    // A changes: the rows were measured for another instrument.
    h.state_mut().state.designs[0].spec.aperture_mm += 10.0;
    h.run_steps(2);
    assert!(h.query_by_label_contains("Stale").is_some(), "rows of an older A are marked stale");
}
