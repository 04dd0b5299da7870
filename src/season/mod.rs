//! Seasons: how often a design sees a site cloud- and glint-free over a period, and what its
//! products' error is over those looks.
//!
//! A season file names a study (the scene, the designs, the retrievals and the correction), the
//! site on Earth, a period and the orbit's local time. For each design, the accesses of its
//! sun-synchronous orbit (its own altitude, [`crate::orbit`]) — or of a real spacecraft's
//! two-line elements propagated with SGP4 (`orbit.tle`), which every design then flies — to the
//! site are found over the period; each becomes a [`looks::Look`] with the sun and view geometry of that pass, judged
//! valid or not the way a processor would:
//! - the sun at most `max_sun_zenith_deg` from the zenith (l2gen's HISOLZEN, 75°), and the site
//!   seen at most `max_view_zenith_deg` from it (HISATZEN, 60°);
//! - the site inside the swath: the design's field of view about its across-track pointing, or
//!   about any roll up to `max_roll_deg` for an agile platform;
//! - no high glint: the Cox–Munk normalised glint radiance L_GN = ρ_g μ₀/π at the site at most
//!   `glint_threshold_per_sr` (l2gen's HIGLINT, 0.005 sr⁻¹; Wang & Bailey 2001), with the design
//!   tilted fore or aft by `glint_tilt_deg`, whichever side glints less (PACE OCI's strategy);
//! - clear enough: a cloud cover drawn for the look from the month's climatological fraction
//!   ([`looks::cloud_cover`]) leaves at least `min_clear_pct` of the site clear.
//!
//! Valid looks are then run through the whole chain at the look's geometry (sun, date, heading,
//! pointing), at the season's decimation, and their product errors collected
//! ([`run::run_season`]). A valid look's cloud cover is in its scene as a cloud field with its
//! shadows (`scene::clouds`), which the processor screens out with its own cloud test and shadow
//! projection, so a valid look's product error counts the water it loses to them and the shadow
//! it misses.
//!
//! ## References
//! - Wang, M. & Bailey, S. W. (2001) Correction of sun glint contamination on the SeaWiFS ocean
//!   and atmosphere products. Appl. Opt. 40, 4790–4798 (L_GN and the high-glint mask).
//! - NASA OBPG, SeaDAS l2gen defaults (`msl12_defaults.par`): `glint_thresh` 0.005,
//!   `satzen` 60°, `solzen` 75°.
//! - Falls, L. W. (1974) The beta distribution: a statistical model for world cloud cover.
//!   J. Geophys. Res. 79, 1261–1264.

pub mod figure;
pub mod looks;
pub mod months;
pub mod run;
pub mod shard;
pub mod stats;
pub mod summary;

use serde::{Deserialize, Serialize};

use crate::parse::FieldError;
use crate::ranges::Range;
use crate::study::{Source, StudySpec};

/// The orbit every design of a season flies (each at its own altitude).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitSpec {
    /// Local mean solar time of the descending node, hours (10.5: 10:30, Sentinel-2's).
    #[serde(default = "default_node")]
    pub descending_node_h: f64,
    /// Argument of latitude at 00:00 UT on 1 January of the period's first year, degrees (which
    /// days the passes fall on; a shorter period within the year keeps the same orbit).
    #[serde(default)]
    pub phase_deg: f64,
    /// A real spacecraft's two-line elements (line 1, line 2): every design flies this orbit,
    /// propagated with SGP4 ([`crate::orbit::TleOrbit`]), and each look runs at the spacecraft's
    /// altitude at the pass; the node time and phase above are then unused. The period must lie
    /// within [`TLE_REACH_DAYS`] of the elements' epoch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tle: Option<(String, String)>,
}

/// How far a season may reach from its element set's epoch, days: an element set predicts which
/// passes see a site for days to weeks around its epoch (SGP4's along-track error grows with
/// time from the epoch, mostly with the unmodelled drag: Vallado et al. 2006); beyond that the
/// passes are no longer the spacecraft's, so a newer element set is needed.
pub const TLE_REACH_DAYS: f64 = 30.0;

fn default_node() -> f64 {
    10.5
}

impl Default for OrbitSpec {
    fn default() -> Self {
        Self { descending_node_h: default_node(), phase_deg: 0.0, tle: None }
    }
}

