//! Export: the comparison figure (PNG and SVG: maps, colour bar, metrics table, a caption naming
//! the presets and the changed parameters) with the resolved configurations beside it; and the
//! data (cubes and metrics of every design, as `shoal study` writes them). Every file is written
//! atomically; a failed write says why in the app.
//!
//! Off the UI thread: the save dialog (rfd, through the desktop's file-chooser portal) and the
//! writing run on the `shoal-export` [`Worker`], one export at a time, and report back through
//! the answers the app polls each frame.
//! Desktops without a portal get no dialog; the app then offers the typed path.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::ShoalApp;
use super::model::AppState;
pub use super::slide::write_figure;
use crate::engine::RunOutput;
use crate::jobs::{Put, Worker};
use crate::study::{write_bytes, write_run};

/// What an export needs: the results on display and the state that made them.
#[derive(Clone)]
pub struct Snapshot {
    /// The app state.
    pub state: AppState,
    /// Each design's result, in order.
    pub runs: Vec<Option<Arc<RunOutput>>>,
    /// A's decimation.
    pub decimation: usize,
    /// Per design, why it has no result to export (failed, still running), if it has none.
    pub missing: Vec<Option<String>>,
    /// The Season window's season, when it has finished for the designs and scene set now.
    pub season: Option<crate::season::run::SeasonResult>,
}

impl Snapshot {
    /// The snapshot of `app` now: only results of the configuration set (a failed run's or an
    /// earlier configuration's results are never exported as the current design's).
    #[must_use]
    pub fn of(app: &ShoalApp) -> Self {
        use super::link::Standing;
        let n = app.state.designs.len();
        let missing = (0..n)
            .map(|i| {
                let ab = super::model::label(i);
                match app.link.standing(i) {
                    Standing::Current(_) => None,
                    Standing::Failed(e) => Some(format!("{ab}'s run of the configuration set failed ({e})")),
                    Standing::Earlier(_) | Standing::Waiting => {
                        Some(format!("{ab} is still running for the configuration set"))
                    }
                }
            })
            .collect();
        Self {
            state: app.state.clone(),
            runs: (0..n).map(|i| app.link.current(i).map(|s| s.output.clone())).collect(),
            decimation: app.link.current(0).map_or(1, |s| s.decimation),
            missing,
            season: app.ui.explore.season.finished_for(&app.state.configs()).cloned(),
        }
    }

    /// Every design's result, or why there are none to export.
    pub fn all(&self) -> Result<Vec<&Arc<RunOutput>>, String> {
        let runs: Vec<&Arc<RunOutput>> = self.runs.iter().flatten().collect();
        if runs.len() == self.runs.len() && !runs.is_empty() {
            return Ok(runs);
        }
        Err(self.missing.iter().flatten().cloned().collect::<Vec<_>>().join("; ")
            + ": nothing exported (the results on screen do not all belong to the configuration set)")
    }

    /// "cubesat vs smallsat vs nominal over lake_hume_bloom": what is compared now (a loaded
    /// study's name would outlive a change of scene).
    #[must_use]
    pub fn title(&self) -> String {
        let s = &self.state;
        let names: Vec<&str> = s.designs.iter().map(|d| d.preset.as_str()).collect();
        format!("{} over {}", names.join(" vs "), s.scene_name)
    }
}

/// The designs as a study, as set in the app, with the app's requirements.
fn study_of(snap: &Snapshot) -> Result<crate::study::StudyResult, String> {
    let all = snap.all()?;
    let state = &snap.state;
    let runs: Vec<(String, &RunOutput)> =
        all.iter().enumerate().map(|(i, r)| (state.design_name(i), r.as_ref())).collect();
    let changes = state.changes();
    let letters: Vec<String> = (0..runs.len()).map(super::model::label).collect();
    let description = format!(
        "{} as set in the app, {} retrieval{}{}",
        letters.join(" against "),
        state.retrieval_spec().name(),
        if snap.decimation > 1 { format!(", at 1/{} resolution (a preview)", snap.decimation) } else { String::new() },
        if changes.is_empty() { String::new() } else { format!("; instrument edits: {}", changes.join("; ")) }
    );
    let name = snap.title();
    crate::study::StudyResult::of_runs(&name, &description, &runs, Some(state.requirements.clone()))
        .ok_or_else(|| "no results to export yet".to_string())
}

