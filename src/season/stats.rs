//! A season's statistics: looks per month, gaps between valid looks, the revisit requirement,
//! and percentiles of product error.

/// Percentile `p` (0–100) of `values` by linear interpolation between order statistics (the
/// "type 7" of Hyndman & Fan 1996, numpy's default); `None` when empty.
#[must_use]
pub fn percentile(values: &[f64], p: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let h = (v.len() - 1) as f64 * (p / 100.0).clamp(0.0, 1.0);
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    Some(v[lo] + (h - lo as f64) * (v[hi] - v[lo]))
}

/// Gaps between consecutive valid looks, days (`times`: days, sorted).
#[must_use]
pub fn gaps_days(times: &[f64]) -> Vec<f64> {
    times.windows(2).map(|w| w[1] - w[0]).collect()
}

/// Share of the period's days (`from`..`to`, days) on which the last valid look (`times`,
/// sorted) was at most `max_days` before, %: each day is judged at its end; days before the
/// first valid look are not within (what came before the period is not known).
#[must_use]
pub fn revisit_pct(times: &[f64], from: f64, to: f64, max_days: f64) -> f64 {
    let days = (to - from).round().max(1.0) as usize;
    let mut within = 0usize;
    let mut next = 0usize;
    let mut last: Option<f64> = None;
    for d in 0..days {
        let end = from + (d + 1) as f64;
        while next < times.len() && times[next] <= end {
            last = Some(times[next]);
            next += 1;
        }
        if last.is_some_and(|t| end - t <= max_days) {
            within += 1;
        }
    }
    100.0 * within as f64 / days as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate_like_numpy() {
        let v = [3.0, 1.0, 2.0, 4.0];
        assert_eq!(percentile(&v, 50.0), Some(2.5));
        assert_eq!(percentile(&v, 0.0), Some(1.0));
        assert_eq!(percentile(&v, 100.0), Some(4.0));
        assert!((percentile(&v, 90.0).unwrap() - 3.7).abs() < 1e-12);
        assert_eq!(percentile(&[], 50.0), None);
        assert_eq!(percentile(&[f64::NAN, 5.0], 50.0), Some(5.0));
    }

    /// A look every 4 days from day 0.5 over 40 days: gaps of 4; within 5 days on every day
    /// (the first day counts from its look), within 2 days on half of them.
    #[test]
    fn revisit_counts_days_since_the_last_valid_look() {
        let times: Vec<f64> = (0..10).map(|k| 0.5 + 4.0 * f64::from(k)).collect();
        assert!(gaps_days(&times).iter().all(|g| (g - 4.0).abs() < 1e-12));
        assert_eq!(revisit_pct(&times, 0.0, 40.0, 5.0), 100.0);
        // Days ending 1, 2 (look at 0.5: waits 0.5, 1.5), 3 (2.5: no), 4 (3.5: no), then again.
        assert_eq!(revisit_pct(&times, 0.0, 40.0, 2.0), 50.0);
        assert_eq!(revisit_pct(&[], 0.0, 40.0, 5.0), 0.0);
    }
}
