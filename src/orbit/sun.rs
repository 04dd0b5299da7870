//! Time and the sun's position: calendar dates to days since J2000, the sun's right ascension
//! and declination, Greenwich mean sidereal time, and the sun's zenith and azimuth at a site.
//!
//! The sun's coordinates follow the Astronomical Almanac's low-precision formulas (accuracy
//! 0.01° between 1950 and 2050): with n the days from J2000.0 (2000-01-01 12:00 UT),
//! mean longitude L = 280.460° + 0.985 647 4° n, mean anomaly g = 357.528° + 0.985 600 3° n,
//! ecliptic longitude λ = L + 1.915° sin g + 0.020° sin 2g, obliquity ε = 23.439° − 4·10⁻⁷° n,
//! α = atan2(cos ε sin λ, cos λ), δ = asin(sin ε sin λ). Greenwich mean sidereal time
//! GMST = 18.697 374 558 h + 24.065 709 824 419 08 h · n (USNO). UT is taken for TT (the ~70 s
//! between them moves the sun by 0.0008°).
//!
//! ## References
//! - U.S. Naval Observatory & HM Nautical Almanac Office, *The Astronomical Almanac* (2020),
//!   p. C5, "Low precision formulas for the Sun".
//! - USNO, "Computing Greenwich Apparent Sidereal Time" (GMST approximation, 0.1 s per century).
//! - Fliegel, H. F. & Van Flandern, T. C. (1968) A machine algorithm for processing calendar
//!   dates. Commun. ACM 11, 657 (calendar date to Julian day number).

use std::f64::consts::TAU;

/// Seconds in a day.
pub const DAY_S: f64 = 86_400.0;

/// Julian day number of a Gregorian calendar date (Fliegel & Van Flandern 1968): the JD at
/// noon of that date.
#[must_use]
pub fn julian_day_number(year: i64, month: i64, day: i64) -> i64 {
    let a = (month - 14) / 12;
    (1461 * (year + 4800 + a)) / 4 + (367 * (month - 2 - 12 * a)) / 12 - (3 * ((year + 4900 + a) / 100)) / 4 + day
        - 32075
}

/// Days from J2000.0 to 00:00 UT of `YYYY-MM-DD`, or a message naming what is wrong.
pub fn days_since_j2000(date: &str) -> Result<f64, String> {
    let parts: Vec<&str> = date.trim().split('-').collect();
    let [y, m, d] = parts.as_slice() else { return Err(format!("`{date}` is not a date (expected YYYY-MM-DD)")) };
    let num = |s: &str| s.parse::<i64>().map_err(|_| format!("`{date}` is not a date (expected YYYY-MM-DD)"));
    let (y, m, d) = (num(y)?, num(m)?, num(d)?);
    let days_in_month = match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        2 => 28,
        _ => return Err(format!("`{date}`: month {m} is not 1 to 12")),
    };
    if !(1900..=2100).contains(&y) {
        return Err(format!("`{date}`: year {y} is outside 1900 to 2100 (the sun's formulas hold near 2000)"));
    }
    if !(1..=days_in_month).contains(&d) {
        return Err(format!("`{date}`: day {d} is not 1 to {days_in_month}"));
    }
    // JD at noon of the date minus J2000.0 (JD 2451545.0, itself noon), minus half a day.
    Ok((julian_day_number(y, m, d) - 2_451_545) as f64 - 0.5)
}

/// The calendar date (year, month, day) of `days` since J2000.0 (the inverse of
/// [`days_since_j2000`] for the whole day containing it).
#[must_use]
pub fn calendar_date(days: f64) -> (i64, u32, u32) {
    // Fliegel & Van Flandern's inverse, from the Julian day number.
    let jdn = (days + 0.5).floor() as i64 + 2_451_545;
    let l = jdn + 68_569;
    let n = 4 * l / 146_097;
    let l = l - (146_097 * n + 3) / 4;
    let i = 4000 * (l + 1) / 1_461_001;
    let l = l - 1461 * i / 4 + 31;
    let j = 80 * l / 2447;
    let day = l - 2447 * j / 80;
    let l = j / 11;
    let month = j + 2 - 12 * l;
    let year = 100 * (n - 49) + i + l;
    (year, month as u32, day as u32)
}

