//! The desktop app: a live trade-off explorer. Designs A, B, … (two by default, up to eight)
//! over one scene, edited with sliders; the engine thread reruns the chain at preview resolution while a slider moves
//! and refines; maps, metrics, histograms, scatter and SNR side by side; figure and data export.
//!
//! The UI thread only draws: the chain runs on the engine thread (its own rayon pool), and the
//! colour mapping of maps on a raster thread. This is the only module that uses egui.
//!
//! | part | file |
//! |---|---|
//! | persisted state, the designs' configurations | [`model`] |
//! | sessions of older formats brought up to date | `migrate` |
//! | the list of designs: add, remove, reorder | `designs` |
//! | the retrievals offered, as specs | `retrievals` |
//! | the engine thread's results | [`link`] |
//! | product maps, colours, differences (asked for as a result arrives: `prefetch`) | [`raster`] |
//! | histogram and scatter data, off the UI thread | [`plot_data`] |
//! | colours and what they mean | [`theme`] |
//! | presets and instrument editor | `panels` |
//! | derived figures, feasibility, parameter differences | `derived` |
//! | status, typed export, Replace? and error dialogs | `dialogs` |
//! | undo and redo | `history` |
//! | maps with zoom, pan and hover (small multiples) | `maps` |
//! | colour bar, scale bar | `legend` |
//! | the spectrum at a clicked point, 350–2500 nm | [`spectrum`] |
//! | metrics table and plots | [`plots`] |
//! | figure and data export | `export` |
//! | sweep and cost-of-accuracy windows | `explore` |
//! | seed spread of the metrics | `seeds` |

mod banners;
pub mod bench;
pub mod blocks;
mod conditions;
mod derived;
mod designs;
mod dialogs;
mod editors;
pub mod explore;
mod export;
mod history;
mod hover;
mod legend;
pub mod link;
mod listing;
mod logic;
mod maps;
mod metrics_table;
mod migrate;
pub mod model;
mod optics;
mod panels;
mod params;
mod planes;
pub mod plot_data;
pub mod plots;
mod prefetch;
mod probe;
pub mod product_map;
pub mod raster;
mod retrievals;
mod seeds;
mod session;
mod slide;
mod snr_table;
pub mod spectrum;
pub mod theme;
mod view;
mod window;

pub use window::run;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::library::Library;
use link::EngineLink;
use model::AppState;

/// How the app is started.
#[derive(Debug, Clone, Default)]
pub struct AppOptions {
    /// Save a screenshot of the window here once the first full set of results is shown, then quit.
    pub screenshot: Option<PathBuf>,
    /// Engine threads (0: all cores).
    pub engine_threads: usize,
    /// Start from the built-in default instead of the saved session.
    pub fresh: bool,
    /// Window size, logical pixels (`None`: 1500 × 960, or the size saved with the session).
    pub size: Option<[f32; 2]>,
    /// The user's Shoal folder, where the session is kept (`None`: [`crate::library::home_dir`]).
    pub home: Option<PathBuf>,
    /// Open this library study instead of the saved session (it becomes the session).
    pub study: Option<String>,
}

/// A write that would replace a file of the user's, waiting for "Replace" or "Cancel".
enum Confirm {
    /// Save a design's instrument under `name`.
    Instrument { design: usize, name: String, spec: Box<crate::instrument::InstrumentSpec> },
    /// Save the study under `name`.
    Study { name: String, study: Box<crate::study::StudySpec> },
    /// A typed-path export over existing files.
    Export { what: export::What, path: PathBuf, existing: Vec<PathBuf> },
    /// A load that would replace unsaved edits (`what`: whose, and which).
    Discard { command: logic::UiCommand, what: String },
}

