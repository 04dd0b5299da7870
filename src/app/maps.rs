//! The central area: the product maps as small multiples (the truth beside the designs chosen,
//! or a pair of designs and their difference, A | B | A − B) on one colour scale with a colour
//! bar, zoomed and panned together, with the values under the cursor.

use std::sync::Arc;

use egui::{Color32, Pos2, Rect, Sense, Vec2};

use super::ShoalApp;
pub(super) use super::legend::format_value;
use super::legend::{colour_bar, scale_bar};
use super::link::{EngineLink, Standing};
use super::model::{AppState, Layout, ProductKind, label};
use super::raster::{Done, Job, Palette, PanelImage, RasterThread, Role, let_go};
use crate::engine::RunOutput;

/// Zoom and pan shared by every map: the visible part of the image in 0–1 coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Centre of the visible part.
    pub centre: Pos2,
    /// Magnification (1 = whole map).
    pub zoom: f32,
}

impl Default for View {
    fn default() -> Self {
        Self { centre: Pos2::new(0.5, 0.5), zoom: 1.0 }
    }
}

impl View {
    fn uv(&self) -> Rect {
        let half = 0.5 / self.zoom;
        let c = Pos2::new(self.centre.x.clamp(half, 1.0 - half), self.centre.y.clamp(half, 1.0 - half));
        Rect::from_center_size(c, Vec2::splat(2.0 * half))
    }
}

/// The textures on display and the request behind them.
#[derive(Default)]
pub struct Images {
    requested: Option<u64>,
    shown: Option<u64>,
    /// The runs of the requested and shown keys, kept alive: a key holds their addresses, which
    /// a new run must not take while the key may be compared.
    requested_runs: Vec<Option<Arc<RunOutput>>>,
    shown_runs: Vec<Option<Arc<RunOutput>>>,
    pub(super) panels: Vec<(PanelImage, egui::TextureHandle)>,
    palette: Option<Palette>,
    difference_palette: Option<Palette>,
    /// The histogram and scatter data that came with the images.
    plot: Option<std::sync::Arc<super::plot_data::PlotData>>,
}

impl Images {
    /// The runs changed: the next frame asks for new images.
    pub fn invalidate(&mut self) {
        self.requested = None;
    }

    /// The histogram and scatter data of the results on display.
    #[must_use]
    pub fn plot(&self) -> Option<&super::plot_data::PlotData> {
        self.plot.as_deref()
    }

    /// Panels on display.
    #[must_use]
    pub fn panel_count(&self) -> usize {
        self.panels.len()
    }

    /// The titles of the panels on display.
    #[must_use]
    pub fn titles(&self) -> Vec<String> {
        self.panels.iter().map(|(p, _)| p.title.clone()).collect()
    }

    /// Are the newest images on display?
    #[must_use]
    pub fn ready(&self) -> bool {
        self.requested.is_some() && self.requested == self.shown
    }

    /// Ask the raster thread for `job`'s images (the current state's: [`job_for`]), if not
    /// already asked; true when this call asked.
    pub fn request(&mut self, job: Job, raster: &RasterThread) -> bool {
        if self.requested == Some(job.key) {
            return false;
        }
        if self.shown == Some(job.key) {
            // Asked again for what is on display (the runs changed and changed back): nothing to do.
            self.requested = self.shown;
            let_go(std::mem::replace(&mut self.requested_runs, self.shown_runs.clone()), &self.shown_runs);
            return false;
        }
        if job.runs.iter().all(Option::is_none) {
            // Nothing to show (every run failed): no map of an earlier configuration stays up.
            self.panels.clear();
            self.plot = None;
            (self.requested, self.shown) = (Some(job.key), Some(job.key));
            let_go(std::mem::take(&mut self.requested_runs), &[]);
            let_go(std::mem::take(&mut self.shown_runs), &[]);
            return false;
        }
        let (key, runs) = (job.key, job.runs.clone());
        if matches!(raster.request(job), crate::jobs::Put::Closed(_)) {
            return false;
        }
        self.requested = Some(key);
        let_go(std::mem::replace(&mut self.requested_runs, runs), &self.shown_runs);
        true
    }

    /// Upload the raster thread's answer if it is the newest and not already on display (the
    /// answer to a request the engine's result hook made early comes again when the frame that
    /// takes the result asks: [`super::prefetch`]).
    pub fn receive(&mut self, ctx: &egui::Context, done: Done) {
        if Some(done.key) != self.requested || self.shown == Some(done.key) {
            return;
        }
        self.panels = done
            .panels
            .into_iter()
            .map(|p| {
                let img = egui::ColorImage::from_rgba_unmultiplied([p.image.width, p.image.height], &p.image.rgba);
                let tex = ctx.load_texture(format!("map-{}", p.title), img, egui::TextureOptions::NEAREST);
                (p, tex)
            })
            .collect();
        self.palette = Some(done.palette);
        self.difference_palette = done.difference_palette;
        self.plot = Some(done.plot);
        self.shown = Some(done.key);
        let_go(std::mem::replace(&mut self.shown_runs, self.requested_runs.clone()), &self.requested_runs);
    }
}

