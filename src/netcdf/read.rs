//! Reading NetCDF-3 files: our own parser of the header, checked at every step. Each count,
//! length and offset the header claims is compared with the bytes the file really has before
//! anything is allocated or indexed, so a small file cannot make Shoal allocate more than a few
//! times its own size, and a damaged or hostile file gives a message, never a panic or an abort.
//! The header is read once, front to back: linear in its size. (Writing stays with the
//! `netcdf3` crate: [`super::write_file`].)
//!
//! The format, in short: `magic numrecs dim_list gatt_list var_list` then the data, integers
//! big-endian; magic `CDF\x01` (classic, 32-bit offsets) or `CDF\x02` (64-bit offset); a list is
//! `tag nelems [item ...]`, or ZERO ZERO when absent; names and attribute values are padded to 4
//! bytes. A dimension of length 0 is the record (unlimited) dimension, `numrecs` long, allowed
//! only first in a variable; the record variables' data is interleaved per record (record `r` of
//! a variable starts at `begin + r × recsize`, `recsize` the sum of the record variables'
//! `vsize`, or a lone record variable's unpadded size). CDF-5 (`CDF\x05`) and NetCDF-4 (HDF5)
//! files are refused by name.
//!
//! ## References
//! - Unidata, The NetCDF Classic and 64-bit Offset File Formats (NetCDF User's Guide, Appendix B
//!   "File Format Specifications": the grammar, "Note on vsize", "Note on padding", "Note on
//!   streaming data", "Notes on Computing File Offsets"),
//!   <https://docs.unidata.ucar.edu/netcdf-c/current/file_format_specifications.html>.

use std::collections::{HashMap, HashSet};
use std::path::Path;

/// Limits of the NetCDF C library: the longest name, bytes (`NC_MAX_NAME`), and the classic
/// format's most dimensions, variables, attributes per list and dimensions of a variable
/// (`NC_MAX_DIMS`, `NC_MAX_VARS`, `NC_MAX_ATTRS`, `NC_MAX_VAR_DIMS`).
const MAX_NAME: u32 = 256;
const MAX_DIMS: u32 = 1024;
const MAX_VARS: u32 = 8192;
const MAX_ATTS: u32 = 8192;
const MAX_RANK: u32 = 1024;
/// List tags of the spec.
const NC_DIMENSION: u32 = 0x0A;
const NC_VARIABLE: u32 = 0x0B;
const NC_ATTRIBUTE: u32 = 0x0C;
/// `numrecs` of a file being streamed: the record count comes from the file's length.
const STREAMING: u32 = u32::MAX;
/// 2^31 - 1.
const I32_MAX: u64 = 0x7FFF_FFFF;
/// Fewest bytes of a dimension (name length, name, length), an attribute (name length, name,
/// type, count) and a variable (name length, name, rank, ABSENT attributes, type, vsize, begin).
const MIN_DIM: usize = 8;
const MIN_ATT: usize = 12;
const MIN_VAR: usize = 28;

/// What Shoal reads; said when refusing another format.
const WANTED: &str = "Shoal reads NetCDF-3 classic or 64-bit offset files (from xarray: \
                      `to_netcdf(..., format=\"NETCDF3_64BIT\")`)";

/// A NetCDF file's float (line, pixel) variables by name, with their fill values applied
/// (`None` where missing, NaN or the fill value), and the (line, pixel) size.
#[derive(Debug, Clone)]
pub struct Maps {
    /// (lines, pixels).
    pub shape: (usize, usize),
    /// The variables of `wanted` the file has, in the order asked.
    pub maps: Vec<(String, Vec<Option<f64>>)>,
    /// Every variable the file has (for messages).
    pub names: Vec<String>,
}

/// Read the (line, pixel) float variables of `wanted` that `path` has, refusing files over
/// `max_bytes` (or not regular files: [`crate::infile`]), and what [`parse_maps`] refuses.
/// Messages name the file's problem; the caller adds which file it was.
pub fn read_maps(path: &Path, wanted: &[&str], max_bytes: u64) -> Result<Maps, String> {
    // `infile::read`: `infile::open` (a regular file, its size checked before a byte is read),
    // then at most `max_bytes` read.
    let bytes = crate::infile::read(path, max_bytes).map_err(|e| e.message)?;
    parse_maps(&bytes, wanted)
}

