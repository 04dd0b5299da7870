//! The review slide the app exports for a design review: one 1920 × 1080 page (PNG and SVG)
//! carrying the comparison whole — truth, A and B maps on one colour scale with its bar, the SNR
//! per band against the requirement, retrieved against true values, the verdict table, the
//! parameters that differ between A and B, and a caption naming presets, scene and retrieval.
//! Text sizes are chosen for a projector (table 16 px, title 30 px at 1920 px wide).

use ndarray::Array2;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::StudyError;
use super::figures::Maps;
use super::render::{Draw, FONT, Figure, Panel, Placed, err, render};
use crate::colormap::Scale;

/// A map of the slide.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonPanel {
    /// Title above the map.
    pub title: String,
    /// Values.
    pub values: Array2<f32>,
    /// Where values are valid (elsewhere grey).
    pub valid: Array2<bool>,
}

/// Slide size, px.
pub const SLIDE: (u32, u32) = (1920, 1080);

/// A named set of points of one colour (a line of the SNR plot, a cloud of the scatter).
#[derive(Debug, Clone, PartialEq)]
pub struct SlideSeries {
    /// Legend name ("A: cubesat").
    pub name: String,
    /// Colour, RGB.
    pub colour: [u8; 3],
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
}

/// Everything on the slide.
#[derive(Debug, Clone, PartialEq)]
pub struct ReviewSlide {
    /// Title ("Lake Hume bloom — chl-a").
    pub title: String,
    /// Caption lines under everything.
    pub caption: Vec<String>,
    /// Colour-bar label ("chl-a (mg m⁻³)").
    pub label: String,
    /// The maps' shared scale.
    pub scale: Scale,
    /// Diverging palette (differences) rather than viridis.
    pub diverging: bool,
    /// Maps, left to right.
    pub panels: Vec<ComparisonPanel>,
    /// SNR per band, one series per instrument (x: band centre, nm).
    pub snr: Vec<SlideSeries>,
    /// The SNR requirement, if the study states one.
    pub snr_requirement: Option<f64>,
    /// Retrieved against true values, log10, one series per instrument.
    pub scatter: Vec<SlideSeries>,
    /// The scatter's axis title ("chl-a (mg m⁻³)").
    pub scatter_label: String,
    /// Verdict table, first row the header.
    pub verdicts: Vec<Vec<String>>,
    /// Parameters that differ between A and B, first row the header.
    pub parameters: Vec<Vec<String>>,
}

const MARGIN: i32 = 24;
const MAPS_TOP: i32 = 64;
const MAPS_H: u32 = 620;
const MAPS_W: u32 = 1230;
const PLOTS_X: i32 = 1270;

fn text_style(size: u32, colour: RGBColor) -> TextStyle<'static> {
    (FONT, size).into_font().color(&colour)
}

/// The largest font size (11–16 px) at which `rows` fit `max_width` and, a row being the size
/// plus 8 px, `max_height`; `None` when none does (the table is then cut at 11 px).
fn table_fit(rows: &[Vec<String>], (max_width, max_height): (i32, i32)) -> Option<i32> {
    (11..=16)
        .rev()
        .find(|&s| table_widths(rows, s).iter().sum::<i32>() <= max_width && rows.len() as i32 * (s + 8) <= max_height)
}

/// Column widths of `rows` at font size `size`: DejaVu Sans is about 0.56 em per character, plus
/// a gap between columns.
fn table_widths(rows: &[Vec<String>], size: i32) -> Vec<i32> {
    let columns = rows.first().map_or(0, Vec::len);
    (0..columns)
        .map(|c| {
            let chars = rows.iter().map(|r| r.get(c).map_or(0, |s| s.chars().count())).max().unwrap_or(0);
            (chars as f64 * 0.5625 * f64::from(size)).ceil() as i32 + size + 6
        })
        .collect()
}

