//! Study figures, each as PNG and SVG: truth and retrieved maps side by side with one shared
//! colour scale and a colour bar; truth-vs-retrieved density scatter plots; and histograms of the
//! retrieved values stacked by the chosen SIOP set (aLMI) or dominant substrate (SAMBUCA), with
//! the truth's histogram outlined — as in Figures 4–7 of Matthews et al. (2023).
//!
//! Drawing uses plotters with fonts from the embedded DejaVu Sans (no system fonts). Map rasters
//! are painted into the PNG directly and embedded in the SVG as PNG images, so the SVG stays small
//! and its text and axes stay vector.

use ndarray::Array2;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::histogram_figure::Histograms;
pub(super) use super::maps_figure::{Maps, PANEL, TITLE_H};
use super::render::{Draw, FONT, Figure, Panel, Placed, err, render, tick_label};
use super::{StudyError, StudyResult, StudyRun};
use crate::colormap::{Scale, viridis};
use crate::metrics::{Metrics, bin_of, histogram_2d, log_edges};
use crate::retrieval::ProductFlags;

struct Scatter {
    title: String,
    label: String,
    edges: Vec<f64>,
    panels: Vec<(String, Vec<Vec<usize>>)>,
}

impl Draw for Scatter {
    fn size(&self) -> (u32, u32) {
        (480 * self.panels.len() as u32, 500)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        let (top, rest) = root.split_vertically(TITLE_H);
        top.draw_text(&self.title, &(FONT, 17).into_font().color(&BLACK), (10, 8)).map_err(err)?;
        let (lo, hi) = (self.edges[0], self.edges[self.edges.len() - 1]);
        for (area, (title, counts)) in rest.split_evenly((1, self.panels.len())).iter().zip(&self.panels) {
            let mut chart = ChartBuilder::on(area)
                .caption(title, (FONT, 16))
                .margin(8)
                .x_label_area_size(44)
                .y_label_area_size(64)
                .build_cartesian_2d((lo..hi).log_scale(), (lo..hi).log_scale())
                .map_err(err)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(format!("true {}", self.label))
                .y_desc("retrieved")
                .x_label_formatter(&|v| tick_label(*v))
                .y_label_formatter(&|v| tick_label(*v))
                .label_style((FONT, 14))
                .axis_desc_style((FONT, 15))
                .draw()
                .map_err(err)?;
            let max = counts.iter().flatten().copied().max().unwrap_or(1).max(1) as f64;
            let mut cells = Vec::new();
            for (j, row) in counts.iter().enumerate() {
                for (i, &n) in row.iter().enumerate() {
                    if n > 0 {
                        let c = viridis((n as f64).ln_1p() / max.ln_1p());
                        cells.push(Rectangle::new(
                            [(self.edges[i], self.edges[j]), (self.edges[i + 1], self.edges[j + 1])],
                            RGBColor(c[0], c[1], c[2]).filled(),
                        ));
                    }
                }
            }
            chart.draw_series(cells).map_err(err)?;
            chart.draw_series(LineSeries::new(vec![(lo, lo), (hi, hi)], BLACK.stroke_width(1))).map_err(err)?;
        }
        Ok(Vec::new())
    }
}

fn metric_line(m: Option<&Metrics>) -> String {
    m.map_or_else(String::new, |m| {
        // Nothing returned has no error to state (its sums would read MAE 0 %).
        if m.n == 0 {
            return "no pixel returned".to_string();
        }
        format!("MAE {:.0} %, bias {:+.0} %, {:.1} % returned", m.mae_pct(), m.bias_pct(), m.returned_pct)
    })
}

/// What the figures of one retrieval and variable draw from.
struct Context<'a> {
    runs: &'a [&'a StudyRun],
    index: usize,
    var: &'static str,
    scale: Scale,
    title: String,
}