/// The (line, pixel) variables of `wanted` that the NetCDF-3 file `bytes` has: float or double,
/// as f64, `None` where not finite or equal to the variable's `_FillValue` (else its
/// `missing_value`), either given as float or double. Refuses a file that is not NetCDF-3
/// classic or 64-bit offset or whose header does not hold together (see the module's notes),
/// one without `line` and `pixel` dimensions, and a wanted variable of other dimensions or type.
pub fn parse_maps(bytes: &[u8], wanted: &[&str]) -> Result<Maps, String> {
    let h = parse_header(bytes)?;
    let names = h.vars.iter().map(|v| v.name.to_string()).collect();
    let find = |n: &str| h.dims.iter().position(|d| d.name == n);
    let (Some(line), Some(pixel)) = (find("line"), find("pixel")) else {
        return Err("needs dimensions `line` and `pixel`".into());
    };
    let shape = (h.dim_size(line)?, h.dim_size(pixel)?);
    let mut present = Vec::new();
    for &name in wanted {
        let Some(v) = h.by_name.get(name).and_then(|&i| h.vars.get(i)) else { continue };
        if v.dims != [line, pixel] {
            let dims: Vec<String> =
                v.dims.iter().filter_map(|&d| h.dims.get(d)).map(|d| d.name.escape_debug().to_string()).collect();
            return Err(format!("`{name}` has dimensions ({}); expected (line, pixel)", dims.join(", ")));
        }
        present.push((name, v));
    }
    let mut maps = Vec::with_capacity(present.len());
    for (name, v) in present {
        maps.push((name.to_string(), values(bytes, &h, v, shape)?));
    }
    Ok(Maps { shape, maps, names })
}

/// A variable's values as f64 with its fill value applied; `shape` is (lines, pixels).
fn values(bytes: &[u8], h: &Header<'_>, v: &Var<'_>, shape: (usize, usize)) -> Result<Vec<Option<f64>>, String> {
    let ((lines, pixels), name) = (shape, v.name);
    if !matches!(v.ty, NcType::Float | NcType::Double) {
        return Err(format!("`{name}` is not a float variable (it is {})", v.ty.about().0));
    }
    let fill = v.fills.fill.or(v.fills.missing);
    let keep = |x: f64| if x.is_finite() && Some(x) != fill { Some(x) } else { None };
    let past = || format!("variable `{}`'s data runs past the end of the file", name.escape_debug());
    let row = u64::try_from(pixels).ok().and_then(|p| p.checked_mul(v.ty.about().1)).ok_or_else(past)?;
    // Consecutive lines: one record apart for a record variable, else one row.
    let stride = if v.record { h.recsize } else { row };
    let count = lines.checked_mul(pixels).ok_or_else(past)?;
    // The header's checks bound `count` by the file's length; the `min` keeps it so regardless.
    let mut out = Vec::with_capacity(count.min(bytes.len()));
    if row == 0 {
        return Ok(out);
    }
    for r in 0..lines {
        let start = u64::try_from(r).ok().and_then(|r| r.checked_mul(stride)).and_then(|o| o.checked_add(v.begin));
        let range = start.and_then(|s| Some(usize::try_from(s).ok()?..usize::try_from(s.checked_add(row)?).ok()?));
        let chunk = range.and_then(|r| bytes.get(r)).ok_or_else(past)?;
        if v.ty == NcType::Float {
            out.extend(chunk.as_chunks::<4>().0.iter().map(|b| keep(f64::from(f32::from_be_bytes(*b)))));
        } else {
            out.extend(chunk.as_chunks::<8>().0.iter().map(|b| keep(f64::from_be_bytes(*b))));
        }
    }
    Ok(out)
}

/// The external types of NetCDF-3 (`nc_type` 1 to 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum NcType {
    Byte,
    Char,
    Short,
    Int,
    Float,
    Double,
}

impl NcType {
    fn from_tag(tag: u32) -> Option<Self> {
        Some(match tag {
            1 => Self::Byte,
            2 => Self::Char,
            3 => Self::Short,
            4 => Self::Int,
            5 => Self::Float,
            6 => Self::Double,
            _ => return None,
        })
    }

    /// Its name, and the bytes of one value in the file (the spec's `extsize`).
    const fn about(self) -> (&'static str, u64) {
        match self {
            Self::Byte => ("NC_BYTE", 1),
            Self::Char => ("NC_CHAR", 1),
            Self::Short => ("NC_SHORT", 2),
            Self::Int => ("NC_INT", 4),
            Self::Float => ("NC_FLOAT", 4),
            Self::Double => ("NC_DOUBLE", 8),
        }
    }
}

/// The first value of a variable's `_FillValue` and `missing_value` attributes, where float or
/// double.
#[derive(Debug, Default, Clone, Copy)]
struct Fills {
    fill: Option<f64>,
    missing: Option<f64>,
}

