//! The scene file and its validated form.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::SceneError;
use super::clouds::{CloudField, CloudLayer, Sky};
use super::map::{Extent, Map, MapContext, MapSpec};
use super::raster::{GeoFrame, Georeference, RasterCache, fill_nodata, resolve_frame};
use crate::atmosphere::{AtmosphereSpec, SeaSurface};
use crate::parse::{FieldError, ParseError};
use crate::spectral::SpectrumSource;
use crate::water::SiopSource;

/// Where the sun is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunSpec {
    /// Solar zenith angle, degrees (0–85).
    pub zenith_deg: f64,
    /// Solar azimuth, degrees clockwise from north.
    pub azimuth_deg: f64,
}

/// One substrate and where it lies: its areal fraction map (fractions are normalised to sum 1
/// at every point).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SubstrateLayer {
    /// Substrate name from the library (`shoal water --list-substrates`).
    pub name: String,
    /// Its fraction map.
    pub fraction: MapSpec,
}

/// Land in the scene: where (mask ≥ 0.5) and what it reflects.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandSpec {
    /// Land where the map is ≥ 0.5.
    pub mask: MapSpec,
    /// Land surface reflectance (Lambertian, 0–1).
    pub reflectance: SpectrumSource,
}

/// Effects a scene may call for; anything not listed is never computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Effect {
    /// Bottom reflectance through the water column (needs `depth_m`).
    ShallowBottom,
    /// Cox–Munk sun glint (needs a wind-roughened surface in the atmosphere).
    SunGlint,
    /// Light from bright surroundings scattered into a pixel's path (needs `land`).
    Adjacency,
    /// Legacy switch, kept so that older scenes and sessions load: every design that states no
    /// MTF budget of its own (`instrument.effects: [SpatialResponse(...)]`, where each design
    /// now states its optics) is sampled with an ideal optic's PSF — diffraction, the pixel's
    /// footprint, the along-track smear.
    SpatialResponse,
}

impl Effect {
    /// All effects, for reports of what was skipped.
    pub const ALL: [Self; 4] = [Self::ShallowBottom, Self::SunGlint, Self::Adjacency, Self::SpatialResponse];
}

/// A scene as written in RON (`presets/scenes/*.ron`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Short name.
    pub name: String,
    /// What it represents and where its numbers come from.
    #[serde(default)]
    pub description: String,
    /// Where the scene is on Earth (absent: a local frame). `Raster(path)` also sets the grid,
    /// and then `width`, `height` and `cell_m` may be left out.
    #[serde(default)]
    pub georeference: Option<Georeference>,
    /// Cells along x (east), 1–20 000.
    #[serde(default)]
    pub width: usize,
    /// Cells along y (north), 1–20 000.
    #[serde(default)]
    pub height: usize,
    /// Ground size of a cell, m (0.1–10 000).
    #[serde(default)]
    pub cell_m: f64,
    /// The sun.
    pub sun: SunSpec,
    /// Date, YYYY-MM-DD (Sun–Earth distance).
    pub date: String,
    /// Local time, for the record (the sun position is given explicitly).
    #[serde(default)]
    pub time: String,
    /// The atmosphere (its `day_of_year` is set from `date`).
    pub atmosphere: AtmosphereSpec,
    /// The scene's SIOP set.
    pub siop: SiopSource,
    /// Chlorophyll-a, mg m⁻³.
    pub chl_mg_m3: MapSpec,
    /// Non-algal particles, g m⁻³.
    pub nap_g_m3: MapSpec,
    /// CDOM absorption at the SIOP set's reference wavelength, m⁻¹.
    pub cdom_per_m: MapSpec,
    /// Depth, m; absent: optically deep everywhere.
    #[serde(default)]
    pub depth_m: Option<MapSpec>,
    /// Substrates and their fraction maps (used with `ShallowBottom`).
    #[serde(default)]
    pub substrates: Vec<SubstrateLayer>,
    /// Land, if any.
    #[serde(default)]
    pub land: Option<LandSpec>,
    /// Effects the scene calls for.
    #[serde(default)]
    pub effects: Vec<Effect>,
    /// Aerosol optical thickness at 550 nm over the scene, when it varies (a haze front, a
    /// plume): the aerosol model stays `atmosphere.aerosol`, its optical thickness follows this
    /// map and `atmosphere.aot550` is unused. Absent: `atmosphere.aot550` everywhere.
    #[serde(default)]
    pub aot550_map: Option<MapSpec>,
    /// A broken cloud layer and its shadows (absent: a clear sky).
    #[serde(default)]
    pub clouds: Option<CloudLayer>,
}