/// The site's cloud climatology.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudSpec {
    /// Mean cloud fraction of each month, January first (0–1).
    pub monthly_fraction: Vec<f64>,
    /// Where the fractions come from (printed with the results).
    pub source: String,
    /// α + β of the beta distribution a look's cover is drawn from (Falls 1974; 1 gives the
    /// U shape of mostly clear or mostly overcast skies that cloud records show).
    #[serde(default = "default_concentration")]
    pub concentration: f64,
}

fn default_concentration() -> f64 {
    1.0
}

/// How often a valid look must come ("a valid look every `days` days, `pct` % of the time").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RevisitRequirement {
    /// Longest wait for a valid look, days.
    pub days: f64,
    /// Share of the period's days that must be within `days` of the last valid look, %.
    pub pct: f64,
}

/// A season as written in RON (`presets/seasons/*.ron`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeasonSpec {
    /// Short name (file names).
    pub name: String,
    /// What it asks.
    #[serde(default)]
    pub description: String,
    /// The study whose scene, designs, retrievals and correction each look runs.
    pub study: Source<StudySpec>,
    /// The site, degrees (latitude north, longitude east).
    pub site: (f64, f64),
    /// First day, YYYY-MM-DD, the site's local date (from its local mean midnight).
    pub from: String,
    /// Last day, YYYY-MM-DD (inclusive), the site's local date.
    pub to: String,
    /// The orbit.
    #[serde(default)]
    pub orbit: OrbitSpec,
    /// Largest sun zenith a look may have, degrees.
    #[serde(default = "default_max_sun")]
    pub max_sun_zenith_deg: f64,
    /// Largest view zenith a look may have, degrees (l2gen's HISATZEN, 60°).
    #[serde(default = "default_max_view")]
    pub max_view_zenith_deg: f64,
    /// Wind speed for the glint, m/s (the scene's own when its surface is wind-roughened).
    #[serde(default = "default_wind")]
    pub wind_m_s: f64,
    /// RMS error of the wind the processor assumes for the glint, m/s: each look's error is
    /// drawn from a normal distribution of this spread with its weather (an ancillary wind is
    /// not the wind on the water) and given to the image-based correction or the exact one
    /// (which then knows the atmosphere but not the wind). 0: the processor knows the wind.
    #[serde(default)]
    pub processor_wind_rms_m_s: f64,
    /// Largest normalised glint radiance L_GN a valid look may have, sr⁻¹.
    #[serde(default = "default_glint_threshold")]
    pub glint_threshold_per_sr: f64,
    /// How far the platform may roll across track to point at the site, degrees (0: the design
    /// sees only what its swath passes over; an agile platform sees the site from passes up to
    /// this far to either side).
    #[serde(default)]
    pub max_roll_deg: f64,
    /// Fore/aft tilt to avoid the glint, degrees (0: none; else each look tilts this far
    /// forward or back, whichever glints less).
    #[serde(default)]
    pub glint_tilt_deg: f64,
    /// The site's cloud climatology (absent: no clouds).
    #[serde(default)]
    pub clouds: Option<CloudSpec>,
    /// Clear share of the site a valid look needs, %.
    #[serde(default = "default_min_clear")]
    pub min_clear_pct: f64,
    /// Decimation of each look's chain run (1 = full resolution).
    #[serde(default = "default_decimation")]
    pub decimation: usize,
    /// Most looks run through the chain per design (evenly spaced over the valid ones).
    #[serde(default = "default_max_runs")]
    pub max_runs: usize,
    /// Seed of the cloud draws (each look's noise seed is the study's first).
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// The revisit requirement, if any.
    #[serde(default)]
    pub revisit: Option<RevisitRequirement>,
}

fn default_max_sun() -> f64 {
    75.0
}
fn default_max_view() -> f64 {
    60.0
}
fn default_wind() -> f64 {
    5.0
}
fn default_glint_threshold() -> f64 {
    0.005
}
fn default_min_clear() -> f64 {
    50.0
}
fn default_decimation() -> usize {
    4
}
fn default_max_runs() -> usize {
    24
}
fn default_seed() -> u64 {
    1
}

