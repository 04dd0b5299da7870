//! The metrics table of every design: per product, MAE, bias and the share returned against the
//! requirements (one judgement for the app, its exports and `shoal study`:
//! `Requirements::check_run`), each column marked for what it is — the configuration set, its
//! preview, the previous configuration's numbers greyed while the new ones run, or a failure —
//! and every pass under a plausibility warning marked; the bottom-type and SNR rows; the
//! dominant-substrate confusion tables; the seed-spread controls.

use super::model::label;
use super::{ShoalApp, theme};
use crate::engine::RunOutput;
use crate::metrics::Metrics;
use crate::study::Check;

fn pass(ok: bool) -> egui::RichText {
    if ok {
        egui::RichText::new("pass").color(theme::PASS)
    } else {
        egui::RichText::new("FAIL").color(theme::FAIL).strong()
    }
}

/// The verdict cell of a set of checks, the checks listed on hover.
fn verdict_cell(ui: &mut egui::Ui, checks: &[&Check]) {
    match crate::study::verdict(checks.iter().copied()) {
        Some(ok) => {
            let text = checks.iter().map(|c| c.describe()).collect::<Vec<_>>().join("\n");
            ui.label(pass(ok)).on_hover_text(text);
        }
        None => {
            ui.label("").on_hover_text("no requirement on this product (Requirements, left panel)");
        }
    }
}

/// The dominant-substrate confusion tables of every design (rows: true class; cells: % of the row
/// retrieved as each class), when the retrieval unmixes substrates.
pub(super) fn substrate_tables(app: &ShoalApp, ui: &mut egui::Ui) {
    for i in 0..app.state.designs.len() {
        let Some(c) = app
            .link
            .current(i)
            .and_then(|s| s.output.retrievals.first())
            .and_then(|r| r.metrics.substrate_confusion.as_ref())
        else {
            continue;
        };
        let ab = label(i);
        let accuracy = c.accuracy_pct().map_or_else(|| "–".into(), |a| format!("{a:.1} %"));
        egui::CollapsingHeader::new(format!("{ab}: dominant substrate, {accuracy} of pixels correct"))
            .id_salt(format!("confusion-{ab}"))
            .default_open(false)
            .show(ui, |ui| {
                egui::Grid::new(format!("confusion-grid-{ab}")).striped(true).show(ui, |ui| {
                    ui.strong("true \\ retrieved");
                    for name in &c.classes {
                        ui.strong(name.replace('_', " "));
                    }
                    ui.strong("correct");
                    ui.end_row();
                    for (t, row) in c.counts.iter().enumerate() {
                        let n: usize = row.iter().sum();
                        if n == 0 {
                            continue;
                        }
                        ui.label(c.classes[t].replace('_', " "));
                        for &k in row {
                            ui.label(format!("{:.0} %", 100.0 * k as f64 / n as f64))
                                .on_hover_text(format!("{k} of {n} pixels"));
                        }
                        ui.label(c.recall_pct(t).map_or_else(|| "–".into(), |r| format!("{r:.0} %")));
                        ui.end_row();
                    }
                });
            });
    }
}