/// Day of year of `YYYY-MM-DD`.
pub fn day_of_year(date: &str) -> Result<u32, SceneError> {
    let bad = |m: &str| {
        SceneError::Invalid(FieldError {
            field: "date".into(),
            message: format!("`{date}`: {m} (expected YYYY-MM-DD)"),
        })
    };
    let parts: Vec<&str> = date.trim().split('-').collect();
    let [y, m, d] = parts.as_slice() else { return Err(bad("not a date")) };
    let num = |s: &str| s.parse::<u32>().map_err(|_| bad("not a date"));
    let (y, m, d) = (num(y)?, num(m)?, num(d)?);
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let days = [31, if leap { 29 } else { 28 }, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    if !(1..=12).contains(&m) || d == 0 || d > days[(m - 1) as usize] {
        return Err(bad("no such calendar day"));
    }
    Ok(days[..(m - 1) as usize].iter().sum::<u32>() + d)
}

impl SceneSpec {
    /// Parse RON; `origin` names the file in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, SceneError> {
        crate::parse::from_ron(text, origin)
    }

    /// A built-in scene by name (`presets/scenes/NAME.ron`).
    pub fn preset(name: &str) -> Result<Self, SceneError> {
        crate::parse::preset(name)
    }

    /// Names of the built-in scenes.
    #[must_use]
    pub fn preset_names() -> Vec<String> {
        crate::parse::preset_names::<Self>()
    }

    /// Does the bottom show through the water (the scene asks for `ShallowBottom`)? Then only a
    /// retrieval that models a bottom (SAMBUCA) can be right here: aLMI assumes optically deep
    /// water and retrieves no depth or substrate.
    #[must_use]
    pub fn needs_bottom_model(&self) -> bool {
        self.effects.contains(&Effect::ShallowBottom)
    }

    /// Take the grid of the scene's georeference raster: width, height and cell size must be
    /// left out of the scene file or agree with the raster.
    fn set_grid_from_raster(&mut self, grid: Extent) -> Result<(), SceneError> {
        use crate::ranges as r;
        let given = (self.width, self.height, self.cell_m);
        if given != (0, 0, 0.0)
            && (given.0 != grid.width || given.1 != grid.height || (given.2 - grid.cell_m).abs() > 1e-9 * grid.cell_m)
        {
            return Err(SceneError::Invalid(FieldError {
                field: "width".into(),
                message: format!(
                    "the scene says {} × {} cells of {} m but its georeference raster is {} × {} of {} m; leave width, height and cell_m out",
                    given.0, given.1, given.2, grid.width, grid.height, grid.cell_m
                ),
            }));
        }
        for (range, v) in [
            (&r::SCENE_WIDTH, grid.width as f64),
            (&r::SCENE_HEIGHT, grid.height as f64),
            (&r::SCENE_CELL_M, grid.cell_m),
        ] {
            range.check(v).map_err(|message| {
                SceneError::Invalid(FieldError {
                    field: "georeference".into(),
                    message: format!("the raster's grid: {message}"),
                })
            })?;
        }
        (self.width, self.height, self.cell_m) = (grid.width, grid.height, grid.cell_m);
        Ok(())
    }

    /// Check the numbers and that every effect has what it needs.
    pub fn validate(&self) -> Result<(), SceneError> {
        use crate::ranges as r;
        let bad = |field: &str, message: String| Err(SceneError::Invalid(FieldError { field: field.into(), message }));
        let check = |range: &r::Range, v: f64| {
            range
                .check(v)
                .map_err(|message| SceneError::Invalid(FieldError { field: range.field("scene.").into(), message }))
        };
        // A raster georeference sets the grid; its numbers are checked when the scene builds.
        let grid_from_raster = matches!(self.georeference, Some(Georeference::Raster(_)));
        let unset = self.width == 0 && self.height == 0 && self.cell_m == 0.0;
        if !(grid_from_raster && unset) {
            check(&r::SCENE_WIDTH, self.width as f64)?;
            check(&r::SCENE_HEIGHT, self.height as f64)?;
            check(&r::SCENE_CELL_M, self.cell_m)?;
        }
        check(&r::SCENE_SUN_ZENITH_DEG, self.sun.zenith_deg)?;
        if !self.sun.azimuth_deg.is_finite() {
            return bad("sun.azimuth_deg", format!("{} is not a finite angle", self.sun.azimuth_deg));
        }
        day_of_year(&self.date)?;
        let has = |e: Effect| self.effects.contains(&e);
        if has(Effect::ShallowBottom) && self.depth_m.is_none() {
            return bad("effects", "ShallowBottom needs a `depth_m` map".into());
        }
        if has(Effect::ShallowBottom) && self.substrates.is_empty() {
            return bad("substrates", "ShallowBottom needs at least one substrate".into());
        }
        if has(Effect::SunGlint) && matches!(self.atmosphere.surface, SeaSurface::Flat) {
            return bad(
                "effects",
                "SunGlint needs a wind-roughened surface: atmosphere.surface: Wind(speed_m_s: ..)".into(),
            );
        }
        if self.aot550_map.is_some() && self.atmosphere.aerosol == crate::atmosphere::AerosolType::None {
            return bad(
                "aot550_map",
                "an aerosol optical thickness map needs an aerosol model: atmosphere.aerosol is None".into(),
            );
        }
        if has(Effect::Adjacency) && self.land.is_none() {
            return bad("effects", "Adjacency needs `land` (a mask and a reflectance)".into());
        }
        self.clouds.as_ref().map_or(Ok(()), CloudLayer::validate)
    }
}

