//! The GeoKey directory (OGC GeoTIFF 1.1, §7.1): a list of (key, location, count, value) shorts
//! in tag 34735, with text in 34737 and doubles in 34736; and GDAL's XML metadata (tag 42112).

use super::Crs;
use crate::markup::escape as xml_escape;

/// GeoTIFF tag numbers.
pub(super) const MODEL_PIXEL_SCALE: u16 = 33550;
pub(super) const MODEL_TIEPOINT: u16 = 33922;
pub(super) const MODEL_TRANSFORMATION: u16 = 34264;
pub(super) const GEO_KEY_DIRECTORY: u16 = 34735;
pub(super) const GEO_DOUBLE_PARAMS: u16 = 34736;
pub(super) const GEO_ASCII_PARAMS: u16 = 34737;
pub(super) const GDAL_METADATA: u16 = 42112;
pub(super) const GDAL_NODATA: u16 = 42113;

// GeoKey IDs and values (GeoTIFF 1.1, Annex B/C).
const GT_MODEL_TYPE: u16 = 1024;
const GT_RASTER_TYPE: u16 = 1025;
const GT_CITATION: u16 = 1026;
const GEOGRAPHIC_TYPE: u16 = 2048;
const PROJECTED_CS_TYPE: u16 = 3072;
const PROJ_LINEAR_UNITS: u16 = 3076;
const PROJ_LINEAR_UNIT_SIZE: u16 = 3077;
const MODEL_PROJECTED: u16 = 1;
const MODEL_GEOGRAPHIC: u16 = 2;
const USER_DEFINED: u16 = 32767;
const RASTER_PIXEL_IS_AREA: u16 = 1;
/// Raster type "PixelIsPoint": tie points refer to pixel centres.
pub(super) const RASTER_PIXEL_IS_POINT: u16 = 2;
const LINEAR_METRE: u16 = 9001;

/// The name of a user-defined CRS whose file gives no citation (two of them cannot be told
/// apart, so a scene refuses to mix them).
pub const USER_DEFINED_NAME: &str = "user-defined";

/// What the key directory says.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Keys {
    pub(super) crs: Crs,
    /// Size of the linear unit, m.
    pub(super) linear_unit_m: f64,
    /// `GTRasterTypeGeoKey` (1 area, 2 point).
    pub(super) raster_type: u16,
}

/// Parse the key directory (`dir`: tag 34735), its text (34737) and doubles (34736).
pub(super) fn parse(dir: &[u16], ascii: &str, doubles: &[f64]) -> Result<Keys, String> {
    if dir.len() < 4 || dir.len() < 4 + 4 * usize::from(dir[3]) {
        return Err(format!("GeoKeyDirectory has {} shorts, fewer than its header says", dir.len()));
    }
    let mut keys = Keys { crs: Crs::None, linear_unit_m: 1.0, raster_type: RASTER_PIXEL_IS_AREA };
    let mut unit_stated = false;
    let (mut model, mut projected, mut geographic, mut citation) = (None, None, None, String::new());
    for k in dir[4..4 + 4 * usize::from(dir[3])].chunks_exact(4) {
        let (id, location, count, value) = (k[0], k[1], usize::from(k[2]), k[3]);
        let short = (location == 0).then_some(value);
        match id {
            GT_MODEL_TYPE => model = short,
            GT_RASTER_TYPE => keys.raster_type = short.unwrap_or(RASTER_PIXEL_IS_AREA),
            PROJECTED_CS_TYPE => projected = short,
            GEOGRAPHIC_TYPE => geographic = short,
            PROJ_LINEAR_UNITS => {
                unit_stated = true;
                keys.linear_unit_m = match short {
                    Some(LINEAR_METRE) => 1.0,
                    Some(9002) => 0.3048,          // international foot
                    Some(9003) => 1200.0 / 3937.0, // US survey foot
                    Some(9036) => 1000.0,          // kilometre
                    _ => keys.linear_unit_m,
                }
            }
            PROJ_LINEAR_UNIT_SIZE if location == GEO_DOUBLE_PARAMS => {
                if let Some(v) = doubles.get(usize::from(value)) {
                    unit_stated = true;
                    keys.linear_unit_m = *v;
                }
            }
            GT_CITATION if location == GEO_ASCII_PARAMS => {
                let start = usize::from(value);
                citation =
                    ascii.get(start..(start + count).min(ascii.len())).unwrap_or("").trim_end_matches('|').into();
            }
            _ => {}
        }
    }
    keys.crs = match (model, projected, geographic) {
        (Some(MODEL_PROJECTED), Some(code), _) if code != USER_DEFINED => Crs::Projected { epsg: code },
        (Some(MODEL_GEOGRAPHIC), _, Some(code)) if code != USER_DEFINED => Crs::Geographic { epsg: code },
        // A user-defined projection: a local frame, in metres only if its linear unit says so
        // (`Crs::is_metric` checks `linear_unit_m`).
        (Some(MODEL_PROJECTED), _, _) | (Some(USER_DEFINED), _, _) => {
            Crs::LocalMetres { name: if citation.is_empty() { USER_DEFINED_NAME.into() } else { citation } }
        }
        _ => Crs::None,
    };
    // A projected EPSG code implies its unit, which only an EPSG database knows: without the
    // unit key, only the UTM families (metres by definition) are taken as metres. Any other is
    // left unknown (NaN), so a CRS in US feet is never read as metres.
    if let Crs::Projected { epsg } = keys.crs
        && !unit_stated
        && !utm_metres(epsg)
    {
        keys.linear_unit_m = f64::NAN;
    }
    Ok(keys)
}

