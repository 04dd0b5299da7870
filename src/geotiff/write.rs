//! Writing a [`Raster`] as a GeoTIFF: Float32 samples, one plane per band (`PlanarConfiguration`
//! 2, so a band reads without the others), deflate-compressed strips of about 64 KiB, the
//! geotransform as `ModelPixelScale` + `ModelTiepoint` when north-up or `ModelTransformation`
//! when rotated, the CRS as GeoKeys, and GDAL's nodata and metadata tags.

use tiff::encoder::compression::{CompressionAlgorithm, Deflate, DeflateLevel};
use tiff::encoder::{DirectoryEncoder, TiffEncoder, TiffKindStandard};
use tiff::tags::{CompressionMethod, PhotometricInterpretation, PlanarConfiguration, SampleFormat, Tag};

use super::keys::{self, GDAL_METADATA, GDAL_NODATA, GEO_ASCII_PARAMS, GEO_KEY_DIRECTORY};
use super::{GeoTiffError, Raster};

/// Bytes per strip before compression (GDAL's default strip is one to a few rows; larger strips
/// compress better and a 64 KiB strip still decodes without a large buffer).
const STRIP_BYTES: usize = 64 * 1024;

fn tag(n: u16) -> Tag {
    Tag::from_u16_exhaustive(n)
}

/// Text for an ASCII TIFF tag: units written with Unicode superscripts become `sr-1`, `m-3`; any
/// other non-ASCII character becomes an XML character reference (GDAL's XML parser reads it).
pub fn ascii(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '⁻' => out.push('-'),
            '⁰'..='⁹' | '¹' | '²' | '³' => {
                let d = match c {
                    '¹' => 1,
                    '²' => 2,
                    '³' => 3,
                    _ => c as u32 - '⁰' as u32,
                };
                out.push(char::from_digit(d, 10).unwrap_or('?'));
            }
            'µ' | 'μ' => out.push('u'),
            '\0' => {}
            c if c.is_ascii() => out.push(c),
            c => out += &format!("&#x{:X};", c as u32),
        }
    }
    out
}

/// Encode `raster` as GeoTIFF bytes.
pub fn encode(raster: &Raster) -> Result<Vec<u8>, GeoTiffError> {
    let (w, h, n) = (raster.width, raster.height, raster.bands.len());
    if w == 0 || h == 0 || n == 0 {
        return Err(GeoTiffError(format!("a {w} × {h} raster with {n} bands has nothing to write")));
    }
    if let Some(b) = raster.bands.iter().position(|b| b.len() != w * h) {
        return Err(GeoTiffError(format!("band {} has {} values for {w} × {h} cells", b + 1, raster.bands[b].len())));
    }
    // Classic TIFF addresses 4 GiB; the products of one run stay far below.
    if (w * h * n * 4) as u64 >= 3_900_000_000 {
        return Err(GeoTiffError(format!("{w} × {h} × {n} Float32 exceeds classic TIFF's 4 GiB")));
    }
    let (Ok(width), Ok(height), Ok(bands)) = (u32::try_from(w), u32::try_from(h), u16::try_from(n)) else {
        return Err(GeoTiffError(format!("{w} × {h} × {n} is too large for TIFF")));
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    let fail = |e: tiff::TiffError| GeoTiffError::from_tiff("cannot encode GeoTIFF", &e);
    let mut encoder = TiffEncoder::new(&mut bytes).map_err(fail)?;
    let mut dir = encoder.image_directory().map_err(fail)?;

    let rows_per_strip = (STRIP_BYTES / (w * 4)).clamp(1, h);
    let (mut offsets, mut counts) = (Vec::new(), Vec::new());
    let mut deflate = Deflate::with_level(DeflateLevel::Balanced);
    for band in &raster.bands {
        for rows in band.chunks(rows_per_strip * w) {
            let raw: Vec<u8> = rows.iter().flat_map(|v| (*v as f32).to_ne_bytes()).collect();
            let mut packed = Vec::with_capacity(raw.len() / 2);
            deflate.write_to(&mut packed, &raw).map_err(|e| GeoTiffError(format!("deflate: {e}")))?;
            offsets.push(u32::try_from(dir.write_data(&packed[..]).map_err(fail)?).map_err(|_| too_big())?);
            counts.push(u32::try_from(packed.len()).map_err(|_| too_big())?);
        }
    }
    put(&mut dir, Tag::ImageWidth, width)?;
    put(&mut dir, Tag::ImageLength, height)?;
    put(&mut dir, Tag::BitsPerSample, &vec![32u16; n][..])?;
    put(&mut dir, Tag::Compression, CompressionMethod::Deflate.to_u16())?;
    put(&mut dir, Tag::PhotometricInterpretation, PhotometricInterpretation::BlackIsZero.to_u16())?;
    put(&mut dir, Tag::StripOffsets, &offsets[..])?;
    put(&mut dir, Tag::SamplesPerPixel, bands)?;
    put(&mut dir, Tag::RowsPerStrip, rows_per_strip as u32)?;
    put(&mut dir, Tag::StripByteCounts, &counts[..])?;
    put(&mut dir, Tag::PlanarConfiguration, PlanarConfiguration::Planar.to_u16())?;
    if n > 1 {
        // Samples beyond the first of a grey image are "unspecified" extra samples (TIFF 6.0).
        put(&mut dir, Tag::ExtraSamples, &vec![0u16; n - 1][..])?;
    }
    put(&mut dir, Tag::SampleFormat, &vec![SampleFormat::IEEEFP.to_u16(); n][..])?;
    if let Some(g) = raster.geotransform {
        // North-up (rows going south): the usual scale + tie point; anything else (rotated, or
        // rows going north as an ascending pushbroom image's do) as the full matrix.
        if g[2] == 0.0 && g[4] == 0.0 && g[1] > 0.0 && g[5] < 0.0 {
            put(&mut dir, tag(keys::MODEL_PIXEL_SCALE), &[g[1], -g[5], 0.0][..])?;
            put(&mut dir, tag(keys::MODEL_TIEPOINT), &[0.0, 0.0, 0.0, g[0], g[3], 0.0][..])?;
        } else {
            let m = [g[1], g[2], 0.0, g[0], g[4], g[5], 0.0, g[3], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
            put(&mut dir, tag(keys::MODEL_TRANSFORMATION), &m[..])?;
        }
        let (key_dir, text) = keys::build(&raster.crs);
        put(&mut dir, tag(GEO_KEY_DIRECTORY), &key_dir[..])?;
        if !text.is_empty() {
            put(&mut dir, tag(GEO_ASCII_PARAMS), text.as_str())?;
        }
    }
    let xml = keys::metadata_xml(&raster.descriptions, &raster.units, &raster.scales, &raster.metadata);
    put(&mut dir, tag(GDAL_METADATA), xml.as_str())?;
    if let Some(v) = raster.nodata {
        put(&mut dir, tag(GDAL_NODATA), format!("{v}").as_str())?;
    }
    dir.finish().map_err(fail)?;
    Ok(bytes.into_inner())
}

fn too_big() -> GeoTiffError {
    GeoTiffError("the GeoTIFF exceeds classic TIFF's 4 GiB".into())
}

fn put<T: tiff::encoder::TiffValue>(
    dir: &mut DirectoryEncoder<'_, &mut std::io::Cursor<Vec<u8>>, TiffKindStandard>,
    t: Tag,
    value: T,
) -> Result<(), GeoTiffError> {
    dir.write_tag(t, value).map_err(|e| GeoTiffError::from_tiff(&format!("cannot write tag {}", t.to_u16()), &e))
}