/// One scale over the truth and every instrument's returned values (log for concentrations).
fn shared_scale(runs: &[&StudyRun], index: usize, var: &'static str) -> Option<Scale> {
    let first = runs.first()?;
    let truth = first.truth.map(var)?;
    let mut values: Vec<f64> = truth
        .indexed_iter()
        .filter(|((r, c), _)| first.truth.surface.is_water(*r, *c))
        .map(|(_, v)| f64::from(*v))
        .collect();
    for run in runs {
        if let Some(ret) = run.retrievals.get(index)
            && let Some(map) = ret.product.map(var)
        {
            values.extend(
                map.indexed_iter().filter(|((r, c), _)| ret.product.returned(*r, *c)).map(|(_, v)| f64::from(*v)),
            );
        }
    }
    let mut scale = Scale::robust(values.iter().copied().filter(|v| *v > 0.0));
    if !scale.log && scale.lo > 0.0 && var != crate::variable::key::DEPTH {
        scale.log = true;
    }
    Some(scale)
}

fn maps_figure(ctx: &Context<'_>) -> Option<Maps> {
    let first = ctx.runs.first()?;
    let truth = first.truth.map(ctx.var)?;
    let mut panels = vec![Panel {
        title: "truth".into(),
        values: truth.clone(),
        valid: first.truth.surface.water_mask(),
        spacing_m: spacing_m(first),
    }];
    for run in ctx.runs {
        let Some(ret) = run.retrievals.get(ctx.index) else { continue };
        let Some(map) = ret.product.map(ctx.var) else { continue };
        panels.push(Panel {
            title: format!("{}: {}", run.label, metric_line(ret.metrics.get(ctx.var))),
            values: map.clone(),
            valid: Array2::from_shape_fn(map.dim(), |(r, c)| ret.product.returned(r, c) && map[[r, c]] > 0.0),
            spacing_m: spacing_m(run),
        });
    }
    Some(Maps {
        title: ctx.title.clone(),
        label: crate::metrics::label(ctx.var),
        scale: ctx.scale,
        panels,
        diverging: false,
        panel: PANEL,
    })
}

/// Ground distance between a run's neighbouring output pixels, m (nadir GSD × decimation).
fn spacing_m(run: &StudyRun) -> f64 {
    run.viewing.gsd_m * run.viewing.decimation as f64
}

/// The heading of a difference map, the same in the app and the study figures: "A − B (B at A's
/// ground points)", or for classes "A vs B: same class (at A's ground points)".
#[must_use]
pub fn difference_title(a: &str, b: &str, classes: bool) -> String {
    if classes {
        format!("{a} vs {b}: same class (at {a}'s ground points)")
    } else {
        format!("{a} − {b} ({b} at {a}'s ground points)")
    }
}

/// The colour bar of a difference map in the product's unit: "A − B (mg m⁻³)".
#[must_use]
pub fn difference_bar(a: &str, b: &str, unit: &str) -> String {
    if unit.is_empty() { format!("{a} − {b}") } else { format!("{a} − {b} ({unit})") }
}

/// A − B of two instruments' retrievals on A's pixels, B sampled at the pixel nearest each of A's
/// ground points (the instruments' grids differ), on a diverging scale symmetric about zero.
fn difference_figure(ctx: &Context<'_>) -> Option<Maps> {
    let [a, b] = ctx.runs else { return None };
    let (ra, rb) = (a.retrievals.get(ctx.index)?, b.retrievals.get(ctx.index)?);
    let (ma, mb) = (ra.product.map(ctx.var)?, rb.product.map(ctx.var)?);
    let heading = b.viewing.track_heading_deg();
    let mut values = Array2::zeros(ma.dim());
    let mut valid = Array2::from_elem(ma.dim(), false);
    for ((r, c), va) in ma.indexed_iter() {
        let (x, y) = a.viewing.ground_m(0, r, c);
        if ra.product.returned(r, c)
            && let Some((rb_, cb)) = b.viewing.nearest_pixel(x, y, heading)
            && rb.product.returned(rb_, cb)
        {
            values[[r, c]] = va - mb[[rb_, cb]];
            valid[[r, c]] = true;
        }
    }
    let mut magnitudes: Vec<f64> =
        values.iter().zip(&valid).filter(|(_, ok)| **ok).map(|(v, _)| f64::from(*v).abs()).collect();
    if magnitudes.is_empty() {
        return None;
    }
    let k = ((magnitudes.len() as f64 * 0.98) as usize).min(magnitudes.len() - 1);
    let bound = *magnitudes.select_nth_unstable_by(k, f64::total_cmp).1;
    let bound = if bound > 0.0 { bound } else { 1.0 };
    Some(Maps {
        title: format!("{}: {} − {}", ctx.title, a.label, b.label),
        label: difference_bar(&a.label, &b.label, crate::metrics::unit(ctx.var)),
        scale: Scale { lo: -bound, hi: bound, log: false },
        panels: vec![Panel {
            title: difference_title(&a.label, &b.label, false),
            values,
            valid,
            spacing_m: spacing_m(a),
        }],
        diverging: true,
        panel: (PANEL.0 + 90, PANEL.1),
    })
}