/// Is `epsg` a UTM zone in metres (WGS 84 north/south, NAD83, ETRS89, GDA94/GDA2020 MGA)?
fn utm_metres(epsg: u16) -> bool {
    matches!(epsg, 32601..=32660 | 32701..=32760 | 26901..=26923 | 25828..=25838 | 28348..=28358 | 7846..=7859)
}

/// The key directory and its text for `crs` (keys sorted by ID, as the standard asks).
pub(super) fn build(crs: &Crs) -> (Vec<u16>, String) {
    let mut ascii = String::new();
    let mut keys: Vec<[u16; 4]> = vec![[GT_RASTER_TYPE, 0, 1, RASTER_PIXEL_IS_AREA]];
    match crs {
        Crs::Projected { epsg } => {
            keys.push([GT_MODEL_TYPE, 0, 1, MODEL_PROJECTED]);
            keys.push([PROJECTED_CS_TYPE, 0, 1, *epsg]);
        }
        Crs::Geographic { epsg } => {
            keys.push([GT_MODEL_TYPE, 0, 1, MODEL_GEOGRAPHIC]);
            keys.push([GEOGRAPHIC_TYPE, 0, 1, *epsg]);
        }
        Crs::LocalMetres { name } => {
            // A user-defined projected CRS in metres with no datum: GDAL reads it as a local
            // (engineering) CRS named by the citation.
            ascii = format!("{}|", super::write::ascii(&name.replace('|', "/")));
            keys.push([GT_MODEL_TYPE, 0, 1, MODEL_PROJECTED]);
            keys.push([GT_CITATION, GEO_ASCII_PARAMS, ascii.len() as u16, 0]);
            keys.push([PROJECTED_CS_TYPE, 0, 1, USER_DEFINED]);
            keys.push([PROJ_LINEAR_UNITS, 0, 1, LINEAR_METRE]);
        }
        Crs::None => {}
    }
    keys.sort_by_key(|k| k[0]);
    let mut dir = vec![1, 1, 0, keys.len() as u16];
    dir.extend(keys.iter().flatten());
    (dir, ascii)
}