/// A validated scene with its maps ready to sample.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The spec it was built from (paths made relative to the scene file's directory).
    pub spec: SceneSpec,
    /// Raster extent of the maps.
    pub extent: Extent,
    /// Chlorophyll-a map, mg m⁻³.
    pub chl: Map,
    /// NAP map, g m⁻³.
    pub nap: Map,
    /// CDOM map, m⁻¹.
    pub cdom: Map,
    /// Depth map, m, when the bottom is simulated.
    pub depth: Option<Map>,
    /// Substrate fraction maps, by name.
    pub substrates: Vec<(String, Map)>,
    /// Land mask, when the scene has land.
    pub land: Option<Map>,
    /// Aerosol optical thickness at 550 nm, when the scene gives it as a map.
    pub aot550: Option<Map>,
    /// The cloud layer, when the scene has clouds.
    pub clouds: Option<CloudField>,
    /// Directory of the scene file (for relative paths), if any.
    pub base_dir: Option<PathBuf>,
    /// Day of year.
    pub day_of_year: u32,
    /// Where the scene is on Earth, if it is georeferenced.
    pub frame: Option<GeoFrame>,
}

impl Scene {
    /// Bytes the scene's maps hold.
    #[must_use]
    pub fn map_bytes(&self) -> usize {
        let optional = [&self.depth, &self.land, &self.aot550];
        [&self.chl, &self.nap, &self.cdom].iter().map(|m| m.bytes()).sum::<usize>()
            + optional.iter().filter_map(|m| m.as_ref()).map(Map::bytes).sum::<usize>()
            + self.substrates.iter().map(|(_, m)| m.bytes()).sum::<usize>()
            + self.clouds.as_ref().map_or(0, CloudField::bytes)
    }

