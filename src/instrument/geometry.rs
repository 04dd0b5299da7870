//! Pushbroom viewing geometry: where each detector of each line looks on the ground, and from
//! which direction.
//!
//! The instrument flies a straight ground track through the scene centre along `heading_deg`
//! (clockwise from north). Detector j of N looks at the across-track angle
//! α_j = atan((j − (N−1)/2)·p/f), plus the across-track pointing (roll); a geometry group (a
//! filter row of a linear-variable-filter imager) adds an along-track angle to the forward tilt
//! β. The look direction (tan β, tan α, 1) makes the off-nadir angle γ with the nadir; on a
//! spherical Earth of radius R seen from altitude h the view zenith at the ground is
//! sin θ_v = (R + h)/R · sin γ and the ground point lies R·(θ_v − γ) from the sub-satellite
//! point (Schowengerdt 2007, §3.4; [`line_of_sight`], which seasons use too). Lines are one nadir
//! GSD apart (GSD = h·p/f): the line period is GSD / ground speed, and the exposure must fit in it.
//!
//! The scene is small next to the Earth, so the track is straight in the scene frame, the sun is
//! the scene's, and Earth rotation during the overpass is neglected. A filter imager's bands see
//! a ground line at different times (`time_offset_s`); the scene is static, so the delivered cube
//! is co-registered and only the view geometry differs between bands.

use super::InstrumentError;
use super::response::Response;
use super::spec::{InstrumentSpec, ground_speed_m_s};
use crate::atmosphere::Geometry;
use crate::parse::FieldError;
use crate::units::EARTH_RADIUS_M;

/// One detector's line of sight in one geometry group.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    /// Ground offset from the line's reference point, east, m.
    pub dx_m: f64,
    /// Ground offset from the line's reference point, north, m.
    pub dy_m: f64,
    /// Sun and view geometry at the ground point.
    pub geometry: Geometry,
    /// Azimuth of the sensor seen from the ground point, rad clockwise from north (the sun's
    /// azimuth at nadir, where the relative azimuth is taken as 0); with the sun's azimuth it
    /// gives the signed relative azimuth that Stokes U needs ([`crate::atmosphere::stokes`]).
    pub view_azimuth_rad: f64,
}

/// The viewing geometry of a run (possibly decimated for a preview).
#[derive(Debug, Clone, PartialEq)]
pub struct Viewing {
    /// Decimation factor: every `decimation`-th line and detector is simulated.
    pub decimation: usize,
    /// Full-resolution line numbers of the output rows.
    pub line_index: Vec<usize>,
    /// Full-resolution detector numbers of the output columns.
    pub detector_index: Vec<usize>,
    /// Reference ground point of each output row (scene frame, m).
    pub track_m: Vec<(f64, f64)>,
    /// Per geometry group, per output column: the look.
    pub looks: Vec<Vec<Look>>,
    /// Nadir ground sampling distance, m.
    pub gsd_m: f64,
    /// Line period, s (GSD / ground speed).
    pub line_period_s: f64,
    /// Ground speed, m/s.
    pub ground_speed_m_s: f64,
    /// Per geometry group: time after the group-0 view of the same ground line, s.
    pub time_offset_s: Vec<f64>,
    /// Largest view zenith in the run, degrees.
    pub max_view_zenith_deg: f64,
    /// Output rows and columns left out because they look beyond the scene.
    pub cropped: (usize, usize),
}

/// View zenith above which the plane-parallel atmosphere is not trusted (matches the LUT limit).
pub const MAX_VIEW_ZENITH_DEG: f64 = 80.0;

/// One line of sight: where it meets the ground and from which direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineOfSight {
    /// Ground offset from the sub-satellite point, east, m.
    pub dx_m: f64,
    /// Ground offset from the sub-satellite point, north, m.
    pub dy_m: f64,
    /// Sun and view geometry at the ground point.
    pub geometry: Geometry,
    /// Azimuth of the sensor seen from the ground point, rad clockwise from north (the sun's at
    /// nadir).
    pub sensor_azimuth_rad: f64,
}

