//! The rows of the cost table and the one rule every comparison of their times follows — a row
//! against the reference, one row against another for the Pareto front and for the cheapest
//! setting within a tolerance: runs are paired by round ([`crate::timing::Paired`]).
//!
//! A round runs the reference, then every setting in turn, and the next round's reference closes
//! it (the table ends with one more reference run). A setting's run at position p = i/N of its
//! round (row i of N) is set against the reference's time at that moment, interpolated
//! geometrically between the round's reference run r_k and the next one: r_k^(1−p) · r_(k+1)^p.
//! A machine that slows or speeds up through the table (drift) moves a setting and its reference
//! estimate alike. Before interpolating, the reference's runs are smoothed by a running median
//! of three ([`smooth`]), so that one slow reference run — which two rounds lean on — moves no
//! round; a slow run of a setting moves its one round's ratio, which the sign-test interval
//! tolerates as one order statistic once there are 8 rounds or more (with 5 to 7, every round
//! must agree). Until the next reference has run, the round's own reference stands alone. Two
//! settings are compared through these normalised times: in each round,
//! (t_a / ref_a) / (t_b / ref_b).

use super::PerPixel;
use crate::timing::{Comparison, Paired, Sample, Summary};

/// One measured setting.
#[derive(Debug, Clone, PartialEq)]
pub struct CostRow {
    /// What the setting is.
    pub label: String,
    /// Its timed runs so far (one per round; the reference has one more, the closing run).
    pub samples: Vec<Sample>,
    /// Median and range of the samples.
    pub time: Summary,
    /// Per round: the wall time over the reference's at the same moment (1 for the reference).
    pub wall_vs_reference: Vec<f64>,
    /// Per round: the CPU time over the reference's (empty where CPU time cannot be read).
    pub cpu_vs_reference: Vec<f64>,
    /// Wall time against the reference's, paired by round (the reference row: no measurable
    /// difference with itself).
    pub comparison: Comparison,
    /// CPU time against the reference's, paired by round; `None` where CPU time cannot be read.
    pub cpu_comparison: Option<Comparison>,
    /// chl-a MAE against the truth, %.
    pub chl_mae_pct: f64,
    /// `chl_mae_pct` minus the reference's, points of %.
    pub delta_mae_pct: f64,
    /// The products' per-pixel differences from the reference (same grid only).
    pub errors: PerPixel,
}

/// The product whose per-pixel difference from the reference is a row's error, for the Pareto
/// front, the cheapest setting within a tolerance and the Cost window's plot.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ErrorOf {
    /// Chlorophyll-a: median per-pixel relative difference.
    #[default]
    Chl,
    /// Suspended matter (NAP).
    Nap,
    /// CDOM absorption.
    Cdom,
    /// Depth (depth retrievals).
    Depth,
    /// Bottom type: pixels whose dominant bottom type differs from the reference's.
    Bottom,
}

impl ErrorOf {
    /// Every product, in the order menus list them.
    pub const ALL: [Self; 5] = [Self::Chl, Self::Nap, Self::Cdom, Self::Depth, Self::Bottom];

    /// The name on the command line.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Chl => "chl",
            Self::Nap => "nap",
            Self::Cdom => "cdom",
            Self::Depth => "depth",
            Self::Bottom => "bottom",
        }
    }

    /// The product's name in text.
    #[must_use]
    pub const fn label(self) -> &'static str {
        match self {
            Self::Chl => "chl-a",
            Self::Nap => "NAP",
            Self::Cdom => "CDOM",
            Self::Depth => "depth",
            Self::Bottom => "bottom type",
        }
    }

    /// What the error is: "chl-a per pixel vs reference, median %".
    #[must_use]
    pub fn measure(self) -> String {
        match self {
            Self::Bottom => "pixels whose bottom type changes from the reference's, %".into(),
            other => format!("{} per pixel vs reference, median %", other.label()),
        }
    }

    /// The product named `name` ([`Self::name`]).
    #[must_use]
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == name)
    }
}

impl CostRow {
    /// A row not yet timed, with its product errors.
    #[must_use]
    pub(super) fn untimed(label: &str, chl_mae_pct: f64, delta_mae_pct: f64) -> Self {
        Self {
            label: label.into(),
            samples: Vec::new(),
            time: Summary::of(&[]),
            wall_vs_reference: Vec::new(),
            cpu_vs_reference: Vec::new(),
            comparison: Comparison::NoMeasurableDifference(None),
            cpu_comparison: None,
            chl_mae_pct,
            delta_mae_pct,
            errors: PerPixel::default(),
        }
    }

