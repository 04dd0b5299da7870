//! Where the instrument is and when it sees a site: a circular sun-synchronous orbit with the
//! Earth's J2 secular rates, and the accesses to a site over a period with the sun and view
//! geometry of each.
//!
//! The orbit is circular at radius a = R_e + h (R_e the equatorial radius, over which missions
//! quote their altitude); the ground is a sphere of the mean radius R
//! ([`crate::units::EARTH_RADIUS_M`], as the pushbroom geometry uses). Its node precesses at
//! Ω̇ = −(3/2) n J₂ (R_e/a)² cos i and its argument of latitude advances at
//! u̇ = n [1 + (3/4) J₂ (R_e/a)² (3 cos² i − 1)] + (3/4) n J₂ (R_e/a)² (5 cos² i − 1)
//! (the secular rates of M and ω for e = 0; Vallado 2013, eqs. 9-41). Sun-synchronous: Ω̇ equals
//! the mean sun's motion, 2π per tropical year, which fixes cos i = −Ω̇ / ((3/2) n J₂ (R_e/a)²)
//! (Wertz 2009, §6.3; 98.2° at 700 km). The node's local mean solar time stays what it was at the
//! epoch: Ω = α_mean sun + (LTAN − 12 h)·15°/h. Earth-fixed positions follow from Greenwich mean
//! sidereal time ([`sun::gmst_rad`]); the Earth is a sphere here.
//!
//! A site is seen when the satellite passes closest to it (the central angle c between the
//! sub-satellite point and the site is a minimum) within the swath. Then the site lies across
//! track, at off-nadir angle γ with tan γ = R sin c / (a − R cos c), and is seen at view zenith
//! θ_v = γ + c (the pushbroom geometry's sin θ_v = (a/R) sin γ; Schowengerdt 2007, §3.4).
//!
//! ## References
//! - Vallado, D. A. (2013) *Fundamentals of Astrodynamics and Applications*, 4th ed., Microcosm
//!   Press, §9.6 (J2 secular rates).
//! - Wertz, J. R. (2009) *Orbit & Constellation Design & Management*, Microcosm Press, §6.3
//!   (sun-synchronous orbits).
//! - Montenbruck, O. & Gill, E. (2000) *Satellite Orbits*, Springer, Table 3.1 (J₂ and R_e of
//!   EGM96/WGS-84).

pub mod sun;
pub mod tle;

use std::f64::consts::TAU;

use crate::units::{EARTH_GM_M3_S2, EARTH_RADIUS_M};
pub use sun::{SunPosition, days_since_j2000, sun_position};
pub use tle::TleOrbit;

/// Where a spacecraft is: what the pass finder ([`accesses`]) asks of an orbit.
pub trait Track {
    /// The unit vector to the spacecraft in Earth-fixed axes and its distance from the Earth's
    /// centre, m, at `days` since J2000.0; `None` where the orbit has no position (a decayed
    /// TLE).
    fn at(&self, days: f64) -> Option<([f64; 3], f64)>;

    /// Its angular rate about the Earth, rad/s (the pass finder's step in ground track).
    fn angular_rate_rad_s(&self) -> f64;

    /// The most its direction from the Earth's centre turns per second in inertial axes, rad/s:
    /// the bound [`accesses`] skips far grid points by. A circular orbit turns at its mean rate
    /// (the default); an eccentric one faster at perigee.
    fn max_angular_rate_rad_s(&self) -> f64 {
        self.angular_rate_rad_s()
    }
}

impl Track for SunSynchronous {
    fn at(&self, days: f64) -> Option<([f64; 3], f64)> {
        Some((self.direction_ecef(days), self.radius_m()))
    }

    fn angular_rate_rad_s(&self) -> f64 {
        self.latitude_rate_rad_s()
    }
}

/// The Earth's second zonal harmonic (EGM96; Montenbruck & Gill 2000, Table 3.1).
pub const J2: f64 = 1.082_626_68e-3;
/// Equatorial radius the J₂ coefficient is referred to, m (WGS-84).
pub const EARTH_EQUATORIAL_RADIUS_M: f64 = 6_378_137.0;
/// The mean sun's motion: 2π per tropical year of 365.242 19 days, rad/s.
pub const MEAN_SUN_RATE_RAD_S: f64 = TAU / (365.242_19 * sun::DAY_S);

