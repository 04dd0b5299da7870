use super::*;

fn orbit(altitude_km: f64) -> SunSynchronous {
    SunSynchronous {
        altitude_m: altitude_km * 1e3,
        descending_node_h: 10.5,
        phase_rad: 0.0,
        epoch_days: days_since_j2000("2023-01-01").unwrap(),
    }
}

/// Published sun-synchronous inclinations: 98.19° at 700 km (Wertz 2009, Table 6-3), allowed
/// 0.01° (its rounding); Landsat 8 at 705 km, 98.2° (USGS Landsat 8 Data Users Handbook),
/// allowed 0.05° (quoted to 0.1°).
#[test]
fn sun_synchronous_inclination_matches_published_values() {
    let i700 = orbit(700.0).inclination_rad().unwrap().to_degrees();
    let i705 = orbit(705.0).inclination_rad().unwrap().to_degrees();
    assert!((i700 - 98.19).abs() < 0.01, "{i700}");
    assert!((i705 - 98.2).abs() < 0.05, "{i705}");
    assert!(orbit(7000.0).inclination_rad().is_none());
}

/// The node turns once a tropical year, as the mean sun does.
#[test]
fn node_follows_the_mean_sun() {
    let o = orbit(700.0);
    let turn = o.node_rad(o.epoch_days + 365.242_19) - o.node_rad(o.epoch_days);
    assert!((turn - TAU).abs() < 1e-9, "{turn}");
}

/// Find the times the propagated track crosses the equator going north (ascending nodes) by
/// bisection on z.
fn ascending_nodes(o: &SunSynchronous, days: f64) -> Vec<f64> {
    let step = 30.0 / sun::DAY_S;
    let mut out = Vec::new();
    let mut t = o.epoch_days - step / 2.0;
    while t < o.epoch_days + days {
        let (z0, z1) = (o.direction_ecef(t)[2], o.direction_ecef(t + step)[2]);
        if z0 < 0.0 && z1 >= 0.0 {
            let (mut lo, mut hi) = (t, t + step);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if o.direction_ecef(mid)[2] < 0.0 { lo = mid } else { hi = mid }
            }
            out.push(0.5 * (lo + hi));
        }
        t += step;
    }
    out
}

/// The propagated track against the analytic rates: consecutive ascending nodes are one nodal
/// period 2π/u̇ apart (to 10 ms), each shifted west by (ω_E − Ω̇)·T (to 10⁻⁶ rad, 6 m), and the
/// descending node's local mean solar time is the orbit's 10:30 (to 1 s of time).
#[test]
fn propagated_track_matches_the_analytic_rates() {
    let o = orbit(786.0);
    let nodes = ascending_nodes(&o, 2.0);
    assert!(nodes.len() >= 28, "{}", nodes.len());
    let period = o.nodal_period_s();
    let earth_rate = TAU * 1.002_737_909_35 / sun::DAY_S; // GMST's rate, rad/s
    let shift = (earth_rate - o.node_rate_rad_s()) * period;
    for w in nodes.windows(2) {
        assert!(((w[1] - w[0]) * sun::DAY_S - period).abs() < 0.01);
        let lon = |t: f64| {
            let p = o.direction_ecef(t);
            p[1].atan2(p[0])
        };
        let west = (lon(w[0]) - lon(w[1])).rem_euclid(TAU);
        assert!((west - shift).abs() < 1e-6, "{west} vs {shift}");
    }
    // Half a period after an ascending node comes the descending node.
    let descending = nodes[3] + 0.5 * period / sun::DAY_S;
    let p = o.direction_ecef(descending);
    let local = sun::local_mean_solar_time_h(p[1].atan2(p[0]), descending);
    assert!((local - 10.5).abs() < 1.0 / 3600.0, "{local}");
    // Sentinel-2 repeats its ground track after 143 orbits in 10 days: at 786 km the analytic
    // rates give 14.3 revolutions per nodal day to 0.5 %.
    let revs_per_day = sun::DAY_S / period * (TAU / sun::DAY_S) / (earth_rate - o.node_rate_rad_s());
    assert!((revs_per_day / 14.3 - 1.0).abs() < 0.005, "{revs_per_day}");
}

