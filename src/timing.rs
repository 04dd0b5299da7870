//! Timing that can be believed on a noisy machine: every measurement records wall time and the
//! process's CPU time; settings are compared by repeats interleaved with their reference
//! (R A B … R A B …, so a slow spell of the machine hits every setting alike) and paired by
//! round ([`Paired`]): a difference is claimed only when the interval of the per-round ratios
//! excludes 1, and is reported as "no measurable difference" otherwise rather than as a ratio of
//! two noisy numbers.
//!
//! CPU time is the whole process's (user + system, all threads) from `/proc/self/stat`, in the
//! kernel's clock ticks (10 ms on Linux); `None` where that file does not exist. Rows it is used
//! for last a second or more, so the tick is ≤ 1 % of them.

use std::time::Instant;

/// One timed run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Wall-clock time, s.
    pub wall_s: f64,
    /// Process CPU time (all threads), s; `None` where it cannot be read.
    pub cpu_s: Option<f64>,
}

/// The process's user + system CPU time, s (`/proc/self/stat` fields 14 and 15, in clock ticks
/// of 1/100 s: `USER_HZ`, fixed at 100 on Linux, proc(5)).
#[must_use]
pub fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count from after it.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // `rest` starts at field 3 (state): utime is field 14, stime field 15.
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

/// Run `f` once and time it.
pub fn measure<T>(f: impl FnOnce() -> T) -> (T, Sample) {
    let cpu0 = process_cpu_seconds();
    let start = Instant::now();
    let out = f();
    let wall_s = start.elapsed().as_secs_f64();
    let cpu_s = cpu0.zip(process_cpu_seconds()).map(|(a, b)| b - a);
    (out, Sample { wall_s, cpu_s })
}

/// Median and range of a set of samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Number of samples.
    pub n: usize,
    /// Median wall time, s.
    pub wall_s: f64,
    /// Shortest and longest wall time, s.
    pub wall_range_s: (f64, f64),
    /// Median CPU time, s (when every sample has one).
    pub cpu_s: Option<f64>,
    /// Smallest and largest CPU time, s.
    pub cpu_range_s: Option<(f64, f64)>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn range(v: &[f64]) -> (f64, f64) {
    v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)))
}

impl Summary {
    /// The summary of `samples` (NaN medians for none).
    #[must_use]
    pub fn of(samples: &[Sample]) -> Self {
        let wall: Vec<f64> = samples.iter().map(|s| s.wall_s).collect();
        let cpu: Option<Vec<f64>> = samples.iter().map(|s| s.cpu_s).collect();
        let cpu = cpu.filter(|c| !c.is_empty());
        Self {
            n: samples.len(),
            wall_s: median(wall.clone()),
            wall_range_s: range(&wall),
            cpu_s: cpu.clone().map(median),
            cpu_range_s: cpu.as_deref().map(range),
        }
    }

    /// Spread of the wall times around the median, ± % (half the range over the median).
    #[must_use]
    pub fn spread_pct(&self) -> f64 {
        50.0 * (self.wall_range_s.1 - self.wall_range_s.0) / self.wall_s
    }

    /// "1.23 s (1.20–1.31, n 3)".
    #[must_use]
    pub fn wall_text(&self) -> String {
        format!("{:.2} s ({:.2}–{:.2}, n {})", self.wall_s, self.wall_range_s.0, self.wall_range_s.1, self.n)
    }

    /// "2.41 s" or "–" when CPU time could not be read.
    #[must_use]
    pub fn cpu_text(&self) -> String {
        self.cpu_s.map_or_else(|| "–".into(), |c| format!("{c:.2} s"))
    }
}