/// How a column of the metrics table stands against the configuration set.
#[derive(Clone, Copy)]
enum Column<'a> {
    /// Its numbers are the configuration's (at `decimation`; `preview` when not the finest).
    Current { run: &'a RunOutput, decimation: usize, preview: bool },
    /// Numbers of the previous configuration, shown greyed until the new ones arrive.
    Earlier(&'a RunOutput),
    /// The configuration's run failed.
    Failed(&'a str),
    /// Nothing yet.
    Waiting,
}

impl<'a> Column<'a> {
    fn of(app: &'a ShoalApp, i: usize) -> Self {
        use super::link::Standing;
        match app.link.standing(i) {
            Standing::Current(s) => {
                Self::Current { run: &s.output, decimation: s.decimation, preview: s.decimation != app.link.finest() }
            }
            Standing::Earlier(s) => Self::Earlier(&s.output),
            Standing::Failed(e) => Self::Failed(e),
            Standing::Waiting => Self::Waiting,
        }
    }

    /// The run whose numbers the column shows (current or greyed).
    fn run(self) -> Option<&'a RunOutput> {
        match self {
            Self::Current { run, .. } | Self::Earlier(run) => Some(run),
            _ => None,
        }
    }

    /// The column's heading: "A", "A (preview 1/24)", "A (updating)", "A (failed)".
    fn heading(self, ab: &str) -> String {
        match self {
            Self::Current { preview: true, decimation, .. } => format!("{ab} (preview 1/{decimation})"),
            Self::Current { .. } => ab.to_string(),
            Self::Earlier(_) => format!("{ab} (updating)"),
            Self::Failed(_) => format!("{ab} (failed)"),
            Self::Waiting => format!("{ab} (running)"),
        }
    }

    /// A cell's text, greyed when it belongs to the previous configuration.
    fn text(self, t: impl Into<String>) -> egui::RichText {
        let t = egui::RichText::new(t);
        if matches!(self, Self::Earlier(_)) { t.weak().italics() } else { t }
    }
}

/// The verdict of `checks` with the run's plausibility guard: a pass under a warning (a design
/// that saturates over the scene, smears, or has no buildable f-number) reads "pass?" in amber,
/// the warnings on hover; a greyed column's verdict is greyed.
fn guarded_verdict(ui: &mut egui::Ui, checks: &[&Check], column: Column<'_>) {
    let warnings: Vec<&str> =
        column.run().map(|r| r.report.warnings.iter().map(|w| w.message.as_str()).collect()).unwrap_or_default();
    match (crate::study::verdict(checks.iter().copied()), column) {
        (None, _) => {
            ui.label("").on_hover_text("no requirement on this product (Requirements, left panel)");
        }
        (Some(_), Column::Earlier(_)) => {
            ui.label(egui::RichText::new("…").weak())
                .on_hover_text("the previous configuration's verdict is not shown");
        }
        (Some(true), _) if !warnings.is_empty() => {
            let text = checks.iter().map(|c| c.describe()).collect::<Vec<_>>().join("\n");
            ui.label(egui::RichText::new("pass?").color(theme::WARN).strong()).on_hover_text(format!(
                "{text}\n\nThe numbers pass, but the design is implausible here:\n{}",
                warnings.join("\n")
            ));
        }
        (Some(_), _) => verdict_cell(ui, checks),
    }
}

pub(super) fn metrics_table(app: &ShoalApp, ui: &mut egui::Ui, configs: &[crate::engine::RunConfig]) {
    let columns: Vec<Column<'_>> = (0..app.state.designs.len()).map(|i| Column::of(app, i)).collect();
    // One judgement for app, export and CLI: `Requirements::check_run`.
    let checks: Vec<Vec<Check>> = columns
        .iter()
        .map(|c| {
            c.run().map_or_else(Vec::new, |o| {
                let metrics = o.retrievals.first().map(|r| &r.metrics);
                app.state.requirements.check_run(
                    &o.config.instrument.name,
                    o.config.seed,
                    metrics,
                    &o.snr,
                    &o.correction.rrs_metrics,
                )
            })
        })
        .collect();
    // The seed spread, when measured for these very designs.
    let spread = app.ui.seeds.spread_for(configs).unwrap_or_default();
    // Wider than the panel with many designs: it scrolls sideways rather than squeezing.
    egui::ScrollArea::horizontal().id_salt("metrics-scroll").show(ui, |ui| {
        egui::Grid::new("metrics").num_columns(1 + 4 * columns.len()).striped(true).show(ui, |ui| {
            ui.strong("product");
            for (i, c) in columns.iter().enumerate() {
                let ab = label(i);
                let h = c.heading(&ab);
                for (k, what) in ["MAE", "bias", "returned", ""].iter().enumerate() {
                    let text = if k == 3 { h.clone() } else { format!("{ab} {what}") };
                    ui.label(egui::RichText::new(text).strong().color(theme::design(i)));
                }
            }
            ui.end_row();
            let variables: Vec<String> = columns
                .iter()
                .filter_map(|c| c.run())
                .flat_map(|o| o.retrievals.iter().flat_map(|r| r.metrics.variables.iter().map(|v| v.variable.clone())))
                .fold(Vec::new(), |mut acc, v| {
                    if !acc.contains(&v) {
                        acc.push(v);
                    }
                    acc
                });
            for v in &variables {
                ui.label(crate::metrics::label(v)).on_hover_text(format!("`{v}`"));
                for (index, (column, checks)) in columns.iter().zip(&checks).enumerate() {
                    let m: Option<&Metrics> =
                        column.run().and_then(|o| o.retrievals.first()).and_then(|r| r.metrics.get(v));
                    match m {
                        Some(m) if m.n == 0 => {
                            // Nothing returned: no MAE or bias to show (never "0.0 %").
                            let why =
                                column.run().and_then(no_pixel_reason).unwrap_or_else(|| "no pixel returned".into());
                            ui.label(column.text("–")).on_hover_text(&why);
                            ui.label(column.text("–")).on_hover_text(&why);
                            ui.label(column.text(format!("{:.1} %", m.returned_pct))).on_hover_text(&why);
                        }
                        Some(m) => metric_cells(ui, *column, m, v, index, spread, app.ui.seeds.decimation),
                        None => {
                            let why = match column {
                                Column::Failed(e) => format!("the run failed: {e}"),
                                Column::Waiting => "running".into(),
                                _ => "this retrieval does not make this product".into(),
                            };
                            for _ in 0..3 {
                                ui.label("–").on_hover_text(&why);
                            }
                        }
                    }
                    let mine: Vec<&Check> =
                        checks.iter().filter(|c| c.variable.as_deref() == Some(v.as_str())).collect();
                    guarded_verdict(ui, &mine, *column);
                }
                ui.end_row();
            }
            let agreement = |c: &Column<'_>| {
                c.run().and_then(|o| o.retrievals.first()).and_then(|r| r.metrics.substrate_agreement_pct)
            };
            if columns.iter().any(|c| agreement(c).is_some()) {
                ui.label("bottom type").on_hover_text("dominant substrate right, % of returned water pixels");
                for (column, checks) in columns.iter().zip(&checks) {
                    ui.label(column.text(agreement(column).map_or_else(|| "–".into(), |a| format!("{a:.1} % right"))));
                    ui.label("");
                    ui.label("");
                    let mine: Vec<&Check> =
                        checks.iter().filter(|c| c.variable.as_deref() == Some("substrate")).collect();
                    guarded_verdict(ui, &mine, *column);
                }
                ui.end_row();
            }
            if app.state.requirements.snr.is_some() && columns.iter().any(|c| c.run().is_some()) {
                ui.label("SNR, every band");
                for (column, checks) in columns.iter().zip(&checks) {
                    let snr = column.run().map(|o| o.snr.as_slice()).unwrap_or_default();
                    let saturated = snr.iter().filter(|r| r.saturated()).count();
                    let lowest = snr.iter().map(|r| r.snr_analytic).reduce(f64::min);
                    if saturated > 0 {
                        ui.label(egui::RichText::new(format!("{saturated} saturated")).color(theme::FAIL))
                            .on_hover_text(
                                "Bands whose signal at the scene's median water radiance fills the well or the ADC: \
                         their SNR there is no figure of merit",
                            );
                    } else {
                        ui.label(column.text(lowest.map_or_else(|| "–".into(), |s| format!("lowest {s:.0}"))));
                    }
                    ui.label("");
                    ui.label("");
                    let mine: Vec<&Check> = checks.iter().filter(|c| c.variable.is_none()).collect();
                    guarded_verdict(ui, &mine, *column);
                }
                ui.end_row();
            }
            correction_rows(ui, &columns);
            glint_row(ui, &columns);
        });
    });
    if columns.iter().all(|c| c.run().is_none()) {
        ui.label("No results yet.");
    }
}