/// The line of sight tilted `forward_rad` (β) along track and `across_rad` (α, positive right)
/// from a platform at `altitude_m` flying `heading_rad` (clockwise from north), with the sun at
/// (`sun_zenith_rad`, `sun_azimuth_rad`): see the module docs. `Err` holds the off-nadir angle
/// where the view zenith would reach [`MAX_VIEW_ZENITH_DEG`].
pub fn line_of_sight(
    altitude_m: f64,
    heading_rad: f64,
    forward_rad: f64,
    across_rad: f64,
    sun_zenith_rad: f64,
    sun_azimuth_rad: f64,
) -> Result<LineOfSight, f64> {
    let (along, right) = ((heading_rad.sin(), heading_rad.cos()), (heading_rad.cos(), -heading_rad.sin()));
    let (tb, ta) = (forward_rad.tan(), across_rad.tan());
    let norm = (1.0 + tb * tb + ta * ta).sqrt();
    let gamma = (1.0 / norm).acos();
    let sin_vza = (EARTH_RADIUS_M + altitude_m) / EARTH_RADIUS_M * gamma.sin();
    if !(sin_vza < MAX_VIEW_ZENITH_DEG.to_radians().sin()) {
        return Err(gamma);
    }
    let vza = sin_vza.asin();
    let s = EARTH_RADIUS_M * (vza - gamma);
    let psi = ta.atan2(tb); // azimuth of the look in the instrument frame, from along-track
    let (d_along, d_across) = (s * psi.cos(), s * psi.sin());
    // Scene frame offset; the sensor is seen from the ground in the opposite direction.
    let (dx, dy) = (d_along * along.0 + d_across * right.0, d_along * along.1 + d_across * right.1);
    let sensor_azimuth = if s > 0.0 { (-dx).atan2(-dy) } else { sun_azimuth_rad };
    let mut rel = (sensor_azimuth - sun_azimuth_rad).rem_euclid(2.0 * std::f64::consts::PI);
    if rel > std::f64::consts::PI {
        rel = 2.0 * std::f64::consts::PI - rel;
    }
    let geometry = Geometry { sun_zenith_rad, view_zenith_rad: vza, relative_azimuth_rad: rel };
    Ok(LineOfSight { dx_m: dx, dy_m: dy, geometry, sensor_azimuth_rad: sensor_azimuth })
}

