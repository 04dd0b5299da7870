//! NetCDF-3 files with CF metadata, written by the pure-Rust `netcdf3` crate (no C library) and
//! read by our own checked parser ([`read_maps`], [`parse_maps`]): the pieces every NetCDF file
//! of Shoal shares — the products a run writes (`study::netcdf_out`), the input an external
//! retrieval reads and the output it writes back (`retrieval::external`), and the products
//! `shoal score` reads.
//!
//! Files are NetCDF-3 in the 64-bit-offset form (any NetCDF reader opens them; a variable may
//! exceed 2 GiB). Values without a meaning are [`FILL`], declared as `_FillValue`.
//!
//! ## References
//! - Eaton, B. et al. (2020) NetCDF Climate and Forecast (CF) Metadata Conventions, version 1.8.
//! - CF Standard Name Table (chlorophyll, suspended matter, remote-sensing reflectance, depth).
//! - Unidata, The NetCDF Classic and 64-bit Offset File Formats (NetCDF-3).

use std::cell::RefCell;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::Path;
use std::rc::Rc;

use netcdf3::{DataSet, FileWriter, Version};

mod read;
pub use read::{Maps, parse_maps, read_maps};

/// CF standard names of Shoal's product variables and of Rrs (those CF has).
#[must_use]
pub fn standard_name(variable: &str) -> Option<&'static str> {
    match variable {
        "rrs" => {
            Some("surface_ratio_of_upwelling_radiance_emerging_from_sea_water_to_downwelling_radiative_flux_in_air")
        }
        v => crate::variable::of(v).and_then(|v| v.standard_name),
    }
}

/// What a product variable is, and its unit (UDUNITS).
#[must_use]
pub fn meaning(variable: &str) -> (&'static str, &'static str) {
    crate::variable::of(variable).map_or(("", "1"), |v| (v.long_name, v.udunits))
}

/// A variable's values, made when the variable is written: a file's cubes are made one at a time,
/// so writing holds one cube beside the run rather than all of them.
pub struct Values<'a, T>(Box<dyn Fn() -> Vec<T> + 'a>);

impl<'a, T: Clone + 'a> Values<'a, T> {
    /// Values made already (small variables; copied when written).
    #[must_use]
    pub fn ready(values: Vec<T>) -> Self {
        Self(Box::new(move || values.clone()))
    }

    /// Values made by `make` when the variable is written.
    pub fn lazy(make: impl Fn() -> Vec<T> + 'a) -> Self {
        Self(Box::new(make))
    }

    fn make(&self) -> Vec<T> {
        (self.0)()
    }
}

/// A float variable of the data set with its data.
pub struct FloatVar<'a> {
    /// Variable name.
    pub name: String,
    /// Its dimensions, slowest first.
    pub dims: Vec<&'static str>,
    /// Its attributes (`_FillValue` is added by [`define_vars`]).
    pub attrs: Vec<(&'static str, String)>,
    /// Its values, in the dimensions' order.
    pub values: Values<'a, f32>,
}

/// An integer flag variable: name, dimensions, what it is, masks and meanings, values. 32-bit:
/// CF wants the masks in the variable's type, Shoal's product flags use all eight bits of a byte
/// (128 is no NC_BYTE), and the `netcdf3` crate pads a 1- or 2-byte attribute list with fill
/// values where the format wants zero bytes (its own reader then refuses the header; ncdump
/// accepts it): 4-byte attributes need no padding.
pub struct FlagVar<'a> {
    /// Variable name.
    pub name: String,
    /// Its dimensions, slowest first.
    pub dims: Vec<&'static str>,
    /// What it is.
    pub long_name: String,
    /// (mask, meaning) of each flag.
    pub flags: Vec<(i32, &'static str)>,
    /// Its values, in the dimensions' order.
    pub values: Values<'a, i32>,
    /// Auxiliary coordinates (the `coordinates` attribute).
    pub coordinates: &'static str,
}

/// Written where a value has no meaning (land, not returned, invalid Rrs), declared as
/// `_FillValue` (readers such as xarray turn it into NaN): the GeoTIFF products' no-data value.
/// Not NaN itself: the `netcdf3` crate finds a variable by comparing its attributes, and a NaN
/// attribute never equals itself.
pub const FILL: f32 = -9999.0;

/// `keep`-masked values of a map, [`FILL`] elsewhere (and where not finite).
pub fn masked(values: impl Iterator<Item = f32>, keep: impl Fn(usize) -> bool) -> Vec<f32> {
    values.enumerate().map(|(i, v)| if keep(i) && v.is_finite() { v } else { FILL }).collect()
}

/// A shared, seekable, buffered file: the writer owns one handle, Shoal keeps the other to flush
/// and sync it once the writer has closed.
#[derive(Clone)]
struct Shared(Rc<RefCell<BufWriter<std::fs::File>>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.borrow_mut().flush()
    }
}

