//! The TLE orbit against SGP4's published verification and the J₂ rates.

use super::*;

/// `line` (68 characters) with its modulo-10 checksum: digits count their value, a minus sign 1.
pub(super) fn with_checksum(line: &str) -> String {
    let sum: u32 = line.chars().map(|c| if c == '-' { 1 } else { c.to_digit(10).unwrap_or(0) }).sum();
    format!("{line}{}", sum % 10)
}

/// Vallado et al. (2006), the verification run `tcppver.out`: satellite 00005 (a 1958 Vanguard,
/// e = 0.186) at the epoch and 360 min later, TEME km, printed to 1e-8 km; allowed 1e-6 km (the
/// crate's arithmetic order against the C++ reference).
#[test]
fn sgp4_reproduces_vallados_verification_vectors() {
    let tle = TleOrbit::from_lines(
        "1 00005U 58002B   00179.78495062  .00000023  00000-0  28098-4 0  4753",
        "2 00005  34.2682 348.7242 1859667 331.7664  19.3264 10.82419157413667",
    )
    .unwrap();
    for (minutes, want) in
        [(0.0, [7022.46529266, -1400.08296755, 0.03995155]), (360.0, [-7154.03120202, -3783.17682504, -3536.19412294])]
    {
        let got = tle.position_teme_m(tle.epoch_days + minutes / 1440.0).unwrap();
        for k in 0..3 {
            assert!(
                (got[k] / 1e3 - want[k]).abs() < 1e-6,
                "t = {minutes} min, axis {k}: {} vs {}",
                got[k] / 1e3,
                want[k]
            );
        }
    }
}

/// A near-circular element set at 705 km and 98.2° (Landsat 8's orbit; no drag): its node turns
/// with the mean sun, 360°/365.242 days, and at the first-order J₂ rate of its own elements,
/// Ω̇ = −(3/2) n J₂ (R_e/a)² cos i with a from its mean motion (Vallado 2013, eq. 9-41); each
/// allowed 1.5 % (SGP4's mean elements are Brouwer's and it adds J₄ and J₂², which the
/// first-order rate leaves out).
#[test]
fn a_sun_synchronous_element_set_turns_with_the_mean_sun() {
    let line1 = with_checksum("1 39084U 13008A   23001.00000000  .00000000  00000-0  00000-0 0  999");
    let line2 = with_checksum("2 39084  98.2000 100.0000 0001000  90.0000 270.0000 14.57107000 5000");
    let tle = TleOrbit::from_lines(&line1, &line2).unwrap();
    // The node's right ascension at each ascending crossing of the equator over 60 days.
    let node = |from: f64| {
        let z = |d: f64| tle.position_teme_m(d).unwrap()[2];
        let step = 60.0 / sun::DAY_S;
        let mut t = from;
        while !(z(t) < 0.0 && z(t + step) >= 0.0) {
            t += step;
        }
        let (mut lo, mut hi) = (t, t + step);
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            if z(mid) < 0.0 { lo = mid } else { hi = mid }
        }
        let p = tle.position_teme_m(lo).unwrap();
        (lo, p[1].atan2(p[0]))
    };
    let (t0, a0) = node(tle.epoch_days);
    let (t1, a1) = node(tle.epoch_days + 60.0);
    let rate_deg_day = ((a1 - a0).rem_euclid(std::f64::consts::TAU)).to_degrees() / (t1 - t0);
    let want = 360.0 / 365.242_19;
    assert!((rate_deg_day / want - 1.0).abs() < 0.015, "node turns {rate_deg_day} °/day, the sun {want}");
    let n = 14.571_07 * std::f64::consts::TAU / sun::DAY_S;
    let a = (EARTH_GM_M3_S2 / (n * n)).cbrt();
    let j2_rate = -1.5 * n * J2 * (EARTH_EQUATORIAL_RADIUS_M / a).powi(2) * 98.2f64.to_radians().cos();
    let j2_deg_day = j2_rate.to_degrees() * sun::DAY_S;
    assert!((rate_deg_day / j2_deg_day - 1.0).abs() < 0.015, "node turns {rate_deg_day} °/day, J₂ says {j2_deg_day}");
}

/// The same element set's passes over Lake Hume: each is a closest approach seen at the
/// geometry the pass finder states, and over 16 days (Landsat 8's repeat cycle, 233 orbits) the
/// ground track comes back to within a few kilometres.
#[test]
fn a_tle_orbit_passes_over_a_site_and_repeats_its_ground_track() {
    let line1 = with_checksum("1 39084U 13008A   23001.00000000  .00000000  00000-0  00000-0 0  999");
    let line2 = with_checksum("2 39084  98.2000 100.0000 0001000  90.0000 270.0000 14.57107000 5000");
    let tle = TleOrbit::from_lines(&line1, &line2).unwrap();
    let site = Site::from_degrees(-36.1, 147.0);
    let passes = accesses(&tle, &site, tle.epoch_days, tle.epoch_days + 16.0, 0.3);
    assert!(passes.len() >= 4, "{} passes in 16 days within 17° of nadir", passes.len());
    for p in &passes {
        assert!(p.off_nadir_rad.abs() <= 0.3 + 1e-9 && (p.radius_m - 7_083e3).abs() < 15e3, "{p:?}");
        // Closest: the site is no nearer the sub-satellite point a second either side.
        let c = |d: f64| dot(tle.at(d).unwrap().0, site.unit());
        let ds = 1.0 / sun::DAY_S;
        assert!(c(p.days) >= c(p.days - ds) && c(p.days) >= c(p.days + ds));
    }
    let (start, _) = tle.at(tle.epoch_days).unwrap();
    // 233 nodal periods after the epoch, the Earth has turned 16 times under the orbit.
    let period_days = 16.0 / 233.0;
    let best = (-200..=200)
        .map(|k| {
            let d = tle.epoch_days + 233.0 * period_days + f64::from(k) / sun::DAY_S;
            dot(tle.at(d).unwrap().0, start).clamp(-1.0, 1.0).acos() * EARTH_RADIUS_M
        })
        .fold(f64::INFINITY, f64::min);
    assert!(best < 10e3, "the ground track is {:.1} km from where it started", best / 1e3);
}

#[test]
fn a_bad_element_set_is_refused_with_the_reason() {
    let e = TleOrbit::from_lines(
        "1 00005U 58002B   00179.78495062  .00000023  00000-0  28098-4 0  4754",
        "2 00005  34.2682 348.7242 1859667 331.7664  19.3264 10.82419157413667",
    )
    .unwrap_err();
    assert!(e.contains("checksum"), "{e}");
    assert!(TleOrbit::from_lines("not a TLE", "").is_err());
}
