//! Curve figures: a metric against a swept parameter, one line per series (instrument, or the
//! second parameter's value) with the Monte Carlo spread as a band, the requirement as a
//! horizontal line and the point where each series first meets it.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::StudyError;
use super::render::{Draw, FONT, Figure, Placed, err, render, tick_label};
use crate::colormap::categorical;

/// One point of a series: the parameter, the seeds' mean, and their minimum and maximum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// Parameter value.
    pub x: f64,
    /// Mean over seeds.
    pub mean: f64,
    /// Lowest over seeds.
    pub lo: f64,
    /// Highest over seeds.
    pub hi: f64,
}

/// One line.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSeries {
    /// Legend text.
    pub label: String,
    /// Points in increasing x.
    pub points: Vec<CurvePoint>,
    /// Where the mean first meets the requirement (interpolated), if it does.
    pub crossing: Option<f64>,
}

/// What a curve figure shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Curves {
    /// Figure title.
    pub title: String,
    /// x-axis text.
    pub x_label: String,
    /// y-axis text.
    pub y_label: String,
    /// Log x axis.
    pub log_x: bool,
    /// The lines.
    pub series: Vec<CurveSeries>,
    /// The requirement's value and text.
    pub requirement: Option<(f64, String)>,
    /// Lines under the plot.
    pub caption: Vec<String>,
}

/// Where a series' mean first reaches `limit` or below, interpolated linearly between the last
/// point above and the first at or below; `None` if it never does.
#[must_use]
pub fn first_crossing(points: &[CurvePoint], limit: f64) -> Option<f64> {
    let first = points.iter().position(|p| p.mean <= limit)?;
    if first == 0 {
        return Some(points[0].x);
    }
    let (a, b) = (points[first - 1], points[first]);
    let t = (a.mean - limit) / (a.mean - b.mean);
    Some(a.x + t * (b.x - a.x))
}

impl Draw for Curves {
    fn size(&self) -> (u32, u32) {
        (900, 560 + 18 * self.caption.len() as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        let caption_h = 18 * self.caption.len() as u32 + 8;
        let (plot, bottom) = root.split_vertically(self.size().1 - caption_h);
        let points = self.series.iter().flat_map(|s| s.points.iter());
        let (mut x0, mut x1) =
            points.clone().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.x), b.max(p.x)));
        let mut y1 = points.fold(0.0f64, |m, p| m.max(p.hi));
        if let Some((r, _)) = self.requirement {
            y1 = y1.max(r);
        }
        if !(x0.is_finite() && x1.is_finite()) {
            return Err("no points to draw".into());
        }
        if x1 <= x0 {
            x1 = x0 + 1.0;
        }
        if self.log_x && x0 <= 0.0 {
            x0 = x1 / 100.0;
        }
        let y1 = (y1 * 1.1).max(1.0);
        let mut builder = ChartBuilder::on(&plot);
        builder.caption(&self.title, (FONT, 17)).margin(14).x_label_area_size(40).y_label_area_size(60);
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(self.x_label.clone())
                    .y_desc(self.y_label.clone())
                    .x_label_formatter(&|v| tick_label(*v))
                    .y_label_formatter(&|v| format!("{v:.0}"))
                    .label_style((FONT, 12))
                    .axis_desc_style((FONT, 13))
                    .light_line_style(RGBColor(235, 235, 235))
                    .draw()
                    .map_err(err)?;
                for (k, s) in self.series.iter().enumerate() {
                    let c = categorical(k);
                    let colour = RGBColor(c[0], c[1], c[2]);
                    let mut band: Vec<(f64, f64)> = s.points.iter().map(|p| (p.x, p.hi)).collect();
                    band.extend(s.points.iter().rev().map(|p| (p.x, p.lo)));
                    chart.draw_series(std::iter::once(Polygon::new(band, colour.mix(0.18)))).map_err(err)?;
                    chart
                        .draw_series(LineSeries::new(s.points.iter().map(|p| (p.x, p.mean)), colour.stroke_width(2)))
                        .map_err(err)?
                        .label(s.label.clone())
                        .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
                    chart
                        .draw_series(s.points.iter().map(|p| Circle::new((p.x, p.mean), 3, colour.filled())))
                        .map_err(err)?;
                    if let (Some(x), Some((r, _))) = (s.crossing, &self.requirement) {
                        let r = *r;
                        chart
                            .draw_series(std::iter::once(Circle::new((x, r), 7, colour.stroke_width(2))))
                            .map_err(err)?;
                        chart
                            .draw_series(std::iter::once(Text::new(
                                format!("{} at {}", s.label, tick_label(x)),
                                (x, r * 1.04),
                                (FONT, 12).into_font().color(&colour),
                            )))
                            .map_err(err)?;
                    }
                }
                if let Some((r, text)) = &self.requirement {
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            [(x0, *r), (x1, *r)],
                            RGBColor(40, 150, 40).stroke_width(2),
                        )))
                        .map_err(err)?
                        .label(text.clone())
                        .legend(|(x, y)| {
                            PathElement::new([(x, y), (x + 18, y)], RGBColor(40, 150, 40).stroke_width(2))
                        });
                }
                chart
                    .configure_series_labels()
                    .label_font((FONT, 12))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .position(SeriesLabelPosition::UpperRight)
                    .draw()
                    .map_err(err)?;
            }};
        }
        if self.log_x {
            body!(builder.build_cartesian_2d((x0..x1).log_scale(), 0.0..y1).map_err(err)?);
        } else {
            body!(builder.build_cartesian_2d(x0..x1, 0.0..y1).map_err(err)?);
        }
        for (i, line) in self.caption.iter().enumerate() {
            bottom.draw_text(line, &(FONT, 12).into_font().color(&BLACK), (14, 4 + 18 * i as i32)).map_err(err)?;
        }
        Ok(Vec::new())
    }
}

/// Draw `curves` as PNG and SVG.
pub fn curve_figure(name: &str, curves: &Curves) -> Result<Figure, StudyError> {
    render(name, curves)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, mean: f64) -> CurvePoint {
        CurvePoint { x, mean, lo: mean, hi: mean }
    }

    #[test]
    fn crossing_interpolates_between_the_last_fail_and_the_first_pass() {
        let pts = [p(40.0, 60.0), p(80.0, 30.0), p(160.0, 10.0)];
        assert_eq!(first_crossing(&pts, 20.0), Some(120.0));
        assert_eq!(first_crossing(&pts, 70.0), Some(40.0));
        assert_eq!(first_crossing(&pts, 5.0), None);
    }
}
