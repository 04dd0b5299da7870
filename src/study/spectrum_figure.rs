//! The scene's spectrum at a typical water pixel, 350–2500 nm: TOA and path radiance, the true
//! Rrs, each instrument's bands (shaded at their FWHM) and what each measured there (Level-1 and
//! corrected Rrs). The figure a review reads band placement from: which bands sit in gas
//! windows, where the water is dark enough for an aerosol band, how much of the signal the
//! atmosphere is. The spectrum itself is [`crate::engine::spectrum`].

use plotters::coord::Shift;
use plotters::prelude::*;

use super::render::{Draw, FONT, Placed, err, tick_label};
use crate::colormap::categorical;
use crate::engine::RunOutput;
use crate::engine::spectrum::{InstrumentAtPoint, PointSpectrum, SpectrumMaker, instrument_at};

/// The spectrum of a study and what its instruments measured at the same point.
#[derive(Debug, Clone, PartialEq)]
pub struct StudySpectrum {
    /// The scene at the point, seen from the first run's pixel.
    pub point: PointSpectrum,
    /// Per instrument (first seed of each), in study order.
    pub instruments: Vec<InstrumentAtPoint>,
}

/// A typical water pixel of `out` ([`crate::engine::probe::typical_water_pixel`]).
#[must_use]
pub fn typical_water_pixel(out: &RunOutput) -> Option<(usize, usize)> {
    crate::engine::probe::typical_water_pixel(&out.truth)
}

impl StudySpectrum {
    /// The spectrum at `first`'s typical water pixel, and what each of `runs` measured there.
    ///
    /// # Errors
    /// The forward model failing at the point (named).
    pub fn of(first: &RunOutput, runs: &[(String, &RunOutput)]) -> Result<Option<Self>, String> {
        let Some((row, col)) = typical_water_pixel(first) else { return Ok(None) };
        let point = SpectrumMaker::default().at(first, row, col).map_err(|e| e.to_string())?;
        let instruments = runs.iter().map(|(label, out)| instrument_at(out, label, point.ground_m)).collect();
        Ok(Some(Self { point, instruments }))
    }
}

/// The figure: TOA radiance above, Rrs below, on one wavelength axis.
pub(super) struct SpectrumFigure<'a> {
    pub(super) title: String,
    pub(super) data: &'a StudySpectrum,
}

/// log10 of the positive values, as (x, log10 y).
fn logs(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    x.iter().zip(y).filter(|(_, v)| **v > 0.0).map(|(x, v)| (*x, v.log10())).collect()
}

impl Draw for SpectrumFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1000, 720)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        let s = &self.data.point;
        let root = root.titled(&self.title, (FONT, 17)).map_err(err)?;
        let (top, bottom) = root.split_vertically(340);
        let l1 = |i: &InstrumentAtPoint| -> Vec<(f64, f64)> {
            i.bands
                .iter()
                .filter_map(|b| b.level1_w_m2_sr_um.filter(|v| *v > 0.0).map(|v| (b.centre_nm, v.log10())))
                .collect()
        };
        let rrs = |i: &InstrumentAtPoint| -> Vec<(f64, f64)> {
            i.bands.iter().filter_map(|b| b.rrs_per_sr.filter(|v| *v > 0.0).map(|v| (b.centre_nm, v.log10()))).collect()
        };
        let toa_curves = [logs(&s.wavelengths_nm, &s.l_toa_w_m2_sr_um), logs(&s.wavelengths_nm, &s.l_path_w_m2_sr_um)];
        let toa_points: Vec<Vec<(f64, f64)>> = self.data.instruments.iter().map(l1).collect();
        panel(
            &top,
            &self.data.instruments,
            "TOA radiance (W m⁻² sr⁻¹ µm⁻¹)",
            &toa_curves,
            &toa_points,
            &["scene", "path radiance"],
            "Level-1",
        )?;
        let rrs_curves = [logs(&s.wavelengths_nm, &s.rrs_per_sr)];
        let rrs_points: Vec<Vec<(f64, f64)>> = self.data.instruments.iter().map(rrs).collect();
        panel(
            &bottom,
            &self.data.instruments,
            "Rrs (sr⁻¹)",
            &rrs_curves,
            &rrs_points,
            &["scene (truth)"],
            "corrected",
        )?;
        Ok(Vec::new())
    }
}

/// One log-y panel: curves in black and grey, bands shaded, instruments' points in their colours.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    instruments: &[InstrumentAtPoint],
    y_desc: &str,
    curves: &[Vec<(f64, f64)>],
    points: &[Vec<(f64, f64)>],
    curve_names: &[&str],
    point_name: &str,
) -> Result<(), String> {
    let ys = curves.iter().flatten().chain(points.iter().flatten()).map(|p| p.1);
    let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    if !lo.is_finite() {
        return Ok(());
    }
    let (lo, hi) = ((lo - 0.15).floor(), (hi + 0.15).ceil());
    let (x0, x1) = (crate::engine::spectrum::SPECTRUM_START_NM, crate::engine::spectrum::SPECTRUM_END_NM);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, lo..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("wavelength (nm)")
        .y_desc(y_desc)
        .x_labels(12)
        .y_labels((hi - lo) as usize + 1)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| {
            // Decades below a thousandth as powers of ten (0.0000010 reads badly).
            let k = v.round();
            if (v - k).abs() < 1e-9 && k < -3.0 { format!("1e{k:.0}") } else { tick_label(10f64.powf(*v)) }
        })
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(err)?;
    for (k, inst) in instruments.iter().enumerate() {
        let c = categorical(k);
        let fill = RGBColor(c[0], c[1], c[2]).mix(0.15).filled();
        chart
            .draw_series(inst.bands.iter().map(|b| {
                Rectangle::new([(b.centre_nm - b.fwhm_nm / 2.0, lo), (b.centre_nm + b.fwhm_nm / 2.0, hi)], fill)
            }))
            .map_err(err)?;
    }
    let greys = [RGBColor(40, 40, 40), RGBColor(140, 140, 140)];
    for (i, (curve, name)) in curves.iter().zip(curve_names).enumerate() {
        let colour = greys[i % 2];
        chart
            .draw_series(LineSeries::new(curve.iter().copied(), colour.stroke_width(if i == 0 { 2 } else { 1 })))
            .map_err(err)?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], colour.stroke_width(2)));
    }
    for (k, (inst, pts)) in instruments.iter().zip(points).enumerate() {
        let c = categorical(k);
        let colour = RGBColor(c[0], c[1], c[2]);
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
            .map_err(err)?
            .label(format!("{} {point_name} (bands shaded at FWHM)", inst.label))
            .legend(move |(x, y)| Circle::new((x + 7, y), 4, colour.filled()));
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 12))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    Ok(())
}
