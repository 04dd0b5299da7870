//! The scene's truth under every pixel: what the retrievals are scored against.
//!
//! The sampling stage ([`super::sample`]) evaluates the scene once per pixel and keeps, beside
//! the radiance the instrument sees, the values the scene holds there. They travel as one
//! [`Truth`], shared by reference (`Arc`) from the radiance cube to the metrics, the study
//! tables and figures and the app, so a study keeps the truth of each run without copying it.

use ndarray::{Array2, Array3};

/// The scene's truth at each pixel centre, (row, column) maps on the instrument's grid.
#[derive(Debug, Clone, Default)]
pub struct Truth {
    /// Chlorophyll-a, mg m⁻³.
    pub chl_mg_m3: Array2<f32>,
    /// Non-algal particles, g m⁻³.
    pub nap_g_m3: Array2<f32>,
    /// CDOM absorption at 440 nm, m⁻¹.
    pub cdom_per_m: Array2<f32>,
    /// Depth, m (shallow scenes only).
    pub depth_m: Option<Array2<f32>>,
    /// Substrate fractions (row, column, substrate), normalised (shallow scenes only).
    pub substrate_fractions: Option<Array3<f32>>,
    /// Names of the substrates of `substrate_fractions`, in its order.
    pub substrate_names: Vec<String>,
    /// What covers each pixel centre: water, land (and, when the scene makes them, cloud and
    /// cloud shadow). Every stage asks [`SurfaceMap::is_water`], never the codes.
    pub surface: SurfaceMap,
    /// Aerosol optical thickness at 550 nm at each pixel centre, where the scene gives it as a
    /// map (`aot550_map`; otherwise the atmosphere's `aot550` holds everywhere).
    pub aot550: Option<Array2<f32>>,
}

/// What covers a pixel centre.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum SurfaceClass {
    /// Open water: simulated, corrected and retrieved.
    Water = 0,
    /// Land (the scene's land mask).
    Land = 1,
    /// Cloud between the pixel and the sensor (`scene.clouds`).
    Cloud = 2,
    /// Water in a cloud's shadow: still water, with its own truth, that the processor must
    /// screen out or retrieve from darker light.
    CloudShadow = 3,
}

impl SurfaceClass {
    /// Every class, by code.
    pub const ALL: [Self; 4] = [Self::Water, Self::Land, Self::Cloud, Self::CloudShadow];

    /// Its name in the files (CF `flag_meanings`, the GeoTIFF plane's description).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Water => "water",
            Self::Land => "land",
            Self::Cloud => "cloud",
            Self::CloudShadow => "cloud_shadow",
        }
    }

    /// (code, name) of every class: the flags every writer gives the surface-class map.
    #[must_use]
    pub fn flags() -> Vec<(i32, &'static str)> {
        Self::ALL.iter().map(|c| (*c as i32, c.name())).collect()
    }

    /// The class of a code as stored (an unknown code reads as land: never retrieved).
    #[must_use]
    pub const fn of_code(code: u8) -> Self {
        match code {
            0 => Self::Water,
            2 => Self::Cloud,
            3 => Self::CloudShadow,
            _ => Self::Land,
        }
    }

    /// Is it water the chain retrieves from (and scores), unless the processor's cloud screen
    /// leaves it out?
    #[must_use]
    pub const fn is_water(self) -> bool {
        matches!(self, Self::Water | Self::CloudShadow)
    }

    /// Cloud or a cloud's shadow: what a perfect cloud screen leaves out.
    #[must_use]
    pub const fn is_cloudy(self) -> bool {
        matches!(self, Self::Cloud | Self::CloudShadow)
    }
}

/// The surface class of every pixel, (row, column): the one place that says which pixels are
/// water. Stored as the [`SurfaceClass`] codes, which the writers write as they are
/// (`surface_class.npy`, NetCDF `surface_class`, a GeoTIFF plane: 0 water, 1 land, 2 cloud, 3
/// cloud shadow).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SurfaceMap {
    codes: Array2<u8>,
}

