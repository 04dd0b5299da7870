//! A season's looks: each access of a design's orbit to the site, with the geometry the design
//! sees it from, its glint and cloud cover, and whether a processor would keep it.

use rand::SeedableRng;
use rand::rngs::Xoshiro256PlusPlus;
use rand_distr::{Beta, Distribution};

use super::SeasonSpec;
use crate::atmosphere::{Geometry, glint_radiance_norm};
use crate::instrument::{InstrumentSpec, line_of_sight};
use crate::orbit::{Access, EARTH_EQUATORIAL_RADIUS_M, Site, SunSynchronous, TleOrbit, accesses};

/// Why a look is kept or not, in the order the checks are made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Verdict {
    /// Kept: sun high enough, glint low, clear enough.
    Valid,
    /// The sun too low (or set).
    SunLow,
    /// The site seen too obliquely (l2gen's HISATZEN).
    ViewOblique,
    /// High glint at the site.
    Glint,
    /// Too cloudy.
    Cloud,
}

impl Verdict {
    /// Short name for tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Valid => "valid",
            Self::SunLow => "sun low",
            Self::ViewOblique => "view oblique",
            Self::Glint => "glint",
            Self::Cloud => "cloud",
        }
    }
}

/// One pass of one design over the site.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    /// The pass.
    pub access: Access,
    /// Fore/aft tilt of the look, degrees (the design's own without a glint tilt).
    pub forward_tilt_deg: f64,
    /// The spacecraft's altitude at the pass over the equatorial radius, m, when it flies an
    /// element set (`None`: the design's own altitude).
    pub altitude_m: Option<f64>,
    /// Sun and view geometry at the site, with the tilt.
    pub geometry: Geometry,
    /// Normalised glint radiance L_GN = ρ_g μ₀/π at the site, sr⁻¹.
    pub glint_per_sr: f64,
    /// The season's high-glint threshold, sr⁻¹: the look was judged against it at the site, and
    /// the exact correction masks the pixels above it at the wind it assumes.
    pub glint_threshold_per_sr: f64,
    /// Cloud cover drawn for the look (0–1).
    pub cloud_cover: f64,
    /// The seed of the look's weather (the season's seed and the hour of the pass): its cover
    /// was drawn from it, and its scene's cloud field is made from it.
    pub weather_seed: u64,
    /// Wind speed over the site, m/s: the glint the look was judged on, and the sea surface its
    /// chain run sees.
    pub wind_m_s: f64,
    /// The error of the wind the processor assumes for the look's glint, m/s (drawn from the
    /// season's `processor_wind_rms_m_s`; 0 without).
    pub processor_wind_error_m_s: f64,
    /// Kept or why not.
    pub verdict: Verdict,
}

/// Half the design's across-track field of view, rad: atan(N·p / 2f).
#[must_use]
pub fn half_field_of_view_rad(instrument: &InstrumentSpec) -> f64 {
    let half_width_m = instrument.detectors as f64 * instrument.pixel_pitch_um * 1e-6 / 2.0;
    (half_width_m / (instrument.focal_length_mm * 1e-3)).atan()
}

/// Normalised glint radiance L_GN = ρ_g μ₀/π (sr⁻¹; Wang & Bailey 2001) at `g` for `wind_m_s`
/// over water of refractive index `n`, with ρ_g the Cox–Munk glint reflectance: the crate's
/// glint per unit solar flux ([`glint_radiance_norm`]) through a path of no optical depth.
#[must_use]
pub fn normalised_glint_per_sr(g: &Geometry, wind_m_s: f64, n: f64) -> f64 {
    if g.sun_zenith_rad >= std::f64::consts::FRAC_PI_2 {
        return 0.0;
    }
    glint_radiance_norm(g.sun_zenith_rad, g.view_zenith_rad, g.relative_azimuth_rad, wind_m_s, n, 0.0)
}

/// A look's cloud cover: a draw from the beta distribution with mean `fraction` and α + β =
/// `concentration` (Falls 1974); exactly `fraction` when it is 0 or 1.
pub fn cloud_cover(fraction: f64, concentration: f64, rng: &mut Xoshiro256PlusPlus) -> f64 {
    if fraction <= 0.0 || fraction >= 1.0 {
        return fraction.clamp(0.0, 1.0);
    }
    match Beta::new(concentration * fraction, concentration * (1.0 - fraction)) {
        Ok(beta) => beta.sample(rng),
        Err(_) => fraction,
    }
}

