//! Export: the comparison figure (PNG and SVG: maps, colour bar, metrics table, a caption naming
//! the presets and the changed parameters) with the resolved configurations beside it; and the
//! data (cubes and metrics of A and B, as `shoal study` writes them). Every file is written
//! atomically; a failed write says why in the app.

use std::path::{Path, PathBuf};

use super::ShoalApp;
use super::raster::{Palette, product_map};
use crate::colormap::Scale;
use crate::study::{ComparisonPanel, comparison_figure, write_bytes, write_run};

/// Where exports go: the path typed in the app, or chosen in a save dialog.
fn target(app: &ShoalApp) -> PathBuf {
    PathBuf::from(app.ui.export_path.trim())
}

/// Write the comparison figure and the configurations next to `stem`.
pub fn write_figure(app: &ShoalApp, stem: &Path) -> Result<Vec<PathBuf>, String> {
    let runs: Vec<_> = app.link.shown.iter().map(|s| s.as_ref().map(|s| s.output.clone())).collect();
    let (Some(a), Some(b)) = (&runs[0], &runs[1]) else { return Err("no results to export yet".into()) };
    let kind = app.state.product;
    let mut panels = Vec::new();
    for (title, out, truth) in [("truth", a, true), ("A", a, false), ("B", b, false)] {
        if let Some(m) = product_map(out, kind, app.state.band, truth) {
            let label = if truth {
                title.to_string()
            } else {
                format!("{title}: {}", if title == "A" { &app.state.a.preset } else { &app.state.b.preset })
            };
            panels.push(ComparisonPanel { title: label, values: m.values, valid: m.valid });
        }
    }
    if panels.is_empty() {
        return Err(format!("the runs have no {} to show", kind.label()));
    }
    let refs: Vec<super::raster::MapData> =
        panels.iter().map(|p| super::raster::MapData { values: p.values.clone(), valid: p.valid.clone() }).collect();
    let refs: Vec<&super::raster::MapData> = refs.iter().collect();
    let scale = match super::raster::shared_palette(&refs, kind, false) {
        Palette::Sequential(s) => s,
        _ => Scale { lo: 0.0, hi: 8.0, log: false },
    };
    let mut table = vec![vec![
        "instrument".into(),
        "product".into(),
        "MAE %".into(),
        "bias %".into(),
        "returned %".into(),
        "requirement".into(),
    ]];
    for (name, out) in [("A", a), ("B", b)] {
        for ret in &out.retrievals {
            for v in &ret.metrics.variables {
                let m = &v.metrics;
                let req = app.state.requirements.mae_limit(&v.variable).map_or(String::new(), |l| {
                    format!("MAE ≤ {l:.0} %: {}", if m.mae_pct() <= l { "pass" } else { "FAIL" })
                });
                table.push(vec![
                    format!("{name} ({})", out.config.instrument.name),
                    format!("{} {}", ret.metrics.product, v.variable),
                    format!("{:.1}", m.mae_pct()),
                    format!("{:+.1}", m.bias_pct()),
                    format!("{:.1}", m.returned_pct),
                    req,
                ]);
            }
        }
    }
    let changes = app.state.changes();
    let caption = vec![
        format!(
            "A: {}   B: {}   scene: {}   retrieval: {:?}   resolution 1/{}",
            app.state.a.preset,
            app.state.b.preset,
            app.state.scene_name,
            app.state.retrieval,
            app.link.shown[0].as_ref().map_or(1, |s| s.decimation)
        ),
        if changes.is_empty() { "Presets unchanged.".into() } else { format!("Changed: {}", changes.join("; ")) },
        "Shoal: one colour scale for all panels; grey: land or not returned; metrics after Seegers et al. (2018)."
            .into(),
    ];
    let title = format!("{} — {}", app.state.study_name, kind.label());
    let fig = comparison_figure("comparison", &title, kind.label(), scale, false, panels, table, caption)
        .map_err(|e| e.to_string())?;
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    write_bytes(&png, &fig.png).map_err(|e| e.to_string())?;
    write_bytes(&svg, fig.svg.as_bytes()).map_err(|e| e.to_string())?;
    let mut written = vec![png, svg];
    for (name, out) in [("A", a), ("B", b)] {
        let path = PathBuf::from(format!("{}_config_{name}.ron", stem.display()));
        let text = out.config.to_ron().map_err(|e| e.to_string())?;
        write_bytes(&path, text.as_bytes()).map_err(|e| e.to_string())?;
        written.push(path);
    }
    Ok(written)
}

/// Write both runs' cubes and metrics under `dir`.
pub fn write_data(app: &ShoalApp, dir: &Path) -> Result<usize, String> {
    let mut n = 0;
    for (name, s) in ["A", "B"].iter().zip(&app.link.shown) {
        let Some(s) = s else { return Err("no results to export yet".into()) };
        let sub = dir.join(format!("{name}_{}", s.output.config.instrument.name));
        n += write_run(&s.output, &sub).map_err(|e| e.to_string())?.files.len();
    }
    Ok(n)
}

/// Export the figure to the typed path (a save dialog needs a desktop portal; the typed path
/// always works, and the files are named after it).
pub fn figure(app: &mut ShoalApp) {
    let stem = target(app);
    match write_figure(app, &stem) {
        Ok(files) => {
            app.ui.message =
                Some(format!("wrote {}", files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", ")))
        }
        Err(e) => app.ui.error = Some(format!("Export failed: {e}")),
    }
}

/// Export the data to the typed path.
pub fn data(app: &mut ShoalApp) {
    let dir = target(app);
    match write_data(app, &dir) {
        Ok(n) => app.ui.message = Some(format!("wrote {n} files under {}", dir.display())),
        Err(e) => app.ui.error = Some(format!("Export failed: {e}")),
    }
}

/// Save a window screenshot as PNG.
pub fn write_screenshot(path: &Path, img: &egui::ColorImage) -> Result<(), String> {
    use image::ImageEncoder;
    let [w, h] = img.size;
    let rgba: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&rgba, w as u32, h as u32, image::ExtendedColorType::Rgba8)
        .map_err(|e| format!("screenshot PNG: {e}"))?;
    write_bytes(path, &out).map_err(|e| e.to_string())
}