/// A series of runs against another, paired by round: the median of the per-round ratios and a
/// distribution-free interval for it.
///
/// Each round gives one ratio (a setting's time over its reference's, taken next to it in time),
/// so a slow spell of the machine, or a drift across rounds, moves both terms of a pair and
/// cancels; what is left is the setting's own effect and the run-to-run noise. The interval is
/// the sign test's confidence interval for the median (Conover 1999, *Practical Nonparametric
/// Statistics*, §3.2): with the n ratios sorted, [x₍ₖ₎, x₍ₙ₊₁₋ₖ₎] covers the true median with
/// probability 1 − 2·P(B ≤ k − 1), B ~ Binomial(n, ½), whatever the noise's distribution; k is
/// the largest rank that keeps the coverage at [`LEVEL`] or above. It needs no normality, and a
/// single slow run (an outlier) moves at most one order statistic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Paired {
    /// Median ratio.
    pub ratio: f64,
    /// Interval, low end.
    pub lo: f64,
    /// Interval, high end.
    pub hi: f64,
    /// Rounds paired.
    pub n: usize,
    /// The interval's coverage, %.
    pub level_pct: f64,
}

/// The coverage an interval must reach before a difference is claimed: 90 %.
pub const LEVEL: f64 = 0.90;

/// Rounds a claim needs: with fewer, no sign-test interval reaches [`LEVEL`] (4 rounds give
/// 87.5 % at best).
pub const MIN_ROUNDS: usize = 5;

/// P(B ≤ j) for B ~ Binomial(n, ½).
fn binomial_cdf_half(n: usize, j: usize) -> f64 {
    let mut c = 1.0f64;
    let mut sum = 0.0;
    for i in 0..=j.min(n) {
        if i > 0 {
            c = c * (n - i + 1) as f64 / i as f64;
        }
        sum += c;
    }
    sum / 2f64.powi(i32::try_from(n).unwrap_or(i32::MAX))
}

impl Paired {
    /// The paired comparison of `ratios` (one per round, each > 0); `None` without any.
    #[must_use]
    pub fn of(ratios: &[f64]) -> Option<Self> {
        let mut logs: Vec<f64> = ratios.iter().filter(|r| r.is_finite() && **r > 0.0).map(|r| r.ln()).collect();
        let n = logs.len();
        if n == 0 {
            return None;
        }
        logs.sort_by(f64::total_cmp);
        let median = if n % 2 == 1 { logs[n / 2] } else { 0.5 * (logs[n / 2 - 1] + logs[n / 2]) };
        // The largest k whose interval still covers with probability LEVEL (k = 1 at least: the
        // whole range, whose coverage 1 − 2^(1−n) is reported when it falls short).
        let coverage = |k: usize| 1.0 - 2.0 * binomial_cdf_half(n, k - 1);
        let k = (1..=n.div_ceil(2)).take_while(|&k| coverage(k) >= LEVEL).last().unwrap_or(1);
        Some(Self {
            ratio: median.exp(),
            lo: logs[k - 1].exp(),
            hi: logs[n - k].exp(),
            n,
            level_pct: 100.0 * coverage(k),
        })
    }

    /// A known ratio (tests and rows measured once).
    #[must_use]
    pub const fn exact(ratio: f64) -> Self {
        Self { ratio, lo: ratio, hi: ratio, n: 0, level_pct: 100.0 }
    }

    /// Does the interval exclude 1 at the coverage a claim needs?
    #[must_use]
    pub fn differs(&self) -> bool {
        self.level_pct >= 100.0 * LEVEL && (self.hi < 1.0 || self.lo > 1.0)
    }
}

/// A setting's time against its reference's, paired by round ([`Paired`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Comparison {
    /// The interval holds 1, or too few rounds were run to claim anything: the runs cannot
    /// tell the two apart (the ratio and interval, when measured, are kept for the reader).
    NoMeasurableDifference(Option<Paired>),
    /// The setting's median ratio, its interval excluding 1.
    Ratio(Paired),
}

impl Comparison {
    /// The comparison of per-round ratios (setting over reference).
    #[must_use]
    pub fn of_ratios(ratios: &[f64]) -> Self {
        match Paired::of(ratios) {
            Some(p) if p.differs() => Self::Ratio(p),
            other => Self::NoMeasurableDifference(other),
        }
    }

