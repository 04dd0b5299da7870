//! The bottom-type figures of a study whose retrieval unmixes substrates (SAMBUCA): the dominant
//! substrate of the truth and of each instrument's retrieval as class maps with one legend, and
//! where each instrument's dominant substrate agrees with the truth's. The dominant substrate of
//! a pixel is the one with the largest fraction (ties: the first listed); classes are matched by
//! name, so a retrieval listing the substrates in another order maps the same colours.

use ndarray::Array2;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::StudyRun;
use super::render::{Draw, FONT, Placed, err, scale_bar_length};
use crate::colormap::categorical;

/// Panel size, px.
const PANEL: (u32, u32) = (300, 340);
const TITLE_H: u32 = 34;
const LEGEND_W: u32 = 190;
const CAPTION_H: u32 = 26;
/// Grey of land and pixels not returned (the other figures' grey).
const GREY: [u8; 3] = [200, 200, 200];
/// Agree, disagree (the app's agreement colours).
const AGREE: [[u8; 3]; 2] = [[150, 200, 150], [215, 48, 39]];

/// Class maps side by side: class index per pixel (`None`: land or not returned).
pub(super) struct ClassMaps {
    title: String,
    /// Per panel: title, classes, metres per pixel across.
    panels: Vec<(String, Array2<Option<usize>>, f64)>,
    /// Legend: name and colour of each class.
    legend: Vec<(String, [u8; 3])>,
    /// Colour of class `k`.
    palette: Vec<[u8; 3]>,
    caption: String,
}

/// The dominant class of each water pixel of fractions `f` (row, column, class), mapped to
/// `classes` by `names`; `None` where `keep` is false.
fn dominant(
    f: &ndarray::Array3<f32>,
    names: &[String],
    classes: &[String],
    keep: impl Fn(usize, usize) -> bool,
) -> Array2<Option<usize>> {
    let (rows, cols, n) = f.dim();
    let index: Vec<Option<usize>> = names.iter().map(|name| classes.iter().position(|c| c == name)).collect();
    Array2::from_shape_fn((rows, cols), |(r, c)| {
        if !keep(r, c) {
            return None;
        }
        let best = (0..n).max_by(|&a, &b| f[[r, c, a]].total_cmp(&f[[r, c, b]]).then(b.cmp(&a)))?;
        index.get(best).copied().flatten()
    })
}

/// Metres per output column of a run (nadir GSD × decimation).
fn spacing_m(run: &StudyRun) -> f64 {
    run.viewing.gsd_m * run.viewing.decimation as f64
}

/// The two figures of the first retrieval that unmixes substrates, with their file stems
/// (`maps_{retrieval}_substrate`, `agreement_{retrieval}_substrate`); `None` without one.
pub(super) fn substrate_figures(runs: &[&StudyRun], title: &str) -> Option<Vec<(String, ClassMaps)>> {
    let first = runs.first()?;
    let (index, ret0) = first.retrievals.iter().enumerate().find(|(_, r)| r.product.substrate_fractions.is_some())?;
    let truth_f = first.truth.substrate_fractions.as_ref()?;
    let classes = first.truth.substrate_names.clone();
    let palette: Vec<[u8; 3]> = (0..classes.len()).map(categorical).collect();
    let legend: Vec<(String, [u8; 3])> = classes.iter().zip(&palette).map(|(n, c)| (n.replace('_', " "), *c)).collect();
    let water = |run: &StudyRun| {
        let surface = run.truth.surface.clone();
        move |r: usize, c: usize| surface.is_water(r, c)
    };
    let mut maps = vec![(
        "truth".to_string(),
        dominant(truth_f, &first.truth.substrate_names, &classes, water(first)),
        spacing_m(first),
    )];
    let mut agreement = Vec::new();
    for run in runs {
        let Some(ret) = run.retrievals.get(index) else { continue };
        let (Some(f), Some(t)) = (&ret.product.substrate_fractions, &run.truth.substrate_fractions) else { continue };
        let p = &ret.product;
        let surface = &run.truth.surface;
        let retrieved = dominant(f, &p.substrate_names, &classes, |r, c| surface.is_water(r, c) && p.returned(r, c));
        let truth = dominant(t, &run.truth.substrate_names, &classes, |r, c| surface.is_water(r, c));
        let agree = Array2::from_shape_fn(retrieved.dim(), |(r, c)| match (retrieved[[r, c]], truth[[r, c]]) {
            (Some(a), Some(b)) => Some(usize::from(a != b)),
            _ => None,
        });
        let right = agree.iter().filter(|a| **a == Some(0)).count();
        let judged = agree.iter().filter(|a| a.is_some()).count();
        let share = if judged > 0 { 100.0 * right as f64 / judged as f64 } else { 0.0 };
        maps.push((run.label.clone(), retrieved, spacing_m(run)));
        agreement.push((format!("{}: {share:.1} % right", run.label), agree, spacing_m(run)));
    }
    let product = &ret0.metrics.product;
    let stem = ret0.spec.name();
    Some(vec![
        (
            format!("maps_{stem}_substrate"),
            ClassMaps {
                title: format!("{title} — {product} dominant substrate"),
                panels: maps,
                legend,
                palette,
                caption: "The substrate with the largest fraction in each pixel; grey: land, or not returned; flight direction up."
                    .into(),
            },
        ),
        (
            format!("agreement_{stem}_substrate"),
            ClassMaps {
                title: format!("{title} — {product} dominant substrate against the truth"),
                panels: agreement,
                legend: vec![("right".into(), AGREE[0]), ("wrong".into(), AGREE[1])],
                palette: AGREE.to_vec(),
                caption: "Where the retrieved dominant substrate is the truth's; grey: land, or not returned.".into(),
            },
        ),
    ])
}

