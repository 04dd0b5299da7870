//! GeoTIFF in and out: single- or multi-band rasters with their geotransform, CRS, nodata value,
//! band descriptions and units — what GIS and Python tools (GDAL, rasterio, QGIS) read.
//!
//! The TIFF container (strips, tiles, deflate/LZW, sample formats) is the `tiff` crate's; this
//! module adds the GeoTIFF keys (OGC GeoTIFF 1.1, OGC 19-008r4) and GDAL's two private tags:
//! `GDAL_NODATA` (42113, the nodata value as text) and `GDAL_METADATA` (42112, an XML list of
//! band descriptions, units and dataset items).
//!
//! Conventions, as GDAL's: row 0 is the top (first) row of the file, and the geotransform
//! `[x0, dx_col, dx_row, y0, dy_col, dy_row]` maps the *corner* of pixel (col, row) to
//! `X = x0 + col·dx_col + row·dx_row`, `Y = y0 + col·dy_col + row·dy_row` (a north-up raster has
//! `dx_row = dy_col = 0` and `dy_row < 0`).

mod keys;
mod read;
mod write;

pub use keys::USER_DEFINED_NAME;
pub use read::{MAX_SAMPLES, read, read_bytes, read_bytes_limited, read_limited};
pub use write::{ascii as ascii_text, encode};

/// A coordinate reference system, as far as Shoal needs to know it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Crs {
    /// A projected CRS by EPSG code (UTM and the like; coordinates in its linear unit).
    Projected {
        /// EPSG code, e.g. 32756 (WGS 84 / UTM zone 56S).
        epsg: u16,
    },
    /// A geographic CRS by EPSG code (coordinates in degrees).
    Geographic {
        /// EPSG code, e.g. 4326.
        epsg: u16,
    },
    /// A local engineering frame (a user-defined projection; no place on Earth): Shoal's scene
    /// frame when the scene has no georeference. Metres when the file's linear unit is.
    LocalMetres {
        /// What the frame is (written as the citation).
        name: String,
    },
    /// The file carries no CRS.
    None,
}

impl Crs {
    /// Are coordinates in metres (so a cell size is a ground distance)?
    #[must_use]
    pub fn is_metric(&self, linear_unit_m: f64) -> bool {
        match self {
            Self::Projected { .. } | Self::LocalMetres { .. } => (linear_unit_m - 1.0).abs() < 1e-12,
            Self::Geographic { .. } | Self::None => false,
        }
    }

    /// A short description ("EPSG:32756", "local frame (NAME)").
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::Projected { epsg } | Self::Geographic { epsg } => format!("EPSG:{epsg}"),
            Self::LocalMetres { name } => format!("local frame ({name})"),
            Self::None => "none".into(),
        }
    }
}

/// A raster with its georeference.
#[derive(Debug, Clone, PartialEq)]
pub struct Raster {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Band values, band by band, each `width · height` row-major with row 0 the top row.
    pub bands: Vec<Vec<f64>>,
    /// The value that marks a missing cell, if any.
    pub nodata: Option<f64>,
    /// GDAL-order geotransform (see the module doc), if the file has one.
    pub geotransform: Option<[f64; 6]>,
    /// The coordinate reference system.
    pub crs: Crs,
    /// Size of the CRS's linear unit, m (1 for metres; from `ProjLinearUnitsGeoKey`).
    pub linear_unit_m: f64,
    /// Per band: a description (what the band holds).
    pub descriptions: Vec<String>,
    /// Per band: the unit of its values (after `scales`).
    pub units: Vec<String>,
    /// Per band: GDAL's (scale, offset) unpacking, value = scale · stored + offset; (1, 0) for
    /// most files. `bands` hold the stored values; `nodata` is a stored value.
    pub scales: Vec<(f64, f64)>,
    /// Dataset metadata items (name, value), written to and read from `GDAL_METADATA`.
    pub metadata: Vec<(String, String)>,
}

impl Raster {
    /// A raster of `bands` (each `width · height`, top row first) with no georeference.
    #[must_use]
    pub fn new(width: usize, height: usize, bands: Vec<Vec<f64>>) -> Self {
        let n = bands.len();
        Self {
            width,
            height,
            bands,
            nodata: None,
            geotransform: None,
            crs: Crs::None,
            linear_unit_m: 1.0,
            descriptions: vec![String::new(); n],
            units: vec![String::new(); n],
            scales: vec![(1.0, 0.0); n],
            metadata: Vec::new(),
        }
    }

    /// Is stored value `v` missing (NaN, or the nodata value)? The nodata text of a Float32 file
    /// may not be exactly representable (`0.10000000000000001`): it matches at Float32
    /// precision too.
    #[must_use]
    pub fn is_nodata(&self, v: f64) -> bool {
        v.is_nan() || self.nodata.is_some_and(|n| v == n || (v as f32) == (n as f32))
    }