impl Viewing {
    /// The geometry of `spec` over a scene lit from (`sun_zenith_rad`, `sun_azimuth_rad`),
    /// keeping every `decimation`-th line and detector. With `scene_half_m` = the scene's half
    /// sizes (x, y), lines and detectors that look beyond the scene are not simulated (a scene
    /// smaller than the image is imaged where it is; see [`Self::cropped`]).
    pub fn new(
        spec: &InstrumentSpec,
        response: &Response,
        sun_zenith_rad: f64,
        sun_azimuth_rad: f64,
        decimation: usize,
        scene_half_m: Option<(f64, f64)>,
    ) -> Result<Self, InstrumentError> {
        spec.validate()?;
        if decimation == 0 || decimation > 1000 {
            return Err(InstrumentError::Invalid(FieldError {
                field: "decimation".into(),
                message: format!("{decimation} is out of range (allowed: 1 to 1000)"),
            }));
        }
        let h = spec.altitude_km * 1e3;
        let pitch_over_f = spec.pixel_pitch_um * 1e-6 / (spec.focal_length_mm * 1e-3);
        let gsd = spec.gsd_m();
        let speed = ground_speed_m_s(spec.altitude_km);
        let line_period_s = gsd / speed;
        let heading = spec.heading_deg.to_radians();
        let along = (heading.sin(), heading.cos());
        let tilt = spec.forward_tilt_deg.to_radians();
        let roll = spec.across_track_tilt_deg.to_radians();
        let n = spec.detectors;
        let detector_index: Vec<usize> = (0..n).step_by(decimation).collect();
        let line_index: Vec<usize> = (0..spec.lines).step_by(decimation).collect();
        let mut max_vza: f64 = 0.0;
        // Ground offset (east, north) and geometry of a look at angles (β, α).
        let look = |beta: f64, alpha: f64| -> Result<(f64, f64, Geometry, f64), InstrumentError> {
            line_of_sight(h, heading, beta, alpha, sun_zenith_rad, sun_azimuth_rad)
                .map(|l| (l.dx_m, l.dy_m, l.geometry, l.sensor_azimuth_rad))
                .map_err(|gamma| {
                    InstrumentError::Invalid(FieldError {
                        field: "detectors".into(),
                        message: format!(
                            "the swath edge is seen at a view zenith above {MAX_VIEW_ZENITH_DEG}° (off-nadir {:.1}°); reduce detectors, \
                             pixel pitch, forward or across-track tilt, or lengthen the focal length",
                            gamma.to_degrees()
                        ),
                    })
                })
        };
        // The image centre (central detector of the mean group offset) lands on the scene centre.
        let mean_offset =
            response.groups.iter().map(|g| g.offset_rad.0).sum::<f64>() / response.groups.len().max(1) as f64;
        let (cx, cy, ..) = look(tilt + mean_offset, roll)?;
        let mut looks = Vec::with_capacity(response.groups.len());
        for g in &response.groups {
            let row = detector_index
                .iter()
                .map(|&j| {
                    let alpha = ((j as f64 - 0.5 * (n as f64 - 1.0)) * pitch_over_f).atan() + g.offset_rad.1 + roll;
                    let (dx, dy, geometry, view_azimuth_rad) = look(tilt + g.offset_rad.0, alpha)?;
                    max_vza = max_vza.max(geometry.view_zenith_rad.to_degrees());
                    Ok(Look { dx_m: dx - cx, dy_m: dy - cy, geometry, view_azimuth_rad })
                })
                .collect::<Result<Vec<_>, InstrumentError>>()?;
            looks.push(row);
        }
        // Filter rows see a ground line at different times: the along-track ground distance
        // between their footprints over the ground speed.
        let along_of = |g: &[Look]| g.get(g.len() / 2).map_or(0.0, |l| l.dx_m * along.0 + l.dy_m * along.1);
        let first = looks.first().map_or(0.0, |g| along_of(g));
        let time_offset_s = looks.iter().map(|g| (first - along_of(g)) / speed).collect();
        // Co-registration: every group reports the ground point of the reference look (the mean
        // focal-plane offset) — the rows of the delivered cube are ground lines — while keeping
        // its own view geometry.
        if looks.len() > 1 {
            let reference = detector_index
                .iter()
                .map(|&j| {
                    let alpha = ((j as f64 - 0.5 * (n as f64 - 1.0)) * pitch_over_f).atan() + roll;
                    look(tilt + mean_offset, alpha).map(|(dx, dy, ..)| (dx - cx, dy - cy))
                })
                .collect::<Result<Vec<_>, InstrumentError>>()?;
            for group in &mut looks {
                for (l, &(dx, dy)) in group.iter_mut().zip(&reference) {
                    l.dx_m = dx;
                    l.dy_m = dy;
                }
            }
        }
        let n_lines = spec.lines as f64;
        let track_m = line_index
            .iter()
            .map(|&l| {
                let s = (l as f64 - 0.5 * (n_lines - 1.0)) * gsd;
                (s * along.0, s * along.1)
            })
            .collect();
        let mut viewing = Self {
            decimation,
            line_index,
            detector_index,
            track_m,
            looks,
            gsd_m: gsd,
            line_period_s,
            ground_speed_m_s: speed,
            time_offset_s,
            max_view_zenith_deg: max_vza,
            cropped: (0, 0),
        };
        if let Some(half) = scene_half_m {
            viewing.crop(half)?;
        }
        Ok(viewing)
    }

    /// Keep the rows whose central pixel, and the columns whose pixel on the central row, fall
    /// inside the scene (|x| ≤ hx, |y| ≤ hy).
    fn crop(&mut self, (hx, hy): (f64, f64)) -> Result<(), InstrumentError> {
        let inside = |(x, y): (f64, f64)| x.abs() <= hx && y.abs() <= hy;
        let (rows, cols) = (self.lines(), self.columns());
        let keep_rows: Vec<usize> = (0..rows).filter(|&r| inside(self.ground_m(0, r, cols / 2))).collect();
        let keep_cols: Vec<usize> = (0..cols).filter(|&c| inside(self.ground_m(0, rows / 2, c))).collect();
        if keep_rows.is_empty() || keep_cols.is_empty() {
            return Err(InstrumentError::Invalid(FieldError {
                field: "scene".into(),
                message:
                    "the instrument's image does not overlap the scene (check forward_tilt_deg and the scene size)"
                        .into(),
            }));
        }
        self.cropped = (rows - keep_rows.len(), cols - keep_cols.len());
        self.line_index = keep_rows.iter().map(|&r| self.line_index[r]).collect();
        self.track_m = keep_rows.iter().map(|&r| self.track_m[r]).collect();
        self.detector_index = keep_cols.iter().map(|&c| self.detector_index[c]).collect();
        for g in &mut self.looks {
            *g = keep_cols.iter().map(|&c| g[c]).collect();
        }
        Ok(())
    }

    /// Output rows.
    #[must_use]
    pub fn lines(&self) -> usize {
        self.line_index.len()
    }

