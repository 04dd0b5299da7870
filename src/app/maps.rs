//! The central area: the product maps side by side (truth | A | B, or A | B | A − B) on one
//! colour scale with a colour bar, zoomed and panned together, with the values under the cursor.

use std::hash::{DefaultHasher, Hash, Hasher};

use egui::{Color32, Pos2, Rect, Sense, Vec2};

use super::ShoalApp;
use super::link::{EngineLink, Standing};
use super::model::{AppState, Layout, ProductKind};
use super::raster::{Done, Job, Palette, PanelImage, RasterThread};
use crate::colormap::{categorical, diverging, viridis};

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
    panels: Vec<(PanelImage, egui::TextureHandle)>,
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

    /// Are the newest images on display?
    #[must_use]
    pub fn ready(&self) -> bool {
        self.requested.is_some() && self.requested == self.shown
    }

    /// Ask the raster thread for the images of the current state, if not already asked; true
    /// when this call asked.
    pub fn request(&mut self, state: &AppState, link: &EngineLink, raster: &RasterThread) -> bool {
        let mut h = DefaultHasher::new();
        state.product.hash(&mut h);
        state.band.hash(&mut h);
        state.layout.hash(&mut h);
        // The results themselves, not their generation: a result carried over to a new
        // generation (the instrument did not change) keeps its images. A run that failed shows
        // no map (never the previous configuration's).
        let runs = [0, 1].map(|i| match link.standing(i) {
            Standing::Current(s) | Standing::Earlier(s) => Some(s.output.clone()),
            Standing::Failed(_) | Standing::Waiting => None,
        });
        for r in &runs {
            r.as_ref().map(std::sync::Arc::as_ptr).hash(&mut h);
        }
        let key = h.finish();
        if self.requested == Some(key) {
            return false;
        }
        if runs.iter().all(Option::is_none) {
            // Nothing to show (both failed): no map of an earlier configuration stays up.
            self.panels.clear();
            self.plot = None;
            (self.requested, self.shown) = (Some(key), Some(key));
            return false;
        }
        let job = Job { key, runs, kind: state.product, band: state.band, layout: state.layout, max_side: 720 };
        if matches!(raster.request(job), crate::jobs::Put::Closed(_)) {
            return false;
        }
        self.requested = Some(key);
        true
    }

    /// Upload the raster thread's answer if it is the newest.
    pub fn receive(&mut self, ctx: &egui::Context, done: Done) {
        if Some(done.key) != self.requested {
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
    }
}