/// With an image-based correction: the aerosol it found against the scene's, and the corrected
/// Rrs's log-space error at 400–560 nm (pooled over the bands there, as ACIX-Aqua reports it).
fn correction_rows(ui: &mut egui::Ui, columns: &[Column<'_>]) {
    let aerosol = |c: &Column<'_>| c.run().and_then(|o| o.report.aerosol.clone());
    if !columns.iter().any(|c| aerosol(c).is_some()) {
        return;
    }
    ui.label("aerosol found (image-based correction)").on_hover_text(
        "AOT(550) the image-based correction found from the design's own bands (median over the water \
         pixels), against the scene's true AOT",
    );
    for column in columns {
        match aerosol(column) {
            Some(a) => {
                ui.label(column.text(format!("AOT {:.3} (true {:.3})", a.aot550.0, a.aot550_true))).on_hover_text(
                    format!(
                        "5–95 %: {:.3}–{:.3}; per-pixel error (median) {:.3}; Ångström {:.2} (true {:.2}); outside the family: {:.1} %; {}\n{}",
                        a.aot550.1,
                        a.aot550.2,
                        a.aot550_abs_error,
                        a.angstrom,
                        a.angstrom_true,
                        a.outside_family_pct,
                        a.fit,
                        a.epsilon_words()
                    ),
                );
            }
            None => {
                ui.label("–").on_hover_text("the exact correction: the scene's own atmosphere");
            }
        }
        for _ in 0..3 {
            ui.label("");
        }
    }
    ui.end_row();
    ui.label("Rrs 400–560 nm")
        .on_hover_text("the corrected Rrs against the truth, log-space, every band centred in 400–560 nm");
    for column in columns {
        let pooled =
            column.run().and_then(|o| crate::correction::pooled_rrs_error(&o.correction.rrs_metrics, 400.0, 560.0));
        match pooled {
            Some((mae, bias, returned, n)) => {
                ui.label(column.text(format!("{mae:.1} %")))
                    .on_hover_text(format!("log-space MAE over {n} band values ({returned:.1} % positive)"));
                ui.label(column.text(format!("{bias:+.1} %")));
                ui.label(column.text(format!("{returned:.1} %")));
            }
            None => {
                for _ in 0..3 {
                    ui.label("–");
                }
            }
        }
        ui.label("");
    }
    ui.end_row();
}

/// With the exact correction's high-glint mask (`correction.glint_threshold_per_sr`, a season's
/// looks): the water pixels it left out, which the returned shares above no longer count.
fn glint_row(ui: &mut egui::Ui, columns: &[Column<'_>]) {
    let mask = |c: &Column<'_>| c.run().and_then(|o| o.report.exact_high_glint);
    if !columns.iter().any(|c| mask(c).is_some()) {
        return;
    }
    ui.label("left out for high glint").on_hover_text(
        "water pixels the exact correction masked, as l2gen's HIGLINT: the normalised glint it expects from \
         the wind it assumes above its threshold",
    );
    for column in columns {
        match mask(column) {
            Some(g) => {
                let share = if g.water_pixels > 0 { 100.0 * g.pixels as f64 / g.water_pixels as f64 } else { 0.0 };
                ui.label(column.text(format!("{share:.1} %"))).on_hover_text(format!(
                    "{} of {} water pixels: L_GN above {} sr⁻¹ at the assumed wind {:.1} m/s",
                    g.pixels, g.water_pixels, g.threshold_per_sr, g.assumed_wind_m_s
                ));
            }
            None => {
                ui.label("–");
            }
        }
        for _ in 0..3 {
            ui.label("");
        }
    }
    ui.end_row();
}

/// The MAE (with its seed spread when measured), bias and returned cells of variable `v` of
/// the column at `index` (0 A, 1 B, …).
fn metric_cells(
    ui: &mut egui::Ui,
    column: Column<'_>,
    m: &Metrics,
    v: &str,
    index: usize,
    spread: &[crate::study::SeedSpread],
    spread_decimation: usize,
) {
    let unit = crate::metrics::unit(v);
    let in_units = format!(
        "log-space MAE {:.1} %; mean |error| {:.3} {unit}, mean error {:+.3} {unit}, RMSE {:.3} {unit} ({} pixels)",
        m.mae_pct(),
        m.mean_abs_error,
        m.mean_error,
        m.rmse,
        m.n
    );
    // Depth errors read in metres too (a log-space % alone hides whether 10 % is 0.2 m or 2 m).
    let mut text = if unit == "m" {
        format!("{:.1} % ({:.2} m)", m.mae_pct(), m.mean_abs_error)
    } else {
        format!("{:.1} %", m.mae_pct())
    };
    let mut hover = in_units;
    if let Column::Earlier(_) = column {
        hover.push_str("\nThe previous configuration's value: the new one is being computed.");
    }
    let ab = label(index);
    if let Some(s) = spread.iter().find(|s| s.instrument == ab && s.variable == *v).filter(|s| s.seeds > 1) {
        text.push_str(&format!(" ±{:.1}", s.mae_pct_std));
        hover.push_str(&format!(
            "\n± is the standard deviation of the MAE over {} noise seeds at 1/{} (mean {:.1} %, range {:.1}–{:.1} %)",
            s.seeds, spread_decimation, s.mae_pct_mean, s.mae_pct_range.0, s.mae_pct_range.1
        ));
    }
    ui.label(column.text(text)).on_hover_text(hover);
    ui.label(column.text(format!("{:+.1} %", m.bias_pct())));
    ui.label(column.text(format!("{:.1} %", m.returned_pct)));
}

/// Why a run returned no pixel, when the Level-0 flags say: most pixel-bands saturated, or most
/// at zero counts; `None` when neither explains it (the retrieval found no physical solution).
#[must_use]
pub(super) fn no_pixel_reason(out: &RunOutput) -> Option<String> {
    let (rows, cols, bands) = out.report.shape;
    let total = (rows * cols * bands).max(1) as f64;
    let saturated = out.report.saturated as f64 / total;
    let zero = out.report.zero_counts as f64 / total;
    if saturated > 0.2 {
        Some(format!(
            "no pixel returned: {:.0} % of the pixel-bands saturate (the signal fills the well or the ADC: smaller aperture, shorter exposure, more well or gain)",
            100.0 * saturated
        ))
    } else if zero > 0.2 {
        Some(format!("no pixel returned: {:.0} % of the pixel-bands read zero counts", 100.0 * zero))
    } else {
        None
    }
}

/// Start (or cancel) the seed-spread runs, and say what the ± in the table means.
pub(super) fn seed_controls(app: &mut ShoalApp, ui: &mut egui::Ui, configs: &[crate::engine::RunConfig]) {
    ui.horizontal(|ui| {
        let job = &mut app.ui.seeds;
        if job.busy() {
            let (done, total) = job.progress();
            ui.spinner();
            ui.label(format!("seed spread: {done} of {total} runs"));
            if ui.button("Cancel").clicked() {
                job.cancel();
            }
            return;
        }
        let start = ui
            .button("Seed spread")
            .on_hover_text("Rerun every design over several detector-noise seeds; the table then shows ± the MAE's standard deviation over them");
        // Said as the spread's own settings: the table above is the runs on screen, at their
        // own resolution (its column headings say when that is a preview).
        ui.label("over");
        ui.add(egui::DragValue::new(&mut job.seeds).range(2..=20).suffix(" noise seeds").update_while_editing(false));
        ui.label("each run at");
        ui.add(egui::DragValue::new(&mut job.decimation).range(1..=16).prefix("1/").update_while_editing(false))
            .on_hover_text("The resolution of the seed-spread runs (not of the table's runs)");
        if start.clicked() {
            job.start(ui.ctx(), configs);
        } else if job.stale(configs) {
            ui.label(egui::RichText::new("stale: the designs changed").color(theme::WARN))
                .on_hover_text("The spread was measured for other designs; it is not shown. Run it again.");
        } else if !job.status.is_empty() {
            ui.label(&job.status);
        }
    });
}
