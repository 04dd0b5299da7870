//! The review pack's derived figures of the designs' optics, shown when any design states an
//! optical effect (`instrument::effects`): the same figures as the app's Derived table and the
//! study's optics requirements.

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
    ]
}