    /// "0.85× (0.83–0.87)", or "no measurable difference (0.97–1.04×)", or with too few rounds
    /// "no measurable difference (3 rounds; 5 needed)".
    #[must_use]
    pub fn text(&self) -> String {
        match self {
            Self::Ratio(p) if p.n == 0 => format!("{:.2}×", p.ratio),
            Self::Ratio(p) => format!("{:.2}× ({:.2}–{:.2})", p.ratio, p.lo, p.hi),
            Self::NoMeasurableDifference(Some(p)) if p.n > 0 && p.n < MIN_ROUNDS => {
                format!("no measurable difference ({} rounds; {MIN_ROUNDS} needed)", p.n)
            }
            Self::NoMeasurableDifference(Some(p)) if p.n > 0 => {
                format!("no measurable difference ({:.2}–{:.2}×)", p.lo, p.hi)
            }
            Self::NoMeasurableDifference(_) => "no measurable difference".into(),
        }
    }

    /// The ratio, if the setting measurably differs.
    #[must_use]
    pub fn ratio(&self) -> Option<f64> {
        match self {
            Self::NoMeasurableDifference(_) => None,
            Self::Ratio(p) => Some(p.ratio),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(wall: &[f64]) -> Summary {
        Summary::of(&wall.iter().map(|&w| Sample { wall_s: w, cpu_s: Some(2.0 * w) }).collect::<Vec<_>>())
    }

    #[test]
    fn medians_and_ranges() {
        let r = s(&[1.0, 1.2, 1.1]);
        assert_eq!(r.wall_s, 1.1);
        assert_eq!(r.wall_range_s, (1.0, 1.2));
        assert_eq!(r.cpu_s, Some(2.2));
        assert!((r.spread_pct() - 100.0 * 0.1 / 1.1).abs() < 1e-12);
        assert_eq!(s(&[1.0, 3.0]).wall_s, 2.0);
    }

    #[test]
    fn the_sign_test_interval_has_its_binomial_coverage() {
        // n = 5: the whole range, 1 − 2/32 = 93.75 %; n = 7: the second from each end,
        // 1 − 2·8/128 = 87.5 % < 90 %, so again the range (98.4 %); n = 9: the second, 96.1 %.
        let p = Paired::of(&[0.9, 0.8, 1.0, 0.85, 0.95]).unwrap();
        assert!((p.ratio - 0.9).abs() < 1e-12 && (p.lo - 0.8).abs() < 1e-12 && (p.hi - 1.0).abs() < 1e-12);
        assert!((p.level_pct - 93.75).abs() < 1e-9);
        let p = Paired::of(&[1.0; 9]).unwrap();
        assert!((p.level_pct - 100.0 * (1.0 - 2.0 * 10.0 / 512.0)).abs() < 1e-9, "{p:?}");
        let three = Paired::of(&[0.5, 0.5, 0.5]).unwrap();
        assert!(!three.differs(), "3 rounds reach 75 %: no claim");
        assert!(Comparison::of_ratios(&[0.5; 3]).text().contains("3 rounds; 5 needed"));
        assert_eq!(binomial_cdf_half(4, 4), 1.0);
    }

    #[test]
    fn cpu_time_is_read_and_grows_with_work() {
        let Some(before) = process_cpu_seconds() else { return };
        let (_, sample) = measure(|| {
            let start = Instant::now();
            let mut x = 0u64;
            while start.elapsed().as_secs_f64() < 0.05 {
                x = std::hint::black_box(x.wrapping_add(1));
            }
        });
        assert!(sample.wall_s >= 0.05);
        // Ticks of 10 ms: 50 ms of spinning reads as 30–70 ms of CPU.
        let cpu = sample.cpu_s.expect("cpu time");
        assert!((0.02..0.2).contains(&cpu), "{cpu}");
        assert!(process_cpu_seconds().unwrap() >= before);
    }
}
