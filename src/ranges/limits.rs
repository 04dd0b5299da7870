//! The documented ranges of the water model's inputs (`crate::water`; here, above it, so that
//! the table of ranges needs nothing of the water model). Values outside are refused with a message that
//! names the field and the range; inside, the model stays finite (see `tests/`).

/// Largest chlorophyll-a accepted, mg m⁻³ (hypertrophic blooms reach ~10³).
pub const MAX_CHL_MG_M3: f64 = 10_000.0;
/// Largest CDOM absorption at the reference wavelength accepted, m⁻¹.
pub const MAX_CDOM_PER_M: f64 = 1_000.0;
/// Largest NAP concentration accepted, g m⁻³.
pub const MAX_NAP_G_M3: f64 = 10_000.0;
/// Largest depth accepted, m (deeper is optically deep everywhere; say `deep`).
pub const MAX_DEPTH_M: f64 = 11_000.0;
/// Zenith angles must be below this, rad (90°).
pub const MAX_ZENITH_RAD: f64 = std::f64::consts::FRAC_PI_2;
