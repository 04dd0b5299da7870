//! What the app does, as opposed to what it draws: the per-frame bookkeeping ([`ShoalApp::tick`])
//! and the [`UiCommand`]s the panels return, applied after the frame ([`ShoalApp::apply`]).
//! Panels read the state and change plain fields (a slider moves a number); anything that loads,
//! saves, writes or replaces a whole part of the state is a command, applied in one place.

use std::path::PathBuf;
use std::time::Duration;

use super::model::{AppState, ProductKind, Slot, label};
use super::{Confirm, ShoalApp, model};
use crate::library::{Entry, LibraryError};

/// The longest a frame waits for the images of a result it has just taken (see `tick`).
const RASTER_WAIT: Duration = Duration::from_millis(6);

/// Something a panel asked for, applied after the frame.
#[derive(Debug, Clone)]
pub enum UiCommand {
    /// Load a library instrument into a design.
    LoadInstrument {
        /// Which (an index into the designs).
        design: usize,
        /// The library entry.
        entry: Entry,
    },
    /// Load a library scene.
    LoadScene(Entry),
    /// Load a library study (instruments, scene, retrieval, requirements).
    LoadStudy(Entry),
    /// Add a library instrument as a new design.
    AddDesign(Entry),
    /// Remove a design.
    RemoveDesign(usize),
    /// Move a design one place earlier or later in the list.
    MoveDesign {
        /// Which.
        design: usize,
        /// Towards A.
        earlier: bool,
    },
    /// Save a design in the library under `name`.
    SaveInstrument {
        /// Which.
        design: usize,
        /// The preset name.
        name: String,
    },
    /// Save the study (the designs, the scene, the retrieval and the requirements) under `name`.
    SaveStudy {
        /// The preset name.
        name: String,
    },
    /// Run the retrieval of this name (`alm`, `sambuca`: the scene/retrieval banner's switch),
    /// showing its main product.
    UseRetrieval(&'static str),
}

impl ShoalApp {
    /// Apply one command, asking first when it would replace unsaved edits.
    pub(super) fn apply(&mut self, command: UiCommand) {
        if let Some(what) = self.edits_lost_by(&command) {
            self.ui.confirm = Some(Confirm::Discard { command, what });
            return;
        }
        self.apply_confirmed(command);
    }

    /// The unsaved edits `command` would replace, in words; `None` when it replaces none.
    fn edits_lost_by(&self, command: &UiCommand) -> Option<String> {
        let edited = |i: usize| {
            let slot = self.state.designs.get(i)?;
            let prefix = format!("{} ", label(i));
            let changes: Vec<String> =
                self.state.changes().iter().filter_map(|c| c.strip_prefix(&prefix).map(str::to_string)).collect();
            slot.modified().then(|| format!("{} ({}: {})", label(i), slot.preset, changes.join("; ")))
        };
        let lost: Vec<String> = match command {
            UiCommand::LoadInstrument { design, .. } | UiCommand::RemoveDesign(design) => {
                edited(*design).into_iter().collect()
            }
            UiCommand::LoadStudy(_) => (0..self.state.designs.len()).filter_map(edited).collect(),
            _ => Vec::new(),
        };
        let doing = match command {
            UiCommand::LoadInstrument { entry, .. } | UiCommand::LoadStudy(entry) => {
                format!("Loading `{}` replaces", entry.name)
            }
            _ => "Removing the design loses".to_string(),
        };
        (!lost.is_empty()).then(|| format!("{doing} unsaved edits of {}.", lost.join(" and ")))
    }

