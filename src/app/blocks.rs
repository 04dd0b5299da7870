//! What each redraw of a map needs, computed once per map and kept: the block sums of its pixels
//! at the display size, and the sorted sample its colour scale is drawn from.
//!
//! A map on screen is block-averaged down to at most `max_side` pixels on its long side, and its
//! colour scale is shared with the maps beside it. Moving a slider of A changes A's map and
//! therefore the shared scale, so B's map must be recoloured — but B's pixels need not be
//! revisited: a block's colour is the palette at the block's mean position, and the position is
//! affine in `v` (linear scales, differences) or in `ln v` (log scales)
//! ([`crate::colormap::Scale::position_of_mean`]), so the sums of `v` and `ln v` per block are enough. B at full
//! resolution (1.5 M pixels) is then recoloured from ~0.35 M block sums without a logarithm.

use std::sync::Arc;

use super::raster::{Image, MapData, Palette};
use crate::colormap::{categorical, diverging, viridis};

/// Sums of a map's valid pixels per display block.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocks {
    /// Blocks across.
    pub width: usize,
    /// Blocks down.
    pub height: usize,
    /// Σ v per block (row-major, first map row first).
    sum: Vec<f64>,
    /// Σ ln(max(v, f64::MIN_POSITIVE)) per block.
    sum_ln: Vec<f64>,
    /// Valid pixels per block.
    count: Vec<u32>,
    /// The first valid value of each block (row-major inside it): its class, for class maps.
    first: Vec<f32>,
    /// Map pixels per block side, and the map's rows and columns (a block at the edge is smaller).
    step: usize,
    rows: usize,
    cols: usize,
}

impl Blocks {
    /// The block sums of `map` at most `max_side` blocks on its long side.
    #[must_use]
    pub fn of(map: &MapData, max_side: usize) -> Self {
        let (rows, cols) = map.values.dim();
        let step = rows.max(cols).div_ceil(max_side.max(1)).max(1);
        let (height, width) = (rows.div_ceil(step).max(1), cols.div_ceil(step).max(1));
        let n = width * height;
        let mut b = Self {
            width,
            height,
            sum: vec![0.0; n],
            sum_ln: vec![0.0; n],
            count: vec![0; n],
            first: vec![0.0; n],
            step,
            rows,
            cols,
        };
        for ((r, c), v) in map.values.indexed_iter() {
            if !map.valid[[r, c]] {
                continue;
            }
            let k = (r / step) * width + c / step;
            if b.count[k] == 0 {
                b.first[k] = *v;
            }
            let v = f64::from(*v);
            b.sum[k] += v;
            b.sum_ln[k] += v.max(f64::MIN_POSITIVE).ln();
            b.count[k] += 1;
        }
        b
    }

    /// Is block (y, x) drawn in colour? Where only some of its pixels were returned, in
    /// proportion: its returned share against an ordered-dither threshold
    /// ([`crate::colormap::dithered`]), so the
    /// grey share of any part of the image is the share not returned there, at any zoom. (A
    /// block coloured by any returned pixel showed a product with 22 % returned as ~90 % coloured.)
    fn lit(&self, y: usize, x: usize) -> bool {
        let count = self.count[y * self.width + x];
        let pixels = (self.step.min(self.rows - y * self.step) * self.step.min(self.cols - x * self.step)).max(1);
        crate::colormap::dithered(f64::from(count) / pixels as f64, x, y)
    }