impl Seek for Shared {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.borrow_mut().seek(pos)
    }
}

/// Dimensions of a (line, pixel, band) cube.
pub const CUBE: [&str; 3] = ["line", "pixel", "band"];
/// Dimensions of a (line, pixel) map.
pub const MAP: [&str; 2] = ["line", "pixel"];

/// `long_name`, `units` and, where CF has one, `standard_name`.
pub fn attrs(long: &str, units: &str, standard: Option<&str>) -> Vec<(&'static str, String)> {
    let mut a = vec![("long_name", long.to_string()), ("units", units.to_string())];
    if let Some(s) = standard {
        a.push(("standard_name", s.to_string()));
    }
    a
}

/// A text variable (NC_CHAR) and its bytes, as [`band_names`] defines it.
pub type TextVar = (&'static str, Vec<u8>);

/// Define `band_name(band, name_strlen)`, the bands' names as a CF string coordinate (a char
/// array, NUL-padded), and return it to write: xarray reads it as an array of strings. The
/// length is rounded up to 4 bytes, so the variable needs no padding in the file.
pub fn band_names(ds: &mut DataSet, names: &[&str]) -> Result<TextVar, String> {
    let bad = |e: netcdf3::error::InvalidDataSet| format!("NetCDF definition: {e:?}");
    let len = names.iter().map(|n| n.len()).max().unwrap_or(1).max(1).div_ceil(4) * 4;
    ds.add_fixed_dim("name_strlen", len).map_err(bad)?;
    ds.add_var_u8("band_name", &["band", "name_strlen"]).map_err(bad)?;
    ds.add_var_attr_string("band_name", "long_name", "band name").map_err(bad)?;
    let mut bytes = vec![0u8; names.len() * len];
    for (i, n) in names.iter().enumerate() {
        bytes[i * len..i * len + n.len()].copy_from_slice(n.as_bytes());
    }
    Ok(("band_name", bytes))
}

/// Write the data set and its values to `path` through a temporary file, then renamed; `sync`:
/// on disk before the rename (a product; an external program's input, read at once and deleted,
/// skips it: 0.3 s for a full-resolution input).
pub fn write_file(
    path: &Path,
    ds: &DataSet,
    (floats, flags, texts): (&[FloatVar<'_>], &[FlagVar<'_>], &[TextVar]),
    sync: bool,
) -> Result<(), String> {
    let tmp = path.with_extension("nc.partial");
    let fail = |m: String| format!("cannot write {}: {m}", path.display());
    let result = (|| -> Result<(), String> {
        let file = std::fs::File::create(&tmp).map_err(|e| fail(e.to_string()))?;
        let shared = Shared(Rc::new(RefCell::new(BufWriter::with_capacity(1 << 20, file))));
        let mut writer = FileWriter::open_seek_write(&tmp.to_string_lossy(), Box::new(shared.clone()))
            .map_err(|e| fail(format!("{e:?}")))?;
        writer.set_def(ds, Version::Offset64Bit, 0).map_err(|e| fail(format!("{e:?}")))?;
        for v in floats {
            writer.write_var_f32(&v.name, &v.values.make()).map_err(|e| fail(format!("{}: {e:?}", v.name)))?;
        }
        for f in flags {
            writer.write_var_i32(&f.name, &f.values.make()).map_err(|e| fail(format!("{}: {e:?}", f.name)))?;
        }
        for (name, bytes) in texts {
            writer.write_var_u8(name, bytes).map_err(|e| fail(format!("{name}: {e:?}")))?;
        }
        writer.close().map_err(|e| fail(format!("{e:?}")))?;
        let mut buffered = shared.0.borrow_mut();
        buffered.flush().map_err(|e| fail(e.to_string()))?;
        if sync {
            buffered.get_ref().sync_all().map_err(|e| fail(e.to_string()))?;
        }
        Ok(())
    })();
    match result.and_then(|()| std::fs::rename(&tmp, path).map_err(|e| fail(e.to_string()))) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// One variable's values, as [`write_file`] writes them.
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// A float variable ([`FloatVar`]), [`FILL`] where a value has no meaning.
    Float(Vec<f32>),
    /// A flag variable ([`FlagVar`]).
    Int(Vec<i32>),
    /// A text variable ([`TextVar`]): NUL-padded characters.
    Text(Vec<u8>),
}

/// An attribute's value, in the type the file stores it in.
#[derive(Debug, Clone, PartialEq)]
pub enum AttrValue {
    /// Text (NC_CHAR).
    Text(String),
    /// 32-bit floats (`_FillValue`).
    Float(Vec<f32>),
    /// 32-bit integers (`flag_masks`, `flag_values`).
    Int(Vec<i32>),
}

/// A variable held in memory: its dimensions (slowest first), attributes and values.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryVar {
    /// Variable name.
    pub name: String,
    /// Its dimensions' names, slowest first.
    pub dims: Vec<String>,
    /// Its attributes, in the file's order.
    pub attrs: Vec<(String, AttrValue)>,
    /// Its values, in the dimensions' order.
    pub values: Column,
}