    /// A row timed at `walls` seconds (CPU twice the wall) with the verdict `comparison`, chl MAE
    /// 37 % (+0.07 points), with the per-pixel chl error `pixel` (also the Rrs error) and its
    /// 95th percentile `p95`: for the tests of the tables that print rows.
    #[cfg(test)]
    #[must_use]
    pub(crate) fn timed(
        label: &str,
        walls: &[f64],
        comparison: Comparison,
        pixel: Option<f64>,
        p95: Option<f64>,
    ) -> Self {
        let samples: Vec<Sample> = walls.iter().map(|&w| Sample { wall_s: w, cpu_s: Some(2.0 * w) }).collect();
        Self {
            time: Summary::of(&samples),
            samples,
            comparison,
            errors: PerPixel { chl_pct: pixel, chl_p95_pct: p95, rrs_pct: pixel, ..PerPixel::default() },
            ..Self::untimed(label, 37.0, 0.07)
        }
    }

    /// Median wall time, s.
    #[must_use]
    pub fn seconds(&self) -> f64 {
        self.time.wall_s
    }

    /// The error of `of` the Pareto front and the tolerance use: its per-pixel difference from
    /// the reference on the same grid ([`PerPixel`]). `None` for a preview: its pixels are a
    /// subset of the reference's, so it is a different product (fewer pixels), not a cheaper
    /// equal one; `None` too for a product the retrieval does not make.
    #[must_use]
    pub fn error_pct(&self, of: ErrorOf) -> Option<f64> {
        let e = &self.errors;
        match of {
            ErrorOf::Chl => e.chl_pct,
            ErrorOf::Nap => e.nap_pct,
            ErrorOf::Cdom => e.cdom_pct,
            ErrorOf::Depth => e.depth_pct,
            ErrorOf::Bottom => e.bottom_changed_pct,
        }
        .filter(|v| v.is_finite())
    }

    /// This row's wall time against `other`'s, paired by round through their times relative to
    /// the reference.
    #[must_use]
    pub fn against(&self, other: &Self) -> Comparison {
        let ratios: Vec<f64> =
            self.wall_vs_reference.iter().zip(&other.wall_vs_reference).map(|(a, b)| a / b).collect();
        Comparison::of_ratios(&ratios)
    }

    /// Is this row measurably faster than `other` ([`Self::against`])?
    #[must_use]
    pub fn measurably_faster_than(&self, other: &Self) -> bool {
        matches!(self.against(other), Comparison::Ratio(p) if p.ratio < 1.0)
    }

    /// Median wall time relative to the reference (1 for the reference; NaN before a run).
    #[must_use]
    pub fn relative_time(&self) -> f64 {
        Paired::of(&self.wall_vs_reference).map_or(f64::NAN, |p| p.ratio)
    }
}

/// A series smoothed by running medians of three (Tukey 1977, *Exploratory Data Analysis*,
/// ch. 7): each interior value becomes the median of itself and its two neighbours, which keeps
/// a monotone trend and removes a single outlier; an end value becomes the median of itself,
/// its smoothed neighbour and the straight line through the two nearest smoothed values extended
/// to it (a linear trend is kept at the ends too). Series of fewer than four are returned as they
/// are: three values cannot tell an outlying end from a trend.
#[must_use]
pub fn smooth(y: &[f64]) -> Vec<f64> {
    let med3 = |a: f64, b: f64, c: f64| a.max(b).min(a.min(b).max(c));
    let n = y.len();
    if n < 4 {
        return y.to_vec();
    }
    let mut s = y.to_vec();
    for i in 1..n - 1 {
        s[i] = med3(y[i - 1], y[i], y[i + 1]);
    }
    s[0] = med3(y[0], s[1], 2.0 * s[1] - s[2]);
    s[n - 1] = med3(y[n - 1], s[n - 2], 2.0 * s[n - 2] - s[n - 3]);
    s
}

/// The reference's time at position `p` of round `k`, from its smoothed log times: the round's
/// run moved geometrically towards the next run, when that has been made.
fn reference_at(log_reference: &[f64], k: usize, p: f64) -> Option<f64> {
    let r0 = *log_reference.get(k)?;
    Some(log_reference.get(k + 1).map_or(r0, |r1| (1.0 - p) * r0 + p * r1).exp())
}