    /// The image in `palette`: each block's mean position on the scale (sequential), mean value
    /// (diverging), first class (classes) or any disagreement (agreement); the first map row at
    /// the bottom (flight direction up); blocks not returned, and partly returned ones in
    /// proportion ([`Self::lit`]), transparent grey.
    #[must_use]
    pub fn colorize(&self, palette: Palette) -> Image {
        let (w, h) = (self.width, self.height);
        let mut rgba = vec![0u8; w * h * 4];
        let position = match palette {
            Palette::Sequential(s) => Some(s.position_of_mean_fn()),
            _ => None,
        };
        for y in 0..h {
            for x in 0..w {
                let k = y * w + x;
                let n = f64::from(self.count[k]);
                // (A disagreement anywhere in the block shows, however little was returned.)
                let shown = self.lit(y, x) || (palette == Palette::Agreement && self.sum[k] > 0.0);
                let colour = if self.count[k] == 0 || !shown {
                    super::theme::NOT_RETURNED
                } else {
                    let c = match palette {
                        Palette::Sequential(_) => {
                            viridis(position.map_or(f64::NAN, |p| p(self.sum[k] / n, self.sum_ln[k] / n)))
                        }
                        Palette::Diverging(bound) => diverging((self.sum[k] / n) / bound.max(f64::MIN_POSITIVE)),
                        Palette::Classes => categorical(f64::from(self.first[k]).max(0.0) as usize),
                        // Any disagreement in the block shows (a mean above 0).
                        Palette::Agreement => super::theme::AGREEMENT[usize::from(self.sum[k] > 0.0)],
                    };
                    [c[0], c[1], c[2], 255]
                };
                let i = ((h - 1 - y) * w + x) * 4;
                rgba[i..i + 4].copy_from_slice(&colour);
            }
        }
        Image { width: w, height: h, rgba }
    }
}

/// The finite valid values of `map` a shared colour scale is drawn from, ascending: every
/// `len / 50 000`-th pixel (at least every one), so a scale over full-resolution maps costs a
/// sort of at most ~50 000 values per map, once.
#[must_use]
pub fn palette_sample(map: &MapData) -> Vec<f64> {
    let step = (map.values.len() / 50_000).max(1);
    let mut v: Vec<f64> = map
        .values
        .iter()
        .zip(map.valid.iter())
        .step_by(step)
        .filter(|(_, ok)| **ok)
        .map(|(v, _)| f64::from(*v))
        .filter(|v| v.is_finite())
        .collect();
    v.sort_unstable_by(f64::total_cmp);
    v
}

/// A map with its palette sample and block sums at one display size.
#[derive(Debug, Clone, PartialEq)]
pub struct Prepared {
    /// The map.
    pub data: Arc<MapData>,
    /// [`palette_sample`] of it.
    pub sample: Vec<f64>,
    /// [`Blocks::of`] it at the display size.
    pub blocks: Blocks,
}

impl Prepared {
    /// Prepare `data` for display at most `max_side` pixels on its long side.
    #[must_use]
    pub fn new(data: Arc<MapData>, max_side: usize) -> Self {
        Self { sample: palette_sample(&data), blocks: Blocks::of(&data, max_side), data }
    }
}

#[cfg(test)]
mod tests {
    use ndarray::Array2;

    use super::*;
    use crate::colormap::Scale;

    /// The colour of each block as the pixels give it: the mean of each valid pixel's position.
    fn per_pixel(map: &MapData, scale: Scale, max_side: usize) -> Vec<[u8; 3]> {
        let (rows, cols) = map.values.dim();
        let step = rows.max(cols).div_ceil(max_side);
        let (h, w) = (rows.div_ceil(step), cols.div_ceil(step));
        let mut out = Vec::new();
        for y in (0..h).rev() {
            for x in 0..w {
                let (mut sum, mut n) = (0.0, 0);
                for r in y * step..((y + 1) * step).min(rows) {
                    for c in x * step..((x + 1) * step).min(cols) {
                        if map.valid[[r, c]] {
                            sum += scale.position(f64::from(map.values[[r, c]]));
                            n += 1;
                        }
                    }
                }
                let grey = crate::app::theme::NOT_RETURNED;
                out.push(if n == 0 { [grey[0], grey[1], grey[2]] } else { viridis(sum / f64::from(n)) });
            }
        }
        out
    }

