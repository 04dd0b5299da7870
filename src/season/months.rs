//! A season's looks counted by calendar month: the site's months (local mean solar dates,
//! [`super::SeasonSpec::local_offset_days`]), as a cloud climatology's are.

use super::looks::Verdict;
use super::run::{DesignSeason, SeasonResult};

impl DesignSeason {
    /// Looks with `verdict` in each calendar month of the period `from`–`to` (days since J2000.0,
    /// UT), (year, month, count); months and days are the site's, `local_offset_days` ahead of UT
    /// ([`super::SeasonSpec::local_offset_days`]).
    #[must_use]
    pub fn per_month(
        &self,
        verdict: Option<Verdict>,
        (from, to): (f64, f64),
        local_offset_days: f64,
    ) -> Vec<((i64, u32), usize)> {
        let mut months: Vec<((i64, u32), usize)> = Vec::new();
        let mut d = from;
        while d < to {
            let (y, m, _) = crate::orbit::sun::calendar_date(d + local_offset_days + 0.5);
            if months.last().is_none_or(|(k, _)| *k != (y, m)) {
                months.push(((y, m), 0));
            }
            d += 1.0;
        }
        for l in &self.looks {
            if verdict.is_none_or(|v| v == l.verdict) {
                let (y, m, _) = crate::orbit::sun::calendar_date(l.access.days + local_offset_days);
                if let Some(slot) = months.iter_mut().find(|(k, _)| *k == (y, m)) {
                    slot.1 += 1;
                }
            }
        }
        months
    }
}

impl SeasonResult {
    /// [`DesignSeason::per_month`] of `design` over this season's period, in the site's months.
    #[must_use]
    pub fn per_month(&self, design: &DesignSeason, verdict: Option<Verdict>) -> Vec<((i64, u32), usize)> {
        design.per_month(verdict, self.period, self.spec.local_offset_days())
    }
}