fn product_menu(app: &mut ShoalApp, ui: &mut egui::Ui) {
    let state = &mut app.state;
    ui.horizontal(|ui| {
        egui::ComboBox::from_label("Product").selected_text(state.product.label()).show_ui(ui, |ui| {
            for kind in ProductKind::ALL {
                ui.selectable_value(&mut state.product, kind, kind.label());
            }
        });
        if state.product.per_band() {
            let names: Vec<String> = (0..2)
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
        ui.selectable_value(&mut state.layout, Layout::TruthAB, "truth | A | B");
        ui.selectable_value(&mut state.layout, Layout::AbDifference, "A | B | A − B");
        ui.separator();
        if ui.button("Reset zoom").clicked() {
            app.ui.zoom = View::default();
        }
    });
}

fn colour_bar(ui: &mut egui::Ui, palette: Palette, height: f32, label: &str, classes: &[String]) {
    let (rect, _) = ui.allocate_exact_size(Vec2::new(86.0, height), Sense::hover());
    let painter = ui.painter_at(rect);
    let bar = Rect::from_min_size(rect.min + Vec2::new(4.0, 16.0), Vec2::new(16.0, height - 40.0));
    let steps = 64;
    let text = ui.visuals().text_color();
    painter.text(rect.min, egui::Align2::LEFT_TOP, label, egui::FontId::proportional(11.0), text);
    // Classes by name (substrates, SIOP sets); A − B of classes as agree / differ.
    let named: Option<Vec<([u8; 3], String)>> = match palette {
        Palette::Classes => {
            Some(classes.iter().take(12).enumerate().map(|(k, n)| (categorical(k), n.replace('_', " "))).collect())
        }
        Palette::Agreement => {
            Some(vec![(super::theme::AGREEMENT[0], "same".into()), (super::theme::AGREEMENT[1], "different".into())])
        }
        _ => None,
    };
    if let Some(named) = named {
        for (k, (c, name)) in named.iter().enumerate() {
            let r = Rect::from_min_size(bar.min + Vec2::new(0.0, k as f32 * 16.0), Vec2::splat(12.0));
            painter.rect_filled(r, 0.0, Color32::from_rgb(c[0], c[1], c[2]));
            painter.text(
                r.right_center() + Vec2::new(4.0, 0.0),
                egui::Align2::LEFT_CENTER,
                name,
                egui::FontId::proportional(10.0),
                text,
            );
        }
        return;
    }
    for k in 0..steps {
        let t = (k as f64 + 0.5) / steps as f64;
        let c = match palette {
            Palette::Sequential(_) => viridis(t),
            Palette::Diverging(_) => diverging(2.0 * t - 1.0),
            Palette::Classes | Palette::Agreement => [0, 0, 0],
        };
        let y1 = bar.max.y - bar.height() * k as f32 / steps as f32;
        let y0 = bar.max.y - bar.height() * (k + 1) as f32 / steps as f32;
        painter.rect_filled(Rect::from_x_y_ranges(bar.x_range(), y0..=y1), 0.0, Color32::from_rgb(c[0], c[1], c[2]));
    }
    // Round ticks (1, 3, 10, 30 …) where they fall on the bar, not the bar's odd ends.
    let ticks: Vec<(f64, f64)> = match palette {
        Palette::Sequential(s) => s.nice_ticks().into_iter().map(|v| (v, s.position(v))).collect(),
        Palette::Diverging(b) => crate::colormap::Scale { lo: -b, hi: b, log: false }
            .nice_ticks()
            .into_iter()
            .map(|v| (v, 0.5 * (v / b + 1.0)))
            .collect(),
        Palette::Classes | Palette::Agreement => Vec::new(),
    };
    let [r, g, b, a] = super::theme::NOT_RETURNED;
    let swatch = Rect::from_min_size(Pos2::new(bar.min.x, bar.max.y + 6.0), Vec2::splat(10.0));
    painter.rect_filled(swatch, 0.0, Color32::from_rgba_unmultiplied(r, g, b, a));
    painter.text(
        swatch.right_center() + Vec2::new(4.0, 0.0),
        egui::Align2::LEFT_CENTER,
        "not returned",
        egui::FontId::proportional(9.0),
        text,
    );
    for (v, t) in ticks {
        if !(-1e-9..=1.0 + 1e-9).contains(&t) {
            continue;
        }
        let y = bar.max.y - bar.height() * t as f32;
        painter.text(
            Pos2::new(bar.max.x + 4.0, y),
            egui::Align2::LEFT_CENTER,
            crate::colormap::significant(v, 4),
            egui::FontId::proportional(10.0),
            text,
        );
    }
}

/// A scale bar under a map `width_px` wide showing `ground_m` across: the longest round length
/// (1-2-5 steps, 100 m to 500 km) that fits in 40 % of the width.
fn scale_bar(ui: &mut egui::Ui, width_px: f32, ground_m: f64) {
    let (rect, _) = ui.allocate_exact_size(Vec2::new(width_px, 16.0), Sense::hover());
    if !(ground_m.is_finite() && ground_m > 0.0) {
        return;
    }
    let m_per_px = ground_m / f64::from(width_px.max(1.0));
    let lengths = [100.0, 200.0, 500.0, 1e3, 2e3, 5e3, 1e4, 2e4, 5e4, 1e5, 2e5, 5e5];
    let Some(&length) = lengths.iter().rev().find(|&&l| l / m_per_px <= 0.4 * f64::from(width_px)) else { return };
    let px = (length / m_per_px) as f32;
    let colour = ui.visuals().text_color();
    let painter = ui.painter_at(rect);
    let y = rect.min.y + 4.0;
    let (x0, x1) = (rect.min.x + 2.0, rect.min.x + 2.0 + px);
    let stroke = egui::Stroke::new(1.5, colour);
    painter.line_segment([Pos2::new(x0, y), Pos2::new(x1, y)], stroke);
    for x in [x0, x1] {
        painter.line_segment([Pos2::new(x, y - 3.0), Pos2::new(x, y + 3.0)], stroke);
    }
    let label = if length >= 1e3 { format!("{} km", length / 1e3) } else { format!("{length} m") };
    painter.text(Pos2::new(x1 + 6.0, y), egui::Align2::LEFT_CENTER, label, egui::FontId::proportional(10.0), colour);
}

pub(super) fn format_value(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.4}")
    }
}

