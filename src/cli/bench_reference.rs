//! The reference codes' speeds `shoal bench` prints beside its own rows, each with where, when and
//! how it was measured. Only figures measured side by side with Shoal on an idle core (same
//! machine class, one core each, interleaved rounds) are used for the ratios; earlier figures,
//! measured on a loaded machine, are listed as superseded. `tests/bench/reference_codes.py`
//! re-measures them where the user has the reference codes, paired round by round with Shoal.

/// One reference code's measured speed.
#[derive(Debug, Clone, Copy)]
pub struct ReferenceFigure {
    /// Footnote number.
    pub note: usize,
    /// Code and what was timed.
    pub what: &'static str,
    /// Lowest and highest figure over the repeats (equal for a single figure).
    pub range: (f64, f64),
}

impl ReferenceFigure {
    /// "23973 [1]" or "14.0–17.0 [1]".
    #[must_use]
    pub fn text(&self) -> String {
        let f = |v: f64| if v >= 100.0 { format!("{v:.0}") } else { format!("{v:.1}") };
        if self.range.0 == self.range.1 {
            format!("{} [{}]", f(self.range.0), self.note)
        } else {
            format!("{}–{} [{}]", f(self.range.0), f(self.range.1), self.note)
        }
    }

    /// Shoal's `rate` over the reference's: "0.8–1.1×", or one figure.
    #[must_use]
    pub fn ratio(&self, rate: f64) -> String {
        let (lo, hi) = (rate / self.range.1, rate / self.range.0);
        let f = |v: f64| if v >= 10.0 { format!("{v:.0}") } else { format!("{v:.2}") };
        if self.range.0 == self.range.1 { format!("{}×", f(lo)) } else { format!("{}–{}×", f(lo), f(hi)) }
    }

    /// [`Self::ratio`] of a `rate` measured on this machine, marked "(across CPUs)" where this
    /// CPU is not the one the reference was measured on ([`other_machine`]).
    #[must_use]
    pub fn ratio_here(&self, rate: f64) -> String {
        let ratio = self.ratio(rate);
        if other_machine(super::bench::cpu_model()).is_some() { format!("{ratio} (across CPUs)") } else { ratio }
    }
}

/// The CPU note 1's figures were measured on: a `model name` that starts so is that class.
pub const REFERENCE_CPU: &str = "AMD EPYC";

/// Why the ratios printed on a machine whose CPU (`cpu`, its model name) is not of
/// [`REFERENCE_CPU`]'s class are no paired ratios; `None` on that class.
#[must_use]
pub fn other_machine(cpu: &str) -> Option<String> {
    (!cpu.starts_with(REFERENCE_CPU)).then(|| {
        format!(
            "This CPU ({cpu}) is not the one note 1's figures were measured on ({REFERENCE_CPU}): each × column divides this machine's speed by another machine's, so it is no paired ratio (marked \"across CPUs\"). To compare here, run the reference codes beside Shoal with tests/bench/reference_codes.py."
        )
    })
}

/// Where, when and how note 1's figures were measured.
pub const SIDE_BY_SIDE: &str = "[1] Measured side by side with Shoal (commit 080ae1e, 2026-11-27) on an idle core of this machine class (AMD EPYC, 2 logical cores, 23 GB): one core each under taskset, 8 interleaved rounds, load at most 1.1, every paired ratio within 6 % of its median; sambuca d153684 and sambuca_core 64483a0 (CSIRO, Python: forward model and SciPy SLSQP fit), DEA-Water-Quality dd794b0 (aLMI, `chunkProcessLMI`), numpy 1.26. The workloads differ: the reference forward model recomputes its SIOP spectra and returns sub-surface rrs each call; Shoal's aLMI row uses 8 MODIS-like 10 nm bands and synthetic pixels, DEA's 8 monochromatic OLCI centres and its stored pixels; Shoal's SLSQP rows use the heron_island SIOPs and Gaussian bands, its reference mode summing 863 (28 bands) or 1215 (4 bands) wavelengths against SAMBUCA's 451 (tests/bench/README.md). Re-measure: tests/bench/reference_codes.py.";

/// The superseded figures and why.
pub const SUPERSEDED: &str = "Superseded: the figures of 2026-11-23 (SAMBUCA 9 200 forward calls/s, SLSQP 6.4 and 14-17 pixels/s; aLMI 3 600 pixels/s) were measured on a loaded machine: on an idle core the reference codes ran 2.3-3.4 times faster (note 1), so ratios built on them overstated Shoal's lead by that much. ../shared/reference/README.md's figures (13-23 k forward calls/s, 13-58 SLSQP pixels/s, ~6 000 aLMI pixels/s) give no date or method.";

/// SAMBUCA's forward model, shallow, 451 bands.
pub const SAMBUCA_FORWARD: ReferenceFigure =
    ReferenceFigure { note: 1, what: "SAMBUCA forward model, 451 bands", range: (23_973.0, 23_973.0) };

/// SAMBUCA's forward model at infinite depth (it has no deep-only path: a full call), 451 bands:
/// the reference of Shoal's optically deep rows.
pub const SAMBUCA_FORWARD_DEEP: ReferenceFigure =
    ReferenceFigure { note: 1, what: "SAMBUCA forward model, deep, 451 bands", range: (21_888.0, 21_888.0) };

/// The DEA aLMI core, 8 bands and 8 SIOP sets.
pub const DEA_ALMI: ReferenceFigure =
    ReferenceFigure { note: 1, what: "DEA aLMI core, 8 bands, 8 sets", range: (8_209.0, 8_209.0) };

/// SAMBUCA's SLSQP fit, 28 bands and 3 substrate pairs.
pub const SAMBUCA_FIT_28: ReferenceFigure =
    ReferenceFigure { note: 1, what: "SAMBUCA SLSQP, 28 bands, 3 pairs", range: (18.2, 18.2) };

/// SAMBUCA's SLSQP fit, 4 bands and 1 substrate pair.
pub const SAMBUCA_FIT_4: ReferenceFigure =
    ReferenceFigure { note: 1, what: "SAMBUCA SLSQP, 4 bands, 1 pair", range: (47.6, 47.6) };

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_print_with_their_note_and_ratios_span_the_range() {
        assert_eq!(SAMBUCA_FORWARD.text(), "23973 [1]");
        assert_eq!(SAMBUCA_FIT_4.text(), "47.6 [1]");
        assert_eq!(SAMBUCA_FIT_4.ratio(95.2), "2.00×");
        assert_eq!(DEA_ALMI.ratio(820_900.0), "100×");
        let range = ReferenceFigure { note: 1, what: "", range: (14.0, 17.0) };
        assert_eq!((range.text(), range.ratio(34.0)), ("14.0–17.0 [1]".to_string(), "2.00–2.43×".to_string()));
    }

    #[test]
    fn a_ratio_across_cpus_says_so() {
        assert!(other_machine("AMD EPYC 7B13").is_none());
        let w = other_machine("Intel(R) Xeon(R) Processor").unwrap();
        assert!(w.contains("Intel(R) Xeon(R) Processor") && w.contains("AMD EPYC") && w.contains("reference_codes.py"));
    }
}
