//! Drawing a figure once to PNG and once to SVG. Plotters draws text and axes with the embedded
//! DejaVu Sans (no system fonts); map rasters are painted into the PNG directly and embedded in
//! the SVG as base64 PNG images, so the SVG stays small and its text stays vector.

use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;

use ndarray::Array2;

use super::StudyError;
use crate::colormap::{Scale, viridis};

/// One figure in both formats.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// File stem.
    pub name: String,
    /// PNG bytes.
    pub png: Vec<u8>,
    /// SVG text.
    pub svg: String,
}

const FONT_BYTES: &[u8] = crate::assets::DEJAVU_SANS_TTF;
pub(super) const FONT: &str = "sans-serif";

fn fonts() -> Result<(), StudyError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok());
    if ok { Ok(()) } else { Err(StudyError::Io("the embedded font does not load".into())) }
}

/// A raster placed on the figure (painted into the PNG, embedded in the SVG).
pub(super) struct Placed {
    /// Left edge, px.
    pub(super) x: i32,
    /// Top edge, px.
    pub(super) y: i32,
    /// Width, px.
    pub(super) w: u32,
    /// Height, px.
    pub(super) h: u32,
    /// Row-major RGB bytes, `w · h · 3`.
    pub(super) rgb: Vec<u8>,
}

pub(super) trait Draw {
    fn size(&self) -> (u32, u32);
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<Vec<Placed>, String>;
}

pub(super) fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}

/// Base64 (RFC 4648, with padding) for data URIs: the SVG figures' rasters and the review
/// pack's downloads.
#[must_use]
pub fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                s.push(T[((n >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

fn png(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>, StudyError> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgb, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| StudyError::Io(format!("PNG: {e}")))?;
    Ok(out)
}

pub(super) fn render(name: &str, fig: &impl Draw) -> Result<Figure, StudyError> {
    fonts()?;
    let (w, h) = fig.size();
    let fail = |e: String| StudyError::Io(format!("figure {name}: {e}"));
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let placed = {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let placed = fig.draw(&root).map_err(fail)?;
        root.present().map_err(|e| fail(err(e)))?;
        placed
    };
    for p in &placed {
        for row in 0..p.h {
            for col in 0..p.w {
                let (x, y) = (p.x + col as i32, p.y + row as i32);
                if x >= 0 && y >= 0 && (x as u32) < w && (y as u32) < h {
                    let dst = ((y as u32 * w + x as u32) * 3) as usize;
                    let src = ((row * p.w + col) * 3) as usize;
                    buf[dst..dst + 3].copy_from_slice(&p.rgb[src..src + 3]);
                }
            }
        }
    }
    let png_bytes = png(&buf, w, h)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        fig.draw(&root).map_err(fail)?;
        root.present().map_err(|e| fail(err(e)))?;
    }
    let mut images = String::new();
    for p in &placed {
        let data = base64(&png(&p.rgb, p.w, p.h)?);
        images.push_str(&format!(
            "<image x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" style=\"image-rendering:pixelated\" href=\"data:image/png;base64,{data}\"/>\n",
            p.x, p.y, p.w, p.h
        ));
    }
    if let Some(end) = svg.rfind("</svg>") {
        svg.insert_str(end, &images);
    }
    Ok(Figure { name: name.to_string(), png: png_bytes, svg })
}

pub(super) fn tick_label(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.3}").trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        let digits = (-v.abs().log10()).ceil() as usize + 1;
        format!("{v:.digits$}")
    }
}

/// The colour of scale position `t` (0–1) on the viridis or the diverging palette.
pub(super) fn colour(t: f64, diverging: bool) -> [u8; 3] {
    if diverging { crate::colormap::diverging(2.0 * t - 1.0) } else { viridis(t) }
}