/// The ranges of a season's numbers (one table, as [`crate::ranges`]).
pub mod ranges {
    use crate::ranges::Range;
    /// Site latitude.
    pub const LATITUDE: Range = Range::closed("site.0 (latitude)", -82.0, 82.0, "degrees", "site latitude");
    /// Site longitude.
    pub const LONGITUDE: Range = Range::closed("site.1 (longitude)", -180.0, 360.0, "degrees", "site longitude");
    /// Node time.
    pub const NODE: Range =
        Range::closed("orbit.descending_node_h", 0.0, 24.0, "hours", "local time of the descending node");
    /// Phase.
    pub const PHASE: Range =
        Range::closed("orbit.phase_deg", -360.0, 360.0, "degrees", "argument of latitude at the start");
    /// Sun limit.
    pub const MAX_SUN: Range =
        Range::closed("max_sun_zenith_deg", 10.0, 85.0, "degrees", "largest sun zenith of a look");
    /// View limit.
    pub const MAX_VIEW: Range =
        Range::closed("max_view_zenith_deg", 10.0, 80.0, "degrees", "largest view zenith of a look");
    /// Wind.
    pub const WIND: Range = Range::closed("wind_m_s", 0.0, 30.0, "m/s", "wind speed for the glint");
    /// The processor's wind error.
    pub const WIND_ERROR: Range = Range::closed(
        "processor_wind_rms_m_s",
        0.0,
        10.0,
        "m/s",
        "RMS error of the wind the processor assumes for the glint",
    );
    /// Glint threshold.
    pub const GLINT: Range =
        Range::above("glint_threshold_per_sr", 0.0, 1.0, "sr-1", "largest normalised glint of a valid look");
    /// Roll.
    pub const ROLL: Range = Range::closed("max_roll_deg", 0.0, 45.0, "degrees", "largest roll towards the site");
    /// Glint tilt.
    pub const TILT: Range = Range::closed("glint_tilt_deg", 0.0, 30.0, "degrees", "fore/aft tilt away from the glint");
    /// Clear share.
    pub const CLEAR: Range = Range::closed("min_clear_pct", 0.0, 100.0, "%", "clear share a valid look needs");
    /// Decimation.
    pub const DECIMATION: Range = Range::count("decimation", 1.0, 64.0, "", "decimation of each look's run");
    /// Runs.
    pub const RUNS: Range = Range::count("max_runs", 0.0, 400.0, "", "most chain runs per design");
    /// Cloud fraction.
    pub const CLOUD: Range = Range::closed("clouds.monthly_fraction", 0.0, 1.0, "", "mean cloud fraction of a month");
    /// Beta concentration.
    pub const CONCENTRATION: Range =
        Range::closed("clouds.concentration", 0.05, 100.0, "", "α + β of the cloud-cover distribution");
    /// Revisit days.
    pub const REVISIT_DAYS: Range = Range::closed("revisit.days", 0.5, 366.0, "days", "longest wait for a valid look");
    /// Revisit share.
    pub const REVISIT_PCT: Range = Range::closed("revisit.pct", 0.0, 100.0, "%", "share of days within the wait");
    /// The period.
    pub const PERIOD_DAYS: Range = Range::closed("to", 1.0, 3_660.0, "days", "length of the period (from .. to)");
}

fn check(range: &Range, value: f64) -> Result<(), FieldError> {
    range.check(value).map_err(|message| FieldError { field: range.path.to_string(), message })
}

