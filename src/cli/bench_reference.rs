//! The reference codes' speeds `shoal bench` prints beside its own rows, each with where and when
//! it was measured. Only figures measured side by side with Shoal (same machine, same day, one
//! core) are used for the ratios; the older, unattributed figures from
//! `../shared/reference/README.md` are listed as superseded, since run side by side the codes
//! were slower than those figures and the ratios built on them flattered nobody honestly.

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
    /// "9 200 [1]" or "14–17 [1]".
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
}

/// Where and when note 1's figures were measured.
pub const SIDE_BY_SIDE: &str = "[1] Measured side by side with Shoal on one core of this machine class (AMD EPYC, 2 logical cores, 23 GB), 2026-11-23: SAMBUCA core 1.2.3 (CSIRO, Python) forward model and its SciPy SLSQP fit, and the DEA-Water-Quality aLMI (Python) core loop, each on its own benchmark pixels.";

/// The superseded figures and where they came from.
pub const SUPERSEDED: &str = "Superseded: ../shared/reference/README.md gives 13–23 k forward calls/s and 13–58 SLSQP pixels/s for SAMBUCA and ~6 000 pixels/s for aLMI \"on this machine class\", without date or method; run side by side the codes were slower (note 1), so those figures are no longer used for ratios.";

/// SAMBUCA's forward model, shallow, 451 bands.
pub const SAMBUCA_FORWARD: ReferenceFigure =
    ReferenceFigure { note: 1, what: "SAMBUCA forward model, 451 bands", range: (9_200.0, 9_200.0) };

/// The DEA aLMI core, 8 bands and 8 SIOP sets.
pub const DEA_ALMI: ReferenceFigure =
    ReferenceFigure { note: 1, what: "DEA aLMI core, 8 bands, 8 sets", range: (3_600.0, 3_600.0) };

/// SAMBUCA's SLSQP fit, 28 bands and 3 substrate pairs.
pub const SAMBUCA_FIT_28: ReferenceFigure =
    ReferenceFigure { note: 1, what: "SAMBUCA SLSQP, 28 bands, 3 pairs", range: (6.4, 6.4) };

/// SAMBUCA's SLSQP fit, 4 bands and 1 substrate pair.
pub const SAMBUCA_FIT_4: ReferenceFigure =
    ReferenceFigure { note: 1, what: "SAMBUCA SLSQP, 4 bands, 1 pair", range: (14.0, 17.0) };

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_print_with_their_note_and_ratios_span_the_range() {
        assert_eq!(SAMBUCA_FORWARD.text(), "9200 [1]");
        assert_eq!(SAMBUCA_FIT_4.text(), "14.0–17.0 [1]");
        assert_eq!(SAMBUCA_FIT_4.ratio(34.0), "2.00–2.43×");
        assert_eq!(DEA_ALMI.ratio(360_000.0), "100×");
    }
}
