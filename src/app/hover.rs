//! What the maps say under the cursor: the value of every panel at one ground point, and the
//! names of the classes a class map shows.

use egui::Pos2;

use super::ShoalApp;
use super::link::Standing;
use super::maps::format_value;
use super::model::ProductKind;
use super::raster::Role;

/// The run on display of design `i` (the configuration set's, or the previous one's meanwhile).
fn run_of(app: &ShoalApp, i: usize) -> Option<&crate::engine::RunOutput> {
    match app.link.standing(i) {
        Standing::Current(s) | Standing::Earlier(s) => Some(&s.output),
        _ => None,
    }
}

/// The value under the cursor in every panel, at one ground point — the hovered panel's pixel;
/// a panel on another design's grid reads its pixel nearest that point ("–" off its image). Rows
/// are drawn bottom-up. Class maps by class name, the difference of classes as agree or differ.
pub(super) fn hover_readout(app: &mut ShoalApp, ui: &mut egui::Ui, hovered: Option<(Pos2, usize)>) {
    let classes = class_names(app);
    if let Some((uv, d0)) = hovered {
        let mut parts = Vec::new();
        let cell_of = |(rows, cols): (usize, usize)| {
            let c = ((uv.x * cols as f32) as usize).min(cols.saturating_sub(1));
            let r = (((1.0 - uv.y) * rows as f32) as usize).min(rows.saturating_sub(1));
            (r, c)
        };
        // The cell and ground point under the cursor, on the hovered design's grid.
        let cell = run_of(app, d0).map(|o| cell_of((o.viewing.lines(), o.viewing.columns())));
        let ground = run_of(app, d0).zip(cell).map(|(o, (r, c))| o.viewing.ground_m(0, r, c));
        for (panel, _) in &app.images.panels {
            let d = match panel.role {
                Role::Truth(i) | Role::Design(i) | Role::Difference(i, _) => i,
            };
            let at = match (d == d0, ground, run_of(app, d)) {
                (true, _, _) | (_, None, _) => Some(cell_of(panel.data.values.dim())),
                (false, Some((x, y)), Some(o)) => o.viewing.nearest_pixel(x, y, o.config.instrument.heading_deg),
                (false, Some(_), None) => None,
            };
            let Some((r, c)) = at.filter(|&(r, c)| r < panel.data.values.nrows() && c < panel.data.values.ncols())
            else {
                parts.push(format!("{}: –", panel.title));
                continue;
            };
            let value = panel.data.values[[r, c]];
            let text = if !panel.data.valid[[r, c]] {
                "–".into()
            } else if app.state.product.categorical() && !matches!(panel.role, Role::Difference(..)) {
                // A class map holds the class index: show its name.
                classes
                    .get(value.max(0.0) as usize)
                    .map_or_else(|| format_value(f64::from(value)), |n| n.replace('_', " "))
            } else if matches!(panel.role, Role::Difference(..)) && app.state.product.categorical() {
                if value > 0.5 { "differ".into() } else { "agree".into() }
            } else {
                format_value(f64::from(value))
            };
            parts.push(format!("{}: {text}", panel.title));
        }
        app.ui.hover = cell;
        if let Some((r, c)) = cell {
            let point = ground.map_or_else(String::new, |(x, y)| format!(" ({x:.0}, {y:.0}) m"));
            ui.label(format!("{} row {r}, column {c}{point}   {}", super::model::label(d0), parts.join("   ")));
        }
    } else {
        ui.label("Drag to pan, scroll to zoom (the maps move together); click for the spectrum there.");
        // The app keeps every n-th pixel of the cubes (`engine::views`): say so on their maps.
        let cube = matches!(app.state.product, ProductKind::Rrs | ProductKind::Level1 | ProductKind::Snr);
        let strides = app.link.shown.iter().flatten().filter_map(|s| s.output.views.as_ref()).map(|v| v.stride);
        if let Some(n) = strides.max().filter(|&n| cube && n > 1) {
            ui.small(format!(
                "Cube maps keep one pixel in {n} × {n} at most, drawn over its block, so eight designs fit \
                 a laptop's memory; products are at full resolution."
            ));
        }
    }
}

/// The names of the shown product's classes, in colour order (substrates or SIOP sets).
pub(super) fn class_names(app: &ShoalApp) -> Vec<String> {
    let Some(out) = (0..app.state.designs.len()).find_map(|i| app.link.current(i)).map(|s| &s.output) else {
        return Vec::new();
    };
    match app.state.product {
        ProductKind::Substrate => super::raster::substrate_classes(out),
        ProductKind::SiopSet => out.retrievals.first().map(|r| r.product.siop_set_names.clone()).unwrap_or_default(),
        _ => Vec::new(),
    }
}