/// Undo [`crate::markup::escape`] and decode character references (`&#x207B;`, `&#8315;`).
fn xml_unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(at) = rest.find('&') {
        out += &rest[..at];
        let tail = &rest[at..];
        let end = tail.find(';').filter(|&e| e <= 10);
        let decoded = end.and_then(|e| match &tail[1..e] {
            "lt" => Some('<'),
            "gt" => Some('>'),
            "quot" => Some('"'),
            "apos" => Some('\''),
            "amp" => Some('&'),
            r if r.starts_with("#x") || r.starts_with("#X") => {
                u32::from_str_radix(&r[2..], 16).ok().and_then(char::from_u32)
            }
            r if r.starts_with('#') => r[1..].parse().ok().and_then(char::from_u32),
            _ => None,
        });
        match (decoded, end) {
            (Some(c), Some(e)) => {
                out.push(c);
                rest = &tail[e + 1..];
            }
            _ => {
                out.push('&');
                rest = &tail[1..];
            }
        }
    }
    out + rest
}

/// Text for GDAL's XML: markup escaped, then anything beyond ASCII (an ASCII TIFF tag) as a
/// character reference, which GDAL's XML parser and [`parse_metadata`] decode.
fn xml_text(s: &str) -> String {
    super::write::ascii(&xml_escape(s))
}

/// GDAL's metadata XML: band descriptions (`role="description"`), units (`role="unittype"`),
/// scale and offset when not 1 and 0 (`role="scale"`, `role="offset"`) and dataset items, as
/// GDAL's GTiff driver writes them.
pub(super) fn metadata_xml(
    descriptions: &[String],
    units: &[String],
    scales: &[(f64, f64)],
    items: &[(String, String)],
) -> String {
    let mut s = String::from("<GDALMetadata>\n");
    for (k, v) in items {
        s += &format!("  <Item name=\"{}\">{}</Item>\n", xml_text(k), xml_text(v));
    }
    for (band, d) in descriptions.iter().enumerate().filter(|(_, d)| !d.is_empty()) {
        s += &format!("  <Item name=\"DESCRIPTION\" sample=\"{band}\" role=\"description\">{}</Item>\n", xml_text(d));
    }
    for (band, u) in units.iter().enumerate().filter(|(_, u)| !u.is_empty()) {
        s += &format!("  <Item name=\"UNITTYPE\" sample=\"{band}\" role=\"unittype\">{}</Item>\n", xml_text(u));
    }
    for (band, (scale, offset)) in scales.iter().enumerate().filter(|(_, so)| **so != (1.0, 0.0)) {
        s += &format!("  <Item name=\"SCALE\" sample=\"{band}\" role=\"scale\">{scale}</Item>\n");
        s += &format!("  <Item name=\"OFFSET\" sample=\"{band}\" role=\"offset\">{offset}</Item>\n");
    }
    s + "</GDALMetadata>"
}

/// One `<Item …>value</Item>`: its (name, value) attributes and its value.
type Item = (Vec<(String, String)>, String);

/// Every `<Item …>value</Item>` of GDAL's metadata: (attributes, value). Attributes are
/// `name="value"` or `name='value'` (both are XML). An item that does not close, or whose
/// attributes do not read, is an error: a unit lost to a typo would read feet as metres.
fn items(xml: &str) -> Result<Vec<Item>, String> {
    let mut out = Vec::new();
    let mut rest = xml;
    while let Some(start) = rest.find("<Item") {
        let after = &rest[start + 5..];
        let n = out.len() + 1;
        let (Some(close), Some(end)) = (after.find('>'), after.find("</Item>")) else {
            return Err(format!("GDAL_METADATA item {n} does not close (`</Item>`)"));
        };
        if close > end {
            return Err(format!("GDAL_METADATA item {n} is malformed"));
        }
        let attributes = attributes(&after[..close]).ok_or_else(|| {
            format!("GDAL_METADATA item {n}'s attributes `{}` do not read as name=\"value\"", after[..close].trim())
        })?;
        out.push((attributes, xml_unescape(&after[close + 1..end])));
        rest = &after[end + 7..];
    }
    Ok(out)
}