    /// Ctrl+Z undoes, Ctrl+Shift+Z and Ctrl+Y redo — unless a text field has the keyboard (it
    /// keeps its own undo of the text being typed).
    fn undo_shortcuts(&mut self, ctx: &egui::Context) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        if ctx.memory(|m| m.focused().is_some()) {
            return;
        }
        let (redo, undo) = ctx.input_mut(|i| {
            let redo = i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z))
                || i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Y));
            (redo, i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Z)))
        });
        if redo || undo {
            self.step_history(redo);
        }
    }

    /// Undo (or redo) one step; the engine link moves each design's result with its design, so
    /// only a design that comes back or changed runs again.
    pub(super) fn step_history(&mut self, redo: bool) {
        let moved = if redo { self.ui.history.redo(&mut self.state) } else { self.ui.history.undo(&mut self.state) };
        if let Some(moved) = moved {
            self.link.remap(&moved);
        }
    }

    /// Apply one command without asking.
    pub(super) fn apply_confirmed(&mut self, command: UiCommand) {
        match command {
            UiCommand::LoadInstrument { design, entry } => match self.library.load_instrument(&entry) {
                Ok(spec) => {
                    if let Some(slot) = self.state.designs.get_mut(design) {
                        *slot = Slot::new(&entry.name, spec);
                    }
                }
                Err(err) => self.ui.error = Some(format!("Cannot load instrument `{}`: {err}", entry.name)),
            },
            UiCommand::AddDesign(entry) => match self.library.load_instrument(&entry) {
                Ok(spec) => {
                    if self.state.add_design(Slot::new(&entry.name, spec)).is_none() {
                        self.ui.error = Some(format!(
                            "Cannot add `{}`: the app compares {} designs at most",
                            entry.name,
                            super::model::MAX_DESIGNS
                        ));
                    }
                }
                Err(err) => self.ui.error = Some(format!("Cannot load instrument `{}`: {err}", entry.name)),
            },
            UiCommand::RemoveDesign(design) => {
                if let Some(moved) = self.state.remove_design(design) {
                    self.link.remap(&moved);
                }
            }
            UiCommand::MoveDesign { design, earlier } => {
                if let Some(moved) = self.state.move_design(design, earlier) {
                    self.link.remap(&moved);
                }
            }
            UiCommand::LoadScene(entry) => match self.library.load_scene(&entry) {
                Ok(spec) => {
                    self.state.scene = spec;
                    self.state.scene_name = entry.name;
                }
                Err(err) => self.ui.error = Some(format!("Cannot load scene `{}`: {err}", entry.name)),
            },
            UiCommand::LoadStudy(entry) => {
                let loaded = self.library.load_study(&entry).map_err(|e| e.to_string());
                let dir = entry.path.as_deref().and_then(std::path::Path::parent);
                let opened = loaded
                    .and_then(|study| AppState::from_study(&study, dir).map(|s| (s, study.requirements.is_some())));
                match opened {
                    Ok((mut s, requirements_from_study)) => {
                        s.dark = self.state.dark;
                        // The study's own requirements when it states them, else the ones in use.
                        if !requirements_from_study {
                            s.requirements = self.state.requirements.clone();
                        }
                        self.state = s;
                    }
                    Err(err) => self.ui.error = Some(format!("Cannot load study `{}`: {err}", entry.name)),
                }
            }
            UiCommand::SaveInstrument { design, name } => {
                let Some(slot) = self.state.designs.get(design) else { return };
                let spec = Box::new(slot.spec.clone());
                self.save(Confirm::Instrument { design, name, spec }, false);
            }
            UiCommand::UseRetrieval(name) => {
                if self.state.select_retrieval(name) {
                    let headline = self.state.retrieval_spec().algorithm().headline();
                    self.state.product = ProductKind::of_variable(headline).unwrap_or(ProductKind::Chl);
                }
            }
            UiCommand::SaveStudy { name } => {
                let study = Box::new(self.study_to_save(&name));
                self.save(Confirm::Study { name, study }, false);
            }
        }
    }

    /// The study the app shows, as `shoal study` would run it: the designs, the scene with its
    /// seed, the retrieval, the noise seed and the requirements in use.
    fn study_to_save(&self, name: &str) -> crate::study::StudySpec {
        let s = &self.state;
        let names: Vec<String> =
            (0..s.designs.len()).map(|i| format!("{} {}", label(i), s.designs[i].preset)).collect();
        crate::study::StudySpec {
            name: name.into(),
            description: format!("saved from the app: {} over {}", names.join(" vs "), s.scene_name),
            scene: crate::study::Source::Inline(Box::new(s.seeded_scene())),
            instruments: s.designs.iter().map(|d| crate::study::Source::Inline(Box::new(d.spec.clone()))).collect(),
            retrievals: vec![s.retrieval_spec()],
            seeds: vec![s.noise_seed],
            detector: None,
            calibration: (s.calibration != crate::calibration::CalibrationSpec::default())
                .then(|| s.calibration.clone()),
            correction: None,
            fidelity: (s.fidelity != crate::engine::Fidelity::default()).then(|| s.fidelity.clone()),
            requirements: Some(s.requirements.clone()),
            snr_reference: s.snr_reference.clone(),
            budgets: None,
        }
    }

    /// The per-frame logic before drawing: submit changed configurations, take results, maps
    /// and export news.
    pub(super) fn tick(&mut self, ctx: &egui::Context) {
        self.undo_shortcuts(ctx);
        if self.applied_theme != Some(self.state.dark) {
            ctx.set_theme(if self.state.dark { egui::Theme::Dark } else { egui::Theme::Light });
            self.applied_theme = Some(self.state.dark);
        }
        let mut configs = self.state.configs();
        if let Some(a) = configs.first_mut() {
            a.fault = self.ui.fault;
        }
        self.link.submit_if_changed(configs, self.state.decimations());
        let wake = ctx.clone();
        self.listing.poll(&self.library, move || wake.request_repaint());
        if self.link.poll() {
            self.images.invalidate();
        }
        if let Some(r) = &self.raster {
            // A new result's images are waited for briefly, so that they appear in the frame that
            // took the result rather than one refresh (16.7 ms) later: recolouring A's preview
            // beside B at full resolution takes a few ms from the kept block sums (`blocks`),
            // begun when the engine had the result (`prefetch`). The wait is capped, so a slower
            // answer (B's first full-resolution maps) only costs this frame the cap and arrives
            // with a later frame.
            let job = super::maps::job_for(&self.state, &self.link);
            let asked = self.images.request(job.clone(), r);
            // Every answer is looked at (one made early for a result may come after the one
            // asked for); only the one asked for is shown.
            let deadline = asked.then(|| std::time::Instant::now() + RASTER_WAIT);
            while let Some(done) = match deadline {
                Some(d) if !self.images.ready() => r.poll_until(d),
                _ => r.poll(),
            } {
                self.images.receive(ctx, done);
            }
            if self.images.ready() {
                self.link.maps_on_screen();
            }
            self.prefetch.update(job, &self.link);
        }
        while let Some(news) = self.ui.exports.poll() {
            match news {
                super::export::News::Written(m) => self.ui.message = Some(m),
                super::export::News::Failed(e) => self.ui.error = Some(e),
                super::export::News::NoChoice(what) => {
                    let what = what.noun();
                    self.ui.message = Some(format!(
                        "No {what} exported: no file was chosen. If no dialog appeared, this desktop has no file-chooser portal; use Path to type one."
                    ));
                    self.ui.typed_export = true;
                }
            }
        }
        self.ui.explore.poll();
        self.ui.seeds.poll();
        if self.link.busy() || self.ui.exports.running > 0 || self.ui.explore.busy() || self.ui.seeds.busy() {
            ctx.request_repaint_after(Duration::from_millis(30));
        }
    }

    /// Export to a typed path, asking first if that would replace existing files.
    pub(super) fn export_to(&mut self, what: super::export::What, path: PathBuf) {
        let snap = super::export::Snapshot::of(self);
        let existing = super::export::existing(what, &path, self.state.designs.len());
        if existing.is_empty() {
            self.ui.exports.write_to(what, snap, path);
        } else {
            self.ui.confirm = Some(Confirm::Export { what, path, existing });
        }
    }

    /// Save a design, or the study, in the library; asks before replacing a preset of that name.
    pub(super) fn save(&mut self, confirm: Confirm, overwrite: bool) {
        let result = match &confirm {
            Confirm::Instrument { name, spec, .. } => self.library.save_instrument(name, spec, overwrite),
            Confirm::Study { name, study } => self.library.save_study(name, study, overwrite),
            Confirm::Export { .. } | Confirm::Discard { .. } => return,
        };
        match result {
            Ok(path) => {
                self.listing.reread(&self.library);
                if let Confirm::Instrument { design, name, spec } = confirm
                    && let Some(slot) = self.state.designs.get_mut(design)
                {
                    *slot = model::Slot::new(&name, *spec);
                }
                self.ui.message = Some(format!("saved {}", path.display()));
            }
            Err(LibraryError::Exists(_)) if !overwrite => self.ui.confirm = Some(confirm),
            Err(e) => self.ui.error = Some(format!("Cannot save: {e}")),
        }
    }
}