/// The class of a returned pixel for the histograms: chosen SIOP set, or dominant substrate.
fn category(p: &crate::retrieval::Product, r: usize, c: usize) -> usize {
    if let Some(s) = &p.siop_set {
        usize::try_from(s[[r, c]]).unwrap_or(0)
    } else if let Some(f) = &p.substrate_fractions {
        (0..f.dim().2).max_by(|&a, &b| f[[r, c, a]].total_cmp(&f[[r, c, b]])).unwrap_or(0)
    } else {
        0
    }
}

fn scatter_and_histograms(ctx: &Context<'_>) -> Option<(Scatter, Histograms)> {
    let ret0 = ctx.runs.first()?.retrievals.get(ctx.index)?;
    let (lo, hi) = (ctx.scale.lo.max(1e-6), ctx.scale.hi.max(ctx.scale.lo * 1.01));
    let edges = log_edges(lo, hi, 60);
    let hist_edges = log_edges(lo, hi, 36);
    let categories: Vec<String> = if ret0.product.siop_set.is_some() {
        ret0.product.siop_set_names.clone()
    } else if ret0.product.substrate_fractions.is_some() {
        ret0.product.substrate_names.iter().map(|n| format!("{n} dominant")).collect()
    } else {
        vec![ret0.metrics.product.clone()]
    };
    let mut scatter_panels = Vec::new();
    let mut hist_panels = Vec::new();
    let mut hist_water = Vec::new();
    for run in ctx.runs {
        let (Some(ret), Some(truth)) = (run.retrievals.get(ctx.index), run.truth.map(ctx.var)) else { continue };
        let Some(map) = ret.product.map(ctx.var) else { continue };
        let p = &ret.product;
        let water_returned = |r: usize, c: usize| run.truth.surface.is_water(r, c) && p.returned(r, c);
        let pairs = map
            .indexed_iter()
            .filter(|((r, c), _)| water_returned(*r, *c))
            .map(|((r, c), v)| (f64::from(truth[[r, c]]), f64::from(*v)));
        let caption = ret.metrics.get(ctx.var).map_or_else(String::new, |m| {
            if m.n == 0 {
                // No pixel returned: no error to state (an empty set's MAE is not 0 %).
                format!("{}: N 0, none returned", run.label)
            } else {
                format!(
                    "{}: N {}, MAE {:.0} %, bias {:+.0} %, R² {:.2}",
                    run.label,
                    m.n,
                    m.mae_pct(),
                    m.bias_pct(),
                    m.r2
                )
            }
        });
        scatter_panels.push((caption, histogram_2d(pairs, &edges)));
        let nb = hist_edges.len() - 1;
        let mut counts = vec![vec![0usize; nb]; categories.len().max(1)];
        let mut truth_counts = vec![0usize; nb];
        let mut water = 0;
        for ((r, c), v) in map.indexed_iter() {
            if !run.truth.surface.is_water(r, c) {
                continue;
            }
            water += 1;
            if let Some(b) = bin_of(&hist_edges, f64::from(truth[[r, c]])) {
                truth_counts[b] += 1;
            }
            if p.returned(r, c)
                && let (Some(b), Some(row)) = (bin_of(&hist_edges, f64::from(*v)), counts.get_mut(category(p, r, c)))
            {
                row[b] += 1;
            }
        }
        let note = if p.flags.iter().any(|f| f & ProductFlags::FAILED != 0) { " (failures excluded)" } else { "" };
        hist_panels.push((format!("{}{note}", run.label), counts, truth_counts));
        hist_water.push(water);
    }
    Some((
        Scatter { title: ctx.title.clone(), label: crate::metrics::label(ctx.var), edges, panels: scatter_panels },
        Histograms {
            title: ctx.title.clone(),
            label: crate::metrics::label(ctx.var),
            edges: hist_edges,
            categories,
            panels: hist_panels,
            water: hist_water,
        },
    ))
}

