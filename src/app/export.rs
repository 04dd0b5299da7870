//! Export: the comparison figure (PNG and SVG: maps, colour bar, metrics table, a caption naming
//! the presets and the changed parameters) with the resolved configurations beside it; and the
//! data (cubes and metrics of A and B, as `shoal study` writes them). Every file is written
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
use super::raster::{Palette, product_map};
use crate::colormap::Scale;
use crate::engine::RunOutput;
use crate::jobs::{Put, Worker};
use crate::study::{ComparisonPanel, ReviewSlide, SlideSeries, review_slide, write_bytes, write_run};

/// What an export needs: the results on display and the state that made them.
#[derive(Clone)]
pub struct Snapshot {
    /// The app state.
    pub state: AppState,
    /// A's and B's results.
    pub runs: [Option<Arc<RunOutput>>; 2],
    /// A's decimation.
    pub decimation: usize,
}

impl Snapshot {
    /// The snapshot of `app` now.
    #[must_use]
    pub fn of(app: &ShoalApp) -> Self {
        Self {
            state: app.state.clone(),
            runs: [0, 1].map(|i| app.link.shown[i].as_ref().map(|s| s.output.clone())),
            decimation: app.link.shown[0].as_ref().map_or(1, |s| s.decimation),
        }
    }
}

/// Write the comparison figure and the configurations next to `stem`.
pub fn write_figure(snap: &Snapshot, stem: &Path) -> Result<Vec<PathBuf>, String> {
    let state = &snap.state;
    let (Some(a), Some(b)) = (&snap.runs[0], &snap.runs[1]) else { return Err("no results to export yet".into()) };
    let kind = state.product;
    let mut panels = Vec::new();
    for (title, out, truth) in [("truth", a, true), ("A", a, false), ("B", b, false)] {
        if let Some(m) = product_map(out, kind, state.band, truth) {
            let label = if truth {
                title.to_string()
            } else {
                format!("{title}: {}", if title == "A" { &state.a.preset } else { &state.b.preset })
            };
            panels.push(ComparisonPanel { title: label, values: m.values, valid: m.valid });
        }
    }
    if panels.is_empty() {
        return Err(format!("the runs have no {} to show", kind.label()));
    }
    let refs: Vec<super::raster::MapData> =
        panels.iter().map(|p| super::raster::MapData { values: p.values.clone(), valid: p.valid.clone() }).collect();
    let refs: Vec<&super::raster::MapData> = refs.iter().collect();
    let scale = match super::raster::shared_palette(&refs, kind, false) {
        Palette::Sequential(s) => s,
        _ => Scale { lo: 0.0, hi: 8.0, log: false },
    };
    let table = verdict_table(state, a, b);
    let changes = state.changes();
    let caption = vec![
        format!(
            "A: {}   B: {}   scene: {}   retrieval: {}   resolution 1/{}",
            state.a.preset,
            state.b.preset,
            state.scene_name,
            match state.retrieval {
                super::model::RetrievalKind::Almi => "aLMI",
                super::model::RetrievalKind::Sambuca => "SAMBUCA",
            },
            snap.decimation
        ),
        if changes.is_empty() { "Presets unchanged.".into() } else { format!("Changed: {}", changes.join("; ")) },
        "Shoal: one colour scale for all panels; grey: land or not returned; metrics after Seegers et al. (2018)."
            .into(),
    ];
    let title = format!("{} — {}", state.study_name, kind.label());
    let variable = kind.variable().unwrap_or("chl_mg_m3");
    // One series per instrument, in A's and B's colours.
    let series = |i: usize, out: &RunOutput, points: Vec<(f64, f64)>| {
        let [r, g, b, _] = super::theme::INSTRUMENT[i].to_array();
        SlideSeries {
            name: format!("{}: {}", if i == 0 { "A" } else { "B" }, out.config.instrument.name),
            colour: [r, g, b],
            points,
        }
    };
    let plot = super::plot_data::plot_data(&snap.runs, variable);
    let (mut snr, mut scatter) = (Vec::new(), Vec::new());
    for (i, out) in [a, b].into_iter().enumerate() {
        let analytic = out.snr.iter().filter(|r| r.snr_analytic.is_finite()).map(|r| (r.centre_nm, r.snr_analytic));
        snr.push(series(i, out, analytic.collect()));
        scatter.push(series(i, out, plot.scatter[i].iter().map(|p| (p[0], p[1])).collect()));
    }
    let slide = ReviewSlide {
        title,
        caption,
        label: kind.label().to_string(),
        scale,
        diverging: false,
        panels,
        snr,
        snr_requirement: state.requirements.snr,
        scatter,
        scatter_label: format!("({})", crate::metrics::unit(variable)),
        verdicts: table,
        parameters: super::params::differences(
            &a.config.instrument,
            &b.config.instrument,
            (a.response.bands.bands.len(), b.response.bands.bands.len()),
        ),
    };
    let fig = review_slide("comparison", &slide).map_err(|e| e.to_string())?;
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    write_bytes(&png, &fig.png).map_err(|e| e.to_string())?;
    write_bytes(&svg, fig.svg.as_bytes()).map_err(|e| e.to_string())?;
    let mut written = vec![png, svg];
    for (name, out) in [("A", a), ("B", b)] {
        let path = PathBuf::from(format!("{}_config_{name}.ron", stem.display()));
        let text = out.config.to_ron().map_err(|e| e.to_string())?;
        write_bytes(&path, text.as_bytes()).map_err(|e| e.to_string())?;
        written.push(path);
    }
    Ok(written)
}

