//! The comparison figure the app exports for a design review: maps side by side on one scale,
//! a metrics table and caption lines.

use ndarray::Array2;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::StudyError;
use super::figures::{Maps, Panel};
use super::render::{Draw, FONT, Figure, Placed, err, render};
use crate::colormap::Scale;

/// A map of a comparison figure.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonPanel {
    /// Title above the map.
    pub title: String,
    /// Values.
    pub values: Array2<f32>,
    /// Where values are valid (elsewhere grey).
    pub valid: Array2<bool>,
}

/// A comparison figure: maps side by side on one scale, then a table and a caption.
struct Comparison {
    maps: Maps,
    table: Vec<Vec<String>>,
    caption: Vec<String>,
}

const ROW_H: u32 = 18;

impl Draw for Comparison {
    fn size(&self) -> (u32, u32) {
        let (w, h) = self.maps.size();
        (w.max(760), h + ROW_H * (self.table.len() as u32 + 1) + 16 * self.caption.len() as u32 + 12)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        let placed = self.maps.draw(root)?;
        let (_, maps_h) = self.maps.size();
        let columns = self.table.first().map_or(0, Vec::len);
        let widths: Vec<i32> = (0..columns)
            .map(|c| {
                self.table.iter().map(|row| row.get(c).map_or(0, |s| s.chars().count())).max().unwrap_or(0) as i32 * 8
                    + 18
            })
            .collect();
        for (r, row) in self.table.iter().enumerate() {
            let y = (maps_h + 6 + ROW_H * r as u32) as i32;
            let mut x = 10;
            let style = if r == 0 {
                (FONT, 12).into_font().color(&BLACK)
            } else {
                (FONT, 12).into_font().color(&RGBColor(30, 30, 30))
            };
            for (c, cell) in row.iter().enumerate() {
                root.draw_text(cell, &style, (x, y)).map_err(err)?;
                x += widths.get(c).copied().unwrap_or(80);
            }
            if r == 0 {
                let line_y = y + ROW_H as i32 - 3;
                root.draw(&PathElement::new(vec![(10, line_y), (x, line_y)], BLACK)).map_err(err)?;
            }
        }
        let table_end = maps_h + ROW_H * (self.table.len() as u32 + 1);
        for (i, line) in self.caption.iter().enumerate() {
            let y = (table_end + 4 + 16 * i as u32) as i32;
            root.draw_text(line, &(FONT, 11).into_font().color(&RGBColor(60, 60, 60)), (10, y)).map_err(err)?;
        }
        Ok(placed)
    }
}

/// A comparison figure (PNG and SVG): `panels` side by side on one `scale` (viridis, or the
/// diverging palette for differences) with a colour bar labelled `label`, a table (first row the
/// header) and caption lines — what the app exports for a design review.
#[allow(clippy::too_many_arguments)]
pub fn comparison_figure(
    name: &str,
    title: &str,
    label: &str,
    scale: Scale,
    diverging: bool,
    panels: Vec<ComparisonPanel>,
    table: Vec<Vec<String>>,
    caption: Vec<String>,
) -> Result<Figure, StudyError> {
    let panels = panels.into_iter().map(|p| Panel { title: p.title, values: p.values, valid: p.valid }).collect();
    let maps = Maps { title: title.into(), label: label.into(), scale, panels, diverging };
    render(name, &Comparison { maps, table, caption })
}
