//! The optics of a study's designs, drawn only when a design states an optical effect
//! (`instrument::effects`): the system MTF against spatial frequency along and across track at
//! 560 nm (each design's MTF budget, or an ideal optic's), and the stray-light ratio against
//! distance from a bright edge at 443 nm (Metop-3MI's half-bright field) for the designs that
//! state stray light. The review pack's "MTF curves per design, stray-light ratio against
//! distance".

use plotters::coord::Shift;
use plotters::prelude::*;

use super::StudyResult;
use super::render::{Draw, FONT, Placed, err};
use crate::colormap::categorical;
use crate::instrument::InstrumentSpec;
use crate::instrument::effects::{self, mtf::Axis};
use crate::instrument::spatial::first_plane_geometry;

/// The wavelength the MTF curves are drawn at, nm.
const MTF_AT_NM: f64 = 560.0;
/// The wavelength the stray-light curves are drawn at, nm.
const STRAY_AT_NM: f64 = 443.0;
/// Points per curve.
const POINTS: usize = 121;

/// One design's curves.
struct Curves {
    label: String,
    /// (cycles per pixel, MTF along, MTF across).
    mtf: Vec<(f64, f64, f64)>,
    /// (distance m, ratio) where the design states stray light.
    stray: Option<Vec<(f64, f64)>>,
}

/// The figure's data.
pub(super) struct OpticsFigure {
    title: String,
    designs: Vec<Curves>,
}

impl Curves {
    fn of(label: &str, spec: &InstrumentSpec) -> Self {
        let ideal = effects::MtfBudget::default();
        let budget = effects::spatial_response(&spec.effects).unwrap_or(&ideal);
        let g = first_plane_geometry(spec);
        let mtf = (0..POINTS)
            .map(|i| {
                let cycles_per_px = i as f64 / (POINTS - 1) as f64;
                let nu = cycles_per_px / g.pitch_ground_m;
                let at = |axis| budget.otf(&g, MTF_AT_NM, nu, axis).abs();
                (cycles_per_px, at(Axis::Along), at(Axis::Across))
            })
            .collect();
        let stray = effects::edge_ratio(&spec.effects, 1.0, STRAY_AT_NM).map(|_| {
            (0..POINTS)
                .map(|i| {
                    // 10 m to 20 km, evenly in log distance.
                    let d = 10.0 * 2000f64.powf(i as f64 / (POINTS - 1) as f64);
                    (d, effects::edge_ratio(&spec.effects, d, STRAY_AT_NM).unwrap_or(0.0))
                })
                .collect()
        });
        Self { label: label.into(), mtf, stray }
    }
}

impl OpticsFigure {
    /// The figure of `result`, if any design states an optical effect.
    pub(super) fn of(result: &StudyResult) -> Option<Self> {
        let mut designs: Vec<Curves> = Vec::new();
        let mut any = false;
        for (label, _, config) in &result.study.runs {
            if designs.iter().any(|d| d.label == *label) {
                continue;
            }
            any |= !config.instrument.effects.is_empty();
            designs.push(Curves::of(label, &config.instrument));
        }
        (any && !designs.is_empty())
            .then(|| Self { title: format!("{} — the designs' optics", result.study.spec.name), designs })
    }
}

impl Draw for OpticsFigure {
    fn size(&self) -> (u32, u32) {
        (1000, 440)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(&self.title, (FONT, 16)).map_err(err)?;
        let (left, right) = root.split_horizontally(500);
        let colour = |k: usize| {
            let c = categorical(k);
            RGBColor(c[0], c[1], c[2])
        };
        // MTF against frequency, Nyquist marked.
        let mut chart = ChartBuilder::on(&left)
            .caption(format!("system MTF at {MTF_AT_NM:.0} nm (solid: along, dashed: across)"), (FONT, 14))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("spatial frequency (cycles per pixel)")
            .y_desc("MTF")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(err)?;
        chart
            .draw_series(DashedLineSeries::new(vec![(0.5, 0.0), (0.5, 1.0)], 4, 4, BLACK.mix(0.5).stroke_width(1)))
            .map_err(err)?;
        for (k, d) in self.designs.iter().enumerate() {
            let c = colour(k);
            chart
                .draw_series(LineSeries::new(d.mtf.iter().map(|p| (p.0, p.1)), c.stroke_width(2)))
                .map_err(err)?
                .label(d.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], c.stroke_width(2)));
            chart
                .draw_series(DashedLineSeries::new(d.mtf.iter().map(|p| (p.0, p.2)), 6, 4, c.stroke_width(2)))
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(err)?;
        // Stray light against distance, log-log.
        let stray: Vec<(usize, &Vec<(f64, f64)>)> =
            self.designs.iter().enumerate().filter_map(|(k, d)| d.stray.as_ref().map(|s| (k, s))).collect();
        let positive = || stray.iter().flat_map(|(_, s)| s.iter().map(|p| p.1)).filter(|v| *v > 0.0);
        let (lo, hi) = positive().fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if !lo.is_finite() {
            right.draw(&Text::new("no design states stray light", (120, 200), (FONT, 14).into_font())).map_err(err)?;
            return Ok(Vec::new());
        }
        let mut chart = ChartBuilder::on(&right)
            .caption(format!("stray light past a bright edge at {STRAY_AT_NM:.0} nm"), (FONT, 14))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((10.0..20_000.0).log_scale(), ((lo / 2.0).max(1e-9)..hi * 2.0).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("distance into the dark half (m)")
            .y_desc("stray / bright radiance")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(err)?;
        for (k, s) in stray {
            let points: Vec<(f64, f64)> = s.iter().copied().filter(|p| p.1 > 0.0).collect();
            chart.draw_series(LineSeries::new(points, colour(k).stroke_width(2))).map_err(err)?;
        }
        Ok(Vec::new())
    }
}