/// Every figure of a study: for each retrieval and each variable it retrieves with a truth —
/// maps, a density scatter and histograms (the first seed of each instrument).
pub fn figure_set(result: &StudyResult) -> Result<Vec<Figure>, StudyError> {
    let mut seen = Vec::new();
    let runs: Vec<&StudyRun> = result
        .runs
        .iter()
        .filter(|r| {
            let first = !seen.contains(&r.label);
            seen.push(r.label.clone());
            first
        })
        .collect();
    let Some(first) = runs.first() else { return Ok(Vec::new()) };
    let mut figures = Vec::new();
    if let Some(snr) = super::snr_figure::SnrFigure::of(result) {
        figures.push(render("snr", &snr)?);
    }
    if let Some(optics) = super::optics_figure::OpticsFigure::of(result) {
        figures.push(render("optics", &optics)?);
    }
    if let Some(rrs) = super::rrs_figure::RrsFigure::of(result) {
        figures.push(render("rrs_error", &rrs)?);
    }
    if let Some(data) = result.spectrum.as_deref() {
        let s = &data.point;
        let title = format!(
            "{} — the scene at a typical water pixel ({:.0}, {:.0}) m, view zenith {:.1}°{}",
            result.study.spec.name,
            s.ground_m.0,
            s.ground_m.1,
            s.view_zenith_deg,
            if s.gases { "" } else { "; gases left out by the scene" }
        );
        figures.push(render("spectrum", &super::spectrum_figure::SpectrumFigure { title, data })?);
    }
    for (index, ret0) in first.retrievals.iter().enumerate() {
        for var in crate::variable::KEYS {
            if first.truth.map(var).is_none() || ret0.product.map(var).is_none() {
                continue;
            }
            let Some(scale) = shared_scale(&runs, index, var) else { continue };
            let title = format!("{} — {} {}", result.study.spec.name, ret0.metrics.product, crate::metrics::label(var));
            let ctx = Context { runs: &runs, index, var, scale, title };
            let name = format!("{}_{}", ret0.spec.name(), var);
            if let Some(maps) = maps_figure(&ctx) {
                figures.push(render(&format!("maps_{name}"), &maps)?);
            }
            if let Some(diff) = difference_figure(&ctx) {
                figures.push(render(&format!("difference_{name}"), &diff)?);
            }
            if let Some((scatter, histograms)) = scatter_and_histograms(&ctx) {
                figures.push(render(&format!("scatter_{name}"), &scatter)?);
                figures.push(render(&format!("histogram_{name}"), &histograms)?);
            }
        }
    }
    // Bottom type: the dominant substrate's maps and where it is right.
    for (name, maps) in super::substrate_figure::substrate_figures(&runs, &result.study.spec.name).unwrap_or_default() {
        figures.push(render(&name, &maps)?);
    }
    Ok(figures)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_map_figure_renders_to_png_and_svg() {
        let values = Array2::from_shape_fn((40, 60), |(r, c)| 1.0 + (r * c) as f32 / 10.0);
        let valid = Array2::from_shape_fn((40, 60), |(r, _)| r > 2);
        let fig = Maps {
            title: "test".into(),
            label: "chl-a (mg m⁻³)".into(),
            scale: Scale { lo: 1.0, hi: 240.0, log: true },
            panels: vec![Panel { title: "truth".into(), values, valid, spacing_m: 20.0 }],
            diverging: false,
            panel: PANEL,
        };
        let f = render("t", &fig).unwrap();
        assert_eq!(&f.png[1..4], b"PNG");
        assert!(f.svg.contains("<image") && f.svg.contains("chl-a"));
    }
}