/// Rasterise `panel` into `w × h` pixels (block means in scale space; grey where invalid, and
/// where partly invalid in proportion).
pub(super) fn raster(panel: &Panel, scale: &Scale, w: u32, h: u32, diverging: bool) -> Vec<u8> {
    let (rows, cols) = panel.values.dim();
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    for y in 0..h {
        for x in 0..w {
            // Row 0 (the first line) at the bottom: the image reads in the flight direction.
            let yf = h - 1 - y;
            let (r0, r1) = (
                (yf as usize * rows) / h as usize,
                (((yf + 1) as usize * rows) / h as usize).max(yf as usize * rows / h as usize + 1),
            );
            let (c0, c1) = (
                (x as usize * cols) / w as usize,
                (((x + 1) as usize * cols) / w as usize).max(x as usize * cols / w as usize + 1),
            );
            let (mut sum, mut n) = (0.0, 0usize);
            for r in r0..r1.min(rows) {
                for c in c0..c1.min(cols) {
                    if panel.valid[[r, c]] {
                        sum += scale.position(f64::from(panel.values[[r, c]]));
                        n += 1;
                    }
                }
            }
            // Partly returned cells grey in proportion (`colormap::dithered`).
            let cell = (r1.min(rows) - r0) * (c1.min(cols) - c0);
            let lit = n > 0 && crate::colormap::dithered(n as f64 / cell.max(1) as f64, x as usize, yf as usize);
            let colour = if lit { colour(sum / n as f64, diverging) } else { [200, 200, 200] };
            let i = ((y * w + x) * 3) as usize;
            rgb[i..i + 3].copy_from_slice(&colour);
        }
    }
    rgb
}

/// One map of a figure: values and where they are valid (elsewhere grey).
pub(super) struct Panel {
    pub(super) title: String,
    pub(super) values: Array2<f32>,
    pub(super) valid: Array2<bool>,
    /// Ground distance between neighbouring pixels, m (0: no scale bar).
    pub(super) spacing_m: f64,
}

/// The longest 1, 2 or 5 × 10ᵏ m that fits in `max_m` (a scale bar's length), with its label.
pub(super) fn scale_bar_length(max_m: f64) -> Option<(f64, String)> {
    if !(max_m.is_finite() && max_m > 0.0) {
        return None;
    }
    let decade = 10f64.powf(max_m.log10().floor());
    let len = [5.0, 2.0, 1.0].into_iter().map(|k| k * decade).find(|l| *l <= max_m)?;
    let label = if len >= 1000.0 { format!("{} km", len / 1000.0) } else { format!("{len} m") };
    Some((len, label))
}

/// A per-band chart: band centre (nm, with 15 nm of margin) against a logarithmic `y_desc` (a
/// factor 1.6 of margin) spanning the finite positive `ys`; the SNR and Rrs-error figures'
/// frame. An error, `nothing`, when there is no x or no such y.
pub(super) fn band_log_chart<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    y_desc: &str,
    xs: impl Iterator<Item = f64>,
    ys: impl Iterator<Item = f64>,
    nothing: &str,
) -> Result<ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, LogCoord<f64>>>, String> {
    let (x_lo, x_hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
    let (y_lo, y_hi) = ys
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| (lo.min(y), hi.max(y)));
    if !(x_lo.is_finite() && y_lo.is_finite()) {
        return Err(nothing.into());
    }
    let (x_lo, x_hi) = (x_lo - 15.0, x_hi + 15.0);
    let (y_lo, y_hi) = (y_lo / 1.6, y_hi * 1.6);
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, 16))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x_lo..x_hi, (y_lo..y_hi).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("band centre (nm)")
        .y_desc(y_desc)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_bars_are_round_lengths() {
        assert_eq!(scale_bar_length(3_700.0), Some((2_000.0, "2 km".into())));
        assert_eq!(scale_bar_length(640.0), Some((500.0, "500 m".into())));
        assert_eq!(scale_bar_length(1.0e4), Some((10_000.0, "10 km".into())));
        assert_eq!(scale_bar_length(0.0), None);
    }

    #[test]
    fn base64_matches_rfc4648_vectors() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }
}