/// A table at (x, y) within `room` (width, height), first row bold-ruled; columns as wide as
/// their longest cell. The font shrinks from 16 px to 11 px until the table fits
/// ([`table_fit`]); rows and columns that still do not are left out and the last line says how
/// many (eight designs' parameters ran off the slide). Returns the height drawn.
fn table<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Vec<String>],
    (x, y): (i32, i32),
    (max_width, max_height): (i32, i32),
) -> Result<i32, String> {
    let columns = rows.first().map_or(0, Vec::len);
    let size = table_fit(rows, (max_width, max_height)).unwrap_or(11);
    let widths = table_widths(rows, size);
    // The columns that fit (always the first, the row names).
    let mut shown = 0;
    let mut used = 0;
    for w in &widths {
        if shown > 0 && used + w > max_width {
            break;
        }
        used += w;
        shown += 1;
    }
    let row_h = size + 8;
    let size = u32::try_from(size).unwrap_or(16);
    // The rows that fit, one line kept for the note when some do not.
    let fit = usize::try_from(max_height / row_h).unwrap_or(1).max(2);
    let rows_fit = if rows.len() > fit { fit - 1 } else { rows.len() };
    for (r, row) in rows.iter().take(rows_fit).enumerate() {
        let ty = y + row_h * r as i32;
        let mut tx = x;
        for (c, cell) in row.iter().take(shown).enumerate() {
            // A verdict alone ("pass", "FAIL: …") or at the end of a value ("10.6 / +5.5 pass").
            let colour = match cell.as_str() {
                s if s.starts_with("FAIL") || s.ends_with(" FAIL") => RGBColor(190, 30, 30),
                // A pass under a plausibility warning, amber as in the app.
                s if s == "pass?" || s.ends_with(" pass?") => RGBColor(180, 110, 0),
                s if s == "pass" || s.ends_with(" pass") => RGBColor(30, 130, 30),
                _ => RGBColor(25, 25, 25),
            };
            root.draw_text(cell, &text_style(size, colour), (tx, ty)).map_err(err)?;
            tx += widths.get(c).copied().unwrap_or(90);
        }
        if r == 0 {
            let ly = ty + row_h - 4;
            root.draw(&PathElement::new(vec![(x, ly), (tx, ly)], BLACK)).map_err(err)?;
        }
    }
    let mut notes = Vec::new();
    if rows.len() > rows_fit {
        notes.push(format!("{} more rows", rows.len() - rows_fit));
    }
    if shown < columns {
        notes.push(format!("{} more columns", columns - shown));
    }
    let mut height = row_h * rows_fit as i32;
    if !notes.is_empty() {
        let more = format!("… {} in the review pack", notes.join(" and "));
        root.draw_text(&more, &text_style(14, RGBColor(90, 90, 90)), (x, y + height)).map_err(err)?;
        height += row_h;
    }
    Ok(height)
}

/// An x–y chart of `series` in `area` (lines for the SNR, dots for the scatter).
fn chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[SlideSeries],
    lines: bool,
    extra: Option<(f64, &str)>,
) -> Result<(), String> {
    let all = series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = all
        .fold((f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY), |(a, b, c, d), &(x, y)| {
            (a.min(x), b.max(x), c.min(y), d.max(y))
        });
    if let Some((level, _)) = extra {
        (y0, y1) = (y0.min(level), y1.max(level));
    }
    if !(x0.is_finite() && x1 > x0 && y0.is_finite() && y1 > y0) {
        area.draw_text(&format!("{title}: no data"), &text_style(16, BLACK), (10, 10)).map_err(err)?;
        return Ok(());
    }
    if lines {
        // SNR from zero, so that a halved SNR looks halved.
        y0 = y0.min(0.0);
    } else {
        // The scatter on one square range, so the 1:1 line is the diagonal.
        (x0, x1) = (x0.min(y0), x1.max(y1));
        (y0, y1) = (x0, x1);
    }
    let pad = |a: f64, b: f64| 0.04 * (b - a);
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    let mut ctx = ChartBuilder::on(area)
        .caption(title, text_style(18, BLACK))
        .margin(8)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d((x0 - px)..(x1 + px), (y0 - py)..(y1 + py))
        .map_err(err)?;
    let tick = |v: &f64| crate::colormap::significant(*v, 4);
    ctx.configure_mesh()
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style(text_style(14, BLACK))
        .axis_desc_style(text_style(15, BLACK))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    for s in series {
        let colour = RGBColor(s.colour[0], s.colour[1], s.colour[2]);
        if lines {
            ctx.draw_series(LineSeries::new(s.points.iter().copied(), colour.stroke_width(2)))
                .map_err(err)?
                .label(&s.name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            ctx.draw_series(s.points.iter().map(|&p| Circle::new(p, 3, colour.filled()))).map_err(err)?;
        } else {
            ctx.draw_series(s.points.iter().map(|&p| Circle::new(p, 1, colour.mix(0.5).filled())))
                .map_err(err)?
                .label(&s.name)
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
        }
    }
    if let Some((level, name)) = extra {
        let green = RGBColor(30, 130, 30);
        ctx.draw_series(LineSeries::new(vec![(x0 - px, level), (x1 + px, level)], green.stroke_width(2)))
            .map_err(err)?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], green.stroke_width(2)));
    }
    if !lines {
        let grey = RGBColor(80, 80, 80);
        ctx.draw_series(LineSeries::new(vec![(x0, x0), (x1, x1)], grey.stroke_width(1)))
            .map_err(err)?
            .label("1:1")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], grey));
    }
    // The legend outside the data: in the upper left for the SNR (which falls to the NIR), lower
    // right for the scatter (whose cloud follows the diagonal).
    ctx.configure_series_labels()
        .position(if lines { SeriesLabelPosition::UpperRight } else { SeriesLabelPosition::LowerRight })
        .label_font(text_style(14, BLACK))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(200, 200, 200))
        .draw()
        .map_err(err)?;
    Ok(())
}