/// What the raster thread is asked for the state and results now on display: each design's
/// result of the current or an earlier configuration. Keyed by the results themselves, not their
/// generation: a result carried over to a new generation (the instrument did not change) keeps
/// its images. A run that failed shows no map (never the previous configuration's).
#[must_use]
pub fn job_for(state: &AppState, link: &EngineLink) -> Job {
    let runs = (0..state.designs.len())
        .map(|i| match link.standing(i) {
            Standing::Current(s) | Standing::Earlier(s) => Some(s.output.clone()),
            Standing::Failed(_) | Standing::Waiting => None,
        })
        .collect();
    Job {
        key: 0,
        runs,
        on_maps: state.on_maps.clone(),
        pair: state.pair,
        kind: state.product,
        band: state.band,
        layout: state.layout,
        max_side: 720,
    }
    .keyed()
}

fn product_menu(app: &mut ShoalApp, ui: &mut egui::Ui) {
    let state = &mut app.state;
    // Wrapped: with eight designs the layout buttons and pair selectors outgrow a narrow panel.
    ui.horizontal_wrapped(|ui| {
        // Tall enough for every entry: a retrieval's own products come last and would scroll out of
        // sight in the default height.
        let menu = egui::ComboBox::from_label("Product").selected_text(state.product.label()).height(480.0);
        menu.show_ui(ui, |ui| {
            // The retrieval's own products (QAA's IOPs) after the core ones.
            let variables = state.retrieval_spec().algorithm().variables();
            for kind in ProductKind::ALL.into_iter().chain(ProductKind::extras(&variables)) {
                ui.selectable_value(&mut state.product, kind, kind.label());
            }
        });
        if state.product.per_band() {
            let names: Vec<String> = (0..state.designs.len())
                .find_map(|i| app.link.current(i))
                .map(|s| {
                    s.output
                        .response
                        .bands
                        .bands
                        .iter()
                        .map(|b| format!("{} ({:.0} nm)", b.name, b.centre_nm))
                        .collect()
                })
                .unwrap_or_default();
            let current = names.get(state.band).cloned().unwrap_or_else(|| format!("band {}", state.band + 1));
            egui::ComboBox::from_label("Band").selected_text(current).show_ui(ui, |ui| {
                for (i, n) in names.iter().enumerate() {
                    ui.selectable_value(&mut state.band, i, n);
                }
            });
        }
        ui.separator();
        let mapped: Vec<String> = state.on_maps.iter().map(|&i| label(i)).collect();
        ui.selectable_value(&mut state.layout, Layout::TruthAB, format!("truth | {}", mapped.join(" | ")))
            .on_hover_text("The truth beside the designs ticked \"map\" in the design list");
        let [p, q] = state.pair.map(label);
        ui.selectable_value(&mut state.layout, Layout::AbDifference, format!("{p} | {q} | {p} − {q}"))
            .on_hover_text("Two designs and their difference (the second sampled on the first's pixels)");
        if state.layout == Layout::AbDifference && state.designs.len() > 2 {
            for (k, id) in [(0, "pair-first"), (1, "pair-second")] {
                let names: Vec<String> = (0..state.designs.len()).map(|i| state.design_name(i)).collect();
                egui::ComboBox::from_id_salt(id).selected_text(label(state.pair[k])).width(40.0).show_ui(ui, |ui| {
                    for (i, name) in names.into_iter().enumerate() {
                        ui.selectable_value(&mut state.pair[k], i, name);
                    }
                });
            }
            if state.pair[0] == state.pair[1] {
                state.settle();
            }
        }
        ui.separator();
        if ui.button("Reset zoom").clicked() {
            app.ui.zoom = View::default();
        }
    });
}

/// Per design, for its panels: (shows the previous configuration, the preview's decimation if
/// a preview), the address of its current run, its swath, and why its run returned no pixel.
struct PanelStates {
    marks: Vec<(bool, Option<usize>)>,
    current: Vec<Option<usize>>,
    swath_m: Vec<Option<f64>>,
    empty: Vec<Option<String>>,
}