/// A dimension: its name and length (0: the record dimension).
struct Dim<'a> {
    name: &'a str,
    len: u32,
}

/// A variable as the header describes it, its sizes computed from its dimensions and type.
struct Var<'a> {
    name: &'a str,
    /// Indices into the dimensions, slowest first.
    dims: Vec<usize>,
    ty: NcType,
    fills: Fills,
    /// Offset of its data (of its first record for a record variable).
    begin: u64,
    /// Whether its first dimension is the record dimension.
    record: bool,
    /// Bytes of its data (of one record for a record variable), unpadded.
    slab: u64,
}

/// What the header says, checked against the file.
struct Header<'a> {
    dims: Vec<Dim<'a>>,
    vars: Vec<Var<'a>>,
    by_name: HashMap<&'a str, usize>,
    numrecs: u64,
    recsize: u64,
}

impl Header<'_> {
    /// The length of dimension `d`: `numrecs` for the record dimension.
    fn dim_size(&self, d: usize) -> Result<usize, String> {
        let n = match self.dims.get(d).map_or(0, |d| d.len) {
            0 => self.numrecs,
            n => u64::from(n),
        };
        usize::try_from(n).map_err(|_| format!("a dimension of {n} is more than this computer can hold"))
    }
}

/// Whether the file is 64-bit offset (`CDF\x02`) rather than classic (`CDF\x01`); other formats
/// are refused by name.
fn is_64bit_offset(bytes: &[u8]) -> Result<bool, String> {
    match bytes.first_chunk::<4>() {
        Some(b"CDF\x01") => Ok(false),
        Some(b"CDF\x02") => Ok(true),
        Some(b"CDF\x05") => Err(format!("is a CDF-5 file (NetCDF-3 64-bit data, NETCDF3_64BIT_DATA); {WANTED}")),
        Some(b"\x89HDF") => Err(format!("is a NetCDF-4 (HDF5) file; {WANTED}")),
        Some([b'C', b'D', b'F', v]) => Err(format!("is a NetCDF file of unknown version {v}; {WANTED}")),
        _ => Err(format!("is not a NetCDF file (it does not start with `CDF`); {WANTED}")),
    }
}

/// The header of `bytes`, every count checked against the bytes left, every variable's data
/// against the file.
fn parse_header(bytes: &[u8]) -> Result<Header<'_>, String> {
    let wide = is_64bit_offset(bytes)?;
    let mut c = Cursor { bytes, pos: 4 };
    let numrecs = c.u32("the number of records")?;
    let dims = dims(&mut c)?;
    c.atts("global attributes")?;
    let (vars, by_name) = vars(&mut c, &dims, wide)?;
    let header_end = u64::try_from(c.pos).map_err(|e| e.to_string())?;
    let len = u64::try_from(bytes.len()).map_err(|e| e.to_string())?;
    // Note on padding: a lone record variable is not padded between records.
    let mut records = vars.iter().filter(|v| v.record);
    let recsize = match (records.next(), records.next()) {
        (None, _) => Some(0),
        (Some(v), None) => Some(v.slab),
        _ => vars.iter().filter(|v| v.record).try_fold(0u64, |s, v| s.checked_add(v.slab.checked_next_multiple_of(4)?)),
    }
    .ok_or("the record size overflows")?;
    let numrecs = if numrecs == STREAMING {
        // Note on streaming data: the whole records the file's length holds.
        let fit = |v: &Var<'_>| match len.checked_sub(v.begin).and_then(|x| x.checked_sub(v.slab)) {
            Some(room) if recsize > 0 => (room / recsize).saturating_add(1),
            _ => 0,
        };
        vars.iter().filter(|v| v.record).map(fit).min().unwrap_or(0)
    } else {
        u64::from(numrecs)
    };
    for v in &vars {
        let name = v.name.escape_debug();
        if v.begin < header_end {
            return Err(format!(
                "variable `{name}` starts inside the header (offset {}; the header ends at byte {header_end})",
                v.begin
            ));
        }
        let extent = match (v.record, numrecs) {
            (false, _) => Some(v.slab),
            (true, 0) => continue,
            (true, n) => n.saturating_sub(1).checked_mul(recsize).and_then(|x| x.checked_add(v.slab)),
        };
        if extent.and_then(|e| v.begin.checked_add(e)).is_none_or(|end| end > len) {
            let size = extent.map_or_else(|| "over 2^64".to_string(), |e| e.to_string());
            return Err(format!(
                "variable `{name}`'s data (offset {}, {size} bytes) runs past the end of the file ({len} bytes)",
                v.begin
            ));
        }
    }
    Ok(Header { dims, vars, by_name, numrecs, recsize })
}