impl SurfaceMap {
    /// The map of `codes` ([`SurfaceClass`] as `u8`).
    #[must_use]
    pub fn from_codes(codes: Array2<u8>) -> Self {
        Self { codes }
    }

    /// Every pixel water, `dim` (rows, columns).
    #[must_use]
    pub fn all_water(dim: (usize, usize)) -> Self {
        Self { codes: Array2::zeros(dim) }
    }

    /// (rows, columns).
    #[must_use]
    pub fn dim(&self) -> (usize, usize) {
        self.codes.dim()
    }

    /// The class at (row, column).
    #[must_use]
    pub fn at(&self, row: usize, column: usize) -> SurfaceClass {
        SurfaceClass::of_code(self.codes[[row, column]])
    }

    /// Is (row, column) water the chain retrieves from?
    #[must_use]
    pub fn is_water(&self, row: usize, column: usize) -> bool {
        self.at(row, column).is_water()
    }

    /// Is the pixel at `index` (row-major) water?
    #[must_use]
    pub fn is_water_at(&self, index: usize) -> bool {
        self.codes.as_slice().is_some_and(|c| c.get(index).is_some_and(|&v| SurfaceClass::of_code(v).is_water()))
    }

    /// Is the pixel at `index` (row-major) open water: water out of any cloud's shadow, under
    /// the full sun?
    #[must_use]
    pub fn is_open_water_at(&self, index: usize) -> bool {
        self.codes.as_slice().is_some_and(|c| c.get(index).is_some_and(|&v| v == SurfaceClass::Water as u8))
    }

    /// The water pixels.
    #[must_use]
    pub fn water_count(&self) -> usize {
        self.codes.iter().filter(|&&c| SurfaceClass::of_code(c).is_water()).count()
    }

    /// True where water.
    #[must_use]
    pub fn water_mask(&self) -> Array2<bool> {
        self.codes.mapv(|c| SurfaceClass::of_code(c).is_water())
    }

    /// Does any pixel see cloud or a cloud's shadow?
    #[must_use]
    pub fn has_clouds(&self) -> bool {
        self.codes.iter().any(|&c| SurfaceClass::of_code(c).is_cloudy())
    }

    /// The screen of a processor that knows every cloud and shadow exactly (the perfect
    /// processor's): true on cloud and cloud shadow.
    #[must_use]
    pub fn exact_screen(&self) -> Array2<bool> {
        self.codes.mapv(|c| SurfaceClass::of_code(c).is_cloudy())
    }

    /// The map a processor corrects over, given its cloud screen (`screened`: true where it
    /// flags cloud or shadow): land as here (a land mask is static and known), every screened
    /// pixel `Cloud` (not corrected), the rest water, a cloud it missed included.
    #[must_use]
    pub fn as_screened(&self, screened: &Array2<bool>) -> Self {
        let codes = ndarray::Zip::from(&self.codes).and(screened).map_collect(|&c, &s| {
            if SurfaceClass::of_code(c) == SurfaceClass::Land {
                SurfaceClass::Land as u8
            } else if s {
                SurfaceClass::Cloud as u8
            } else {
                SurfaceClass::Water as u8
            }
        });
        Self { codes }
    }

    /// The codes as stored, for writers.
    #[must_use]
    pub fn codes(&self) -> &Array2<u8> {
        &self.codes
    }
}

impl Truth {
    /// Whether pixel (row, column) is water.
    #[must_use]
    pub fn is_water(&self, row: usize, column: usize) -> bool {
        self.surface.is_water(row, column)
    }

    /// The truth map of a scalar product variable (`chl_mg_m3`, `nap_g_m3`, `cdom_per_m`,
    /// `depth_m`), if this truth has it.
    #[must_use]
    pub fn map(&self, variable: &str) -> Option<&Array2<f32>> {
        use crate::variable::key;
        match variable {
            key::CHL => Some(&self.chl_mg_m3),
            key::NAP => Some(&self.nap_g_m3),
            key::CDOM => Some(&self.cdom_per_m),
            key::DEPTH => self.depth_m.as_ref(),
            _ => None,
        }
    }
}