/// Transient UI state (not persisted).
#[derive(Default)]
struct UiState {
    error: Option<String>,
    message: Option<String>,
    preset_name: String,
    export_path: String,
    typed_export: bool,
    exports: export::Exports,
    explore: explore::Explore,
    seeds: seeds::SeedSpreadJob,
    frame_times_ms: Vec<f32>,
    history: history::History,
    /// Where the histogram, scatter and SNR plots were last drawn (for the layout test).
    plot_rects: Vec<egui::Rect>,
    /// Where the maps and their colour bars were last drawn (for the layout test).
    map_rects: Vec<egui::Rect>,
    /// The widest the metrics table has been drawn, and for how many designs.
    metrics_width: Option<(usize, f32)>,
    zoom: maps::View,
    hover: Option<(usize, usize)>,
    /// A fault injected into A's runs (tests; `SHOAL_FAULT` at start).
    fault: Option<crate::engine::Fault>,
    /// A save or export that asks before replacing a file.
    confirm: Option<Confirm>,
    /// An instrument value refused by its range: (parameter key, message), shown inline.
    param_error: Option<(&'static str, String)>,
    /// A scene, atmosphere or calibration value refused by its range.
    conditions_error: Option<String>,
    /// A focal-plane edit refused by the instrument's validation.
    plane_error: Option<String>,
    /// Why the last edit of the optical effects was refused.
    optics_error: Option<String>,
    /// The spectrum at the point last clicked on a map.
    spectrum: spectrum::SpectrumWindow,
    /// What the panels asked for this frame, applied after it is drawn (`logic.rs`).
    commands: Vec<logic::UiCommand>,
}

/// The app.
pub struct ShoalApp {
    /// The persisted state.
    pub state: AppState,
    /// The engine link.
    pub link: EngineLink,
    library: Library,
    /// The library's listing, kept so that frames never read the disk.
    listing: listing::Listing,
    images: maps::Images,
    raster: Option<raster::RasterThread>,
    /// What the engine's result hook asks the raster thread for early.
    prefetch: Arc<prefetch::Prefetch>,
    ui: UiState,
    options: AppOptions,
    screenshot_taken: Arc<std::sync::Mutex<Option<Arc<egui::ColorImage>>>>,
    screenshot_requested: bool,
    applied_theme: Option<bool>,
    /// Where the session is saved (`None` in tests: nothing is written).
    session_path: Option<PathBuf>,
    /// The state last written there.
    saved_state: Option<AppState>,
    /// The session write in progress (on its own thread: the UI thread never touches the disk).
    session_writer: Option<std::thread::JoinHandle<Result<(), String>>>,
    /// This window's hold on the session (`None`: it does not save the session).
    _session_lock: Option<session::SessionLock>,
}

/// Storage key of the session.
const STATE_KEY: &str = "shoal-session";

impl ShoalApp {
    /// The app with `state` (tests and the eframe creator).
    pub fn with_state(state: AppState, ctx: &egui::Context, options: AppOptions) -> Self {
        window::install_fonts(ctx);
        let engine_wake = ctx.clone();
        let link = EngineLink::new(
            link::engine_threads(options.engine_threads),
            Arc::new(move || engine_wake.request_repaint()),
        )
        .unwrap_or_else(|e| {
            // Without an engine thread (the OS refused a thread) nothing can run: say why and stop.
            eprintln!("error: cannot start the engine thread: {e}");
            std::process::exit(1);
        });
        let wake = ctx.clone();
        let raster = raster::spawn_raster_thread(move || wake.request_repaint()).ok();
        let prefetch = Arc::new(prefetch::Prefetch::default());
        if let Some(r) = &raster {
            link.set_result_hook(prefetch.hook(prefetch::asking(r.requester())));
        }
        let export_path = crate::library::export_dir().join("comparison").display().to_string();
        Self {
            state,
            link,
            listing: listing::Listing::new(&Library::user()),
            library: Library::user(),
            images: maps::Images::default(),
            raster,
            prefetch,
            ui: UiState { preset_name: "my_instrument".into(), export_path, ..UiState::default() },
            options,
            screenshot_taken: Arc::default(),
            screenshot_requested: false,
            applied_theme: None,
            session_path: None,
            saved_state: None,
            session_writer: None,
            _session_lock: None,
        }
    }