/// A circular sun-synchronous orbit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunSynchronous {
    /// Altitude above the equatorial radius, m (as missions quote it; the ground is a sphere of
    /// the mean radius).
    pub altitude_m: f64,
    /// Local mean solar time of the descending node, hours (10.5: a 10:30 morning orbit).
    pub descending_node_h: f64,
    /// Argument of latitude at the epoch, rad (0: at the ascending node).
    pub phase_rad: f64,
    /// The epoch, days since J2000.0.
    pub epoch_days: f64,
}

impl SunSynchronous {
    /// Orbit radius a = R_e + h, m (missions quote altitude over the equatorial radius).
    #[must_use]
    pub fn radius_m(&self) -> f64 {
        EARTH_EQUATORIAL_RADIUS_M + self.altitude_m
    }

    /// Keplerian mean motion n = √(μ/a³), rad/s.
    #[must_use]
    pub fn mean_motion_rad_s(&self) -> f64 {
        (EARTH_GM_M3_S2 / self.radius_m().powi(3)).sqrt()
    }

    /// (3/2) n J₂ (R_e/a)², rad/s: the scale of the J₂ rates.
    fn j2_rate(&self) -> f64 {
        1.5 * self.mean_motion_rad_s() * J2 * (EARTH_EQUATORIAL_RADIUS_M / self.radius_m()).powi(2)
    }

    /// The inclination that makes the node follow the mean sun, rad (module docs); `None` above
    /// the altitude where no inclination can (about 5 970 km).
    #[must_use]
    pub fn inclination_rad(&self) -> Option<f64> {
        let cos_i = -MEAN_SUN_RATE_RAD_S / self.j2_rate();
        (cos_i >= -1.0).then(|| cos_i.acos())
    }

    /// The node's rate Ω̇, rad/s (the mean sun's, by construction).
    #[must_use]
    pub fn node_rate_rad_s(&self) -> f64 {
        let cos_i = self.inclination_rad().map_or(0.0, f64::cos);
        -self.j2_rate() * cos_i
    }

    /// The argument of latitude's rate u̇ = Ṁ + ω̇, rad/s (module docs).
    #[must_use]
    pub fn latitude_rate_rad_s(&self) -> f64 {
        let c2 = self.inclination_rad().map_or(0.0, f64::cos).powi(2);
        let k = 0.5 * self.j2_rate(); // (3/4) n J₂ (R_e/a)²
        self.mean_motion_rad_s() + k * (3.0 * c2 - 1.0) + k * (5.0 * c2 - 1.0)
    }

    /// Nodal period 2π/u̇, s.
    #[must_use]
    pub fn nodal_period_s(&self) -> f64 {
        TAU / self.latitude_rate_rad_s()
    }

    /// Right ascension of the ascending node at `days` since J2000.0, rad: the mean sun's plus
    /// the node's local time from noon (LTAN = LTDN + 12 h).
    #[must_use]
    pub fn node_rad(&self, days: f64) -> f64 {
        let ltan_h = self.descending_node_h + 12.0;
        let at_epoch = sun::sun_coordinates(self.epoch_days).mean_longitude_rad + (ltan_h - 12.0) / 24.0 * TAU;
        at_epoch + self.node_rate_rad_s() * (days - self.epoch_days) * sun::DAY_S
    }

    /// Unit vector to the satellite in Earth-fixed axes (x to Greenwich on the equator, z north).
    #[must_use]
    pub fn direction_ecef(&self, days: f64) -> [f64; 3] {
        let i = self.inclination_rad().unwrap_or(0.0);
        let u = self.phase_rad + self.latitude_rate_rad_s() * (days - self.epoch_days) * sun::DAY_S;
        let node = self.node_rad(days);
        let (su, cu) = u.sin_cos();
        let (so, co) = node.sin_cos();
        let (si, ci) = i.sin_cos();
        let eci = [cu * co - su * so * ci, cu * so + su * co * ci, su * si];
        let (sg, cg) = sun::gmst_rad(days).sin_cos();
        [eci[0] * cg + eci[1] * sg, -eci[0] * sg + eci[1] * cg, eci[2]]
    }
}