/// The dimension list: names unique, at most one record dimension.
fn dims<'a>(c: &mut Cursor<'a>) -> Result<Vec<Dim<'a>>, String> {
    let n = c.list(NC_DIMENSION, "dimensions", MIN_DIM, MAX_DIMS)?;
    let mut dims = Vec::with_capacity(n);
    let mut seen = HashSet::with_capacity(n);
    let mut record: Option<&str> = None;
    for _ in 0..n {
        let name = c.name("dimension")?;
        let len = c.u32("a dimension's length")?;
        if !seen.insert(name) {
            return Err(format!("the header names two dimensions `{}`", name.escape_debug()));
        }
        if len == 0
            && let Some(first) = record.replace(name)
        {
            return Err(format!(
                "the header has two record (unlimited) dimensions, `{}` and `{}`; NetCDF-3 allows one",
                first.escape_debug(),
                name.escape_debug()
            ));
        }
        dims.push(Dim { name, len });
    }
    Ok(dims)
}

/// The variable list (names unique) and each variable's index by name.
type Vars<'a> = (Vec<Var<'a>>, HashMap<&'a str, usize>);

/// The variable list: names unique, each variable checked by [`var`].
fn vars<'a>(c: &mut Cursor<'a>, dims: &[Dim<'a>], wide: bool) -> Result<Vars<'a>, String> {
    let n = c.list(NC_VARIABLE, "variables", MIN_VAR, MAX_VARS)?;
    let mut vars = Vec::with_capacity(n);
    let mut by_name = HashMap::with_capacity(n);
    for i in 0..n {
        let name = c.name("variable")?;
        if by_name.insert(name, i).is_some() {
            return Err(format!("the header names two variables `{}`", name.escape_debug()));
        }
        vars.push(var(c, name, dims, wide)?);
    }
    Ok((vars, by_name))
}

/// One variable after its name: dimension ids (the record dimension only first), attributes,
/// type, a `vsize` consistent with the dimensions and type (Note on vsize), `begin`.
fn var<'a>(c: &mut Cursor<'a>, name: &'a str, dims: &[Dim<'_>], wide: bool) -> Result<Var<'a>, String> {
    let shown = name.escape_debug();
    let rank = c.count(&format!("dimensions of variable `{shown}`"), 4, MAX_RANK)?;
    let mut ids = Vec::with_capacity(rank);
    for k in 0..rank {
        let id = c.u32("a dimension id")?;
        let Some((i, d)) = usize::try_from(id).ok().and_then(|i| Some((i, dims.get(i)?))) else {
            return Err(format!("variable `{shown}` uses dimension {id}, but the file has {} dimensions", dims.len()));
        };
        if d.len == 0 && k > 0 {
            return Err(format!(
                "variable `{shown}` has the record (unlimited) dimension `{}` in place {}; NetCDF-3 allows it only first",
                d.name.escape_debug(),
                k + 1
            ));
        }
        ids.push(i);
    }
    let fills = c.atts(&format!("attributes of variable `{shown}`"))?;
    let tag = c.u32("a variable's type")?;
    let ty = NcType::from_tag(tag)
        .ok_or_else(|| format!("variable `{shown}` has type {tag}; NetCDF-3 types are 1 (NC_BYTE) to 6 (NC_DOUBLE)"))?;
    let vsize = c.u32("a variable's size")?;
    let begin = if wide {
        let b = c.array::<8>("a variable's offset")?;
        u64::try_from(i64::from_be_bytes(b)).map_err(|_| format!("variable `{shown}` has a negative offset"))?
    } else {
        u64::from(c.u32("a variable's offset")?)
    };
    let record = ids.first().and_then(|&i| dims.get(i)).is_some_and(|d| d.len == 0);
    let slab = ids
        .iter()
        .skip(usize::from(record))
        .try_fold(ty.about().1, |p, &i| p.checked_mul(u64::from(dims.get(i).map_or(0, |d| d.len))));
    let padded = slab.and_then(|s| s.checked_next_multiple_of(4));
    let (Some(slab), Some(padded)) = (slab, padded) else {
        return Err(format!("variable `{shown}`'s size overflows"));
    };
    // vsize is 2^32 - 1 for a variable too big for it (the `netcdf3` crate writes that from 2^31).
    let too_big = vsize == u32::MAX && padded > I32_MAX;
    if u64::from(vsize) != padded && !too_big {
        return Err(format!(
            "variable `{shown}` has size {vsize} in the header, but its dimensions and type make {padded} bytes"
        ));
    }
    Ok(Var { name, dims: ids, ty, fills, begin, record, slab })
}