/// Write the review pack of every design into the folder `dir` (index.html, figures, review.json):
/// the same page `shoal report` writes, with the app's requirements.
pub fn write_review_pack(snap: &Snapshot, dir: &Path) -> Result<PathBuf, String> {
    let result = study_of(snap)?;
    let figures = crate::study::figure_set(&result).map_err(|e| e.to_string())?;
    let out = crate::study::OutputDir::create(dir, "Shoal app: review pack").map_err(|e| e.to_string())?;
    let mut data = crate::report::review_data(&result, &[], &[]);
    // An edited design is described by what it is now, and from which preset, never by the
    // preset's words alone.
    for (summary, slot) in data.instruments.iter_mut().zip(&snap.state.designs) {
        if slot.modified() {
            summary.description = format!("{}. Edited from the preset `{}`.", slot.spec.summary(), slot.preset);
        }
    }
    // The season the Season window ran for these designs, with its figures, as `shoal report
    // --season` carries one.
    let mut figures = figures;
    if let Some(season) = &snap.season {
        data.seasons.push(crate::season::summary::SeasonSummary::of(season));
        let limits: Vec<(String, f64)> = crate::season::summary::variables(season)
            .into_iter()
            .filter_map(|(_, v)| Some((v.clone(), snap.state.requirements.for_variable(&v)?.mae_pct?)))
            .collect();
        figures.extend(crate::season::figure::figures(season, &limits).map_err(|e| e.to_string())?);
    }
    crate::report::write_pack(&data, &figures, out.path()).map_err(|e| e.to_string())?;
    out.commit().map_err(|e| e.to_string())?;
    Ok(dir.join("index.html"))
}

/// Where the typed path `name` writes `what`: the figure at NAME.png and NAME.svg, the data in
/// the folder NAME_data and the review pack in NAME_review (one name no longer sends the data
/// and the pack to the same folder, each replacing the other).
#[must_use]
pub fn typed_target(what: What, name: &Path) -> PathBuf {
    let suffix = match what {
        What::Figure => return name.to_path_buf(),
        What::Data => "_data",
        What::ReviewPack => "_review",
    };
    let mut s = name.as_os_str().to_os_string();
    s.push(suffix);
    PathBuf::from(s)
}

/// The configuration file of design `i` beside the figure at `stem` (`…_config_A.ron`).
#[must_use]
pub fn config_path(stem: &Path, i: usize) -> PathBuf {
    PathBuf::from(format!("{}_config_{}.ron", stem.display(), super::model::label(i)))
}

/// Files an export of `designs` designs to `path` would replace (empty: nothing of the user's
/// is overwritten).
#[must_use]
pub fn existing(what: What, path: &Path, designs: usize) -> Vec<PathBuf> {
    let candidates: Vec<PathBuf> = match what {
        What::Figure => {
            let stem = path.with_extension("");
            let mut v = vec![stem.with_extension("png"), stem.with_extension("svg")];
            v.extend((0..designs).map(|i| config_path(&stem, i)));
            v
        }
        // A folder is replaced whole ([`crate::study::OutputDir`]): anything in it counts.
        What::ReviewPack | What::Data => {
            let full = std::fs::read_dir(path).is_ok_and(|mut entries| entries.next().is_some());
            if full { vec![path.to_path_buf()] } else { Vec::new() }
        }
    };
    candidates.into_iter().filter(|p| p.exists()).collect()
}