/// A place on the ground, rad (longitude east positive).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// Latitude, rad (north positive).
    pub latitude_rad: f64,
    /// Longitude, rad (east positive).
    pub longitude_rad: f64,
}

impl Site {
    /// From degrees.
    #[must_use]
    pub fn from_degrees(latitude_deg: f64, longitude_deg: f64) -> Self {
        Self { latitude_rad: latitude_deg.to_radians(), longitude_rad: longitude_deg.to_radians() }
    }

    fn unit(&self) -> [f64; 3] {
        let (sp, cp) = self.latitude_rad.sin_cos();
        let (sl, cl) = self.longitude_rad.sin_cos();
        [cp * cl, cp * sl, sp]
    }

    /// Local north and east unit vectors.
    fn north_east(&self) -> ([f64; 3], [f64; 3]) {
        let (sp, cp) = self.latitude_rad.sin_cos();
        let (sl, cl) = self.longitude_rad.sin_cos();
        ([-sp * cl, -sp * sl, cp], [-sl, cl, 0.0])
    }
}

/// One pass of the satellite over a site, at its closest approach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Access {
    /// Time of closest approach, days since J2000.0.
    pub days: f64,
    /// Off-nadir angle of the site, rad, positive to the right of the ground track.
    pub off_nadir_rad: f64,
    /// View zenith at the site, rad.
    pub view_zenith_rad: f64,
    /// Azimuth of the sensor seen from the site, rad clockwise from north.
    pub view_azimuth_rad: f64,
    /// Direction of the ground track, rad clockwise from north.
    pub heading_rad: f64,
    /// The sun at the site.
    pub sun: SunPosition,
    /// Whether the satellite was flying south (on the descending half of its orbit).
    pub descending: bool,
    /// The spacecraft's distance from the Earth's centre at the pass, m.
    pub radius_m: f64,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The passes of `orbit` over `site` between `from_days` and `to_days` whose site lies within
/// `max_off_nadir_rad` of nadir (either side), in time order. Each pass's closest approach is
/// bracketed on a 20 s grid and refined by golden-section search to well under a second.
///
/// Far from the site the grid is not walked point by point: in a grid step the sub-satellite
/// point moves by at most δ = (ω_max + ω_E)·20 s over the ground (ω_max the orbit's largest
/// angular rate, ω_E the Earth's; 5 % more, for the node's drift), so from a point at central
/// angle c no point of the next (c − c_limit)/δ is within reach, and the walk resumes after
/// them. It resumes with the values the point-by-point walk would hold there, evaluated at the
/// same times, so the passes found are the same to the bit (tested); a year of a
/// sun-synchronous orbit asks for about 1/20 of the grid's positions.
#[must_use]
pub fn accesses(orbit: &impl Track, site: &Site, from_days: f64, to_days: f64, max_off_nadir_rad: f64) -> Vec<Access> {
    let r = EARTH_RADIUS_M;
    // The central angle at which the site is seen at the largest off-nadir angle: sin(γ + c) =
    // (a/R) sin γ (at the orbit's radius where the search starts; an eccentric orbit's is
    // checked again at each pass).
    let a = orbit.at(from_days).map_or(r, |(_, a)| a);
    let gamma = max_off_nadir_rad.clamp(0.0, 1.5);
    let c_max = max_central_angle(a, gamma);
    let step_days = 20.0 / sun::DAY_S;
    // A grid point next to the minimum is at most one step of ground track away.
    let step_arc = orbit.angular_rate_rad_s() * 20.0 + 7.3e-5 * 20.0;
    let limit_angle = (c_max + step_arc).min(std::f64::consts::PI);
    let cos_limit = limit_angle.cos();
    let s = site.unit();
    // dot(p, s) = cos c; -1 where the orbit has no position (such a point is never skipped from).
    let closeness = |d: f64| orbit.at(d).map_or(-1.0, |(p, _)| dot(p, s));
    let n = ((to_days - from_days) / step_days).ceil().max(0.0) as usize;
    // The walk's value at grid point `j` (j = −1 the point before the first), at the time the
    // point-by-point walk evaluates it: each point's successor at its own time plus one step.
    let value_at = |j: isize| match j {
        ..=-1 => closeness(from_days - step_days),
        0 => closeness(from_days),
        _ => closeness(from_days + (j - 1) as f64 * step_days + step_days),
    };
    let skip_arc = 1.05 * (orbit.max_angular_rate_rad_s() + 7.3e-5) * 20.0;
    let mut out = Vec::new();
    let (mut prev, mut here) = (value_at(-1), value_at(0));
    let mut k = 0;
    while k <= n {
        if here < cos_limit && here > -1.0 {
            // Points k + 1 … k + skip − 1 are all farther than the limit; k + skip may not be.
            let skip = ((here.acos() - limit_angle) / skip_arc).floor();
            if skip >= 2.0 {
                k = k.saturating_add(skip as usize);
                if k > n {
                    break;
                }
                (prev, here) = (value_at(k as isize - 1), value_at(k as isize));
                continue;
            }
        }
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
        k += 1;
    }
    out
}

