//! `shoal mtf`: the system MTF at Nyquist of every band of one or more instruments, on each
//! band's focal plane, from the MTF budget each states (an ideal optic where it states none;
//! `instrument::effects::mtf`), with the budget's parts along track.

use super::CliError;
use super::simulate::INSTRUMENTS;
use crate::instrument::InstrumentSpec;
use crate::instrument::spatial::nyquist_table;

/// Arguments of `shoal mtf`.
#[derive(Debug, clap::Args)]
pub struct MtfArgs {
    /// Instruments: built-in or library names, or .ron files (default: every built-in preset).
    pub instruments: Vec<String>,
    /// Print only the worst band of each plane (the figure a review states).
    #[arg(long)]
    pub worst: bool,
}

/// Run `shoal mtf`.
pub fn run(args: &MtfArgs) -> Result<(), CliError> {
    let specs: Vec<InstrumentSpec> = if args.instruments.is_empty() {
        InstrumentSpec::preset_names()
            .iter()
            .map(|n| InstrumentSpec::preset(n).map_err(|e| CliError::Run(e.to_string())))
            .collect::<Result<_, _>>()?
    } else {
        args.instruments.iter().map(|a| INSTRUMENTS.resolve(a).map(|v| v.0)).collect::<Result<_, _>>()?
    };
    super::output::emit(&table(&specs, args.worst)?, None)
}

/// The Markdown table of `specs`.
pub(crate) fn table(specs: &[InstrumentSpec], worst: bool) -> Result<String, CliError> {
    let mut out = String::from(
        "| instrument | budget | plane | band | centre nm | GSD m | MTF along | MTF across | diffraction | wavefront | pixel | diffusion | crosstalk | jitter | smear | TDI line rate | TDI transfer |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for spec in specs {
        let rows = nyquist_table(spec).map_err(|e| CliError::Input(format!("{}: {e}", spec.name)))?;
        let stated =
            if crate::instrument::effects::spatial_response(&spec.effects).is_some() { "stated" } else { "ideal" };
        let mut shown: Vec<&crate::instrument::spatial::NyquistRow> = rows.iter().collect();
        if worst {
            shown = Vec::new();
            for r in &rows {
                match shown.iter_mut().find(|s| s.plane == r.plane) {
                    Some(s) if r.along.min(r.across) < s.along.min(s.across) => *s = r,
                    Some(_) => {}
                    None => shown.push(r),
                }
            }
        }
        for r in shown {
            let parts: Vec<String> = r.parts_along.iter().map(|p| format!("{:.3}", p.1)).collect();
            out.push_str(&format!(
                "| {} | {stated} | {} | {} | {:.1} | {:.1} | {:.3} | {:.3} | {} |\n",
                spec.name,
                r.plane,
                r.band,
                r.centre_nm,
                r.gsd_m,
                r.along,
                r.across,
                parts.join(" | ")
            ));
        }
    }
    Ok(out)
}