/// A data set and its values made: exactly what [`write_file`] would write, held in memory. The
/// Python package builds its xarray datasets from it, so a dataset and the file hold the same
/// dimensions, variables, attributes and values by construction.
#[derive(Debug, Clone, PartialEq)]
pub struct InMemory {
    /// Dimensions and their sizes, in the file's order.
    pub dims: Vec<(String, usize)>,
    /// Global attributes.
    pub attrs: Vec<(String, AttrValue)>,
    /// Variables, in the file's order.
    pub variables: Vec<MemoryVar>,
}

/// The attributes' values in the types the file stores.
fn attr_values(attrs: &[&netcdf3::Attribute]) -> Vec<(String, AttrValue)> {
    attrs
        .iter()
        .filter_map(|a| {
            let value = match a.data_type() {
                netcdf3::DataType::U8 => AttrValue::Text(a.get_as_string()?),
                netcdf3::DataType::F32 => AttrValue::Float(a.get_f32()?.to_vec()),
                netcdf3::DataType::I32 => AttrValue::Int(a.get_i32()?.to_vec()),
                // Shoal writes no other attribute type.
                _ => return None,
            };
            Some((a.name().to_string(), value))
        })
        .collect()
}

/// The data set of `ds` with the values of `floats`, `flags` and `texts` made.
#[must_use]
pub fn in_memory(ds: &DataSet, (floats, flags, texts): (&[FloatVar<'_>], &[FlagVar<'_>], &[TextVar])) -> InMemory {
    let mut columns: Vec<(String, Column)> = floats
        .iter()
        .map(|v| (v.name.clone(), Column::Float(v.values.make())))
        .chain(flags.iter().map(|f| (f.name.clone(), Column::Int(f.values.make()))))
        .chain(texts.iter().map(|(name, bytes)| ((*name).to_string(), Column::Text(bytes.clone()))))
        .collect();
    let variables = ds
        .get_vars()
        .into_iter()
        .filter_map(|v| {
            let at = columns.iter().position(|(n, _)| n == v.name())?;
            let values = columns.swap_remove(at).1;
            Some(MemoryVar {
                name: v.name().to_string(),
                dims: v.dim_names(),
                attrs: attr_values(&v.get_attrs()),
                values,
            })
        })
        .collect();
    InMemory {
        dims: ds.get_dims().iter().map(|d| (d.name(), d.size())).collect(),
        attrs: attr_values(&ds.get_global_attrs()),
        variables,
    }
}

/// Add `floats` and `flags` to `ds` with their attributes: `_FillValue` on every float variable
/// of more than one dimension, `flag_values`/`flag_masks` and `flag_meanings` on the flags.
pub fn define_vars(ds: &mut DataSet, floats: &[FloatVar<'_>], flags: &[FlagVar<'_>]) -> Result<(), String> {
    let bad = |e: netcdf3::error::InvalidDataSet| format!("NetCDF definition: {e:?}");
    for v in floats {
        ds.add_var_f32(&v.name, &v.dims).map_err(bad)?;
        for (k, value) in &v.attrs {
            ds.add_var_attr_string(&v.name, k, value).map_err(bad)?;
        }
        if v.dims.len() > 1 {
            ds.add_var_attr_f32(&v.name, "_FillValue", vec![FILL]).map_err(bad)?;
        }
    }
    for f in flags {
        ds.add_var_i32(&f.name, &f.dims).map_err(bad)?;
        ds.add_var_attr_string(&f.name, "long_name", &f.long_name).map_err(bad)?;
        if f.flags.len() == 1 {
            ds.add_var_attr_i32(&f.name, "flag_values", vec![0, f.flags[0].0]).map_err(bad)?;
            ds.add_var_attr_string(&f.name, "flag_meanings", format!("not_{} {}", f.flags[0].1, f.flags[0].1))
                .map_err(bad)?;
        } else {
            ds.add_var_attr_i32(&f.name, "flag_masks", f.flags.iter().map(|x| x.0).collect()).map_err(bad)?;
            let meanings: Vec<&str> = f.flags.iter().map(|x| x.1).collect();
            ds.add_var_attr_string(&f.name, "flag_meanings", meanings.join(" ")).map_err(bad)?;
        }
        if !f.coordinates.is_empty() {
            ds.add_var_attr_string(&f.name, "coordinates", f.coordinates).map_err(bad)?;
        }
    }
    Ok(())
}