impl Draw for ReviewSlide {
    fn size(&self) -> (u32, u32) {
        SLIDE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        // The title at 30 px, smaller where it would run off the slide (eight designs' names).
        let room = 1920 - 2 * MARGIN;
        let fits = |size: u32| {
            root.estimate_text_size(&self.title, &text_style(size, BLACK)).is_ok_and(|(w, _)| w as i32 <= room)
        };
        let size = (16..=30).rev().find(|&s| fits(s)).unwrap_or(16);
        let title = if fits(size) {
            self.title.clone()
        } else {
            let keep = (f64::from(room) / (0.56 * f64::from(size))) as usize;
            format!("{}…", self.title.chars().take(keep.saturating_sub(1)).collect::<String>())
        };
        root.draw_text(&title, &text_style(size, BLACK), (MARGIN, 16 + (30 - size as i32) / 2)).map_err(err)?;
        // The maps, on the study figures' renderer at slide size: in one row, as tall as their
        // aspect needs at that width (at most MAPS_H), so many designs' narrow maps leave their
        // room below to the tables.
        let n = self.panels.len().max(1) as u32;
        let panel_w = (MAPS_W - 110) / n;
        let aspect = self.panels.first().map_or(1.0, |p| p.values.ncols() as f64 / p.values.nrows().max(1) as f64);
        let panel_h = ((f64::from(panel_w.saturating_sub(20)) / aspect.max(1e-3)).ceil() as u32 + 56).min(MAPS_H - 60);
        let maps = Maps {
            title: String::new(),
            label: self.label.clone(),
            scale: self.scale,
            panels: self
                .panels
                .iter()
                .map(|p| Panel {
                    title: p.title.clone(),
                    values: p.values.clone(),
                    valid: p.valid.clone(),
                    spacing_m: 0.0,
                })
                .collect(),
            diverging: self.diverging,
            panel: (panel_w, panel_h),
        };
        let (mw, mh) = maps.size();
        let area = root.clone().shrink((MARGIN / 2, MAPS_TOP), (mw, mh));
        let mut placed = maps.draw(&area)?;
        for p in &mut placed {
            p.x += MARGIN / 2;
            p.y += MAPS_TOP;
        }
        // SNR and scatter down the right-hand side.
        let snr_area = root.clone().shrink((PLOTS_X, MAPS_TOP), (1920 - PLOTS_X as u32 - 16, 310));
        let requirement = self.snr_requirement.map(|v| (v, "requirement"));
        chart(&snr_area, "SNR per band", ("band centre (nm)", "SNR"), &self.snr, true, requirement)?;
        let scatter_area = root.clone().shrink((PLOTS_X, MAPS_TOP + 325), (1920 - PLOTS_X as u32 - 16, 300));
        let x = format!("log10 true {}", self.scatter_label);
        let y = format!("log10 retrieved {}", self.scatter_label);
        chart(&scatter_area, "Retrieved against true", (&x, &y), &self.scatter, false, None)?;
        // The verdicts under the maps, the parameters under the charts; both above the caption.
        let caption_y = 1080 - 24 * self.caption.len() as i32 - 10;
        let left_w = PLOTS_X - MARGIN - 16;
        let right_w = 1920 - PLOTS_X - 16;
        let table_y = (MAPS_TOP + mh as i32 + 24).max(MAPS_TOP + 280);
        let charts_end = MAPS_TOP + MAPS_H as i32 + 24;
        root.draw_text("Verdicts", &text_style(20, BLACK), (MARGIN, table_y)).map_err(err)?;
        // The parameters beside the verdicts, under the charts, when they fit there; else under
        // the verdicts on the left's full width, both tables at one font that fits them together.
        let right_fits = table_fit(&self.parameters, (right_w, caption_y - charts_end - 30)).is_some();
        let left_h = caption_y - table_y - 30;
        let verdict_h = if right_fits {
            left_h
        } else {
            let rows = (self.verdicts.len() + self.parameters.len()) as i32;
            let size = ((left_h - 50) / rows.max(1) - 8).clamp(11, 16);
            self.verdicts.len() as i32 * (size + 8)
        };
        let drawn = table(root, &self.verdicts, (MARGIN, table_y + 30), (left_w, verdict_h))?;
        let below_y = table_y + 30 + drawn + 20;
        let (px, py, room) = if right_fits {
            (PLOTS_X, charts_end, (right_w, caption_y - charts_end - 30))
        } else {
            (MARGIN, below_y, (left_w, caption_y - below_y - 30))
        };
        // "A and B differ in" for a pair; with more designs, against the first column's.
        let names: Vec<&str> =
            self.parameters.first().map(|h| h.iter().skip(1).map(String::as_str).collect()).unwrap_or_default();
        let heading = match names.as_slice() {
            [a, b] => format!("{a} and {b} differ in"),
            [a, ..] => format!("The designs against {a}"),
            [] => "Parameters".to_string(),
        };
        root.draw_text(&heading, &text_style(20, BLACK), (px, py)).map_err(err)?;
        table(root, &self.parameters, (px, py + 30), room)?;
        for (i, line) in self.caption.iter().enumerate() {
            root.draw_text(line, &text_style(15, RGBColor(60, 60, 60)), (MARGIN, caption_y + 24 * i as i32))
                .map_err(err)?;
        }
        Ok(placed)
    }
}