    #[test]
    fn block_sums_colour_as_the_pixels_do_on_log_and_linear_scales() {
        // Values over three decades, some invalid, a block size that does not divide the map.
        let values =
            Array2::from_shape_fn((37, 23), |(r, c)| 10f32.powf(((r * 7 + c * 13) % 29) as f32 / 29.0 * 3.0 - 1.0));
        let valid = Array2::from_shape_fn((37, 23), |(r, c)| (r + 2 * c) % 5 != 0);
        let map = MapData { values, valid };
        let blocks = Blocks::of(&map, 10);
        assert_eq!((blocks.width, blocks.height), (6, 10));
        for scale in [Scale { lo: 0.2, hi: 50.0, log: true }, Scale { lo: 0.0, hi: 80.0, log: false }] {
            let image = blocks.colorize(Palette::Sequential(scale));
            let want = per_pixel(&map, scale, 10);
            for (k, px) in image.rgba.chunks(4).enumerate() {
                let (got, want) = (&px[..3], want[k]);
                // A partly returned block drawn grey by the dither is grey, whatever its mean.
                let (x, y) = (k % blocks.width, blocks.height - 1 - k / blocks.width);
                if !blocks.lit(y, x) {
                    assert_eq!(got, &crate::app::theme::NOT_RETURNED[..3], "block {k}");
                    continue;
                }
                // Σ position / n and the position of Σ v / n differ by rounding only: at most
                // one step of a colour channel where a value falls on a step's edge.
                assert!(
                    got.iter().zip(want).all(|(a, b)| a.abs_diff(b) <= 1),
                    "block {k}: {got:?} against {want:?} ({scale:?})"
                );
            }
        }
    }

    /// A product returned at scattered pixels (22 %, as QAA over Lake Hume) shows as much grey
    /// as it did not return, whole and zoomed in: within 10 points at zooms 1, 4 and 16.
    #[test]
    fn a_scattered_return_is_grey_in_proportion_at_every_zoom() {
        let (rows, cols) = (2000, 1024);
        // A deterministic scatter: a pixel is returned when its hash falls under 0.22.
        let hash = |r: usize, c: usize| {
            let mut z = (r as u64) << 32 | c as u64;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        let valid = Array2::from_shape_fn((rows, cols), |(r, c)| hash(r, c) < 0.22);
        let map = MapData { values: Array2::from_elem((rows, cols), 5.0), valid: valid.clone() };
        let blocks = Blocks::of(&map, 720);
        let image = blocks.colorize(Palette::Sequential(Scale { lo: 1.0, hi: 10.0, log: true }));
        let grey = crate::app::theme::NOT_RETURNED;
        let (w, h) = (image.width, image.height);
        let is_grey = |x: usize, y: usize| image.rgba[(y * w + x) * 4..][..3] == grey[..3];
        for zoom in [1usize, 4, 16] {
            // The centre window of 1/zoom of each side, in image cells and in map pixels (the
            // image's first row is the map's last).
            let (iw, ih) = (w / zoom, h / zoom);
            let (x0, y0) = ((w - iw) / 2, (h - ih) / 2);
            let cells = iw * ih;
            let grey_cells =
                (y0..y0 + ih).flat_map(|y| (x0..x0 + iw).map(move |x| (x, y))).filter(|&(x, y)| is_grey(x, y));
            let grey_pct = 100.0 * grey_cells.count() as f64 / cells as f64;
            let step = blocks.step;
            let (r0, r1) = ((h - y0 - ih) * step, ((h - y0) * step).min(rows));
            let (c0, c1) = (x0 * step, ((x0 + iw) * step).min(cols));
            let window = valid.slice(ndarray::s![r0..r1, c0..c1]);
            let returned_pct = 100.0 * window.iter().filter(|v| **v).count() as f64 / window.len() as f64;
            assert!(
                (grey_pct - (100.0 - returned_pct)).abs() < 10.0,
                "zoom {zoom}: {grey_pct:.1} % grey where {returned_pct:.1} % was returned"
            );
        }
        // Whole blocks returned stay coloured, blocks of nothing stay grey.
        let full = MapData { values: Array2::from_elem((40, 40), 5.0), valid: Array2::from_elem((40, 40), true) };
        let b = Blocks::of(&full, 7);
        assert!((0..b.height).all(|y| (0..b.width).all(|x| b.lit(y, x))), "an edge block is its own size");
    }
}
