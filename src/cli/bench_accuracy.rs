//! `shoal bench --accuracy`: the cost-of-accuracy table (see `sweep::cost`) for the CubeSat over
//! Lake Hume.

use std::fmt::Write as _;

use super::CliError;
use crate::control::RunControl;
use crate::engine::RunConfig;
use crate::instrument::InstrumentSpec;
use crate::scene::SceneSpec;
use crate::sweep::cost_of_accuracy;

/// The cost-of-accuracy table (Markdown), printed row by row.
pub fn accuracy_rows(out: &mut String, quick: bool) -> Result<(), CliError> {
    let mut base = RunConfig::new(SceneSpec::preset("lake_hume_bloom")?, InstrumentSpec::preset("cubesat")?);
    base.retrievals = vec![crate::retrieval::RetrievalSpec::Almi {
        siop_sets: crate::retrieval::sets::default_almi_sets(),
        settings: crate::retrieval::AlmiSettings::default(),
    }];
    base.fidelity.decimation = if quick { 4 } else { 1 };
    let _ = writeln!(out, "\n## Cost of accuracy (CubeSat over Lake Hume, aLMI, seed 1; a fresh engine per row)\n");
    let _ = writeln!(
        out,
        "| setting | time s | × reference | chl MAE % | ΔMAE vs reference (points) | chl per pixel vs reference, median % | Rrs(443) per pixel, median % |\n|---|---|---|---|---|---|---|"
    );
    super::output::emit(&std::mem::take(out), None)?;
    let pct = |v: Option<f64>| v.map_or_else(|| "– (other grid)".to_string(), |v| format!("{v:.3}"));
    let mut failed = None;
    cost_of_accuracy(&base, &RunControl::new(), |r| {
        let line = format!(
            "| {} | {:.2} | {:.2} | {:.1} | {:+.2} | {} | {} |\n",
            r.label,
            r.seconds,
            r.ratio,
            r.chl_mae_pct,
            r.delta_mae_pct,
            pct(r.chl_pixel_pct),
            pct(r.rrs_pixel_pct)
        );
        if let Err(e) = super::output::emit(&line, None) {
            failed = Some(e);
        }
    })?;
    if let Some(e) = failed {
        return Err(e);
    }
    let _ = writeln!(
        out,
        "\nEach row changes one setting from the defaults (the last, three). Per-pixel columns compare the same pixels with the same noise, so they isolate the setting's own error; a preview's ΔMAE mixes that with fewer pixels in the sample."
    );
    Ok(())
}
