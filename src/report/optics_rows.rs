//! The review pack's derived figures of the designs' optics and focal planes, shown when any
//! design states an effect (`instrument::effects`): the same figures as the app's Derived table
//! and the study's optics and focal-plane requirements.

use super::Derived;
use crate::engine::RunConfig;
use crate::instrument::effects;
use crate::instrument::spatial::nyquist_table;

/// The optics rows of `configs` (none when no design states an effect).
pub(super) fn optics_rows(configs: &[&RunConfig]) -> Vec<Derived> {
    if configs.iter().all(|c| c.instrument.effects.is_empty()) {
        return Vec::new();
    }
    let row = |name: &str, f: &dyn Fn(&RunConfig) -> String| Derived {
        name: name.into(),
        values: configs.iter().map(|c| f(c)).collect(),
    };
    vec![
        row("MTF at Nyquist, worst band (along / across)", &|c| {
            let budget = if effects::spatial_response(&c.instrument.effects).is_some() { "" } else { ", ideal optic" };
            nyquist_table(&c.instrument).ok().map_or_else(
                || "–".into(),
                |t| {
                    let along = t.iter().map(|r| r.along).fold(f64::INFINITY, f64::min);
                    let across = t.iter().map(|r| r.across).fold(f64::INFINITY, f64::min);
                    format!("{along:.2} / {across:.2}{budget}")
                },
            )
        }),
        row("polarisation sensitivity, largest band", &|c| {
            effects::polarisation_sensitivity(&c.instrument.effects)
                .map_or_else(|| "–".into(), |v| format!("{:.2} %", 100.0 * v))
        }),
        row("stray light 1 km past a bright edge, 443 nm", &|c| {
            effects::edge_ratio(&c.instrument.effects, 1000.0, 443.0)
                .map_or_else(|| "–".into(), |v| format!("{:.3} %", 100.0 * v))
        }),
        row("focal plane (TDI; non-linearity and registration left; coder)", &|c| focal_plane_summary(&c.instrument)),
    ]
}

/// One line of what a design's focal plane does: TDI stages, the non-linearity and band-to-band
/// registration the processor leaves, the coder's bound or rate target ("–" for an ideal one).
#[must_use]
pub fn focal_plane_summary(spec: &crate::instrument::InstrumentSpec) -> String {
    let list = &spec.effects;
    let mut parts = Vec::new();
    if let Some(t) = effects::tdi(list) {
        parts.push(format!("TDI {} ({})", t.stages, if t.digital { "digital" } else { "charge" }));
    }
    if effects::non_linearity(list).is_some() {
        parts.push(format!("{:.2} % at full well", crate::study::nonlinearity_left_pct(spec)));
    }
    if effects::misregistration(list).is_some() {
        parts.push(format!("{:.3} px rms", crate::study::registration_px(spec)));
    }
    if let Some(p) = effects::fixed_patterns(list) {
        parts.push(format!("striping {:.2} %, {:.2} % dead", 100.0 * p.gain_drift, 100.0 * p.dead_fraction));
    }
    if let Some(c) = effects::compression(list) {
        parts.push(if c.bits_per_sample > 0.0 {
            format!("coder ≤ {:.1} bit/sample", c.bits_per_sample)
        } else if c.max_error_dn > 0 {
            format!("coder ±{} DN", c.max_error_dn)
        } else {
            "lossless coder".into()
        });
    }
    if let Some(b) = effects::binning(list) {
        parts.push(format!("binned {}", b.describe()));
    }
    if let Some(k) = effects::spectral_knowledge(list) {
        parts.push(k.describe());
    }
    if parts.is_empty() { "–".into() } else { parts.join("; ") }
}
