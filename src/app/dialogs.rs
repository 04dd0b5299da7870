//! The top bar's status and the app's dialogs: the typed-path export row, the "Replace?"
//! question before a save, export or load would overwrite something of the user's, and the
//! error dialog.

use std::path::PathBuf;
use std::time::Instant;

use super::{Confirm, ShoalApp, export};

impl ShoalApp {
    /// The typed-path export row (shown on request, or when a dialog could not be used).
    pub(super) fn typed_export(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let l = ui.label("Export to");
            ui.add(egui::TextEdit::singleline(&mut self.ui.export_path).desired_width(420.0)).labelled_by(l.id);
            let path = PathBuf::from(self.ui.export_path.trim());
            if ui.button("Write figure").on_hover_text("NAME.png, NAME.svg and NAME_config_A/B.ron").clicked() {
                self.export_to(export::What::Figure, path.clone());
            }
            if ui.button("Write data").on_hover_text("A folder NAME with one sub-folder per instrument").clicked() {
                self.export_to(export::What::Data, path.clone());
            }
            if ui
                .button("Write review pack")
                .on_hover_text("A folder NAME with index.html (self-contained, opens in any browser) and its figures")
                .clicked()
            {
                self.export_to(export::What::ReviewPack, path);
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

    pub(super) fn status(&mut self, ui: &mut egui::Ui) {
        match self.link.progress {
            Some(p) if self.link.busy() => {
                let which = if p.index == 0 { "A" } else { "B" };
                let level = if p.decimation == 1 {
                    "full resolution".to_string()
                } else {
                    format!("preview 1/{}", p.decimation)
                };
                let key = (self.link.generation(), p.index, p.decimation);
                let since = match self.ui.progress_since {
                    Some((k, t)) if k == key => t,
                    _ => {
                        let now = Instant::now();
                        self.ui.progress_since = Some((key, now));
                        now
                    }
                };
                let elapsed = since.elapsed().as_secs_f64();
                // The stages add their rows as they start, so the row fraction alone runs ahead;
                // the last run at this resolution, when there is one, gives the time it takes.
                let (fraction, text) = match self.ui.run_seconds.get(&(p.index, p.decimation)) {
                    Some(&last) if last > 0.5 => {
                        let f = (elapsed / last).min(0.99);
                        let left = (last - elapsed).max(0.0);
                        (f, format!("{which}: {level} {:.0} %, ~{left:.0} s left", 100.0 * f))
                    }
                    _ => {
                        let f = if p.total > 0 { p.done as f64 / p.total as f64 } else { 0.0 };
                        (f.min(0.99), format!("{which}: {level} {:.0} %", 100.0 * f.min(0.99)))
                    }
                };
                ui.add(egui::ProgressBar::new(fraction as f32).desired_width(220.0).text(text)).on_hover_text(
                    "Estimated from the last run of this instrument at this resolution (its stages may now be \
                     cached, so it can finish sooner); the first run shows the share of rows done.",
                );
            }
            _ if self.link.busy() => {
                ui.add(egui::ProgressBar::new(0.0).desired_width(140.0).text("starting"));
            }
            _ => {
                ui.label("up to date");
            }
        }
        if let Some(ms) = self.median_frame_ms() {
            ui.small("diagnostics").on_hover_text(format!(
                "Diagnostics: the UI thread lays out a frame in {ms:.1} ms (median); the engine works \
                 on its own threads."
            ));
        }
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