/// The argument in [lo, hi] where the unimodal `f` is largest (golden-section search to 1 ms).
fn golden_max(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    while hi - lo > 1e-3 / sun::DAY_S {
        if f1 < f2 {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + ratio * (hi - lo);
            f2 = f(x2);
        } else {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - ratio * (hi - lo);
            f1 = f(x1);
        }
    }
    0.5 * (lo + hi)
}

/// The largest central angle (rad, between the sub-satellite point and a ground point) that a
/// satellite at radius `a_m` sees within off-nadir angle `gamma_rad`: sin(γ + c) = (a/R)·sin γ
/// on the near side of the Earth (the sine rule in the triangle of the Earth's centre, the
/// satellite and the ground point; Wertz 2009, §8.3). Past the horizon's off-nadir angle
/// asin(R/a) the ray misses the Earth, and the answer stays the horizon's, acos(R/a).
fn max_central_angle(a_m: f64, gamma_rad: f64) -> f64 {
    let r = EARTH_RADIUS_M;
    let x = (a_m / r) * gamma_rad.sin();
    if x >= 1.0 { (r / a_m).clamp(-1.0, 1.0).acos() } else { x.asin() - gamma_rad }
}

/// The geometry of the pass closest to `site` at `days`, if the site is within off-nadir angle
/// `max_gamma` of the ground track.
fn access_at(orbit: &impl Track, site: &Site, days: f64, max_gamma: f64) -> Option<Access> {
    let (p, a) = orbit.at(days)?;
    let s = site.unit();
    let r = EARTH_RADIUS_M;
    let c_max = max_central_angle(a, max_gamma);
    let c = dot(p, s).clamp(-1.0, 1.0).acos();
    if c > c_max {
        return None;
    }
    let gamma = (r * c.sin()).atan2(a - r * c.cos());
    // Ground-track direction from a centred difference of one second.
    let ds = 1.0 / sun::DAY_S;
    let (p0, p1) = (orbit.at(days - ds)?.0, orbit.at(days + ds)?.0);
    let v = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
    let (north, east) = site.north_east();
    let heading = dot(v, east).atan2(dot(v, north)).rem_euclid(TAU);
    // p × v points left of the track (up × forward); the site to the right is on the other side.
    let right = dot(cross(p, v), s) < 0.0;
    let d = [p[0] - s[0] * dot(s, p), p[1] - s[1] * dot(s, p), p[2] - s[2] * dot(s, p)];
    let view_azimuth = if c > 1e-9 {
        dot(d, east).atan2(dot(d, north)).rem_euclid(TAU)
    } else {
        // Straight overhead: the azimuth is undefined; the track's left-hand normal stands in.
        (heading - std::f64::consts::FRAC_PI_2).rem_euclid(TAU)
    };
    Some(Access {
        days,
        off_nadir_rad: if right { gamma } else { -gamma },
        view_zenith_rad: gamma + c,
        view_azimuth_rad: view_azimuth,
        heading_rad: heading,
        sun: sun_position(site.latitude_rad, site.longitude_rad, days),
        descending: dot(v, north) < 0.0,
        radius_m: a,
    })
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tle_tests;
