//! One field's allowed values: its path, ends, unit and meaning, and the checks and messages
//! made from them.

use super::Editor;
use super::table::number;

/// The allowed values of one numeric field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Where the field lives (see the module documentation).
    pub path: &'static str,
    /// Lower end.
    pub lo: f64,
    /// `lo` itself is refused.
    pub lo_open: bool,
    /// Upper end.
    pub hi: f64,
    /// `hi` itself is refused.
    pub hi_open: bool,
    /// Unit (empty: dimensionless or a count).
    pub unit: &'static str,
    /// Only whole numbers (counts, bits).
    pub whole: bool,
    /// What the field is.
    pub meaning: &'static str,
    /// How an editor offers it (the app's instrument sliders, the sweep list's names); `None`:
    /// set in files only.
    pub editor: Option<Editor>,
}

impl Range {
    /// The same range, offered by editors as `editor` says.
    #[must_use]
    pub const fn edited(self, editor: Editor) -> Self {
        Self { editor: Some(editor), ..self }
    }

    /// `lo` to `hi`, both allowed.
    #[must_use]
    pub const fn closed(path: &'static str, lo: f64, hi: f64, unit: &'static str, meaning: &'static str) -> Self {
        Self { path, lo, lo_open: false, hi, hi_open: false, unit, whole: false, meaning, editor: None }
    }

    /// Above `lo`, at most `hi`.
    #[must_use]
    pub const fn above(path: &'static str, lo: f64, hi: f64, unit: &'static str, meaning: &'static str) -> Self {
        Self { path, lo, lo_open: true, hi, hi_open: false, unit, whole: false, meaning, editor: None }
    }

    /// Whole numbers from `lo` to `hi`.
    #[must_use]
    pub const fn count(path: &'static str, lo: f64, hi: f64, unit: &'static str, meaning: &'static str) -> Self {
        Self { path, lo, lo_open: false, hi, hi_open: false, unit, whole: true, meaning, editor: None }
    }

    /// The same range with `hi` refused.
    #[must_use]
    pub const fn below_hi(self) -> Self {
        Self { hi_open: true, ..self }
    }

    /// Is `value` allowed?
    ///
    /// ```
    /// use shoal::ranges::INSTRUMENT_APERTURE_MM as r;
    /// assert!(r.contains(2000.0) && !r.contains(0.0) && !r.contains(f64::NAN));
    /// ```
    #[must_use]
    pub fn contains(&self, value: f64) -> bool {
        let lo_ok = if self.lo_open { value > self.lo } else { value >= self.lo };
        let hi_ok = if self.hi_open { value < self.hi } else { value <= self.hi };
        value.is_finite() && lo_ok && hi_ok && (!self.whole || value.fract() == 0.0)
    }

    /// The range in words: "0.01 to 10000 e-/DN", "above 0, at most 2000 mm".
    #[must_use]
    pub fn allowed(&self) -> String {
        let unit = if self.unit.is_empty() { String::new() } else { format!(" {}", self.unit) };
        let whole = if self.whole { " (whole number)" } else { "" };
        let (lo, hi) = (number(self.lo), number(self.hi));
        match (self.lo_open, self.hi_open) {
            (false, false) => format!("{lo} to {hi}{unit}{whole}"),
            (true, false) => format!("above {lo}, at most {hi}{unit}{whole}"),
            (false, true) => format!("{lo} to below {hi}{unit}{whole}"),
            (true, true) => format!("above {lo}, below {hi}{unit}{whole}"),
        }
    }

    /// `Ok` when allowed, else the message "VALUE is out of range (allowed: RANGE)".
    pub fn check(&self, value: f64) -> Result<(), String> {
        if self.contains(value) {
            Ok(())
        } else {
            Err(format!("{value} is out of range (allowed: {})", self.allowed()))
        }
    }

    /// The field's own name: the path's last part (`aperture_mm`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.path.rsplit('.').next().unwrap_or(self.path)
    }

    /// The field as a validator reports it: the path without `section` (`instrument.` →
    /// `aperture_mm`; `kind.Spectrograph.start_nm` keeps its variant).
    #[must_use]
    pub fn field(&self, section: &str) -> &'static str {
        self.path.strip_prefix(section).unwrap_or(self.path)
    }

    /// Values just outside the range (for tests): the open end itself, or one step past a
    /// closed end (1 for whole numbers; 1 % of the end, or 0.01, otherwise). Values a field's
    /// type cannot hold (a negative count) are left out.
    #[must_use]
    pub fn just_outside(&self) -> Vec<f64> {
        let step = |end: f64| if self.whole { 1.0 } else { (end.abs() * 0.01).max(0.01) };
        let below = if self.lo_open { self.lo } else { self.lo - step(self.lo) };
        let above = if self.hi_open { self.hi } else { self.hi + step(self.hi) };
        let mut out = Vec::new();
        if !(self.whole && below < 0.0) {
            out.push(below);
        }
        out.push(above);
        out
    }
}
