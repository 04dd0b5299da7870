//! Reading a GeoTIFF into a [`Raster`]: any of the `tiff` crate's sample types (8–64-bit
//! integers, Float32/64), one or many bands, interleaved or planar, stripped or tiled,
//! uncompressed, deflate or LZW; the first image of the file.

use std::io::Cursor;
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult};
use tiff::tags::{PlanarConfiguration, Tag};

use super::keys::{self, GDAL_METADATA, GDAL_NODATA, GEO_ASCII_PARAMS, GEO_DOUBLE_PARAMS, GEO_KEY_DIRECTORY};
use super::{Crs, GeoTiffError, Raster};

/// Most samples (all bands) the reader holds at once, whatever the budget.
pub const MAX_SAMPLES: usize = 1 << 29;

/// Read the GeoTIFF at `path` (at most [`MAX_SAMPLES`] samples).
pub fn read(path: &Path) -> Result<Raster, GeoTiffError> {
    read_limited(path, MAX_SAMPLES)
}

/// Read the GeoTIFF at `path` if it holds at most `max_samples` samples (all bands), checked
/// from its header before anything is decoded: a small compressed file can claim gigabytes.
pub fn read_limited(path: &Path, max_samples: usize) -> Result<Raster, GeoTiffError> {
    // No sample takes more than 8 bytes uncompressed: a larger file holds more than it may.
    let max_bytes = (max_samples as u64).saturating_mul(8).saturating_add(1 << 20);
    let bytes = crate::infile::read(path, max_bytes).map_err(|e| GeoTiffError(format!("cannot read {e}")))?;
    read_bytes_limited(&bytes, &path.display().to_string(), max_samples)
}

fn samples(result: DecodingResult) -> Vec<f64> {
    match result {
        DecodingResult::U8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U64(v) => v.into_iter().map(|x| x as f64).collect(),
        DecodingResult::F16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F64(v) => v,
        DecodingResult::I8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I64(v) => v.into_iter().map(|x| x as f64).collect(),
    }
}

/// Read GeoTIFF `bytes`; `origin` names the file in errors (at most [`MAX_SAMPLES`] samples).
pub fn read_bytes(bytes: &[u8], origin: &str) -> Result<Raster, GeoTiffError> {
    read_bytes_limited(bytes, origin, MAX_SAMPLES)
}

/// [`read_bytes`] for a file of at most `max_samples` samples.
pub fn read_bytes_limited(bytes: &[u8], origin: &str, max_samples: usize) -> Result<Raster, GeoTiffError> {
    // The decoder asserts on some malformed inputs; a bad file must be an error, not a crash.
    std::panic::catch_unwind(|| decode(bytes, origin, max_samples.min(MAX_SAMPLES))).unwrap_or_else(|_| {
        Err(GeoTiffError(format!("{origin}: the TIFF decoder failed on this file (malformed or unsupported layout)")))
    })
}

