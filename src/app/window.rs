//! The window around the app: fonts, icon, and opening it with eframe.

use super::{AppOptions, ShoalApp};

/// Add DejaVu Sans after egui's default fonts: units need glyphs they lack (m⁻³, e⁻, µm).
pub(super) fn install_fonts(ctx: &egui::Context) {
    use egui::epaint::text::{FontInsert, FontPriority, InsertFontFamily};
    let families = [egui::FontFamily::Proportional, egui::FontFamily::Monospace]
        .into_iter()
        .map(|family| InsertFontFamily { family, priority: FontPriority::Lowest })
        .collect();
    ctx.add_font(FontInsert::new("dejavu-sans", egui::FontData::from_static(crate::assets::DEJAVU_SANS_TTF), families));
}

/// The app icon: a sine swell over a depth gradient, drawn here (no image file).
fn icon() -> egui::IconData {
    let n = 64u32;
    let mut rgba = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let wave = 24.0 + 6.0 * (f64::from(x) / 64.0 * std::f64::consts::TAU).sin();
            let c = if f64::from(y) < wave {
                [240, 246, 250]
            } else {
                crate::colormap::viridis(0.15 + 0.6 * f64::from(y) / 64.0)
            };
            rgba.extend_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }
    egui::IconData { rgba, width: n, height: n }
}

/// Open the app window (blocks until it closes).
pub fn run(options: AppOptions) -> Result<(), String> {
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("Shoal — instrument trade-offs over water")
            .with_inner_size(options.size.unwrap_or([1500.0, 960.0]))
            .with_min_inner_size([900.0, 600.0])
            .with_icon(icon()),
        // eframe's own file (window size and egui's memory) beside the session, so that with
        // SHOAL_HOME set nothing is written outside it.
        persistence_path: Some(crate::library::home_dir().join("window.ron")),
        // A size asked for on the command line wins over the one saved with the session.
        persist_window: options.size.is_none(),
        ..Default::default()
    };
    eframe::run_native("shoal", native, Box::new(move |cc| Ok(Box::new(ShoalApp::new(cc, options)))))
        .map_err(|e| format!("cannot open the app window: {e} (no display? run `shoal study` for the headless study)"))
}