/// The verdict table of the slide: per instrument and product, MAE, bias, returned share and
/// the judgement of `Requirements::check_run` (the app's and `shoal study`'s).
fn verdict_table(state: &AppState, a: &RunOutput, b: &RunOutput) -> Vec<Vec<String>> {
    let mut table: Vec<Vec<String>> = vec![vec![
        "instrument".into(),
        "product".into(),
        "MAE %".into(),
        "bias %".into(),
        "returned %".into(),
        "requirement".into(),
    ]];
    for (name, out) in [("A", a), ("B", b)] {
        for ret in &out.retrievals {
            // The app's and `shoal study`'s judgement: `Requirements::check_run`.
            let checks =
                state.requirements.check_run(&out.config.instrument.name, out.config.seed, Some(&ret.metrics), &[]);
            for v in &ret.metrics.variables {
                let m = &v.metrics;
                let mine: Vec<&crate::study::Check> =
                    checks.iter().filter(|c| c.variable.as_deref() == Some(v.variable.as_str())).collect();
                let req = match crate::study::verdict(mine.iter().copied()) {
                    Some(ok) => {
                        let name = crate::metrics::name(&v.variable);
                        let failed: Vec<String> = mine
                            .iter()
                            .filter(|c| !c.pass)
                            .map(|c| c.what.replace(v.variable.as_str(), name))
                            .collect();
                        if ok { "pass".into() } else { format!("FAIL: {}", failed.join(", ")) }
                    }
                    None => String::new(),
                };
                let (mae, bias) = if m.n == 0 {
                    ("–".into(), "–".into())
                } else {
                    (format!("{:.1}", m.mae_pct()), format!("{:+.1}", m.bias_pct()))
                };
                table.push(vec![
                    format!("{name} ({})", out.config.instrument.name),
                    format!("{} {}", ret.metrics.product, crate::metrics::label(&v.variable)),
                    mae,
                    bias,
                    format!("{:.1}", m.returned_pct),
                    req,
                ]);
            }
        }
    }
    table
}

/// Write the review pack of A and B into the folder `dir` (index.html, figures, review.json):
/// the same page `shoal report` writes, with the app's requirements.
pub fn write_review_pack(snap: &Snapshot, dir: &Path) -> Result<PathBuf, String> {
    let (Some(a), Some(b)) = (&snap.runs[0], &snap.runs[1]) else { return Err("no results to export yet".into()) };
    let state = &snap.state;
    let runs = [
        (format!("{} (A)", a.config.instrument.name), a.as_ref()),
        (format!("{} (B)", b.config.instrument.name), b.as_ref()),
    ];
    let changes = state.changes();
    let description = format!(
        "A against B as set in the app{}{}",
        if snap.decimation > 1 { format!(", preview at 1/{} resolution", snap.decimation) } else { String::new() },
        if changes.is_empty() { String::new() } else { format!("; changed from the presets: {}", changes.join("; ")) }
    );
    let result =
        crate::study::StudyResult::of_runs(&state.study_name, &description, &runs, Some(state.requirements.clone()))
            .ok_or("no results to export yet")?;
    let figures = crate::study::figure_set(&result).map_err(|e| e.to_string())?;
    let out = crate::study::OutputDir::create(dir, "Shoal app: review pack").map_err(|e| e.to_string())?;
    crate::report::write_pack(&crate::report::review_data(&result, &[], &[]), &figures, out.path())
        .map_err(|e| e.to_string())?;
    out.commit().map_err(|e| e.to_string())?;
    Ok(dir.join("index.html"))
}

/// Files an export to `path` would replace (empty: nothing of the user's is overwritten).
#[must_use]
pub fn existing(what: What, path: &Path) -> Vec<PathBuf> {
    let candidates: Vec<PathBuf> = match what {
        What::Figure => {
            let stem = path.with_extension("");
            let mut v = vec![stem.with_extension("png"), stem.with_extension("svg")];
            v.extend(["A", "B"].map(|n| PathBuf::from(format!("{}_config_{n}.ron", stem.display()))));
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

/// Write both runs' cubes and metrics into the folder `dir` (written whole: a new or empty
/// folder, or one Shoal wrote, which is replaced).
pub fn write_data(snap: &Snapshot, dir: &Path) -> Result<usize, String> {
    let out = crate::study::OutputDir::create(dir, "Shoal app: data export").map_err(|e| e.to_string())?;
    let mut n = 0;
    for (name, run) in ["A", "B"].iter().zip(&snap.runs) {
        let Some(run) = run else { return Err("no results to export yet".into()) };
        let sub = format!("{name}_{}", run.config.instrument.name);
        let sub = crate::parse::join_name(out.path(), "instrument.name", &sub).map_err(|e| e.to_string())?;
        n += write_run(run, &sub).map_err(|e| e.to_string())?.files.len();
    }
    out.commit().map_err(|e| e.to_string())?;
    Ok(n)
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