/// `name="value" other='value'` (a trailing `/` aside) as (name, value) pairs; `None` when the
/// text is anything else.
fn attributes(text: &str) -> Option<Vec<(String, String)>> {
    let mut out = Vec::new();
    let mut rest = text.trim().trim_end_matches('/').trim();
    while !rest.is_empty() {
        let eq = rest.find('=')?;
        let name = rest[..eq].trim();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || "_-:".contains(c)) {
            return None;
        }
        let value_part = rest[eq + 1..].trim_start();
        let quote = value_part.chars().next().filter(|q| *q == '"' || *q == '\'')?;
        let close = value_part[1..].find(quote)?;
        out.push((name.to_string(), xml_unescape(&value_part[1..=close])));
        rest = value_part[close + 2..].trim_start();
    }
    Some(out)
}

/// GDAL's metadata of a file with `bands` bands, read back.
pub(super) struct Metadata {
    pub(super) descriptions: Vec<String>,
    pub(super) units: Vec<String>,
    /// Per band: (scale, offset) of GDAL's unpacking, value = scale · stored + offset.
    pub(super) scales: Vec<(f64, f64)>,
    pub(super) items: Vec<(String, String)>,
}

/// Read GDAL's metadata XML back; a scale or offset that is not a number is an error (guessing
/// would mis-scale every value).
pub(super) fn parse_metadata(xml: &str, bands: usize) -> Result<Metadata, String> {
    let mut m = Metadata {
        descriptions: vec![String::new(); bands],
        units: vec![String::new(); bands],
        scales: vec![(1.0, 0.0); bands],
        items: Vec::new(),
    };
    for (attributes, value) in items(xml)? {
        let get = |k: &str| attributes.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str());
        let sample = match get("sample") {
            None => None,
            Some(s) => match s.trim().parse::<usize>() {
                Ok(b) if b < bands => Some(b),
                _ => {
                    return Err(format!(
                        "GDAL band item's sample `{s}` is not a band of the file (0 to {})",
                        bands.saturating_sub(1)
                    ));
                }
            },
        };
        // A per-band role without its band would drop the band's unit or scale unseen (a band
        // item without a role is GDAL's band metadata, such as statistics).
        if get("role").is_some() && sample.is_none() {
            return Err(format!(
                "GDAL metadata item `{}` has a role but no sample (the band it is of)",
                get("name").unwrap_or("")
            ));
        }
        let number = |what: &str| {
            value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("GDAL band {what} `{value}` is not a number"))
        };
        match (get("role"), sample) {
            (Some("description"), Some(b)) => m.descriptions[b] = value,
            (Some("unittype"), Some(b)) => m.units[b] = value,
            (Some("scale"), Some(b)) => m.scales[b].0 = number("scale")?,
            (Some("offset"), Some(b)) => m.scales[b].1 = number("offset")?,
            (None, None) => m.items.push((get("name").unwrap_or("").to_string(), value)),
            // Other band items (statistics, colour interpretation) carry no unit or scale.
            _ => {}
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn metadata_reads_units_in_either_quote_and_refuses_what_it_cannot_read() {
        let good = "<GDALMetadata><Item name='UNITTYPE' sample='0' role='unittype'>ft</Item>\
            <Item name=\"STATISTICS_MEAN\" sample=\"0\">3.2</Item><Item name=\"AREA\">lake</Item></GDALMetadata>";
        let m = parse_metadata(good, 1).unwrap();
        assert_eq!(m.units, vec!["ft".to_string()]);
        assert_eq!(m.items, vec![("AREA".to_string(), "lake".to_string())]);
        // Each of these would have lost the unit `ft` and read feet as metres.
        for bad in [
            "<Item name=\"UNITTYPE\" sample=\"0\" role=\"unittype\">ft",
            "<Item name=UNITTYPE sample=0 role=unittype>ft</Item>",
            "<Item name=\"UNITTYPE\" sample=\"zero\" role=\"unittype\">ft</Item>",
            "<Item name=\"UNITTYPE\" sample=\"3\" role=\"unittype\">ft</Item>",
            "<Item name=\"UNITTYPE\" role=\"unittype\">ft</Item>",
            "<Item name=\"UNITTYPE\" sample=\"0\" role=\"unittype>ft</Item>",
        ] {
            assert!(parse_metadata(bad, 1).is_err(), "{bad}");
        }
    }
}