/// Write every design's data into the folder `dir` as `shoal study` writes a study: the metrics
/// tables (CSV and JSON), the requirement checks, the seed spread, the figures, `review.json`
/// (so `shoal report DIR` makes the pack) and per instrument its cubes, SNR table, report and
/// configuration. Written whole: a new or empty folder, or one Shoal wrote, which is replaced.
///
/// The app's runs keep views of their cubes, not the cubes ([`crate::engine::Engine::for_app`]):
/// each design is run again here up to its Rrs, one at a time, by an engine that keeps them (the
/// same configuration and seed make the same cubes), with the retrievals the app ran, and its
/// cubes are let go once written.
pub fn write_data(snap: &Snapshot, dir: &Path) -> Result<usize, String> {
    let result = study_of(snap)?;
    let out = crate::study::OutputDir::create(dir, "Shoal app: data export").map_err(|e| e.to_string())?;
    let mut outputs = crate::study::write_study(&result, out.path(), true).map_err(|e| e.to_string())?;
    for (i, run) in snap.runs.iter().enumerate() {
        let Some(run) = run else { continue };
        let sub = format!("{}_{}", super::model::label(i), run.config.instrument.name);
        let sub = crate::parse::join_name(out.path(), "instrument.name", &sub).map_err(|e| e.to_string())?;
        let rerun;
        let run = if run.cubes.is_some() {
            &**run
        } else {
            // The configuration the run flew (binning folded in, so flying it again changes
            // nothing); its retrievals are the run's, not run again.
            let mut config = run.config.clone();
            config.retrievals.clear();
            let control = crate::control::RunControl::default();
            let mut out = crate::engine::Engine::new().run(&config, &control).map_err(|e| e.to_string())?;
            out.retrievals.clone_from(&run.retrievals);
            out.config.retrievals.clone_from(&run.config.retrievals);
            rerun = out;
            &rerun
        };
        outputs.files.extend(write_run(run, &sub).map_err(|e| e.to_string())?.files);
    }
    let mut review = crate::report::review_data(&result, &[], &[]);
    review.figures = outputs.figure_names();
    let json = crate::report::review_json(&review).map_err(|e| e.to_string())?;
    write_bytes(&out.path().join(crate::report::REVIEW_JSON), json.as_bytes()).map_err(|e| e.to_string())?;
    out.commit().map_err(|e| e.to_string())?;
    Ok(outputs.files.len() + 1)
}

/// Which export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum What {
    /// The comparison figure (PNG, SVG, configurations).
    Figure,
    /// Cubes and metrics.
    Data,
    /// The review pack (a folder with index.html).
    ReviewPack,
}

impl What {
    /// What it is, in messages.
    #[must_use]
    pub fn noun(self) -> &'static str {
        match self {
            Self::Figure => "figure",
            Self::Data => "data",
            Self::ReviewPack => "review pack",
        }
    }
}

/// News from an export thread.
#[derive(Debug)]
pub enum News {
    /// The dialog closed without a choice (cancelled, or no file-chooser portal).
    NoChoice(What),
    /// Written: the message to show.
    Written(String),
    /// Failed: why.
    Failed(String),
}

/// Where an export goes.
enum Place {
    /// Ask in a save dialog, starting at this path.
    Dialog(PathBuf),
    /// This path (typed by the user).
    Path(PathBuf),
}

/// One export asked for.
struct Order {
    what: What,
    snap: Snapshot,
    place: Place,
}

/// Exports run one at a time on the `shoal-export` [`Worker`] (started at the first export):
/// the dialog and the writing never block a frame. Unlike the maps, no export may be dropped for
/// a newer one, so orders wait in a queue here and the worker gets the next when it answers.
#[derive(Default)]
pub struct Exports {
    worker: Option<Worker<Order, News>>,
    queue: VecDeque<Order>,
    busy: bool,
    failures: Vec<String>,
    /// Exports asked for and not yet answered.
    pub running: usize,
}

impl Exports {
    /// Ask for a place in a save dialog (a folder for data), then write `snap` there.
    pub fn with_dialog(&mut self, what: What, snap: Snapshot, start: &Path) {
        self.order(Order { what, snap, place: Place::Dialog(start.to_path_buf()) });
    }

    /// Write `snap` to `path` (the typed path).
    pub fn write_to(&mut self, what: What, snap: Snapshot, path: PathBuf) {
        self.order(Order { what, snap, place: Place::Path(path) });
    }

