//! SNR per band for every instrument of a study, at the scene's reference (median water)
//! radiance, with the study's SNR requirement drawn across: the figure a design review reads
//! the radiometric margin from. Analytic SNR as [`crate::instrument::analytic_snr`] gives it;
//! the measured SNR (from the noisy cube) as open markers.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::StudyResult;
use super::render::{Draw, FONT, Placed, band_log_chart, err};
use crate::colormap::categorical;

/// One instrument's points: its label and, per band, (centre nm, analytic SNR, measured SNR).
type Series = (String, Vec<(f64, f64, f64)>);

/// SNR against band centre, one series per instrument.
pub(super) struct SnrFigure {
    pub(super) title: String,
    /// Per instrument.
    pub(super) series: Vec<Series>,
    /// The smallest SNR asked, if the study has one.
    pub(super) requirement: Option<f64>,
}

impl SnrFigure {
    /// The figure of `result` (first seed of each instrument), if any run has SNR rows.
    pub(super) fn of(result: &StudyResult) -> Option<Self> {
        let mut series: Vec<Series> = Vec::new();
        for run in &result.runs {
            if series.iter().any(|(l, _)| *l == run.label) || run.snr.is_empty() {
                continue;
            }
            let points = run.snr.iter().map(|r| (r.centre_nm, r.snr_analytic, r.snr_measured)).collect();
            series.push((run.label.clone(), points));
        }
        (!series.is_empty()).then(|| Self {
            title: format!("{} — SNR per band at the scene's median water radiance", result.study.spec.name),
            series,
            requirement: result.study.spec.requirements.as_ref().and_then(|r| r.snr),
        })
    }
}

impl Draw for SnrFigure {
    fn size(&self) -> (u32, u32) {
        (900, 460)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        let finite = |v: f64| v.is_finite() && v > 0.0;
        let points = || self.series.iter().flat_map(|(_, p)| p.iter());
        let mut chart = band_log_chart(
            root,
            &self.title,
            "SNR",
            points().map(|p| p.0),
            points().flat_map(|p| [p.1, p.2]).chain(self.requirement),
            "no finite SNR to plot",
        )?;
        if let Some(r) = self.requirement {
            let (x_lo, x_hi) = (chart.x_range().start, chart.x_range().end);
            chart
                .draw_series(DashedLineSeries::new(vec![(x_lo, r), (x_hi, r)], 8, 5, BLACK.stroke_width(2)))
                .map_err(err)?
                .label(format!("requirement: SNR ≥ {r}"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], BLACK.stroke_width(2)));
        }
        for (k, (label, points)) in self.series.iter().enumerate() {
            let c = categorical(k);
            let colour = RGBColor(c[0], c[1], c[2]);
            let analytic: Vec<(f64, f64)> = points.iter().filter(|p| finite(p.1)).map(|p| (p.0, p.1)).collect();
            chart
                .draw_series(LineSeries::new(analytic.clone(), colour.stroke_width(2)))
                .map_err(err)?
                .label(format!("{label} (analytic)"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], colour.stroke_width(2)));
            chart.draw_series(analytic.iter().map(|&p| Circle::new(p, 4, colour.filled()))).map_err(err)?;
            chart
                .draw_series(
                    points.iter().filter(|p| finite(p.2)).map(|p| Circle::new((p.0, p.2), 6, colour.stroke_width(1))),
                )
                .map_err(err)?
                .label(format!("{label} (measured)"))
                .legend(move |(x, y)| Circle::new((x + 7, y), 5, colour.stroke_width(1)));
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerLeft)
            .draw()
            .map_err(err)?;
        Ok(Vec::new())
    }
}
