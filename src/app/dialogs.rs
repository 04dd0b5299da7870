//! The top bar's status and the app's dialogs: the typed-path export row, the "Replace?"
//! question before a save, export or load would overwrite something of the user's, and the
//! error dialog.

use std::path::PathBuf;

use super::{Confirm, ShoalApp, export};

impl ShoalApp {
    /// The typed-path export row (shown on request, or when a dialog could not be used).
    pub(super) fn typed_export(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_centered(|ui| {
            let l = ui.label("Export to");
            ui.add(egui::TextEdit::singleline(&mut self.ui.export_path).desired_width(420.0)).labelled_by(l.id);
            let path = PathBuf::from(self.ui.export_path.trim());
            let target = |what| export::typed_target(what, &path);
            if ui
                .button("Write figure")
                .on_hover_text("NAME.png, NAME.svg and NAME_config_A.ron, … per design")
                .clicked()
            {
                self.export_to(export::What::Figure, target(export::What::Figure));
            }
            if ui.button("Write data").on_hover_text("A folder NAME_data with one sub-folder per design").clicked() {
                self.export_to(export::What::Data, target(export::What::Data));
            }
            if ui
                .button("Write review pack")
                .on_hover_text(
                    "A folder NAME_review with index.html (self-contained, opens in any browser) and its figures",
                )
                .clicked()
            {
                self.export_to(export::What::ReviewPack, target(export::What::ReviewPack));
            }
            // What was written (or is being), in the row the buttons are in: the message row is
            // this one while it is open.
            if self.ui.exports.running > 0 {
                ui.spinner();
            } else if let Some(m) = &self.ui.message {
                ui.add(egui::Label::new(egui::RichText::new(m.as_str()).small()).truncate());
            }
        });
    }

    /// The "replace?" question, when a save or export would overwrite a file.
    fn confirm_dialog(&mut self, ctx: &egui::Context) {
        let Some(confirm) = &self.ui.confirm else { return };
        let question = match confirm {
            Confirm::Instrument { name, .. } => format!("Your library already has an instrument `{name}`."),
            Confirm::Study { name, .. } => format!("Your library already has a study `{name}`."),
            Confirm::Export { existing, .. } => format!(
                "These already exist: {}",
                existing.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
            ),
            Confirm::Discard { what, .. } => format!("{what} Undo (Ctrl+Z) brings them back."),
        };
        let r = egui::Modal::new(egui::Id::unique("shoal-confirm")).show(ctx, |ui| {
            ui.heading("Replace?");
            ui.label(question);
            ui.horizontal(|ui| (ui.button("Replace").clicked(), ui.button("Cancel").clicked())).inner
        });
        let (replace, cancel) = r.inner;
        if replace {
            match self.ui.confirm.take() {
                Some(Confirm::Export { what, path, .. }) => {
                    self.ui.exports.write_to(what, export::Snapshot::of(self), path);
                }
                Some(Confirm::Discard { command, .. }) => self.apply_confirmed(command),
                Some(save) => self.save(save, true),
                None => {}
            }
        } else if cancel || r.should_close() {
            self.ui.confirm = None;
            self.ui.message = Some("nothing replaced".into());
        }
    }

    /// The run's state, in a box of fixed width (nothing beside it moves as the text changes):
    /// the stage running and how far its rows have gone, with the time left in it once its pace
    /// is known; Cancel; after a cancel, Refine; a failed instrument in red; "up to date" only
    /// when every design shows the configuration set, at the finest level asked for.
    pub(super) fn status(&mut self, ui: &mut egui::Ui) {
        let size = egui::vec2(STATUS_WIDTH, ui.spacing().interact_size.y);
        let failed: Vec<String> = (0..self.state.designs.len())
            .filter(|&i| matches!(self.link.standing(i), super::link::Standing::Failed(_)))
            .map(super::model::label)
            .collect();
        let mut cancel = false;
        let mut refine = false;
        ui.allocate_ui_with_layout(size, egui::Layout::left_to_right(egui::Align::Center), |ui| {
            ui.set_min_size(size);
            if self.link.busy() {
                cancel =
                    ui.button("Cancel run").on_hover_text("Stop here: what is on screen stays, as a preview").clicked();
                match self.link.progress {
                    Some(p) => {
                        let (fraction, text, hover) = progress_text(&p);
                        let bar = egui::ProgressBar::new(fraction).desired_width(ui.available_width() - 4.0).text(text);
                        ui.add(bar).on_hover_text(hover);
                    }
                    None => {
                        ui.spinner();
                        ui.label("starting");
                    }
                }
            } else if self.link.cancelled() {
                // Before a failure: with several designs, one that failed must not keep the others
                // at their previews.
                refine = ui.button("Refine").on_hover_text("Run on to full resolution").clicked();
                let also = if failed.is_empty() { String::new() } else { format!("; {} failed", failed.join(", ")) };
                ui.colored_label(super::theme::WARN, format!("stopped: previews{also}"));
            } else if !failed.is_empty() {
                ui.colored_label(super::theme::FAIL, format!("{} failed: see the maps", failed.join(" and ")))
                    .on_hover_text(
                        "The run of the configuration set failed; its reason is shown where its maps would be.",
                    );
            } else if let Some((i, why)) = (0..self.state.designs.len()).find_map(|i| {
                let run = self.link.current(i)?;
                run.output.retrievals.first()?.failure.clone().map(|w| (i, w))
            }) {
                // A retrieval that returned nothing is not "up to date": its banner says why.
                ui.colored_label(super::theme::FAIL, format!("{}: retrieval returned nothing", super::model::label(i)))
                    .on_hover_text(why);
            } else if self.state.preview_only {
                ui.label("preview only (settings)");
            } else {
                ui.label("up to date");
            }
        });
        if cancel {
            self.link.cancel();
        }
        if refine {
            self.link.refine();
        }
        if let Some(ms) = self.median_frame_ms() {
            ui.small("diagnostics").on_hover_ui(|ui| {
                ui.label(format!(
                    "Diagnostics: the UI thread lays out a frame in {ms:.1} ms (median); the engine works \
                     on its own threads."
                ));
                ui.label(self.memory_plan());
            });
        }
    }

