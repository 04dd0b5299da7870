//! Timing that can be believed on a noisy machine: every measurement records wall time and the
//! process's CPU time; settings are compared by repeats interleaved with their reference
//! (R A B … R A B …, so a slow spell of the machine hits every setting alike), and a setting
//! whose range of wall times overlaps the reference's is reported as "no measurable difference"
//! rather than as a ratio of two noisy numbers.
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

/// A setting's time against its reference's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Comparison {
    /// The two ranges of wall times overlap: the repeats cannot tell them apart.
    NoMeasurableDifference,
    /// Ratio of the medians (setting / reference), the ranges apart.
    Ratio(f64),
}

impl Comparison {
    /// Compare `setting` with `reference` by their wall-time ranges.
    #[must_use]
    pub fn of(setting: &Summary, reference: &Summary) -> Self {
        let (a, b) = (setting.wall_range_s, reference.wall_range_s);
        if setting.n < 2 || reference.n < 2 {
            // One sample has no range: a ratio, which the reader is told rests on one run.
            return Self::Ratio(setting.wall_s / reference.wall_s);
        }
        if a.0 <= b.1 && b.0 <= a.1 {
            Self::NoMeasurableDifference
        } else {
            Self::Ratio(setting.wall_s / reference.wall_s)
        }
    }

    /// "0.42×" or "no measurable difference".
    #[must_use]
    pub fn text(&self) -> String {
        match self {
            Self::NoMeasurableDifference => "no measurable difference".into(),
            Self::Ratio(r) => format!("{r:.2}×"),
        }
    }

    /// The ratio, if the ranges are apart.
    #[must_use]
    pub fn ratio(&self) -> Option<f64> {
        match self {
            Self::NoMeasurableDifference => None,
            Self::Ratio(r) => Some(*r),
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
    fn medians_ranges_and_overlap() {
        let r = s(&[1.0, 1.2, 1.1]);
        assert_eq!(r.wall_s, 1.1);
        assert_eq!(r.wall_range_s, (1.0, 1.2));
        assert_eq!(r.cpu_s, Some(2.2));
        assert!((r.spread_pct() - 100.0 * 0.1 / 1.1).abs() < 1e-12);
        // Overlapping ranges: no ratio is claimed.
        assert_eq!(Comparison::of(&s(&[1.15, 1.3, 1.25]), &r), Comparison::NoMeasurableDifference);
        // Apart: the ratio of the medians.
        assert_eq!(Comparison::of(&s(&[0.5, 0.55, 0.6]), &r), Comparison::Ratio(0.55 / 1.1));
        assert_eq!(s(&[1.0, 3.0]).wall_s, 2.0);
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