/// Every access found is the closest approach a brute-force 0.5 s scan finds, with the site
/// within the swath; the geometry closes (θ_v = γ + c, sin θ_v = (a/R) sin γ).
#[test]
fn accesses_are_closest_approaches_within_the_swath() {
    let o = orbit(700.0);
    let site = Site::from_degrees(-36.1, 147.0);
    let max_off = 20f64.to_radians();
    let found = accesses(&o, &site, o.epoch_days, o.epoch_days + 16.0, max_off);
    // A ±20° swath at 700 km is ~520 km wide; at 36° S the descending tracks are ~2 200 km
    // apart, so about one pass in four days by day and as many by night.
    assert!((6..=10).contains(&found.len()), "{}", found.len());
    for a in &found {
        assert!(a.off_nadir_rad.abs() <= max_off + 1e-9);
        let ratio = (a.view_zenith_rad.sin() / a.off_nadir_rad.abs().sin()) / (o.radius_m() / EARTH_RADIUS_M);
        assert!(a.off_nadir_rad.abs() < 1e-6 || (ratio - 1.0).abs() < 1e-9, "{ratio}");
        let s = site.unit();
        let scan = (-120..=120)
            .map(|k| a.days + f64::from(k) * 0.5 / sun::DAY_S)
            .max_by(|x, y| dot(o.direction_ecef(*x), s).total_cmp(&dot(o.direction_ecef(*y), s)))
            .unwrap();
        assert!((scan - a.days).abs() * sun::DAY_S < 0.5, "{} s", (scan - a.days) * sun::DAY_S);
        assert!(a.sun.zenith_rad.is_finite() && a.heading_rad.is_finite());
    }
    // A 10:30 descending orbit sees Lake Hume in the morning on its descending passes and at
    // night on its ascending ones.
    for a in found.iter().filter(|a| a.descending) {
        let t = sun::local_mean_solar_time_h(site.longitude_rad, a.days);
        assert!((9.5..11.5).contains(&t), "{t}");
        assert!(a.sun.zenith_rad < 80f64.to_radians());
    }
    assert!(found.iter().any(|a| !a.descending && a.sun.zenith_rad > std::f64::consts::FRAC_PI_2));
}

/// A site right of the track comes out with a positive off-nadir angle: the view azimuth points
/// from the site back across the track, 90° from the heading on the left-hand side.
#[test]
fn off_nadir_sign_and_view_azimuth_agree() {
    let o = orbit(700.0);
    let site = Site::from_degrees(-36.1, 147.0);
    for a in accesses(&o, &site, o.epoch_days, o.epoch_days + 16.0, 0.35) {
        if a.off_nadir_rad.abs() < 0.01 {
            continue;
        }
        let left_normal = (a.heading_rad - std::f64::consts::FRAC_PI_2).rem_euclid(TAU);
        let diff = (a.view_azimuth_rad - left_normal + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI;
        if a.off_nadir_rad > 0.0 {
            assert!(diff.abs() < 0.05, "right: view azimuth {diff} rad off the left normal");
        } else {
            assert!(diff.abs() > std::f64::consts::PI - 0.05, "left: {diff}");
        }
    }
}

#[test]
fn a_year_of_accesses_finds_a_plausible_number_of_passes() {
    // Not a timing assertion (tests are not benchmarks): a year's search must finish and find
    // a plausible number of passes (a 700 km orbit with a ±20° swath sees a site at 23° S about
    // every 4–5 days by day and as often by night).
    let o = orbit(700.0);
    let site = Site::from_degrees(-23.44, 151.91);
    let year = accesses(&o, &site, o.epoch_days, o.epoch_days + 365.0, 20f64.to_radians());
    assert!((120..200).contains(&year.len()), "{}", year.len());
}

/// The pass finder before it skipped far grid points: every point of the 20 s grid in turn.
fn accesses_point_by_point(orbit: &impl Track, site: &Site, from_days: f64, to_days: f64, max_off: f64) -> Vec<Access> {
    let r = EARTH_RADIUS_M;
    let a = orbit.at(from_days).map_or(r, |(_, a)| a);
    let gamma = max_off.clamp(0.0, 1.5);
    let c_max = ((a / r) * gamma.sin()).min(1.0).asin() - gamma;
    let step_days = 20.0 / sun::DAY_S;
    let step_arc = orbit.angular_rate_rad_s() * 20.0 + 7.3e-5 * 20.0;
    let cos_limit = (c_max + step_arc).min(std::f64::consts::PI).cos();
    let s = site.unit();
    let closeness = |d: f64| orbit.at(d).map_or(-1.0, |(p, _)| dot(p, s));
    let n = ((to_days - from_days) / step_days).ceil().max(0.0) as usize;
    let mut out = Vec::new();
    let (mut prev, mut here) = (closeness(from_days - step_days), closeness(from_days));
    for k in 0..=n {
        let t = from_days + k as f64 * step_days;
        let next = closeness(t + step_days);
        if here >= cos_limit && here >= prev && here > next {
            let best = golden_max(&closeness, t - step_days, t + step_days);
            if (from_days..=to_days).contains(&best)
                && let Some(access) = access_at(orbit, site, best, gamma)
            {
                out.push(access);
            }
        }
        (prev, here) = (here, next);
    }
    out
}

/// Skipping the grid points out of reach finds the passes the point-by-point walk finds, to the
/// bit: two altitudes, swaths from nadir-only to ±60°, sites from the equator to 80° S, a start
/// off the grid's phase, and an element set (SGP4).
#[test]
fn skipping_far_grid_points_finds_the_same_passes_to_the_bit() {
    let sites = [(-36.1, 147.0), (-23.44, 151.91), (0.0, -60.0), (-80.0, 10.0), (51.5, -0.1)];
    for altitude in [500.0, 786.0] {
        let o = SunSynchronous { phase_rad: 1.234, ..orbit(altitude) };
        for (lat, lon) in sites {
            let site = Site::from_degrees(lat, lon);
            for max_off in [0.0, 0.05, 0.35, 1.05] {
                let from = o.epoch_days + 0.123_456;
                let fast = accesses(&o, &site, from, from + 40.0, max_off);
                let slow = accesses_point_by_point(&o, &site, from, from + 40.0, max_off);
                assert_eq!(fast, slow, "{altitude} km, site ({lat}, {lon}), off-nadir {max_off}");
                assert!(max_off < 0.3 || !fast.is_empty(), "{altitude} km ({lat}, {lon}) {max_off}: no pass");
            }
        }
    }
    let line1 = super::tle_tests::with_checksum("1 39084U 13008A   23001.00000000  .00000000  00000-0  00000-0 0  999");
    let line2 = super::tle_tests::with_checksum("2 39084  98.2000 100.0000 0001000  90.0000 270.0000 14.57107000 5000");
    let tle = TleOrbit::from_lines(&line1, &line2).unwrap();
    for (lat, lon) in sites {
        let site = Site::from_degrees(lat, lon);
        let fast = accesses(&tle, &site, tle.epoch_days, tle.epoch_days + 30.0, 0.3);
        assert_eq!(fast, accesses_point_by_point(&tle, &site, tle.epoch_days, tle.epoch_days + 30.0, 0.3));
    }
}

/// A track that counts the positions asked of it.
struct Counted<'a, T>(&'a T, std::cell::Cell<usize>);