    /// Validate `spec` and build its maps; `base_dir` is the scene file's directory.
    pub fn build(spec: &SceneSpec, base_dir: Option<&Path>) -> Result<Self, SceneError> {
        spec.validate()?;
        let mut spec = spec.clone();
        spec.siop = spec.siop.relative_to(base_dir);
        let day = day_of_year(&spec.date)?;
        spec.atmosphere.day_of_year = day;
        spec.atmosphere
            .validate()
            .map_err(|e| SceneError::Invalid(FieldError { field: "atmosphere".into(), message: e.to_string() }))?;
        let mut cache = RasterCache::default();
        let frame = match &spec.georeference {
            Some(g) => {
                let (frame, grid) = resolve_frame(g, base_dir, &mut cache)?;
                if let Some(grid) = grid {
                    spec.set_grid_from_raster(grid)?;
                }
                Some(frame)
            }
            None => None,
        };
        let extent = Extent { width: spec.width, height: spec.height, cell_m: spec.cell_m };
        let mut ctx = MapContext { base_dir, frame: frame.as_ref(), cache };
        let mut map = |s: &MapSpec, field: &str| Map::build(s, extent, field, &mut ctx);
        // The land mask first: a raster map may lack data only on land.
        let mut land = match &spec.land {
            Some(l) => Some(map(&l.mask, "land.mask")?),
            None => None,
        };
        let mut chl = map(&spec.chl_mg_m3, "chl_mg_m3")?;
        let mut nap = map(&spec.nap_g_m3, "nap_g_m3")?;
        let mut cdom = map(&spec.cdom_per_m, "cdom_per_m")?;
        let bottom = spec.effects.contains(&Effect::ShallowBottom);
        let mut depth = match (&spec.depth_m, bottom) {
            (Some(d), true) => Some(map(d, "depth_m")?),
            _ => None,
        };
        let mut substrates = if bottom {
            spec.substrates
                .iter()
                .map(|l| Ok((l.name.clone(), map(&l.fraction, &format!("substrates.{}", l.name))?)))
                .collect::<Result<Vec<_>, SceneError>>()?
        } else {
            Vec::new()
        };
        if let Some(cells) = land.as_mut().and_then(Map::cells_mut)
            && let Some(i) = cells.iter().position(|v| v.is_nan())
        {
            return Err(SceneError::Invalid(FieldError {
                field: "land.mask".into(),
                message: format!(
                    "{} cells have no data (the first at column {}, row {} from the south); the land mask must cover the scene",
                    cells.iter().filter(|v| v.is_nan()).count(),
                    i % extent.width,
                    i / extent.width
                ),
            }));
        }
        let aot550 = match &spec.aot550_map {
            Some(m) => Some(map(m, "aot550_map")?),
            None => None,
        };
        if let Some(cells) = aot550.as_ref().and_then(Map::cells)
            && cells.iter().any(|v| v.is_nan())
        {
            return Err(SceneError::Invalid(FieldError {
                field: "aot550_map".into(),
                message: format!(
                    "{} cells have no data; the aerosol map must cover the scene",
                    cells.iter().filter(|v| v.is_nan()).count()
                ),
            }));
        }
        let land_at = |col: usize, row: usize| {
            let (hx, hy) = extent.half_size_m();
            let (x, y) = (-hx + (col as f64 + 0.5) * extent.cell_m, -hy + (row as f64 + 0.5) * extent.cell_m);
            land.as_ref().is_some_and(|m| m.value_at(x, y) > 0.5)
        };
        let water_maps =
            [(&mut chl, "chl_mg_m3".to_string()), (&mut nap, "nap_g_m3".into()), (&mut cdom, "cdom_per_m".into())]
                .into_iter()
                .chain(depth.as_mut().map(|d| (d, "depth_m".to_string())))
                .chain(substrates.iter_mut().map(|(n, m)| (m, format!("substrates.{n}"))));
        for (m, field) in water_maps {
            if let Some(cells) = m.cells_mut() {
                fill_nodata(cells, extent, &field, frame.as_ref(), &land_at)?;
            }
        }
        let clouds = match &spec.clouds {
            Some(c) => {
                Some(CloudField::build(c, extent, spec.sun.zenith_deg.to_radians(), spec.sun.azimuth_deg.to_radians())?)
            }
            None => None,
        };
        let scene = Self {
            clouds,
            spec,
            extent,
            chl,
            nap,
            cdom,
            depth,
            substrates,
            land,
            aot550,
            base_dir: base_dir.map(Path::to_path_buf),
            day_of_year: day,
            frame,
        };
        scene.check_ranges()?;
        Ok(scene)
    }