/// Per instrument, for its panels: (shows the previous configuration, the preview's decimation
/// if a preview), which run the truth panel comes from, each run's swath, and why a run
/// returned no pixel.
struct PanelStates {
    marks: Vec<(bool, Option<usize>)>,
    truth_from: usize,
    swath_m: Vec<Option<f64>>,
    empty: Vec<Option<String>>,
}

fn panel_states(app: &ShoalApp) -> PanelStates {
    // Per instrument: is what is shown the previous configuration's (greyed, marked), or the
    // current one's preview?
    let finest = app.link.finest();
    let marks: Vec<(bool, Option<usize>)> = (0..2)
        .map(|i| match app.link.standing(i) {
            Standing::Earlier(_) => (true, None),
            Standing::Current(s) if s.decimation != finest => (false, Some(s.decimation)),
            _ => (false, None),
        })
        .collect();
    // The truth comes from A's run (B's when A has none).
    let truth_from = usize::from(!matches!(app.link.standing(0), Standing::Current(_) | Standing::Earlier(_)));
    // Swath of the instrument whose grid each panel is on (B's panel on B's, the rest on A's).
    let swath_m: Vec<Option<f64>> = (0..2)
        .map(|i| match app.link.standing(i) {
            Standing::Current(s) | Standing::Earlier(s) => Some(s.output.config.instrument.swath_m()),
            _ => None,
        })
        .collect();
    let empty: Vec<Option<String>> = (0..2)
        .map(|i| match app.link.standing(i) {
            Standing::Current(s) => super::metrics_table::no_pixel_reason(&s.output),
            _ => None,
        })
        .collect();
    PanelStates { marks, truth_from, swath_m, empty }
}

/// The central panel.
pub fn central(app: &mut ShoalApp, ui: &mut egui::Ui) {
    use super::banners::{external_banner, failure_box, product_note, retrieval_banner};
    retrieval_banner(app, ui);
    external_banner(app, ui);
    product_menu(app, ui);
    if let Some(note) = product_note(app) {
        ui.label(note);
    }
    let failures: Vec<(usize, String)> = (0..2)
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
    let width = ((avail.x - bar_w - 8.0 * n as f32) / n as f32).max(60.0);
    let mut hovered: Option<Pos2> = None;
    let mut clicked = None;
    let mut view = app.ui.zoom;
    let PanelStates { marks, truth_from, swath_m, empty } = panel_states(app);
    ui.horizontal(|ui| {
        for (panel, tex) in &app.images.panels {
            ui.vertical(|ui| {
                let index = match panel.title.as_str() {
                    "A" => Some(0),
                    "B" => Some(1),
                    "truth" => Some(truth_from),
                    _ => None,
                };
                let (earlier, preview) = index.map_or((marks[0].0 || marks[1].0, None), |i| marks[i]);
                let title = match (earlier, preview) {
                    (true, _) => format!("{} (previous configuration, updating)", panel.title),
                    (false, Some(d)) => format!("{} (preview 1/{d})", panel.title),
                    _ => panel.title.clone(),
                };
                ui.label(title);
                let img = &panel.image;
                let aspect = img.width as f32 / img.height.max(1) as f32;
                let height = (width / aspect).min(avail.y - 58.0).max(40.0);
                let w = (height * aspect).min(width);
                let (rect, resp) = ui.allocate_exact_size(Vec2::new(w, height), Sense::click_and_drag());
                let painter = ui.painter_at(rect);
                painter.rect_filled(rect, 0.0, ui.visuals().extreme_bg_color);
                // The previous configuration's map, greyed until the new one arrives.
                let tint = if earlier { Color32::from_gray(110) } else { Color32::WHITE };
                painter.image(tex.id(), rect, view.uv(), tint);
                if let Some(why) = index.and_then(|i| empty[i].as_ref()).filter(|_| panel.title != "truth") {
                    painter.text(
                        rect.center(),
                        egui::Align2::CENTER_CENTER,
                        "no pixel returned",
                        egui::FontId::proportional(14.0),
                        super::theme::FAIL,
                    );
                    resp.clone().on_hover_text(why);
                }
                let swath = if panel.title == "B" { swath_m[1] } else { swath_m[0].or(swath_m[1]) };
                if let Some(swath) = swath {
                    scale_bar(ui, w, swath * f64::from(view.uv().width()));
                }
                if resp.dragged() {
                    view.centre -= resp.drag_delta() / rect.size() / view.zoom;
                }
                // A click opens the scene's spectrum at that point (A's pixel for the truth and
                // difference panels when A has a result).
                if let Some(p) = resp.clicked().then(|| resp.interact_pointer_pos()).flatten() {
                    let uv = view.uv();
                    let f = (p - rect.min) / rect.size();
                    let run = index.filter(|_| panel.title != "truth").unwrap_or(truth_from);
                    clicked = Some(super::spectrum::Pick {
                        run,
                        uv: (uv.min.x + f.x * uv.width(), uv.min.y + f.y * uv.height()),
                    });
                }
                if resp.hovered() {
                    let scroll = ui.input_mut(|i| {
                        let s = i.smooth_scroll_delta;
                        i.smooth_scroll_delta = Vec2::ZERO;
                        (s.y, i.zoom_delta())
                    });
                    view.zoom = (view.zoom * scroll.1 * (scroll.0 * 0.003).exp()).clamp(1.0, 64.0);
                    if let Some(p) = resp.hover_pos() {
                        let uv = view.uv();
                        let f = (p - rect.min) / rect.size();
                        hovered = Some(Pos2::new(uv.min.x + f.x * uv.width(), uv.min.y + f.y * uv.height()));
                    }
                }
            });
        }
        let palette = app.images.palette;
        let label = app.state.product.label().split(" (").next().unwrap_or("").to_string();
        let classes = class_names(app);
        ui.vertical(|ui| {
            if let Some(p) = palette {
                colour_bar(ui, p, 220.0, &label, &classes);
            }
            if let Some(p) = app.images.difference_palette {
                // The difference in the product's own unit ("A − B (mg m⁻³)").
                let unit = app.state.product.label().split_once(" (").map_or(String::new(), |(_, u)| format!(" ({u}"));
                colour_bar(ui, p, 160.0, &format!("A − B{unit}"), &classes);
            }
        });
    });
    app.ui.zoom = view;
    if let Some(pick) = clicked {
        app.ui.spectrum.pick(pick);
    }
    hover_readout(app, ui, hovered);
}