impl<T: Track> Track for Counted<'_, T> {
    fn at(&self, days: f64) -> Option<([f64; 3], f64)> {
        self.1.set(self.1.get() + 1);
        self.0.at(days)
    }
    fn angular_rate_rad_s(&self) -> f64 {
        self.0.angular_rate_rad_s()
    }
}

/// What the skipping is for: a year over Lake Hume with a ±20° reach asks for the orbit's
/// position at a small fraction of the 1.58 million grid points (82 000 of them, with the
/// golden-section refinements).
#[test]
fn a_year_asks_for_far_fewer_positions_than_grid_points() {
    let o = orbit(700.0);
    let site = Site::from_degrees(-36.1, 147.0);
    let counted = Counted(&o, std::cell::Cell::new(0));
    let year = accesses(&counted, &site, o.epoch_days, o.epoch_days + 365.0, 20f64.to_radians());
    let grid = (365.0 * sun::DAY_S / 20.0) as usize;
    assert!(counted.1.get() * 15 < grid, "{} positions for {grid} grid points", counted.1.get());
    assert!((120..220).contains(&year.len()), "{}", year.len());
}

/// Past the horizon's off-nadir angle (asin(R/a) = 64.2° at 700 km) a wider reach sees no
/// further: the central angle stays the horizon's (25.8°), and every pass a 57° reach finds, a
/// reach of 1.4 rad (80°) finds too, with the same geometry. (The search once took the
/// central angle as π/2 − γ there, so that 80° kept passes only out to 10°.)
#[test]
fn a_reach_past_the_horizon_keeps_every_pass_a_smaller_one_finds() {
    let o = orbit(700.0);
    let horizon = (EARTH_RADIUS_M / o.radius_m()).acos();
    assert!((horizon.to_degrees() - 25.8).abs() < 0.05, "{}", horizon.to_degrees());
    assert_eq!(max_central_angle(o.radius_m(), 1.4), horizon);
    assert!(max_central_angle(o.radius_m(), 1.0) < horizon);
    let site = Site::from_degrees(-36.1, 147.0);
    let narrow = accesses(&o, &site, o.epoch_days, o.epoch_days + 16.0, 1.0);
    let wide = accesses(&o, &site, o.epoch_days, o.epoch_days + 16.0, 1.4);
    assert!(narrow.len() >= 20, "{}", narrow.len());
    for a in &narrow {
        assert!(
            wide.iter().any(|w| (w.days - a.days).abs() * sun::DAY_S < 1.0 && (w.off_nadir_rad - a.off_nadir_rad).abs() < 1e-9),
            "the pass at off-nadir {:.1}° is lost",
            a.off_nadir_rad.to_degrees()
        );
    }
    assert!(wide.len() > narrow.len());
    assert!(wide.iter().all(|w| w.off_nadir_rad.abs() < (EARTH_RADIUS_M / o.radius_m()).asin() + 1e-9));
}