/// Reading the header front to back; every read checked against the bytes left.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn short(&self, n: usize, what: &str) -> String {
        let (at, len) = (self.pos, self.bytes.len());
        format!("the header is cut short: {what} at byte {at} needs {n} bytes, the file has {len}")
    }

    /// The next `n` bytes.
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        match end.and_then(|e| Some((e, self.bytes.get(self.pos..e)?))) {
            Some((end, piece)) => {
                self.pos = end;
                Ok(piece)
            }
            None => Err(self.short(n, what)),
        }
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let piece = self.take(N, what)?;
        piece.first_chunk::<N>().copied().ok_or_else(|| self.short(N, what))
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        self.array::<4>(what).map(u32::from_be_bytes)
    }

    /// A count of items of at least `each` bytes: refused if they cannot fit in the bytes left
    /// or are more than `max`.
    fn count(&mut self, what: &str, each: usize, max: u32) -> Result<usize, String> {
        let n = self.u32(what)?;
        let need = usize::try_from(n).ok().and_then(|n| n.checked_mul(each));
        if need.is_none_or(|need| need > self.remaining()) {
            return Err(format!("the header claims {n} {what} but the file has {} bytes", self.bytes.len()));
        }
        if n > max {
            return Err(format!("the header claims {n} {what}; at most {max} are read"));
        }
        usize::try_from(n).map_err(|e| e.to_string())
    }

    /// A list's length: `tag nelems`, or ZERO ZERO (absent).
    fn list(&mut self, tag: u32, what: &str, each: usize, max: u32) -> Result<usize, String> {
        let at = self.pos;
        match self.u32(what)? {
            0 => match self.u32(what)? {
                0 => Ok(0),
                n => Err(format!("the header's list of {what} at byte {at} has no tag but claims {n} entries")),
            },
            t if t == tag => self.count(what, each, max),
            t => Err(format!("the header has tag {t:#x} at byte {at} where the list of {what} (tag {tag:#x}) belongs")),
        }
    }

    /// A name: at most [`MAX_NAME`] bytes of UTF-8, padded to 4 bytes.
    fn name(&mut self, what: &str) -> Result<&'a str, String> {
        let at = self.pos;
        let n = self.u32(what)?;
        if n > MAX_NAME {
            return Err(format!("the header has a {what} name of {n} bytes at byte {at} (at most {MAX_NAME})"));
        }
        let n = usize::try_from(n).map_err(|e| e.to_string())?;
        let padded = self.take(n.checked_next_multiple_of(4).unwrap_or(n), what)?;
        let raw = padded.get(..n).ok_or_else(|| self.short(n, what))?;
        std::str::from_utf8(raw).map_err(|_| format!("the header has a {what} name at byte {at} that is not UTF-8"))
    }

    /// An attribute list (names unique), keeping the first float or double value of
    /// `_FillValue` and `missing_value`.
    fn atts(&mut self, what: &str) -> Result<Fills, String> {
        let n = self.list(NC_ATTRIBUTE, what, MIN_ATT, MAX_ATTS)?;
        let mut seen = HashSet::with_capacity(n);
        let mut fills = Fills::default();
        for _ in 0..n {
            let name = self.name("attribute")?;
            if !seen.insert(name) {
                return Err(format!("attribute `{}` appears twice in the {what}", name.escape_debug()));
            }
            let tag = self.u32("an attribute's type")?;
            let ty = NcType::from_tag(tag).ok_or_else(|| {
                format!("attribute `{}` ({what}) has type {tag}; NetCDF-3 types are 1 to 6", name.escape_debug())
            })?;
            let count = self.u32("an attribute's length")?;
            let size = u64::from(count).checked_mul(ty.about().1).and_then(|s| s.checked_next_multiple_of(4));
            let Some(size) = size.and_then(|s| usize::try_from(s).ok()).filter(|&s| s <= self.remaining()) else {
                return Err(format!(
                    "attribute `{}` ({what}) claims {count} values but the file has {} bytes",
                    name.escape_debug(),
                    self.bytes.len()
                ));
            };
            let values = self.take(size, "an attribute's values")?;
            let first = match ty {
                NcType::Float => values.first_chunk::<4>().map(|b| f64::from(f32::from_be_bytes(*b))),
                NcType::Double => values.first_chunk::<8>().map(|b| f64::from_be_bytes(*b)),
                _ => None,
            };
            match name {
                "_FillValue" => fills.fill = first,
                "missing_value" => fills.missing = first,
                _ => {}
            }
        }
        Ok(fills)
    }
}

#[cfg(test)]
mod tests;
