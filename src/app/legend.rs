//! The maps' legends: the colour bar (a scale, or classes by name), the scale bar in ground
//! distance, and numbers formatted for the hover readout.

use egui::{Color32, Pos2, Rect, Sense, Vec2};

use super::raster::Palette;
use crate::colormap::{categorical, diverging, viridis};

/// The colour bar of `palette`, `height` tall, titled `label` (classes by their names).
pub(super) fn colour_bar(ui: &mut egui::Ui, palette: Palette, height: f32, label: &str, classes: &[String]) -> Rect {
    let (rect, _) = ui.allocate_exact_size(Vec2::new(86.0, height), Sense::hover());
    let painter = ui.painter_at(rect);
    let bar = Rect::from_min_size(rect.min + Vec2::new(4.0, 16.0), Vec2::new(16.0, height - 40.0));
    let steps = 64;
    let text = ui.visuals().text_color();
    painter.text(rect.min, egui::Align2::LEFT_TOP, label, egui::FontId::proportional(11.0), text);
    // Classes by name (substrates, SIOP sets); A − B of classes as agree / differ.
    let named: Option<Vec<([u8; 3], String)>> = match palette {
        Palette::Classes => {
            Some(classes.iter().take(12).enumerate().map(|(k, n)| (categorical(k), n.replace('_', " "))).collect())
        }
        Palette::Agreement => {
            Some(vec![(super::theme::AGREEMENT[0], "same".into()), (super::theme::AGREEMENT[1], "different".into())])
        }
        _ => None,
    };
    if let Some(named) = named {
        for (k, (c, name)) in named.iter().enumerate() {
            let r = Rect::from_min_size(bar.min + Vec2::new(0.0, k as f32 * 16.0), Vec2::splat(12.0));
            painter.rect_filled(r, 0.0, Color32::from_rgb(c[0], c[1], c[2]));
            painter.text(
                r.right_center() + Vec2::new(4.0, 0.0),
                egui::Align2::LEFT_CENTER,
                name,
                egui::FontId::proportional(10.0),
                text,
            );
        }
        return rect;
    }
    for k in 0..steps {
        let t = (k as f64 + 0.5) / steps as f64;
        let c = match palette {
            Palette::Sequential(_) => viridis(t),
            Palette::Diverging(_) => diverging(2.0 * t - 1.0),
            Palette::Classes | Palette::Agreement => [0, 0, 0],
        };
        let y1 = bar.max.y - bar.height() * k as f32 / steps as f32;
        let y0 = bar.max.y - bar.height() * (k + 1) as f32 / steps as f32;
        painter.rect_filled(Rect::from_x_y_ranges(bar.x_range(), y0..=y1), 0.0, Color32::from_rgb(c[0], c[1], c[2]));
    }
    // Round ticks (1, 3, 10, 30 …) where they fall on the bar, not the bar's odd ends.
    let ticks: Vec<(f64, f64)> = match palette {
        Palette::Sequential(s) => s.nice_ticks().into_iter().map(|v| (v, s.position(v))).collect(),
        Palette::Diverging(b) => crate::colormap::Scale { lo: -b, hi: b, log: false }
            .nice_ticks()
            .into_iter()
            .map(|v| (v, 0.5 * (v / b + 1.0)))
            .collect(),
        Palette::Classes | Palette::Agreement => Vec::new(),
    };
    let [r, g, b, a] = super::theme::NOT_RETURNED;
    let swatch = Rect::from_min_size(Pos2::new(bar.min.x, bar.max.y + 6.0), Vec2::splat(10.0));
    painter.rect_filled(swatch, 0.0, Color32::from_rgba_unmultiplied(r, g, b, a));
    painter.text(
        swatch.right_center() + Vec2::new(4.0, 0.0),
        egui::Align2::LEFT_CENTER,
        "not returned",
        egui::FontId::proportional(9.0),
        text,
    );
    for (v, t) in ticks {
        if !(-1e-9..=1.0 + 1e-9).contains(&t) {
            continue;
        }
        let y = bar.max.y - bar.height() * t as f32;
        painter.text(
            Pos2::new(bar.max.x + 4.0, y),
            egui::Align2::LEFT_CENTER,
            crate::colormap::significant(v, 4),
            egui::FontId::proportional(10.0),
            text,
        );
    }
    rect
}

/// A scale bar under a map `width_px` wide showing `ground_m` across: the longest round length
/// (1-2-5 steps, 100 m to 500 km) that fits in 40 % of the width.
pub(super) fn scale_bar(ui: &mut egui::Ui, width_px: f32, ground_m: f64) {
    let (rect, _) = ui.allocate_exact_size(Vec2::new(width_px, 16.0), Sense::hover());
    if !(ground_m.is_finite() && ground_m > 0.0) {
        return;
    }
    let m_per_px = ground_m / f64::from(width_px.max(1.0));
    let lengths = [100.0, 200.0, 500.0, 1e3, 2e3, 5e3, 1e4, 2e4, 5e4, 1e5, 2e5, 5e5];
    let Some(&length) = lengths.iter().rev().find(|&&l| l / m_per_px <= 0.4 * f64::from(width_px)) else { return };
    let px = (length / m_per_px) as f32;
    let colour = ui.visuals().text_color();
    let painter = ui.painter_at(rect);
    let y = rect.min.y + 4.0;
    let (x0, x1) = (rect.min.x + 2.0, rect.min.x + 2.0 + px);
    let stroke = egui::Stroke::new(1.5, colour);
    painter.line_segment([Pos2::new(x0, y), Pos2::new(x1, y)], stroke);
    for x in [x0, x1] {
        painter.line_segment([Pos2::new(x, y - 3.0), Pos2::new(x, y + 3.0)], stroke);
    }
    let label = if length >= 1e3 { format!("{} km", length / 1e3) } else { format!("{length} m") };
    painter.text(Pos2::new(x1 + 6.0, y), egui::Align2::LEFT_CENTER, label, egui::FontId::proportional(10.0), colour);
}

pub(super) fn format_value(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.4}")
    }
}