/// The UT calendar date and minute of the day of `days` since J2000.0, rounded to the minute
/// (a time in the last half-minute before midnight is 00:00 of the next day).
#[must_use]
pub fn date_and_minute(days: f64) -> ((i64, u32, u32), u32) {
    let minutes = ((days + 0.5) * 1440.0).round() as i64;
    let (day, minute) = (minutes.div_euclid(1440), minutes.rem_euclid(1440));
    (calendar_date(day as f64 - 0.25), minute as u32)
}

/// The sun's equatorial coordinates and mean longitude at `days` since J2000.0 (radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunCoordinates {
    /// Right ascension α, rad in [0, 2π).
    pub right_ascension_rad: f64,
    /// Declination δ, rad.
    pub declination_rad: f64,
    /// Mean longitude L (the right ascension of the mean sun), rad in [0, 2π).
    pub mean_longitude_rad: f64,
}

/// The sun's coordinates (Astronomical Almanac low-precision formulas; module docs).
#[must_use]
pub fn sun_coordinates(days: f64) -> SunCoordinates {
    let l = (280.460 + 0.985_647_4 * days).to_radians();
    let g = (357.528 + 0.985_600_3 * days).to_radians();
    let lambda = l + 1.915f64.to_radians() * g.sin() + 0.020f64.to_radians() * (2.0 * g).sin();
    let eps = (23.439 - 0.000_000_4 * days).to_radians();
    let ra = (eps.cos() * lambda.sin()).atan2(lambda.cos()).rem_euclid(TAU);
    let dec = (eps.sin() * lambda.sin()).asin();
    SunCoordinates { right_ascension_rad: ra, declination_rad: dec, mean_longitude_rad: l.rem_euclid(TAU) }
}

/// Greenwich mean sidereal time at `days` since J2000.0, rad in [0, 2π) (USNO).
#[must_use]
pub fn gmst_rad(days: f64) -> f64 {
    let hours = 18.697_374_558 + 24.065_709_824_419_08 * days;
    (hours.rem_euclid(24.0) / 24.0) * TAU
}

/// The sun seen from a site: zenith and azimuth (clockwise from north), rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunPosition {
    /// Solar zenith angle, rad.
    pub zenith_rad: f64,
    /// Solar azimuth, rad clockwise from north.
    pub azimuth_rad: f64,
}

/// The sun's zenith and azimuth at latitude φ, longitude λ (rad, east positive) at `days` since
/// J2000.0: hour angle H = GMST + λ − α, cos θ₀ = sin φ sin δ + cos φ cos δ cos H,
/// azimuth atan2(−sin H cos δ, sin δ cos φ − cos δ sin φ cos H) (spherical astronomy).
#[must_use]
pub fn sun_position(latitude_rad: f64, longitude_rad: f64, days: f64) -> SunPosition {
    let sun = sun_coordinates(days);
    let h = gmst_rad(days) + longitude_rad - sun.right_ascension_rad;
    let (sd, cd) = sun.declination_rad.sin_cos();
    let (sp, cp) = latitude_rad.sin_cos();
    let cos_z = (sp * sd + cp * cd * h.cos()).clamp(-1.0, 1.0);
    let azimuth = (-h.sin() * cd).atan2(sd * cp - cd * sp * h.cos()).rem_euclid(TAU);
    SunPosition { zenith_rad: cos_z.acos(), azimuth_rad: azimuth }
}