impl SeasonSpec {
    /// Parse RON; `origin` names the file in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, crate::study::StudyError> {
        crate::parse::from_ron(text, origin)
    }

    /// A built-in season by name (`presets/seasons/NAME.ron`).
    pub fn preset(name: &str) -> Result<Self, crate::study::StudyError> {
        crate::parse::preset(name)
    }

    /// Names of the built-in seasons.
    #[must_use]
    pub fn preset_names() -> Vec<String> {
        crate::parse::preset_names::<Self>()
    }

    /// The orbit's epoch, days since J2000.0: 00:00 UT on 1 January of `from`'s year.
    pub fn epoch_days(&self) -> Result<f64, FieldError> {
        let year = self.from.trim().split('-').next().unwrap_or_default();
        crate::orbit::days_since_j2000(&format!("{year}-01-01"))
            .map_err(|message| FieldError { field: "from".into(), message })
    }

    /// The site's local mean solar time minus UT, days (longitude east / 360, the longitude taken
    /// in −180…180°). A season's dates and months are the site's own, as a cloud climatology's
    /// months are: a 09:30 pass over Heron Island (151.9° E) is at 23:22 UT the day before.
    #[must_use]
    pub fn local_offset_days(&self) -> f64 {
        ((self.site.1 + 180.0).rem_euclid(360.0) - 180.0) / 360.0
    }

    /// The period as days since J2000.0 (UT): from the site's local mean midnight starting `from`
    /// to the one ending `to`.
    pub fn period_days(&self) -> Result<(f64, f64), FieldError> {
        let day = |field: &str, text: &str| {
            crate::orbit::days_since_j2000(text).map_err(|message| FieldError { field: field.into(), message })
        };
        let (from, to) = (day("from", &self.from)?, day("to", &self.to)? + 1.0);
        check(&ranges::PERIOD_DAYS, to - from)?;
        let offset = self.local_offset_days();
        Ok((from - offset, to - offset))
    }

    /// Check every number against its range, naming the field.
    pub fn validate(&self) -> Result<(), FieldError> {
        use ranges as r;
        crate::parse::check_name("name", &self.name)?;
        check(&r::LATITUDE, self.site.0)?;
        check(&r::LONGITUDE, self.site.1)?;
        check(&r::NODE, self.orbit.descending_node_h)?;
        check(&r::PHASE, self.orbit.phase_deg)?;
        check(&r::MAX_SUN, self.max_sun_zenith_deg)?;
        check(&r::MAX_VIEW, self.max_view_zenith_deg)?;
        check(&r::WIND, self.wind_m_s)?;
        check(&r::WIND_ERROR, self.processor_wind_rms_m_s)?;
        check(&r::GLINT, self.glint_threshold_per_sr)?;
        check(&r::ROLL, self.max_roll_deg)?;
        check(&r::TILT, self.glint_tilt_deg)?;
        check(&r::CLEAR, self.min_clear_pct)?;
        check(&r::DECIMATION, self.decimation as f64)?;
        check(&r::RUNS, self.max_runs as f64)?;
        if let Some(c) = &self.clouds {
            if c.monthly_fraction.len() != 12 {
                return Err(FieldError {
                    field: "clouds.monthly_fraction".into(),
                    message: format!("{} values (allowed: 12, January first)", c.monthly_fraction.len()),
                });
            }
            for f in &c.monthly_fraction {
                check(&r::CLOUD, *f)?;
            }
            check(&r::CONCENTRATION, c.concentration)?;
        }
        if let Some(q) = &self.revisit {
            check(&r::REVISIT_DAYS, q.days)?;
            check(&r::REVISIT_PCT, q.pct)?;
        }
        let (from, to) = self.period_days()?;
        if let Some((line1, line2)) = &self.orbit.tle {
            let tle = crate::orbit::TleOrbit::from_lines(line1, line2)
                .map_err(|message| FieldError { field: "orbit.tle".into(), message })?;
            let (early, late) = (tle.epoch_days - from, to - tle.epoch_days);
            if early > TLE_REACH_DAYS || late > TLE_REACH_DAYS {
                let ((y, m, d), _) = crate::orbit::sun::date_and_minute(tle.epoch_days);
                return Err(FieldError {
                    field: "orbit.tle".into(),
                    message: format!(
                        "the elements' epoch is {y:04}-{m:02}-{d:02}; the period ({} to {}) must lie within {TLE_REACH_DAYS} \
                         days of it (use the element set nearest the period)",
                        self.from, self.to
                    ),
                });
            }
        }
        Ok(())
    }
}

impl crate::parse::Preset for SeasonSpec {
    const FOLDER: &'static str = "seasons";
    type Error = crate::study::StudyError;
    fn parse_error(origin: &str, message: String) -> Self::Error {
        crate::study::StudyError::Parse(crate::parse::ParseError { origin: origin.into(), message })
    }
    fn unknown(name: &str, known: &[String]) -> Self::Error {
        crate::study::StudyError::Invalid(FieldError {
            field: "season".into(),
            message: format!("no built-in season `{name}` (known: {})", known.join(", ")),
        })
    }
}