/// The value under the cursor in every panel (rows are drawn bottom-up): class maps by class
/// name, A − B of classes as agree or differ.
fn hover_readout(app: &mut ShoalApp, ui: &mut egui::Ui, hovered: Option<Pos2>) {
    let classes = class_names(app);
    if let Some(uv) = hovered {
        let mut parts = Vec::new();
        let mut cell = None;
        for (panel, _) in &app.images.panels {
            let (rows, cols) = panel.data.values.dim();
            let c = ((uv.x * cols as f32) as usize).min(cols.saturating_sub(1));
            let r = (((1.0 - uv.y) * rows as f32) as usize).min(rows.saturating_sub(1));
            cell.get_or_insert((r, c));
            let value = panel.data.values[[r, c]];
            let text = if !panel.data.valid[[r, c]] {
                "–".into()
            } else if app.state.product.categorical() && panel.title != "A − B" {
                // A class map holds the class index: show its name.
                classes
                    .get(value.max(0.0) as usize)
                    .map_or_else(|| format_value(f64::from(value)), |n| n.replace('_', " "))
            } else if panel.title == "A − B" && app.state.product.categorical() {
                if value > 0.5 { "differ".into() } else { "agree".into() }
            } else {
                format_value(f64::from(value))
            };
            parts.push(format!("{}: {text}", panel.title));
        }
        app.ui.hover = cell;
        if let Some((r, c)) = cell {
            ui.label(format!("row {r}, column {c}   {}", parts.join("   ")));
        }
    } else {
        ui.label("Drag to pan, scroll to zoom (the maps move together); click for the spectrum there.");
    }
}

/// The names of the shown product's classes, in colour order (substrates or SIOP sets).
fn class_names(app: &ShoalApp) -> Vec<String> {
    let Some(out) = (0..2).find_map(|i| app.link.current(i)).map(|s| &s.output) else { return Vec::new() };
    match app.state.product {
        ProductKind::Substrate => super::raster::substrate_classes(out),
        ProductKind::SiopSet => out.retrievals.first().map(|r| r.product.siop_set_names.clone()).unwrap_or_default(),
        _ => Vec::new(),
    }
}