/// Local mean solar time at longitude λ (rad) at `days` since J2000.0, hours in [0, 24): the
/// hour angle of the mean sun plus 12 h.
#[must_use]
pub fn local_mean_solar_time_h(longitude_rad: f64, days: f64) -> f64 {
    let mean_sun = sun_coordinates(days).mean_longitude_rad;
    let h = gmst_rad(days) + longitude_rad - mean_sun;
    (h.rem_euclid(TAU) / TAU * 24.0 + 12.0).rem_euclid(24.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_round_trip_and_j2000_is_day_zero_at_noon() {
        assert_eq!(days_since_j2000("2000-01-01").unwrap(), -0.5);
        assert_eq!(days_since_j2000("2000-01-02").unwrap(), 0.5);
        for date in ["2023-06-21", "2024-02-29", "1999-12-31", "2050-07-04"] {
            let d = days_since_j2000(date).unwrap();
            let (y, m, dd) = calendar_date(d + 0.3);
            assert_eq!(format!("{y:04}-{m:02}-{dd:02}"), date);
        }
        let d = days_since_j2000("2023-06-21").unwrap();
        assert_eq!(date_and_minute(d + 0.5), ((2023, 6, 21), 720));
        assert_eq!(date_and_minute(d + 1.0 - 10.0 / 86_400.0), ((2023, 6, 22), 0));
        assert!(days_since_j2000("2023-02-29").unwrap_err().contains("day 29"));
        assert!(days_since_j2000("2023-13-01").unwrap_err().contains("month 13"));
        assert!(days_since_j2000("June").is_err());
    }

    /// The Astronomical Almanac's own worked value: at 2000-01-01 12:00 UT (n = 0) the sun is at
    /// α 281.28°, δ −23.03° (its formulas evaluated by hand: L 280.46°, g 357.528°, λ 280.378°).
    /// The June solstice of 2023 (21 June 14:58 UT) has δ = +23.44° to 0.01°.
    #[test]
    fn sun_coordinates_at_j2000_and_the_solstice() {
        let s = sun_coordinates(0.0);
        assert!((s.right_ascension_rad.to_degrees() - 281.28).abs() < 0.01, "{}", s.right_ascension_rad.to_degrees());
        assert!((s.declination_rad.to_degrees() + 23.03).abs() < 0.01, "{}", s.declination_rad.to_degrees());
        let solstice = days_since_j2000("2023-06-21").unwrap() + (14.0 + 58.0 / 60.0) / 24.0;
        assert!((sun_coordinates(solstice).declination_rad.to_degrees() - 23.44).abs() < 0.01);
    }

    /// At local solar noon of the equinox the sun's zenith is the latitude; at the solstice over
    /// Lake Hume (36.1° S) it is 36.1 + 23.44 = 59.5° and the sun is due north.
    #[test]
    fn noon_zenith_follows_latitude_and_declination() {
        let (lat, lon) = ((-36.1f64).to_radians(), 147.0f64.to_radians());
        let day = days_since_j2000("2023-06-21").unwrap();
        // Find the minimum zenith over the day (solar noon) by scanning minutes.
        let (zmin, az) = (0..1440)
            .map(|m| sun_position(lat, lon, day + f64::from(m) / 1440.0))
            .map(|p| (p.zenith_rad.to_degrees(), p.azimuth_rad.to_degrees()))
            .fold((f64::MAX, 0.0), |best, p| if p.0 < best.0 { p } else { best });
        assert!((zmin - (36.1 + 23.44)).abs() < 0.05, "noon zenith {zmin}");
        assert!(!(1.0..=359.0).contains(&az), "noon azimuth {az}");
    }

    #[test]
    fn sidereal_time_gains_about_four_minutes_a_day() {
        let gain = (gmst_rad(1.0) - gmst_rad(0.0)).rem_euclid(TAU).to_degrees();
        assert!((gain - 0.985_6).abs() < 1e-3, "{gain}");
        // Local mean solar time at Greenwich at 00:00 UT is midnight to within the GMST/mean-sun
        // model's consistency (seconds).
        let t = local_mean_solar_time_h(0.0, days_since_j2000("2023-03-01").unwrap());
        assert!(t.min(24.0 - t) < 0.01, "{t}");
    }
}