    /// The app as eframe creates it: the saved session, or the default study. A fresh start
    /// (`--fresh`, `--screenshot`) reads and writes no session; a second window while another
    /// holds the session starts from it but does not save it (and says so).
    #[must_use]
    pub fn new(cc: &eframe::CreationContext<'_>, options: AppOptions) -> Self {
        let home = options.home.clone().unwrap_or_else(crate::library::home_dir);
        let path = session::session_path(&home);
        let lock = if options.fresh { Err(String::new()) } else { session::SessionLock::acquire(&path) };
        // A fresh start does not read the session either (an unreadable one stays where it is).
        let saved = if options.fresh { None } else { Some(session::load_session(&path)) };
        let (state, problem) = match (options.fresh, saved.unwrap_or(session::SavedSession::None)) {
            (true, _) => (None, None),
            (false, session::SavedSession::Restored(s, reset)) => (
                Some(*s),
                (!reset.is_empty()).then(|| {
                    format!("Parts of the saved session were out of range and were reset: {}.", reset.join("; "))
                }),
            ),
            // A session saved by an earlier Shoal in eframe's own storage (outside SHOAL_HOME).
            (false, session::SavedSession::None) => {
                let stored = cc.storage.and_then(|s| s.get_string(STATE_KEY));
                let mut old = stored.and_then(|t| AppState::from_session_text(&t).ok());
                let reset = old.as_mut().map(session::repair).unwrap_or_default();
                (
                    old,
                    (!reset.is_empty())
                        .then(|| format!("Parts of the saved session were reset: {}.", reset.join("; "))),
                )
            }
            (false, session::SavedSession::Unreadable { message, kept_at }) => (
                None,
                Some(format!(
                    "The saved session could not be read ({message}); it is kept at {} and the app \
                     starts from the default study.",
                    kept_at.display()
                )),
            ),
        };
        let study = options.study.clone();
        let mut app = Self::with_state(state.unwrap_or_default(), &cc.egui_ctx, options);
        app.ui.error = problem;
        if let Some(name) = study {
            match app.library.find(crate::library::PresetKind::Study, &name) {
                Some(entry) => app.apply_confirmed(logic::UiCommand::LoadStudy(entry)),
                None => {
                    app.ui.error = Some(format!("No study `{name}` in the library: the app opens the session instead."))
                }
            }
        }
        match lock {
            Ok(lock) => {
                app.session_path = Some(path);
                app._session_lock = Some(lock);
            }
            Err(why) if !why.is_empty() => {
                let before = app.ui.error.take().map(|e| format!("{e} ")).unwrap_or_default();
                app.ui.error = Some(format!("{before}{why}: this window will not save its session."));
            }
            Err(_) => {}
        }
        match crate::engine::Fault::from_env() {
            Ok(fault) => app.ui.fault = fault,
            Err(e) => app.ui.error = Some(e),
        }
        app
    }

