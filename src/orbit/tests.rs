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
