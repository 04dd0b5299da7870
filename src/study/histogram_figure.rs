//! The study figures' histograms: per design, its retrieved values' distribution (stacked by the
//! class each pixel chose) against the truth's, as shares of the design's own water pixels, four
//! designs to a row.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::maps_figure::TITLE_H;
use super::render::{Draw, FONT, Placed, err, tick_label};
use crate::colormap::categorical;

/// One figure of histograms, a panel per design.
pub(super) struct Histograms {
    pub(super) title: String,
    pub(super) label: String,
    pub(super) edges: Vec<f64>,
    pub(super) categories: Vec<String>,
    /// Per panel: title, counts[category][bin], truth counts[bin].
    pub(super) panels: Vec<(String, Vec<Vec<usize>>, Vec<usize>)>,
    /// Per panel, the run's water pixels: what its bars are shares of (the bins hold only the
    /// values inside the plotted range).
    pub(super) water: Vec<usize>,
}

/// The factor on the tallest bar that leaves room above it for a legend of `entries` lines, so
/// the legend (top right, 19 px a line at 14 px text) covers no data in a ~390 px plot.
fn legend_headroom(entries: usize) -> f64 {
    let legend_px = 19.0 * entries as f64 + 24.0;
    1.0 / (1.0 - (legend_px / 390.0).min(0.65))
}

/// Histogram panels per row: eight designs in one row made a 4160-pixel figure.
const HIST_COLUMNS: usize = 4;

impl Histograms {
    /// Columns and rows of the panels' grid.
    fn grid(&self) -> (usize, usize) {
        let n = self.panels.len().max(1);
        let cols = n.min(HIST_COLUMNS);
        (cols, n.div_ceil(cols))
    }
}

impl Draw for Histograms {
    fn size(&self) -> (u32, u32) {
        let (cols, rows) = self.grid();
        (520 * cols as u32, 500 + (rows as u32 - 1) * (500 - TITLE_H))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        let (top, rest) = root.split_vertically(TITLE_H);
        top.draw_text(&self.title, &(FONT, 17).into_font().color(&BLACK), (10, 8)).map_err(err)?;
        let (lo, hi) = (self.edges[0], self.edges[self.edges.len() - 1]);
        let nb = self.edges.len() - 1;
        // Shares of each run's own water pixels, so a 10 m imager's millions of pixels do not
        // flatten a 300 m one's bars; one axis for all panels.
        let water = |k: usize| self.water.get(k).copied().unwrap_or(0).max(1) as f64;
        let ymax = self
            .panels
            .iter()
            .enumerate()
            .map(|(k, (_, c, t))| {
                (0..nb)
                    .map(|b| 100.0 * c.iter().map(|row| row[b]).sum::<usize>().max(t[b]) as f64 / water(k))
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
            .max(1e-9)
            * legend_headroom(self.panels.iter().map(|(_, c, _)| c.len()).max().unwrap_or(0) + 1);
        let (cols, rows) = self.grid();
        for (k, (area, (title, counts, truth))) in rest.split_evenly((rows, cols)).iter().zip(&self.panels).enumerate()
        {
            let pct = |n: usize| 100.0 * n as f64 / water(k);
            let mut chart = ChartBuilder::on(area)
                .caption(title, (FONT, 16))
                .margin(8)
                .x_label_area_size(44)
                .y_label_area_size(70)
                .build_cartesian_2d((lo..hi).log_scale(), 0.0..ymax)
                .map_err(err)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(self.label.clone())
                .y_desc("% of water pixels")
                .x_label_formatter(&|v| tick_label(*v))
                .y_label_formatter(&|v| crate::colormap::significant(*v, 3))
                .label_style((FONT, 14))
                .axis_desc_style((FONT, 15))
                .draw()
                .map_err(err)?;
            let mut base = vec![0usize; nb];
            for (k, row) in counts.iter().enumerate() {
                if row.iter().all(|&n| n == 0) {
                    continue;
                }
                let c = categorical(k);
                let colour = RGBColor(c[0], c[1], c[2]);
                let bars: Vec<_> = (0..nb)
                    .filter(|&b| row[b] > 0)
                    .map(|b| {
                        Rectangle::new(
                            [(self.edges[b], pct(base[b])), (self.edges[b + 1], pct(base[b] + row[b]))],
                            colour.filled(),
                        )
                    })
                    .collect();
                chart
                    .draw_series(bars)
                    .map_err(err)?
                    .label(self.categories.get(k).cloned().unwrap_or_default())
                    .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 10, y + 5)], colour.filled()));
                for b in 0..nb {
                    base[b] += row[b];
                }
            }
            let outline: Vec<(f64, f64)> =
                (0..nb).flat_map(|b| [(self.edges[b], pct(truth[b])), (self.edges[b + 1], pct(truth[b]))]).collect();
            chart
                .draw_series(LineSeries::new(outline, BLACK.stroke_width(2)))
                .map_err(err)?
                .label("truth")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 12, y)], BLACK.stroke_width(2)));
            chart
                .configure_series_labels()
                .label_font((FONT, 14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(err)?;
        }
        Ok(Vec::new())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::render::render;

    /// Eight designs' histograms wrap four to a row, on one axis of shares: a design with a
    /// hundred times the pixels (a 10 m imager beside 300 m ones) reaches the same height.
    #[test]
    fn histograms_are_shares_four_to_a_row() {
        let edges: Vec<f64> = (0..=4).map(|k| 10f64.powi(k - 1)).collect();
        let panel = |k: usize| {
            let scale = if k == 7 { 100 } else { 1 };
            (
                format!("{k}"),
                vec![vec![10 * scale, 30 * scale, 40 * scale, 20 * scale]],
                vec![10 * scale, 30 * scale, 40 * scale, 20 * scale],
            )
        };
        let h = Histograms {
            title: "t".into(),
            label: "chl-a".into(),
            edges,
            categories: vec!["returned".into()],
            panels: (0..8).map(panel).collect(),
            water: (0..8).map(|k| if k == 7 { 10_000 } else { 100 }).collect(),
        };
        assert_eq!(h.size(), (2080, 500 + 466));
        let f = render("h", &h).unwrap();
        assert!(f.svg.contains("% of water pixels"));
        // The tallest bar, 40 %, sets the axis (not 4000 pixels): its tick labels are shares.
        assert!(f.svg.contains(">\n40\n<") || f.svg.contains(">40<") || f.svg.contains("\n40\n"), "no 40 % tick");
        assert!(!f.svg.contains("4000"), "an axis in pixels");
    }
}