fn decode(bytes: &[u8], origin: &str, max_samples: usize) -> Result<Raster, GeoTiffError> {
    let fail = |e: tiff::TiffError| GeoTiffError::from_tiff(origin, &e);
    let mut d = Decoder::new(Cursor::new(bytes)).map_err(fail)?;
    let (w, h) = d.dimensions().map_err(fail)?;
    let (w, h) = (w as usize, h as usize);
    let n = usize::from(d.find_tag_unsigned::<u16>(Tag::SamplesPerPixel).map_err(fail)?.unwrap_or(1));
    let planar = d.find_tag_unsigned::<u16>(Tag::PlanarConfiguration).map_err(fail)?
        == Some(PlanarConfiguration::Planar.to_u16());
    let tag = |t: u16| Tag::from_u16_exhaustive(t);
    // Tags first: reading the image borrows the decoder.
    let doubles = |d: &mut Decoder<Cursor<&[u8]>>, t: u16| -> Result<Option<Vec<f64>>, GeoTiffError> {
        d.find_tag(tag(t)).map_err(fail)?.map(|v| v.into_f64_vec().map_err(fail)).transpose()
    };
    let scale = doubles(&mut d, keys::MODEL_PIXEL_SCALE)?;
    let tiepoint = doubles(&mut d, keys::MODEL_TIEPOINT)?;
    let matrix = doubles(&mut d, keys::MODEL_TRANSFORMATION)?;
    let key_dir = d.find_tag_unsigned_vec::<u16>(tag(GEO_KEY_DIRECTORY)).map_err(fail)?;
    let key_doubles = doubles(&mut d, GEO_DOUBLE_PARAMS)?.unwrap_or_default();
    let text = |d: &mut Decoder<Cursor<&[u8]>>, t: u16| -> Result<Option<String>, GeoTiffError> {
        d.find_tag(tag(t)).map_err(fail)?.map(|v| v.into_string().map_err(fail)).transpose()
    };
    let key_ascii = text(&mut d, GEO_ASCII_PARAMS)?.unwrap_or_default();
    let metadata = text(&mut d, GDAL_METADATA)?;
    let nodata = text(&mut d, GDAL_NODATA)?;

    // Chunk by chunk (strips or tiles, per plane when planar): the crate's whole-image read
    // asserts on some tiled multi-band layouts GDAL writes, and one chunk at a time keeps the
    // buffers small.
    // A header can claim any size: refuse what would not fit in memory before allocating.
    if w.saturating_mul(h).saturating_mul(n) > max_samples {
        return Err(GeoTiffError(format!(
            "{origin}: {w} × {h} × {n} samples ({:.1} GB as read) is more than this run may hold ({max_samples} samples; see SHOAL_MEMORY_BUDGET); crop it to the scene or coarsen it first (gdal_translate -srcwin, gdalwarp -tr)",
            (w as f64) * (h as f64) * (n as f64) * 8.0 / 1e9
        )));
    }
    let spp = if planar { 1 } else { n };
    let mut bands = vec![vec![f64::NAN; w * h]; n];
    let (cw, ch) = d.chunk_dimensions();
    let (cw, ch) = (cw as usize, ch as usize);
    if cw == 0 || ch == 0 {
        return Err(GeoTiffError(format!("{origin}: chunks of {cw} × {ch} pixels")));
    }
    let across = w.div_ceil(cw);
    let per_plane = across * h.div_ceil(ch);
    for plane in 0..(if planar { n } else { 1 }) {
        for k in 0..per_plane {
            let index =
                u32::try_from(plane * per_plane + k).map_err(|_| GeoTiffError(format!("{origin}: too many chunks")))?;
            let chunk = samples(d.read_chunk(index).map_err(fail)?);
            let (x0, y0) = ((k % across) * cw, (k / across) * ch);
            let (dw, dh) = (cw.min(w - x0), ch.min(h - y0));
            if chunk.len() < dw * dh * spp {
                return Err(GeoTiffError(format!(
                    "{origin}: chunk {index} holds {} samples, not {}",
                    chunk.len(),
                    dw * dh * spp
                )));
            }
            for r in 0..dh {
                for c in 0..dw {
                    for s in 0..spp {
                        bands[plane + s][(y0 + r) * w + x0 + c] = chunk[(r * dw + c) * spp + s];
                    }
                }
            }
        }
    }

    let keys = match &key_dir {
        Some(dir) => keys::parse(dir, &key_ascii, &key_doubles).map_err(|e| GeoTiffError(format!("{origin}: {e}")))?,
        None => keys::Keys { crs: Crs::None, linear_unit_m: 1.0, raster_type: 1 },
    };
    let mut geotransform = match (matrix, scale, tiepoint) {
        (Some(m), _, _) if m.len() >= 8 => Some([m[3], m[0], m[1], m[7], m[4], m[5]]),
        (_, Some(s), Some(t)) if s.len() >= 2 && t.len() >= 6 => {
            // Tie point (I, J) ↔ (X, Y); rows go south (the GeoTIFF convention for a positive
            // ScaleY).
            Some([t[3] - t[0] * s[0], s[0], 0.0, t[4] + t[1] * s[1], 0.0, -s[1]])
        }
        _ => None,
    };
    if keys.raster_type == keys::RASTER_PIXEL_IS_POINT
        && let Some(g) = &mut geotransform
    {
        // The tie point is a pixel centre: move the origin to the corner, as GDAL does.
        g[0] -= 0.5 * (g[1] + g[2]);
        g[3] -= 0.5 * (g[4] + g[5]);
    }
    let nodata = match nodata.as_deref().map(str::trim) {
        None | Some("") => None,
        Some(s) => {
            Some(s.parse::<f64>().map_err(|_| GeoTiffError(format!("{origin}: GDAL_NODATA `{s}` is not a number")))?)
        }
    };
    let meta = match &metadata {
        Some(xml) => keys::parse_metadata(xml, n).map_err(|e| GeoTiffError(format!("{origin}: {e}")))?,
        None => keys::Metadata {
            descriptions: vec![String::new(); n],
            units: vec![String::new(); n],
            scales: vec![(1.0, 0.0); n],
            items: Vec::new(),
        },
    };
    Ok(Raster {
        width: w,
        height: h,
        bands,
        nodata,
        geotransform,
        crs: keys.crs,
        linear_unit_m: keys.linear_unit_m,
        descriptions: meta.descriptions,
        units: meta.units,
        scales: meta.scales,
        metadata: meta.items,
    })
}