    /// Draw one frame into `ui` (everything but the eframe plumbing). The per-frame logic
    /// (submitting changed configurations, taking results and images) runs before it, in
    /// eframe's `logic` ([`Self::tick`]), which eframe also calls while the window is hidden.
    pub fn draw(&mut self, ui: &mut egui::Ui) {
        let start = Instant::now();
        let ctx = ui.ctx().clone();
        egui::Panel::top("top").show(ui, |ui| {
            self.top_bar(ui);
            // A second row always there, so a message or the typed-path row never moves the
            // window's content down: the typed path when asked for, else the last message.
            ui.allocate_ui_with_layout(
                egui::vec2(ui.available_width(), ui.spacing().interact_size.y),
                egui::Layout::left_to_right(egui::Align::Center),
                |ui| {
                    ui.set_min_height(ui.spacing().interact_size.y);
                    if self.ui.typed_export {
                        self.typed_export(ui);
                    } else if let Some(m) = &self.ui.message {
                        ui.add(egui::Label::new(egui::RichText::new(m.as_str()).small()).truncate());
                    }
                },
            );
        });
        // At most 45 % of the window (and 560 px): a panel grown by eight designs' buttons pushed
        // the maps' controls off a 1280-pixel screen. What is wider scrolls inside it.
        let left_max = (0.45 * ctx.content_rect().width()).clamp(320.0, 560.0);
        egui::Panel::left("left")
            .resizable(true)
            .default_size(380.0_f32.min(left_max))
            .size_range(240.0..=left_max)
            .show(ui, |ui| {
                egui::ScrollArea::both().show(ui, |ui| panels::left(self, ui));
            });
        // No lower than its first height less 60 px: egui remembers a panel's height, and one
        // sized on a 720-pixel screen kept the plots a 300-pixel strip at 4K.
        let plots_h = plots::panel_height(ui.ctx());
        let bottom_max = (0.6 * ctx.content_rect().height()).max(plots_h);
        egui::Panel::bottom("bottom")
            .resizable(true)
            .default_size(plots_h)
            .size_range((plots_h - 60.0)..=bottom_max)
            .show(ui, |ui| plots::bottom(self, ui));
        egui::CentralPanel::default().show(ui, |ui| maps::central(self, ui));
        explore::windows(self, &ctx);
        if self.ui.spectrum.open {
            spectrum::spectrum_window(self, &ctx);
        }
        // Commands after the panels that asked for them, before the dialogs that may report them.
        for command in std::mem::take(&mut self.ui.commands) {
            self.apply(command);
        }
        self.dialogs(&ctx);
        // After everything that may change the design this frame: one undo step per settled change.
        self.ui.history.observe(&self.state, ctx.input(|i| i.pointer.any_down()));
        // The UI thread's work for this frame (layout; not the GPU, not the wait for vsync).
        self.ui.frame_times_ms.push(start.elapsed().as_secs_f32() * 1e3);
        if self.ui.frame_times_ms.len() > 240 {
            self.ui.frame_times_ms.remove(0);
        }
    }

    fn top_bar(&mut self, ui: &mut egui::Ui) {
        // Fixed-width controls first and the names (whose "(modified)" comes and goes) last, so
        // no button moves under the pointer as the text changes.
        ui.horizontal(|ui| {
            ui.heading("Shoal");
            ui.separator();
            let undo = self.ui.history.undo_text();
            let clicked = ui
                .add_enabled(undo.is_some(), egui::Button::new("Undo"))
                .on_hover_text(undo.map_or_else(|| "Nothing to undo".into(), |t| format!("Undo: {t} (Ctrl+Z)")))
                .clicked();
            if clicked {
                self.step_history(false);
            }
            let redo = self.ui.history.redo_text();
            let clicked = ui
                .add_enabled(redo.is_some(), egui::Button::new("Redo"))
                .on_hover_text(redo.map_or_else(|| "Nothing to redo".into(), |t| format!("Redo: {t} (Ctrl+Shift+Z)")))
                .clicked();
            if clicked {
                self.step_history(true);
            }
            ui.separator();
            // One menu for the three exports keeps the top bar within 1280 px.
            let exports = [
                (export::What::Figure, "Figure…", "Choose where to write the comparison figure (PNG and SVG) and the configurations"),
                (export::What::Data, "Data…", "Choose a folder for the cubes and metrics of every design, as `shoal study` writes them"),
                (
                    export::What::ReviewPack,
                    "Review pack…",
                    "Choose a folder for the review pack: one self-contained index.html (verdict, figures, provenance) that opens in any browser",
                ),
            ];
            ui.menu_button("Export", |ui| {
                for (what, label, hover) in exports {
                    if ui.button(label).on_hover_text(hover).clicked() {
                        self.ui.exports.with_dialog(what, export::Snapshot::of(self), Path::new(self.ui.export_path.trim()));
                        ui.close();
                    }
                }
            })
            .response
            .on_hover_text("Write the comparison figure, the data or the review pack");
            ui.separator();
            ui.toggle_value(&mut self.ui.explore.sweep_open, "Sweep")
                .on_hover_text("A curve: one parameter of every design over a range, with noise seeds");
            ui.toggle_value(&mut self.ui.explore.cost_open, "Cost")
                .on_hover_text("Time against error for each fidelity setting");
            ui.toggle_value(&mut self.ui.explore.design_open, "Design")
                .on_hover_text("The cheapest design from A that meets the requirements, and its cost against error");
            ui.toggle_value(&mut self.ui.explore.season.open, "Season")
                .on_hover_text("The designs over a season at a site: valid looks (orbit, glint, clouds) and the error over them");
            ui.separator();
            ui.toggle_value(&mut self.ui.typed_export, "Path")
                .on_hover_text("Export to a typed path (for desktops without a file-chooser portal)");
            if self.ui.exports.running > 0 {
                ui.spinner();
            }
            ui.separator();
            ui.selectable_value(&mut self.state.dark, false, "Light");
            ui.selectable_value(&mut self.state.dark, true, "Dark");
            ui.separator();
            self.status(ui);
            ui.separator();
            let mark =
                |s: &model::Slot| if s.modified() { format!("{} (modified)", s.preset) } else { s.preset.clone() };
            let designs: Vec<String> =
                self.state.designs.iter().enumerate().map(|(i, s)| format!("{}: {}", model::label(i), mark(s))).collect();
            let names = format!("{}   scene: {}", designs.join("   "), self.state.scene_name);
            ui.add(egui::Label::new(names.as_str()).truncate()).on_hover_text(names);
        });
    }