/// Render `slide` as PNG and SVG (1920 × 1080).
pub fn review_slide(name: &str, slide: &ReviewSlide) -> Result<Figure, StudyError> {
    render(name, slide)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slide_is_1920_by_1080_with_every_part_named() {
        let values = Array2::from_shape_fn((60, 40), |(r, c)| 1.0 + (r + c) as f32 / 10.0);
        let valid = Array2::from_elem((60, 40), true);
        let panel = |t: &str| ComparisonPanel { title: t.into(), values: values.clone(), valid: valid.clone() };
        let series = |name: &str, k: f64| SlideSeries {
            name: name.into(),
            colour: [200, 30, 30],
            points: (0..8).map(|i| (400.0 + 60.0 * f64::from(i), k * (300.0 - 20.0 * f64::from(i)))).collect(),
        };
        let slide = ReviewSlide {
            title: "Lake Hume bloom — chl-a".into(),
            caption: vec!["A: cubesat   B: smallsat".into()],
            label: "chl-a (mg m⁻³)".into(),
            scale: Scale { lo: 1.0, hi: 8.0, log: true },
            diverging: false,
            panels: vec![panel("truth"), panel("A"), panel("B")],
            snr: vec![series("A: cubesat", 0.3), series("B: smallsat", 1.0)],
            snr_requirement: Some(100.0),
            scatter: vec![SlideSeries {
                name: "A".into(),
                colour: [30, 30, 200],
                points: vec![(0.0, 0.1), (1.0, 0.9)],
            }],
            scatter_label: "chl-a (mg m⁻³)".into(),
            verdicts: vec![vec!["product".into(), "A".into()], vec!["chl-a".into(), "FAIL: MAE".into()]],
            parameters: vec![
                vec!["parameter".into(), "A".into(), "B".into()],
                vec!["aperture".into(), "60 mm".into(), "240 mm".into()],
            ],
        };
        let fig = review_slide("slide", &slide).unwrap();
        let png = image::load_from_memory(&fig.png).unwrap();
        assert_eq!((png.width(), png.height()), SLIDE);
        for part in ["SNR per band", "Retrieved against true", "Verdicts", "A and B differ in", "requirement", "60 mm"]
        {
            assert!(fig.svg.contains(part), "the slide has no `{part}`");
        }
        assert_eq!(fig.svg.matches("<image").count(), 3, "three maps embedded");
    }
}