    /// Output columns.
    #[must_use]
    pub fn columns(&self) -> usize {
        self.detector_index.len()
    }

    /// Ground point of output pixel (row, column) in group `g`, scene frame, m.
    #[must_use]
    pub fn ground_m(&self, g: usize, row: usize, column: usize) -> (f64, f64) {
        let (x, y) = self.track_m[row];
        let l = &self.looks[g][column];
        (x + l.dx_m, y + l.dy_m)
    }

    /// The output pixel (row, column) nearest to scene point (x, y) m, projecting on the
    /// along-track and across-track axes of a flight on `heading_deg`; `None` off the image.
    #[must_use]
    pub fn nearest_pixel(&self, x: f64, y: f64, heading_deg: f64) -> Option<(usize, usize)> {
        let (rows, cols) = (self.lines(), self.columns());
        if rows == 0 || cols == 0 {
            return None;
        }
        let h = heading_deg.to_radians();
        let (along, right) = ((h.sin(), h.cos()), (h.cos(), -h.sin()));
        let proj = |p: (f64, f64), u: (f64, f64)| p.0 * u.0 + p.1 * u.1;
        let a = |r: usize| proj(self.ground_m(0, r, cols / 2), along);
        let c = |col: usize| proj(self.ground_m(0, rows / 2, col), right);
        let (pa, pc) = (proj((x, y), along), proj((x, y), right));
        // Lines are evenly spaced along track; across track the spacing grows off nadir, so
        // the column is found by bisection on the columns' (monotonic) positions.
        let (a0, a1) = (a(0), a(rows - 1));
        let fr = if rows > 1 { (pa - a0) / (a1 - a0) * (rows - 1) as f64 } else { 0.0 };
        let r = fr.round();
        let col = if cols == 1 {
            0
        } else {
            let increasing = c(cols - 1) > c(0);
            let before = |k: usize| if increasing { c(k) < pc } else { c(k) > pc };
            // First column at or past pc, then the nearer of it and its neighbour.
            let (mut lo, mut hi) = (0usize, cols);
            while lo < hi {
                let mid = (lo + hi) / 2;
                if before(mid) { lo = mid + 1 } else { hi = mid }
            }
            match lo {
                0 => 0,
                k if k == cols => cols - 1,
                k => {
                    if (c(k) - pc).abs() < (c(k - 1) - pc).abs() {
                        k
                    } else {
                        k - 1
                    }
                }
            }
        };
        // Off the image: more than half a pixel beyond the outer columns or lines.
        let half = |k0: usize, k1: usize| 0.5 * (c(k1) - c(k0)).abs();
        let off_across = (col == 0 && (pc - c(0)).abs() > half(0, 1.min(cols - 1)).max(1e-9) && cols > 1)
            || (col == cols - 1 && cols > 1 && (pc - c(cols - 1)).abs() > half(cols - 2, cols - 1));
        (r >= 0.0 && r < rows as f64 && !off_across).then_some((r as usize, col))
    }

    /// The flight's heading, degrees clockwise from north, read from the ground track (0 for a
    /// single line).
    #[must_use]
    pub fn track_heading_deg(&self) -> f64 {
        match (self.track_m.first(), self.track_m.last()) {
            (Some(a), Some(b)) if self.track_m.len() > 1 => (b.0 - a.0).atan2(b.1 - a.1).to_degrees(),
            _ => 0.0,
        }
    }