fn panel_states(app: &ShoalApp) -> PanelStates {
    let finest = app.link.finest();
    let n = app.state.designs.len();
    // Is what is shown the previous configuration's (greyed, marked), or the current one's preview?
    let marks: Vec<(bool, Option<usize>)> = (0..n)
        .map(|i| match app.link.standing(i) {
            Standing::Earlier(_) => (true, None),
            Standing::Current(s) if s.decimation != finest => (false, Some(s.decimation)),
            _ => (false, None),
        })
        .collect();
    let current: Vec<Option<usize>> =
        (0..n).map(|i| app.link.current(i).map(|s| std::sync::Arc::as_ptr(&s.output) as usize)).collect();
    let swath_m: Vec<Option<f64>> = (0..n)
        .map(|i| match app.link.standing(i) {
            Standing::Current(s) | Standing::Earlier(s) => Some(s.output.config.instrument.swath_m()),
            _ => None,
        })
        .collect();
    let empty: Vec<Option<String>> = (0..n)
        .map(|i| match app.link.standing(i) {
            Standing::Current(s) => super::metrics_table::no_pixel_reason(&s.output),
            _ => None,
        })
        .collect();
    PanelStates { marks, current, swath_m, empty }
}

/// Columns of the small multiples: the count that gives `n` panels of aspect `aspect` (width
/// over height) the largest size in `avail`, and that panel width.
fn grid_columns(n: usize, aspect: f32, avail: Vec2, title_h: f32) -> (usize, f32) {
    let n = n.max(1);
    (1..=n)
        .map(|cols| {
            let rows = n.div_ceil(cols);
            let w = (avail.x - 8.0 * cols as f32) / cols as f32;
            let h = (avail.y - (title_h + 26.0) * rows as f32) / rows as f32;
            (cols, w.min(h * aspect).max(40.0))
        })
        .fold((n, 0.0), |best, c| if c.1 > best.1 + 0.5 { c } else { best })
}

/// One map panel in `room` (the most width and height it may take): its title, marked when it
/// shows a preview or the previous configuration; the map, greyed when previous; the scale bar;
/// drag to pan, scroll to zoom (`view`, shared by all). Returns where the pointer is on the map
/// (0–1) on the grid of the panel's design (with that design), and a click, for the spectrum.
fn map_panel(
    ui: &mut egui::Ui,
    (panel, tex): (&PanelImage, &egui::TextureHandle),
    states: &PanelStates,
    room: Vec2,
    view: &mut View,
) -> (Option<(Pos2, usize)>, Option<super::spectrum::Pick>) {
    let PanelStates { marks, current, swath_m, empty } = states;
    // The design a panel belongs to (the truth's and the difference's: their first design, on
    // whose grid they are drawn).
    let design = match panel.role {
        Role::Truth(i) | Role::Design(i) | Role::Difference(i, _) => i,
    };
    let (earlier, preview) = match panel.role {
        Role::Design(i) => marks.get(i).copied().unwrap_or_default(),
        Role::Truth(i) => marks.get(i).map_or((false, None), |m| (m.0, None)),
        Role::Difference(..) => (marks.iter().any(|m| m.0), None),
    };
    // Made from runs that are no longer the current ones (a newer result is being coloured):
    // greyed and said so, never titled as the result the link now holds.
    let superseded = panel.made_from.iter().any(|&(d, run)| current.get(d).copied().flatten() != Some(run));
    let title = match (earlier, superseded, preview) {
        (true, _, _) => format!("{} (previous configuration, updating)", panel.title),
        (false, true, _) => format!("{} (updating)", panel.title),
        (false, false, Some(d)) => format!("{} (preview 1/{d})", panel.title),
        _ => panel.title.clone(),
    };
    let earlier = earlier || superseded;
    // The title never wider than the map (a long one widened the row past the colour bar).
    ui.set_max_width(room.x);
    let title = match panel.role {
        Role::Design(i) => egui::RichText::new(title).color(super::theme::design(i)),
        _ => egui::RichText::new(title),
    };
    ui.add(egui::Label::new(title).truncate());
    let img = &panel.image;
    let aspect = img.width as f32 / img.height.max(1) as f32;
    let height = (room.x / aspect).min(room.y).max(40.0);
    let w = (height * aspect).min(room.x);
    let (rect, resp) = ui.allocate_exact_size(Vec2::new(w, height), Sense::click_and_drag());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, ui.visuals().extreme_bg_color);
    // The previous configuration's map, greyed until the new one arrives.
    let tint = if earlier { Color32::from_gray(110) } else { Color32::WHITE };
    painter.image(tex.id(), rect, view.uv(), tint);
    if let Role::Design(i) = panel.role
        && let Some(why) = empty.get(i).and_then(Option::as_ref)
    {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "no pixel returned",
            egui::FontId::proportional(14.0),
            super::theme::FAIL,
        );
        resp.clone().on_hover_text(why);
    }
    if let Some(swath) = swath_m.get(design).copied().flatten() {
        scale_bar(ui, w, swath * f64::from(view.uv().width()));
    }
    if resp.dragged() {
        view.centre -= resp.drag_delta() / rect.size() / view.zoom;
    }
    let at = |p: Pos2, view: &View| {
        let (uv, f) = (view.uv(), (p - rect.min) / rect.size());
        Pos2::new(uv.min.x + f.x * uv.width(), uv.min.y + f.y * uv.height())
    };
    // A click opens the scene's spectrum at that point (on the grid of the panel's design).
    let clicked = resp
        .clicked()
        .then(|| resp.interact_pointer_pos())
        .flatten()
        .map(|p| super::spectrum::Pick { run: design, uv: at(p, view).into() });
    let mut hovered = None;
    if resp.hovered() {
        let scroll = ui.input_mut(|i| {
            let s = i.smooth_scroll_delta;
            i.smooth_scroll_delta = Vec2::ZERO;
            (s.y, i.zoom_delta())
        });
        view.zoom = (view.zoom * scroll.1 * (scroll.0 * 0.003).exp()).clamp(1.0, 64.0);
        hovered = resp.hover_pos().map(|p| (at(p, view), design));
    }
    (hovered, clicked)
}