    /// The (X, Y) in CRS units of fractional pixel position (col, row) (corner convention:
    /// (0.5, 0.5) is the centre of the first pixel).
    #[must_use]
    pub fn world(&self, col: f64, row: f64) -> Option<(f64, f64)> {
        let g = self.geotransform?;
        Some((g[0] + col * g[1] + row * g[2], g[3] + col * g[4] + row * g[5]))
    }

    /// The fractional pixel position (col, row) of world point (X, Y), if the geotransform is
    /// invertible.
    #[must_use]
    pub fn pixel(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let g = self.geotransform?;
        let det = g[1] * g[5] - g[2] * g[4];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let (dx, dy) = (x - g[0], y - g[3]);
        Some(((g[5] * dx - g[2] * dy) / det, (-g[4] * dx + g[1] * dy) / det))
    }

    /// A metadata item by name.
    #[must_use]
    pub fn item(&self, name: &str) -> Option<&str> {
        self.metadata.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
}

/// A GeoTIFF that cannot be read or written, with the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct GeoTiffError(pub String);

impl GeoTiffError {
    fn from_tiff(what: &str, e: &tiff::TiffError) -> Self {
        Self(format!("{what}: {e}"))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    fn sample() -> Raster {
        let (w, h) = (7, 5);
        let bands = (0..3).map(|b| (0..w * h).map(|i| (b * 100 + i) as f64 * 0.25 - 3.0).collect()).collect();
        let mut r = Raster::new(w, h, bands);
        r.nodata = Some(-9999.0);
        r.bands[1][4] = -9999.0;
        r.geotransform = Some([385_000.0, 10.0, 0.0, 7_405_000.0, 0.0, -10.0]);
        r.crs = Crs::Projected { epsg: 32756 };
        r.descriptions = vec!["Rrs 443".into(), "Rrs 490".into(), "Rrs 560".into()];
        r.units = vec!["sr-1".into(); 3];
        r.metadata = vec![("SHOAL_PRODUCT".into(), "rrs & <test>".into())];
        r
    }

    #[test]
    fn what_is_written_reads_back_the_same() {
        let r = sample();
        let back = read_bytes(&encode(&r).unwrap(), "sample").unwrap();
        assert_eq!((back.width, back.height), (7, 5));
        assert_eq!(back.geotransform, r.geotransform);
        assert_eq!(back.crs, r.crs);
        assert_eq!(back.nodata, Some(-9999.0));
        assert_eq!(back.descriptions, r.descriptions);
        assert_eq!(back.units, r.units);
        assert_eq!(back.item("SHOAL_PRODUCT"), Some("rrs & <test>"));
        // Float32 storage: the test values are exact in f32.
        assert_eq!(back.bands, r.bands);
    }

    #[test]
    fn a_local_frame_and_a_rotated_transform_survive() {
        let mut r = sample();
        r.crs = Crs::LocalMetres { name: "Shoal scene frame".into() };
        let (s, c) = (0.3f64.sin(), 0.3f64.cos());
        r.geotransform = Some([-500.0, 10.0 * c, 10.0 * s, 400.0, 10.0 * s, -10.0 * c]);
        let back = read_bytes(&encode(&r).unwrap(), "rotated").unwrap();
        assert_eq!(back.crs, r.crs);
        let (g, b) = (r.geotransform.unwrap(), back.geotransform.unwrap());
        for k in 0..6 {
            assert!((g[k] - b[k]).abs() < 1e-9, "{g:?} {b:?}");
        }
        let (x, y) = back.world(2.5, 3.5).unwrap();
        let (col, row) = back.pixel(x, y).unwrap();
        assert!((col - 2.5).abs() < 1e-9 && (row - 3.5).abs() < 1e-9);
    }

    #[test]
    fn non_ascii_text_and_band_scales_survive() {
        let mut r = sample();
        r.descriptions[0] = "chl-a über Seegras, µg L⁻¹ & <x>".into();
        r.metadata = vec![("SCENE".into(), "Île d'Été".into())];
        r.scales = vec![(0.01, -5.0), (1.0, 0.0), (2.0, 0.0)];
        let back = read_bytes(&encode(&r).unwrap(), "text").unwrap();
        // Superscripts and µ become ASCII unit text; everything else comes back as written.
        assert_eq!(back.descriptions[0], "chl-a über Seegras, ug L-1 & <x>");
        assert_eq!(back.item("SCENE"), Some("Île d'Été"));
        assert_eq!(back.scales, r.scales);
    }

    #[test]
    fn a_user_defined_crs_in_feet_is_not_metric() {
        assert!(!Crs::LocalMetres { name: "site grid".into() }.is_metric(0.3048));
        assert!(Crs::LocalMetres { name: "site grid".into() }.is_metric(1.0));
    }

    #[test]
    fn garbage_is_an_error_not_a_panic() {
        for bytes in [&b""[..], b"II*\0garbage", b"MM\0*\0\0\0\x08\0\0"] {
            assert!(read_bytes(bytes, "junk").is_err());
        }
        let e = read(std::path::Path::new("/nonexistent/x.tif")).unwrap_err();
        assert!(e.0.contains("/nonexistent/x.tif"), "{e}");
    }
}