    /// What the designs hold at full resolution, planned ([`crate::engine::resources::app_demand`]).
    #[must_use]
    pub fn memory_plan(&self) -> String {
        let configs = self.state.configs();
        let demand = crate::engine::resources::app_demand(
            &configs.iter().collect::<Vec<_>>(),
            crate::engine::worker::app_cache_bytes(),
        );
        let budget = crate::budget::MachineBudget::from_env().map(|b| b.memory_bytes / 1e9);
        let gb = demand.bytes() / 1e9;
        let of = budget.map_or(String::new(), |b| format!(" of the {b:.1} GB budget (SHOAL_MEMORY_BUDGET)"));
        format!(
            "Memory at full resolution, planned: {gb:.2} GB{of}. Each design keeps its products and a view \
             of its cubes (every n-th pixel, at most {} MiB with {} designs); the engine's cache keeps what \
             lets a change restart mid-chain.",
            crate::engine::views::view_bytes_per_run(configs.len()) >> 20,
            configs.len()
        )
    }

    pub(super) fn dialogs(&mut self, ctx: &egui::Context) {
        self.confirm_dialog(ctx);
        if let Some(msg) = self.ui.error.clone() {
            let r = egui::Modal::new(egui::Id::unique("shoal-error")).show(ctx, |ui| {
                ui.heading("Problem");
                ui.label(msg);
                ui.button("OK").clicked()
            });
            if r.inner || r.should_close() {
                self.ui.error = None;
            }
        }
    }
}

/// Width of the status box in the top bar, logical pixels.
const STATUS_WIDTH: f32 = 330.0;

/// The progress bar's fraction, text and hover for the run in flight: the stage and its own rows
/// (a stage without a per-pixel loop shows no fraction), the time left in it only once its pace
/// is known. Never a figure for the whole run: the stages' costs differ by orders of magnitude
/// (a SAMBUCA row costs a thousand Level-0 rows), so no row count can say how much is left.
fn progress_text(p: &super::link::Progress) -> (f32, String, String) {
    let which = super::model::label(p.index);
    let level = if p.decimation == 1 { "full res.".to_string() } else { format!("1/{}", p.decimation) };
    match p.stage {
        Some(stage) if stage.total > 0 => {
            let f = (stage.done as f64 / stage.total as f64).min(1.0);
            let left = stage.seconds_left().map_or_else(String::new, |s| format!(", ~{}", duration(s)));
            (
                f as f32,
                format!("{which} {level}: {} {:.0} %{left}", stage.name, 100.0 * f),
                format!(
                    "{which} at {level}: stage {} (the {}th computed), {} of {} rows after {}{}",
                    stage.name,
                    stage.ordinal,
                    stage.done,
                    stage.total,
                    duration(stage.seconds),
                    if left.is_empty() {
                        "; the time left shows once 5 % of the rows are done".to_string()
                    } else {
                        format!("; at this pace{left} left in this stage")
                    }
                ),
            )
        }
        Some(stage) => (
            0.0,
            format!("{which} {level}: {}", stage.name),
            format!("{which} at {level}: stage {} for {}", stage.name, duration(stage.seconds)),
        ),
        None => (0.0, format!("{which} {level}: starting"), String::new()),
    }
}

/// `12 s`, `3 min 5 s`.
fn duration(seconds: f64) -> String {
    if seconds < 60.0 {
        format!("{seconds:.0} s")
    } else {
        format!("{} min {:.0} s", (seconds / 60.0).floor(), seconds % 60.0)
    }
}
