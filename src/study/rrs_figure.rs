//! The corrected Rrs against the truth, per band, for every instrument of a study: log-space
//! MAE (filled markers, solid line) and |bias| (open markers), as ACIX-Aqua reports an
//! atmospheric correction (Pahlevan et al. 2021), with the study's Rrs requirement drawn over
//! its band range. Drawn where the study's correction is image-based or it has an Rrs
//! requirement: with the exact correction the figure only shows noise.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::StudyResult;
use super::render::{Draw, FONT, Placed, band_log_chart, err};
use crate::colormap::categorical;

/// One instrument's points: its label and, per band, (centre nm, MAE %, |bias| %).
type Series = (String, Vec<(f64, f64, f64)>);

/// Rrs error against band centre, one series per instrument.
pub(super) struct RrsFigure {
    pub(super) title: String,
    pub(super) series: Vec<Series>,
    /// (MAE %, from nm, to nm) of the study's Rrs requirement.
    pub(super) requirement: Option<(f64, f64, f64)>,
}

impl RrsFigure {
    /// The figure of `result` (first seed of each instrument), where it applies.
    pub(super) fn of(result: &StudyResult) -> Option<Self> {
        let spec = &result.study.spec;
        let image = spec.correction.as_ref().and_then(|c| c.image());
        let requirement =
            spec.requirements.as_ref().and_then(|r| r.rrs.as_ref()).map(|r| (r.mae_pct, r.from_nm, r.to_nm));
        if image.is_none() && requirement.is_none() {
            return None;
        }
        let mut series: Vec<Series> = Vec::new();
        for run in &result.runs {
            if series.iter().any(|(l, _)| *l == run.label) || run.rrs_metrics.is_empty() {
                continue;
            }
            let points = run
                .rrs_metrics
                .iter()
                .filter(|m| m.metrics.n > 0)
                .map(|m| (m.centre_nm, m.metrics.mae_pct(), m.metrics.bias_pct().abs()))
                .collect();
            series.push((run.label.clone(), points));
        }
        let correction =
            image.map_or_else(|| "exact correction".to_string(), |i| format!("image-based, {}", i.label()));
        (!series.is_empty()).then(|| Self {
            title: format!("{} — corrected Rrs against the truth per band ({correction})", spec.name),
            series,
            requirement,
        })
    }
}

impl Draw for RrsFigure {
    fn size(&self) -> (u32, u32) {
        (900, 460)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        // Errors below 0.1 % are drawn at 0.1 % (a log axis has no zero).
        let floor = |v: f64| if v.is_finite() { v.max(0.1) } else { f64::NAN };
        let points = || self.series.iter().flat_map(|(_, p)| p.iter());
        let requirement = self.requirement.map(|r| r.0);
        let mut chart = band_log_chart(
            root,
            &self.title,
            "Rrs error, log-space (%)",
            points().map(|p| p.0),
            points().flat_map(|p| [floor(p.1), floor(p.2)]).chain(requirement),
            "no Rrs error to plot",
        )?;
        if let Some((r, from, to)) = self.requirement {
            chart
                .draw_series(DashedLineSeries::new(vec![(from, r), (to, r)], 8, 5, BLACK.stroke_width(2)))
                .map_err(err)?
                .label(format!("requirement: MAE ≤ {r} % ({from:.0}–{to:.0} nm)"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], BLACK.stroke_width(2)));
        }
        for (k, (label, points)) in self.series.iter().enumerate() {
            let c = categorical(k);
            let colour = RGBColor(c[0], c[1], c[2]);
            let mae: Vec<(f64, f64)> = points.iter().map(|p| (p.0, floor(p.1))).filter(|p| p.1.is_finite()).collect();
            chart
                .draw_series(LineSeries::new(mae.clone(), colour.stroke_width(2)))
                .map_err(err)?
                .label(format!("{label}: MAE"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], colour.stroke_width(2)));
            chart.draw_series(mae.iter().map(|&p| Circle::new(p, 4, colour.filled()))).map_err(err)?;
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|p| (p.0, floor(p.2)))
                        .filter(|p| p.1.is_finite())
                        .map(|p| Circle::new(p, 6, colour.stroke_width(1))),
                )
                .map_err(err)?
                .label(format!("{label}: |bias|"))
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