    fn order(&mut self, order: Order) {
        self.queue.push_back(order);
        self.running += 1;
        self.next();
    }

    /// Hand the worker the next order when it is idle.
    fn next(&mut self) {
        if self.busy || self.queue.is_empty() {
            return;
        }
        if self.worker.is_none() {
            // The app repaints while `running` > 0, so the worker needs no waker.
            match Worker::spawn("shoal-export", || {}, run) {
                Ok(w) => self.worker = Some(w),
                Err(e) => {
                    self.fail_all(&format!("cannot start the export thread: {e}"));
                    return;
                }
            }
        }
        let (Some(worker), Some(order)) = (&self.worker, self.queue.pop_front()) else { return };
        match worker.request(order) {
            Put::Queued => self.busy = true,
            // Nothing else asks this worker, so nothing can be replaced; a closed one has stopped.
            Put::Replaced(_) | Put::Closed(_) => {
                self.worker = None;
                self.fail_all("the export thread stopped");
            }
        }
    }

    fn fail_all(&mut self, why: &str) {
        self.queue.clear();
        self.busy = false;
        self.failures.push(why.to_string());
    }

    /// The next news, if any.
    pub fn poll(&mut self) -> Option<News> {
        if let Some(why) = self.failures.pop() {
            self.running = 0;
            return Some(News::Failed(why));
        }
        let news = self.worker.as_ref()?.poll()?;
        self.busy = false;
        self.running = self.running.saturating_sub(1);
        self.next();
        Some(news)
    }
}

/// The worker's job: ask where (when asked to), then write.
fn run(order: Order) -> News {
    let Order { what, snap, place } = order;
    let path = match place {
        Place::Path(p) => p,
        Place::Dialog(start) => {
            let dir = start.parent().map(Path::to_path_buf).unwrap_or_default();
            let name = start.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            let choice = match what {
                What::Figure => rfd::FileDialog::new()
                    .set_title("Export the comparison figure")
                    .set_directory(&dir)
                    .set_file_name(format!("{name}.png"))
                    .add_filter("PNG and SVG figure", &["png", "svg"])
                    .save_file(),
                What::Data => rfd::FileDialog::new()
                    .set_title("Export cubes and metrics to a folder")
                    .set_directory(&dir)
                    .pick_folder(),
                What::ReviewPack => rfd::FileDialog::new()
                    .set_title("Export the review pack to a folder (index.html and its figures)")
                    .set_directory(&dir)
                    .pick_folder(),
            };
            match choice {
                Some(p) => p,
                None => return News::NoChoice(what),
            }
        }
    };
    write(what, &snap, &path)
}

fn write(what: What, snap: &Snapshot, path: &Path) -> News {
    match what {
        What::Figure => {
            // The dialog may return `name.png` or `name.svg`: both files go next to its stem.
            let stem = path.with_extension("");
            match write_figure(snap, &stem) {
                Ok(files) => News::Written(format!(
                    "wrote {}",
                    files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", ")
                )),
                Err(e) => News::Failed(format!("Export failed: {e}")),
            }
        }
        What::Data => match write_data(snap, path) {
            Ok(n) => News::Written(format!("wrote {n} files under {}", path.display())),
            Err(e) => News::Failed(format!("Export failed: {e}")),
        },
        What::ReviewPack => match write_review_pack(snap, path) {
            Ok(index) => News::Written(format!("wrote the review pack: {}", index.display())),
            Err(e) => News::Failed(format!("Export failed: {e}")),
        },
    }
}

/// Save a window screenshot as PNG.
pub fn write_screenshot(path: &Path, img: &egui::ColorImage) -> Result<(), String> {
    use image::ImageEncoder;
    let [w, h] = img.size;
    let rgba: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&rgba, w as u32, h as u32, image::ExtendedColorType::Rgba8)
        .map_err(|e| format!("screenshot PNG: {e}"))?;
    write_bytes(path, &out).map_err(|e| e.to_string())
}