/// The looks of `instrument` (flying the season's orbit at its own altitude) at the season's
/// site over its period, in time order; the site must lie in its swath (at a roll the season
/// allows). The cloud cover is drawn for the hour of each pass, so designs in the same orbit see
/// the same weather. `n`: the water's refractive index (the scene's).
pub fn looks(season: &SeasonSpec, instrument: &InstrumentSpec, wind_m_s: f64, n: f64) -> Vec<Look> {
    let (Ok((from, to)), Ok(epoch_days)) = (season.period_days(), season.epoch_days()) else { return Vec::new() };
    let orbit = SunSynchronous {
        altitude_m: instrument.altitude_km * 1e3,
        descending_node_h: season.orbit.descending_node_h,
        phase_rad: season.orbit.phase_deg.to_radians(),
        epoch_days,
    };
    let site = Site::from_degrees(season.site.0, season.site.1);
    let half = half_field_of_view_rad(instrument);
    let pointing = instrument.across_track_tilt_deg.to_radians();
    let roll = season.max_roll_deg.to_radians();
    let tle = season.orbit.tle.as_ref().and_then(|(l1, l2)| TleOrbit::from_lines(l1, l2).ok());
    let reach = pointing.abs() + roll + half;
    let found = match &tle {
        Some(t) => accesses(t, &site, from, to, reach),
        None => accesses(&orbit, &site, from, to, reach),
    };
    let altitude_of = |a: &Access| tle.as_ref().map(|_| a.radius_m - EARTH_EQUATORIAL_RADIUS_M);
    let local_offset_days = season.local_offset_days();
    let max_sun = season.max_sun_zenith_deg.to_radians();
    let max_view = season.max_view_zenith_deg.to_radians();
    // Fore/aft candidates, degrees: the glint tilt either way, or the design's own forward tilt.
    let t = season.glint_tilt_deg;
    let tilts: Vec<f64> = if t > 0.0 { vec![t, -t] } else { vec![instrument.forward_tilt_deg] };
    found
        .into_iter()
        // Inside the swath at some roll in [pointing − roll, pointing + roll].
        .filter(|a| ((a.off_nadir_rad - pointing).abs() - roll).max(0.0) <= half)
        .map(|access| {
            // The line of sight as the pushbroom geometry computes it: the fore/aft tilt that
            // glints less, the site's own off-nadir angle across track. `None`: seen beyond the
            // chain's largest view zenith.
            let candidate = |forward: f64| {
                let sight = line_of_sight(
                    altitude_of(&access).unwrap_or(orbit.altitude_m),
                    access.heading_rad,
                    forward.to_radians(),
                    access.off_nadir_rad,
                    access.sun.zenith_rad,
                    access.sun.azimuth_rad,
                )
                .ok()
                .map(|l| l.geometry);
                let glint = sight.map_or(f64::INFINITY, |g| normalised_glint_per_sr(&g, wind_m_s, n));
                (forward, sight, glint)
            };
            let (forward_tilt_deg, sight, glint_per_sr) = tilts[1..]
                .iter()
                .map(|s| candidate(*s))
                .fold(candidate(tilts[0]), |best, c| if c.2 < best.2 { c } else { best });
            // Too oblique for the chain: the pass's own geometry, for the record.
            let geometry = sight.unwrap_or_else(|| {
                let rel = (access.view_azimuth_rad - access.sun.azimuth_rad).rem_euclid(std::f64::consts::TAU);
                Geometry {
                    sun_zenith_rad: access.sun.zenith_rad,
                    view_zenith_rad: access.view_zenith_rad,
                    relative_azimuth_rad: rel.min(std::f64::consts::TAU - rel),
                }
            });
            // The weather of the hour of the pass: two designs that pass within the same hour
            // (the same orbit) see the same cover, and a look's cover does not depend on which
            // other looks there are.
            let hour = (access.days * 24.0).floor() as i64 as u64;
            let weather_seed = season.seed ^ hour.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(weather_seed);
            // The site's month (local mean solar date), as the climatology's.
            let month = crate::orbit::sun::calendar_date(access.days + local_offset_days).1 as usize - 1;
            let cloud_cover = season.clouds.as_ref().map_or(0.0, |c| {
                cloud_cover(c.monthly_fraction.get(month).copied().unwrap_or(0.0), c.concentration, &mut rng)
            });
            // Drawn after the cover, from the same weather, so that a wind error leaves every
            // look's cover as it was; within the range the correction accepts.
            let processor_wind_error_m_s = if season.processor_wind_rms_m_s > 0.0 {
                let z: f64 = rand_distr::StandardNormal.sample(&mut rng);
                let allowed = &crate::ranges::CORRECTION_GLINT_WIND_ERROR;
                (season.processor_wind_rms_m_s * z).clamp(allowed.lo, allowed.hi)
            } else {
                0.0
            };
            let verdict = if access.sun.zenith_rad > max_sun {
                Verdict::SunLow
            } else if sight.is_none() || geometry.view_zenith_rad > max_view {
                Verdict::ViewOblique
            } else if glint_per_sr > season.glint_threshold_per_sr {
                Verdict::Glint
            } else if 100.0 * (1.0 - cloud_cover) < season.min_clear_pct {
                Verdict::Cloud
            } else {
                Verdict::Valid
            };
            let altitude_m = altitude_of(&access);
            Look {
                access,
                forward_tilt_deg,
                altitude_m,
                geometry,
                glint_per_sr,
                glint_threshold_per_sr: season.glint_threshold_per_sr,
                cloud_cover,
                weather_seed,
                wind_m_s,
                processor_wind_error_m_s,
                verdict,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Untilted, the pushbroom line of sight at the site is the access's own geometry (the orbit's spherical geometry and the
    /// pushbroom formula agree to the two radii's difference in the altitude, 7 km in 700).
    #[test]
    fn untilted_look_geometry_is_the_access_geometry() {
        let orbit = SunSynchronous {
            altitude_m: 700e3,
            descending_node_h: 10.5,
            phase_rad: 0.0,
            epoch_days: crate::orbit::days_since_j2000("2023-01-01").unwrap(),
        };
        let site = Site::from_degrees(-36.1, 147.0);
        for a in accesses(&orbit, &site, orbit.epoch_days, orbit.epoch_days + 20.0, 0.5) {
            let l = line_of_sight(
                orbit.altitude_m,
                a.heading_rad,
                0.0,
                a.off_nadir_rad,
                a.sun.zenith_rad,
                a.sun.azimuth_rad,
            )
            .unwrap();
            let (g, sensor_az) = (l.geometry, l.sensor_azimuth_rad);
            assert!(
                (g.view_zenith_rad - a.view_zenith_rad).abs() < 2e-3,
                "{} {}",
                g.view_zenith_rad,
                a.view_zenith_rad
            );
            if a.off_nadir_rad.abs() > 0.01 {
                let d = (sensor_az - a.view_azimuth_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                assert!(d.abs() < 0.02, "azimuth off by {d}");
            }
        }
    }

    /// At the specular point L_GN is Cox–Munk's own: R_F(θ) p(0)/(4 cos θ_v) with p(0) = 1/(πσ²)
    /// (Wang & Bailey 2001, eq. 2 with β = 0).
    #[test]
    fn glint_at_the_specular_point_is_cox_munk() {
        let theta = 25f64.to_radians();
        let g = Geometry { sun_zenith_rad: theta, view_zenith_rad: theta, relative_azimuth_rad: std::f64::consts::PI };
        let wind = 7.0;
        let sigma2 = 0.003 + 0.005_12 * wind;
        let rf = crate::atmosphere::fresnel_reflectance(theta.cos(), 1.34);
        let expected = rf / (std::f64::consts::PI * sigma2) / (4.0 * theta.cos());
        let got = normalised_glint_per_sr(&g, wind, 1.34);
        assert!((got / expected - 1.0).abs() < 1e-12, "{got} vs {expected}");
        // Far from it (the sensor at 60° on the sun's side: facets would tilt 42.5°), nothing.
        let away = Geometry { relative_azimuth_rad: 0.0, view_zenith_rad: 60f64.to_radians(), ..g };
        assert!(normalised_glint_per_sr(&away, wind, 1.34) < 1e-6);
    }

    /// Over many draws the cover's mean is the month's fraction (beta mean α/(α+β)) to 0.01,
    /// and with concentration 1 most skies are nearly clear or nearly overcast (U shape).
    #[test]
    fn cloud_draws_follow_the_climatology() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        for f in [0.2, 0.5, 0.7] {
            let draws: Vec<f64> = (0..20_000).map(|_| cloud_cover(f, 1.0, &mut rng)).collect();
            let mean = draws.iter().sum::<f64>() / draws.len() as f64;
            assert!((mean - f).abs() < 0.01, "{f}: {mean}");
            let extreme = draws.iter().filter(|c| **c < 0.1 || **c > 0.9).count() as f64 / draws.len() as f64;
            assert!(extreme > 0.4, "{f}: {extreme}");
        }
        assert_eq!(cloud_cover(0.0, 1.0, &mut rng), 0.0);
        assert_eq!(cloud_cover(1.0, 1.0, &mut rng), 1.0);
    }
}