/// Each row's times against the reference's (row 0), paired by round as the module describes:
/// fills `wall_vs_reference`, `cpu_vs_reference`, `comparison` and `cpu_comparison` from the
/// samples. Called after every run; the rows' order is the order of a round.
pub(super) fn pair_with_reference(rows: &mut [CostRow]) {
    let Some(first) = rows.first() else { return };
    let log = |v: Option<Vec<f64>>| smooth(&v.unwrap_or_default().iter().map(|t| t.ln()).collect::<Vec<_>>());
    let wall = log(first.samples.iter().map(|s| Some(s.wall_s).filter(|w| *w > 0.0)).collect());
    let cpu = log(first.samples.iter().map(|s| s.cpu_s.filter(|c| *c > 0.0)).collect());
    let n = rows.len() as f64;
    for (i, row) in rows.iter_mut().enumerate() {
        let p = i as f64 / n;
        let ratios = |of: &dyn Fn(&Sample) -> Option<f64>, reference: &[f64]| -> Vec<f64> {
            let r: Option<Vec<f64>> =
                row.samples.iter().enumerate().map(|(k, s)| Some(of(s)? / reference_at(reference, k, p)?)).collect();
            r.unwrap_or_default()
        };
        row.wall_vs_reference = ratios(&|s| Some(s.wall_s), &wall);
        row.cpu_vs_reference = ratios(&|s| s.cpu_s, &cpu);
        if i == 0 {
            // The reference against itself: 1 in every round (its smoothed runs stand for it).
            row.wall_vs_reference.fill(1.0);
            row.cpu_vs_reference.fill(1.0);
        }
        row.comparison = if i == 0 {
            Comparison::NoMeasurableDifference(None)
        } else {
            Comparison::of_ratios(&row.wall_vs_reference)
        };
        row.cpu_comparison = (!row.cpu_vs_reference.is_empty()).then(|| {
            if i == 0 { Comparison::NoMeasurableDifference(None) } else { Comparison::of_ratios(&row.cpu_vs_reference) }
        });
    }
}

/// The full-resolution rows on the time–error Pareto front of `of`'s error, fastest first: a
/// row is off the front when another is measurably faster ([`CostRow::measurably_faster_than`])
/// and no less accurate, or as fast within the noise and more accurate. Of rows that tie in
/// both, the first (the reference comes first) stands for them.
#[must_use]
pub fn pareto_front(rows: &[CostRow], of: ErrorOf) -> Vec<&CostRow> {
    let candidates: Vec<(usize, &CostRow, f64)> =
        rows.iter().enumerate().filter_map(|(i, r)| r.error_pct(of).map(|e| (i, r, e))).collect();
    let mut front: Vec<&CostRow> = candidates
        .iter()
        .filter(|(i, r, e)| {
            !candidates.iter().any(|(j, o, f)| {
                let tied_time = !o.measurably_faster_than(r) && !r.measurably_faster_than(o);
                (o.measurably_faster_than(r) && f <= e) || (tied_time && (f < e || (f == e && j < i)))
            })
        })
        .map(|(_, r, _)| *r)
        .collect();
    front.sort_by(|a, b| a.relative_time().total_cmp(&b.relative_time()));
    front
}

/// The cheapest full-resolution row whose error of `of` from the reference is within
/// `tolerance_pct` and that is measurably faster than the reference; the reference itself when
/// none is.
///
/// "Cheapest" is decided only as far as the timings can tell: the candidates that no other
/// candidate is measurably faster than ([`CostRow::measurably_faster_than`]) tie, and of those
/// the one with the smallest chl error is taken (the first listed of equal errors). Should the
/// pairwise verdicts form a cycle (possible in principle with order-statistic intervals), the
/// candidate with the lowest median time relative to the reference is taken.
#[must_use]
pub fn cheapest_within(rows: &[CostRow], of: ErrorOf, tolerance_pct: f64) -> Option<&CostRow> {
    let reference = rows.first()?;
    let candidates: Vec<(&CostRow, f64)> = rows
        .iter()
        .skip(1)
        .filter(|r| !r.samples.is_empty() && r.measurably_faster_than(reference))
        .filter_map(|r| r.error_pct(of).filter(|&e| e <= tolerance_pct).map(|e| (r, e)))
        .collect();
    let unbeaten = candidates.iter().filter(|(r, _)| !candidates.iter().any(|(o, _)| o.measurably_faster_than(r)));
    unbeaten
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .or_else(|| candidates.iter().min_by(|a, b| a.0.relative_time().total_cmp(&b.0.relative_time())))
        .map(|(r, _)| *r)
        .or(Some(reference))
}

#[cfg(test)]
#[path = "rows_tests.rs"]
mod tests;