/// The central panel.
pub fn central(app: &mut ShoalApp, ui: &mut egui::Ui) {
    use super::banners::{external_banner, failure_box, product_note, retrieval_banner};
    retrieval_banner(app, ui);
    super::banners::domain_banner(app, ui);
    external_banner(app, ui);
    product_menu(app, ui);
    if let Some(note) = product_note(app) {
        ui.label(note);
    }
    let failures: Vec<(usize, String)> = (0..app.state.designs.len())
        .filter_map(|i| match app.link.standing(i) {
            Standing::Failed(e) => Some((i, e.to_string())),
            _ => None,
        })
        .collect();
    for (i, e) in &failures {
        failure_box(app, ui, *i, e);
    }
    if app.images.panels.is_empty() {
        if failures.is_empty() && (app.link.busy() || !app.images.ready()) && product_note(app).is_none() {
            ui.add_space(40.0);
            ui.vertical_centered(|ui| {
                ui.spinner();
                ui.label("Running the chain: the first preview appears within seconds.");
            });
        }
        return;
    }
    let n = app.images.panels.len();
    let avail = ui.available_size();
    let bar_w = 96.0;
    let aspect = app.images.panels.first().map_or(1.0, |(p, _)| p.image.width as f32 / p.image.height.max(1) as f32);
    let (cols, width) = grid_columns(n, aspect, Vec2::new(avail.x - bar_w, avail.y - 30.0), 14.0);
    let rows = n.div_ceil(cols);
    let mut hovered: Option<(Pos2, usize)> = None;
    let mut clicked = None;
    let mut view = app.ui.zoom;
    let states = panel_states(app);
    ui.horizontal(|ui| {
        ui.vertical(|ui| {
            for row in app.images.panels.chunks(cols) {
                ui.horizontal(|ui| {
                    for (panel, tex) in row {
                        let room = Vec2::new(width, (avail.y - 30.0) / rows as f32 - 40.0);
                        let (hover, click) =
                            ui.vertical(|ui| map_panel(ui, (panel, tex), &states, room, &mut view)).inner;
                        hovered = hovered.or(hover);
                        clicked = clicked.or(click);
                    }
                });
            }
        });
        let palette = app.images.palette;
        let label_text = app.state.product.label().split(" (").next().unwrap_or("").to_string();
        let classes = super::hover::class_names(app);
        ui.vertical(|ui| {
            app.ui.map_rects.clear();
            if let Some(p) = palette {
                app.ui.map_rects.push(colour_bar(ui, p, 220.0, &label_text, &classes));
            }
            if let Some(p) = app.images.difference_palette {
                // The difference in the product's own unit ("A − B (mg m⁻³)"), as the study figures.
                let product = app.state.product.label();
                let unit = product.split_once(" (").map_or("", |(_, u)| u.trim_end_matches(')'));
                let [a, b] = app.state.pair.map(label);
                app.ui.map_rects.push(colour_bar(ui, p, 160.0, &crate::study::difference_bar(&a, &b, unit), &classes));
            }
        });
    });
    app.ui.zoom = view;
    if let Some(pick) = clicked {
        app.ui.spectrum.pick(pick);
    }
    super::hover::hover_readout(app, ui, hovered);
}
