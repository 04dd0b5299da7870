//! The app's colours, in one place: what each colour means is decided here, and panels, plots
//! and maps name the meaning (`theme::FAIL`), not the RGB.
//!
//! Design colours are ColorBrewer Set1 (Harrower & Brewer 2003, The Cartographic Journal 40,
//! 27–37) in its order, red and blue first (A and B), without its yellow (unreadable on white)
//! and with its grey, the truth's colour, replaced by matplotlib's `tab:cyan` (#17becf).

use egui::Color32;

/// Design A, B, C, … (plot lines, bars, points, the design list's swatches).
pub const DESIGN: [Color32; super::designs::MAX_DESIGNS] = [
    Color32::from_rgb(228, 26, 28),
    Color32::from_rgb(55, 126, 184),
    Color32::from_rgb(77, 175, 74),
    Color32::from_rgb(152, 78, 163),
    Color32::from_rgb(255, 127, 0),
    Color32::from_rgb(166, 86, 40),
    Color32::from_rgb(247, 129, 191),
    Color32::from_rgb(23, 190, 207),
];

/// Design `i`'s colour.
#[must_use]
pub fn design(i: usize) -> Color32 {
    DESIGN[i % DESIGN.len()]
}
/// The truth in plots.
pub const TRUTH: Color32 = Color32::GRAY;
/// Reference lines (1:1).
pub const REFERENCE: Color32 = Color32::DARK_GRAY;
/// A requirement met, and the requirement's line in plots.
pub const PASS: Color32 = Color32::from_rgb(40, 150, 40);
/// A requirement failed, an error, a refused value.
pub const FAIL: Color32 = Color32::from_rgb(200, 40, 40);
/// Near a limit (feasibility amber).
pub const WARN: Color32 = Color32::from_rgb(200, 130, 0);
/// A banner that needs the user's attention (the scene does not suit the retrieval).
pub const NOTICE: Color32 = Color32::from_rgb(200, 90, 0);
/// Maps: pixels where the pair agrees, then disagree (class products).
pub const AGREEMENT: [[u8; 3]; 2] = [[170, 200, 170], [215, 48, 39]];

/// Maps: land and pixels not returned (RGBA, translucent over the panel).
pub const NOT_RETURNED: [u8; 4] = [160, 160, 160, 90];

/// A categorical colour (sweep series), from [`crate::colormap::categorical`].
#[must_use]
pub fn category(k: usize) -> Color32 {
    let c = crate::colormap::categorical(k);
    Color32::from_rgb(c[0], c[1], c[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance between two colours in RGB (0–441).
    fn apart(a: Color32, b: Color32) -> f64 {
        let d = |x: u8, y: u8| (f64::from(x) - f64::from(y)).powi(2);
        (d(a.r(), b.r()) + d(a.g(), b.g()) + d(a.b(), b.b())).sqrt()
    }

    #[test]
    fn every_design_colour_stands_apart_from_the_truth_and_the_others() {
        for (i, &c) in DESIGN.iter().enumerate() {
            // The truth's grey and the 1:1 line's dark grey: no design may pass for either.
            assert!(apart(c, TRUTH) > 60.0 && apart(c, REFERENCE) > 60.0, "design {i}: {c:?}");
            for (j, &o) in DESIGN.iter().enumerate().skip(i + 1) {
                assert!(apart(c, o) > 60.0, "designs {i} and {j}: {c:?} {o:?}");
            }
        }
        // The study figures draw the designs with the same colours.
        for (i, &c) in DESIGN.iter().enumerate() {
            let [r, g, b] = crate::colormap::categorical(i);
            assert_eq!((c.r(), c.g(), c.b()), (r, g, b), "design {i}");
        }
    }
}