    /// Screenshot mode: once every design shows its final results, grab the window.
    fn screenshot(&mut self, ctx: &egui::Context) {
        let Some(path) = self.options.screenshot.clone() else { return };
        let finest = self.state.decimations().last().copied().unwrap_or(1);
        let ready = !self.link.busy()
            && self.link.shown.len() == self.state.designs.len()
            && self.link.shown.iter().all(|s| s.as_ref().is_some_and(|s| s.decimation == finest))
            && self.images.ready();
        if ready && !self.screenshot_requested {
            self.screenshot_requested = true;
            let (slot, wake) = (self.screenshot_taken.clone(), ctx.clone());
            ctx.request_screenshot(move |img| {
                if let Ok(mut s) = slot.lock() {
                    *s = Some(img);
                }
                wake.request_repaint();
            });
        }
        let taken = self.screenshot_taken.lock().ok().and_then(|mut s| s.take());
        if let Some(img) = taken {
            if let Err(e) = export::write_screenshot(&path, &img) {
                eprintln!("error: {e}");
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        if self.options.screenshot.is_some() {
            ctx.request_repaint_after(Duration::from_millis(100));
        }
    }
}

impl Drop for ShoalApp {
    /// The last session write finishes before the app goes (eframe saves on quit, then drops).
    fn drop(&mut self) {
        if let Some(handle) = self.session_writer.take() {
            let _ = handle.join();
        }
    }
}

impl eframe::App for ShoalApp {
    /// Before each frame, and while the window is hidden: the engine's results are taken even
    /// when nothing is drawn.
    fn logic(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        self.tick(ctx);
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.draw(ui);
        let ctx = ui.ctx().clone();
        self.screenshot(&ctx);
    }

    /// Called by eframe on quit and every 30 s: the session goes to our own file (atomic, under
    /// `SHOAL_HOME` when set), only when it changed.
    fn save(&mut self, _storage: &mut dyn eframe::Storage) {
        let Some(path) = self.session_path.clone() else { return };
        // The previous write first (it is long done: saves come every 30 s), so writes never
        // overlap and a failure is reported.
        if let Some(Ok(Err(e))) = self.session_writer.take().map(std::thread::JoinHandle::join) {
            self.saved_state = None;
            self.ui.error = Some(format!("The session was not saved: {e}"));
        }
        if self.saved_state.as_ref() == Some(&self.state) {
            return;
        }
        let state = self.state.clone();
        match std::thread::Builder::new()
            .name("shoal-session".into())
            .spawn(move || session::save_session(&path, &state))
        {
            Ok(handle) => {
                self.session_writer = Some(handle);
                self.saved_state = Some(self.state.clone());
            }
            Err(e) => self.ui.error = Some(format!("The session was not saved: cannot start a thread: {e}")),
        }
    }
}