    /// Every value of every map within its range ([`crate::ranges`]).
    fn check_ranges(&self) -> Result<(), SceneError> {
        use crate::ranges as r;
        let check = |field: &str, m: &Map, range: &r::Range| {
            let (a, b) = m.range();
            match [a, b].into_iter().find(|v| !range.contains(*v)) {
                Some(v) => Err(SceneError::Invalid(FieldError {
                    field: field.into(),
                    message: format!("{v} is out of range (the map spans {a} to {b}; allowed: {})", range.allowed()),
                })),
                None => Ok(()),
            }
        };
        check("chl_mg_m3", &self.chl, &r::SCENE_CHL_MG_M3)?;
        check("nap_g_m3", &self.nap, &r::SCENE_NAP_G_M3)?;
        check("cdom_per_m", &self.cdom, &r::SCENE_CDOM_PER_M)?;
        if let Some(d) = &self.depth {
            check("depth_m", d, &r::SCENE_DEPTH_M).map_err(|e| match e {
                SceneError::Invalid(FieldError { field, message }) if d.range().0 <= 0.0 => {
                    SceneError::Invalid(FieldError { field, message: format!("{message}; land belongs in `land`") })
                }
                other => other,
            })?;
        }
        for (name, m) in &self.substrates {
            check(&format!("substrates.{name}.fraction"), m, &r::SCENE_SUBSTRATE_FRACTION)?;
        }
        if let Some(m) = &self.aot550 {
            check("aot550_map", m, &r::SCENE_AOT550_MAP)?;
        }
        Ok(())
    }

    /// Is there land at (x, y)?
    #[must_use]
    pub fn is_land(&self, x_m: f64, y_m: f64) -> bool {
        self.land.as_ref().is_some_and(|m| m.value_at(x_m, y_m) >= 0.5)
    }

    /// What a sensor at (`view_zenith_rad`, `view_azimuth_rad`, the sensor's azimuth seen from
    /// the ground) sees at ground point (x, y): cloud, the surface in a cloud's shadow, or the
    /// surface in the sun (always, without clouds).
    #[must_use]
    pub fn sky_at(&self, x_m: f64, y_m: f64, view_zenith_rad: f64, view_azimuth_rad: f64) -> Sky {
        self.clouds.as_ref().map_or(Sky::Clear, |c| c.sky_at(x_m, y_m, view_zenith_rad, view_azimuth_rad))
    }

    /// Aerosol optical thickness at 550 nm at (x, y): the map's value, or the atmosphere's.
    #[must_use]
    pub fn aot550_at(&self, x_m: f64, y_m: f64) -> f64 {
        self.aot550.as_ref().map_or(self.spec.atmosphere.aot550, |m| m.value_at(x_m, y_m))
    }

    /// Effects the scene calls for.
    #[must_use]
    pub fn wants(&self, effect: Effect) -> bool {
        self.spec.effects.contains(&effect)
    }
}

impl crate::parse::Preset for SceneSpec {
    const FOLDER: &'static str = "scenes";
    type Error = SceneError;
    fn parse_error(origin: &str, message: String) -> SceneError {
        SceneError::Parse(ParseError { origin: origin.into(), message })
    }
    fn unknown(name: &str, known: &[String]) -> SceneError {
        SceneError::Invalid(FieldError {
            field: "scene".into(),
            message: format!("no built-in scene `{name}` (known: {})", known.join(", ")),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates() {
        assert_eq!(day_of_year("2023-06-21").unwrap(), 172);
        assert!(day_of_year("2023-13-01").is_err());
    }
}