    /// Along-track unit vector in the scene frame (east, north).
    #[must_use]
    pub fn along_track(heading_deg: f64) -> (f64, f64) {
        let h = heading_deg.to_radians();
        (h.sin(), h.cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nominal() -> InstrumentSpec {
        InstrumentSpec::preset("nominal").unwrap()
    }

    #[test]
    fn the_nearest_pixel_of_a_pixels_ground_point_is_itself_at_any_heading() {
        // The nominal instrument (±1° across track) and a wide one (±8°: 20 mm focal length),
        // whose across-track spacing is far from even.
        for (heading, focal_length_mm) in [(0.0, 165.0), (37.0, 165.0), (180.0, 20.0), (290.0, 20.0)] {
            let mut spec = nominal();
            spec.heading_deg = heading;
            spec.focal_length_mm = focal_length_mm;
            spec.aperture_mm = spec.aperture_mm.min(focal_length_mm);
            let r = Response::new(&spec, 1.0).unwrap();
            let v = Viewing::new(&spec, &r, 0.5, 0.0, 4, None).unwrap();
            assert!((v.track_heading_deg().rem_euclid(360.0) - heading).abs() < 1e-6, "{heading}");
            for (row, col) in [(0, 0), (3, 7), (v.lines() - 1, v.columns() - 1)] {
                let (x, y) = v.ground_m(0, row, col);
                assert_eq!(v.nearest_pixel(x, y, heading), Some((row, col)), "heading {heading}");
            }
            let far = v.ground_m(0, 0, 0);
            assert_eq!(v.nearest_pixel(far.0 * 3.0 + 1e5, far.1 * 3.0 + 1e5, heading), None);
            // Every column of the middle line, where the across-track spacing varies most.
            let mid = v.lines() / 2;
            for col in 0..v.columns() {
                let (x, y) = v.ground_m(0, mid, col);
                assert_eq!(v.nearest_pixel(x, y, heading), Some((mid, col)), "heading {heading}");
            }
        }
    }

    #[test]
    fn nadir_gsd_and_swath() {
        let spec = nominal();
        let r = Response::new(&spec, 1.0).unwrap();
        let v = Viewing::new(&spec, &r, 0.5, 0.0, 1, None).unwrap();
        // Adjacent detectors at the centre are one GSD apart (flat-Earth limit near nadir).
        let (a, b) = (v.looks[0][511], v.looks[0][512]);
        assert!(((b.dx_m - a.dx_m) - spec.gsd_m()).abs() < 1e-3 * spec.gsd_m());
        // Heading 0: along track is north, so across track is east; the swath is centred.
        assert!((v.looks[0][0].dx_m + v.looks[0][1023].dx_m).abs() < 1e-6);
        assert!(v.max_view_zenith_deg < 1.1);
        // Lines one GSD apart along north.
        assert!(((v.track_m[1].1 - v.track_m[0].1) - spec.gsd_m()).abs() < 1e-9);
    }

    #[test]
    fn edge_view_zenith_grows_with_earth_curvature() {
        let mut spec = nominal();
        spec.detectors = 20_000;
        spec.focal_length_mm = 20.0;
        assert!(Viewing::new(&spec, &Response::new(&spec, 1.0).unwrap(), 0.5, 0.0, 1, None).is_err());
        spec.focal_length_mm = 100.0;
        let v = Viewing::new(&spec, &Response::new(&spec, 1.0).unwrap(), 0.5, 0.0, 16, None).unwrap();
        let edge = v.looks[0][0];
        let alpha = ((0.0 - 0.5 * 19_999.0) * 5.5e-6 / 0.1_f64).atan().abs();
        // Spherical Earth: view zenith exceeds the look angle.
        assert!(edge.geometry.view_zenith_rad > alpha);
        let sin_vza = (EARTH_RADIUS_M + 560e3) / EARTH_RADIUS_M * alpha.sin();
        assert!((edge.geometry.view_zenith_rad - sin_vza.asin()).abs() < 1e-9);
    }

    /// A roll of r to the right puts the image centre at off-nadir r, seen at sin θ_v = (R+h)/R
    /// sin r from the left of the track (heading north: the sensor to the west, azimuth 270°);
    /// the image stays centred on the scene.
    #[test]
    fn across_track_tilt_views_the_scene_from_the_side() {
        let mut spec = nominal();
        spec.across_track_tilt_deg = 20.0;
        let r = Response::new(&spec, 1.0).unwrap();
        let v = Viewing::new(&spec, &r, 0.5, 0.0, 1, None).unwrap();
        let centre = (v.looks[0][511], v.looks[0][512]);
        let vza = ((EARTH_RADIUS_M + spec.altitude_km * 1e3) / EARTH_RADIUS_M * 20f64.to_radians().sin()).asin();
        let mid = 0.5 * (centre.0.geometry.view_zenith_rad + centre.1.geometry.view_zenith_rad);
        assert!((mid - vza).abs() < 1e-3, "{} vs {}", mid.to_degrees(), vza.to_degrees());
        assert!((centre.0.view_azimuth_rad.to_degrees().rem_euclid(360.0) - 270.0).abs() < 0.1);
        assert!((0.5 * (centre.0.dx_m + centre.1.dx_m)).abs() < spec.gsd_m());
        // Left of the track looks the other way.
        spec.across_track_tilt_deg = -20.0;
        let v = Viewing::new(&spec, &r, 0.5, 0.0, 1, None).unwrap();
        assert!((v.looks[0][512].view_azimuth_rad.to_degrees().rem_euclid(360.0) - 90.0).abs() < 0.1);
    }
}