/// `map` painted at `w` × `h` (nearest pixel; row 0 at the bottom, as maps are stored).
fn paint(map: &Array2<Option<usize>>, palette: &[[u8; 3]], w: u32, h: u32) -> Vec<u8> {
    let (rows, cols) = map.dim();
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        let r = rows.saturating_sub(1).saturating_sub((y as usize * rows) / h.max(1) as usize);
        for x in 0..w {
            let c = ((x as usize * cols) / w.max(1) as usize).min(cols.saturating_sub(1));
            let colour = map.get((r, c)).copied().flatten().and_then(|k| palette.get(k)).copied().unwrap_or(GREY);
            rgb.extend_from_slice(&colour);
        }
    }
    rgb
}

impl Draw for ClassMaps {
    fn size(&self) -> (u32, u32) {
        // Wide enough for the title (DejaVu Sans at 17 px: about 10 px a character).
        let title = 20 + 10 * self.title.chars().count() as u32;
        ((PANEL.0 * self.panels.len().max(1) as u32 + LEGEND_W).max(title), TITLE_H + PANEL.1 + CAPTION_H)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String> {
        root.fill(&WHITE).map_err(err)?;
        root.draw_text(&self.title, &(FONT, 17).into_font().color(&BLACK), (10, 8)).map_err(err)?;
        let mut placed = Vec::new();
        for (i, (title, map, spacing)) in self.panels.iter().enumerate() {
            let x0 = (i as u32 * PANEL.0) as i32;
            let y0 = TITLE_H as i32;
            root.draw_text(title, &(FONT, 13).into_font().color(&BLACK), (x0 + 10, y0 + 4)).map_err(err)?;
            let (rows, cols) = map.dim();
            let (bw, bh) = (PANEL.0 - 20, PANEL.1 - 56);
            let aspect = cols as f64 / rows.max(1) as f64;
            let (w, h) = if aspect >= f64::from(bw) / f64::from(bh) {
                (bw, ((f64::from(bw) / aspect).round() as u32).max(1))
            } else {
                (((f64::from(bh) * aspect).round() as u32).max(1), bh)
            };
            let (mx, my) = (x0 + 10 + ((bw - w) / 2) as i32, y0 + 26);
            root.draw(&Rectangle::new([(mx - 1, my - 1), (mx + w as i32, my + h as i32)], BLACK.stroke_width(1)))
                .map_err(err)?;
            placed.push(Placed { x: mx, y: my, w, h, rgb: paint(map, &self.palette, w, h) });
            if let Some((len_m, label)) = scale_bar_length(0.3 * cols as f64 * spacing) {
                let px = (len_m / (cols as f64 * spacing) * f64::from(w)).round() as i32;
                let (bx, by) = (mx, my + h as i32 + 8);
                root.draw(&Rectangle::new([(bx, by), (bx + px, by + 3)], BLACK.filled())).map_err(err)?;
                root.draw_text(&label, &(FONT, 11).into_font().color(&BLACK), (bx + px + 6, by - 3)).map_err(err)?;
            }
        }
        let lx = (self.panels.len() as u32 * PANEL.0) as i32 + 12;
        for (k, (name, c)) in self.legend.iter().enumerate() {
            let y = TITLE_H as i32 + 30 + 24 * k as i32;
            root.draw(&Rectangle::new([(lx, y), (lx + 16, y + 16)], RGBColor(c[0], c[1], c[2]).filled()))
                .map_err(err)?;
            root.draw_text(name, &(FONT, 13).into_font().color(&BLACK), (lx + 22, y + 1)).map_err(err)?;
        }
        root.draw_text(
            &self.caption,
            &(FONT, 12).into_font().color(&RGBColor(60, 60, 60)),
            (10, (TITLE_H + PANEL.1) as i32 + 6),
        )
        .map_err(err)?;
        Ok(placed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dominant_class_is_matched_by_name_and_land_is_grey() {
        // Two pixels, classes listed in the other order by the retrieval.
        let f = ndarray::Array3::from_shape_vec((1, 2, 2), vec![0.2, 0.8, 0.9, 0.1]).unwrap_or_default();
        let classes = vec!["sand".to_string(), "coral".to_string()];
        let names = vec!["coral".to_string(), "sand".to_string()];
        let d = dominant(&f, &names, &classes, |_, c| c == 0);
        assert_eq!(d[[0, 0]], Some(0), "the larger fraction is `sand`, the truth's class 0");
        assert_eq!(d[[0, 1]], None, "not kept: land");
        let rgb = paint(&d, &[[1, 2, 3], [4, 5, 6]], 2, 1);
        assert_eq!(rgb, vec![1, 2, 3, 200, 200, 200]);
    }
}
