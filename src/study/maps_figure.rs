//! The study figures' map panels: truth and retrieved maps side by side on one colour scale
//! (linear, logarithmic or diverging about zero), each with a scale bar, and a colour bar.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::render::{Draw, FONT, Panel, Placed, colour, err, raster, scale_bar_length, tick_label};
use crate::colormap::Scale;

/// Maps side by side on one colour scale, with a colour bar labelled `label`.
pub(super) struct Maps {
    pub(super) title: String,
    pub(super) label: String,
    pub(super) scale: Scale,
    pub(super) panels: Vec<Panel>,
    pub(super) diverging: bool,
    /// Width and height of each map's panel, px ([`PANEL`] in the study figures).
    pub(super) panel: (u32, u32),
}

/// Panel size of the study figures' maps, px.
pub(super) const PANEL: (u32, u32) = (300, 340);
const BAR_W: u32 = 110;
pub(super) const TITLE_H: u32 = 34;
const CAPTION_H: u32 = 26;

impl Draw for Maps {
    fn size(&self) -> (u32, u32) {
        (self.panel.0 * self.panels.len() as u32 + BAR_W, TITLE_H + self.panel.1 + CAPTION_H)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        root.draw_text(&self.title, &(FONT, 17).into_font().color(&BLACK), (10, 8)).map_err(err)?;
        let mut placed = Vec::new();
        for (i, p) in self.panels.iter().enumerate() {
            let x0 = (i as u32 * self.panel.0) as i32;
            let y0 = TITLE_H as i32;
            root.draw_text(&p.title, &(FONT, 13).into_font().color(&BLACK), (x0 + 10, y0 + 4)).map_err(err)?;
            // Fit the map in the panel, keeping its aspect ratio.
            let (rows, cols) = p.values.dim();
            // Room under the map for the scale bar.
            let (bw, bh) = (self.panel.0 - 20, self.panel.1 - 56);
            let aspect = cols as f64 / rows.max(1) as f64;
            let (w, h) = if aspect >= f64::from(bw) / f64::from(bh) {
                (bw, ((f64::from(bw) / aspect).round() as u32).max(1))
            } else {
                (((f64::from(bh) * aspect).round() as u32).max(1), bh)
            };
            let (mx, my) = (x0 + 10 + ((bw - w) / 2) as i32, y0 + 26);
            root.draw(&Rectangle::new([(mx - 1, my - 1), (mx + w as i32, my + h as i32)], BLACK.stroke_width(1)))
                .map_err(err)?;
            placed.push(Placed { x: mx, y: my, w, h, rgb: raster(p, &self.scale, w, h, self.diverging) });
            // Scale bar under the map (the map raster is painted over whatever is drawn on it).
            if let Some((len_m, label)) = scale_bar_length(0.3 * cols as f64 * p.spacing_m) {
                let px = (len_m / (cols as f64 * p.spacing_m) * f64::from(w)).round() as i32;
                let (bx, by) = (mx, my + h as i32 + 8);
                root.draw(&Rectangle::new([(bx, by), (bx + px, by + 3)], BLACK.filled())).map_err(err)?;
                root.draw_text(&label, &(FONT, 11).into_font().color(&BLACK), (bx + px + 6, by - 3)).map_err(err)?;
            }
        }
        // Colour bar.
        let bx = (self.panels.len() as u32 * self.panel.0) as i32 + 12;
        let (by0, by1) = (TITLE_H as i32 + 26, (TITLE_H + self.panel.1) as i32 - 12);
        let steps = 120;
        for k in 0..steps {
            let t0 = k as f64 / steps as f64;
            let ya = by1 - ((by1 - by0) as f64 * (k + 1) as f64 / steps as f64).round() as i32;
            let yb = by1 - ((by1 - by0) as f64 * t0).round() as i32;
            let c = colour(t0 + 0.5 / steps as f64, self.diverging);
            root.draw(&Rectangle::new([(bx, ya), (bx + 18, yb)], RGBColor(c[0], c[1], c[2]).filled())).map_err(err)?;
        }
        root.draw(&Rectangle::new([(bx, by0), (bx + 18, by1)], BLACK.stroke_width(1))).map_err(err)?;
        for v in self.scale.nice_ticks() {
            let t = self.scale.position(v);
            let y = by1 - ((by1 - by0) as f64 * t).round() as i32;
            root.draw(&PathElement::new(vec![(bx + 18, y), (bx + 23, y)], BLACK)).map_err(err)?;
            root.draw_text(&tick_label(v), &(FONT, 11).into_font().color(&BLACK), (bx + 26, y - 6)).map_err(err)?;
        }
        root.draw_text(&self.label, &(FONT, 12).into_font().color(&BLACK), (bx - 4, TITLE_H as i32 + 6))
            .map_err(err)?;
        let caption = format!(
            "One colour scale for every panel ({}); grey: land, or not returned; flight direction up.",
            if self.scale.log { "logarithmic" } else { "linear" }
        );
        root.draw_text(
            &caption,
            &(FONT, 12).into_font().color(&RGBColor(60, 60, 60)),
            (10, (TITLE_H + self.panel.1) as i32 + 6),
        )
        .map_err(err)?;
        Ok(placed)
    }
}
