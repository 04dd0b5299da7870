//! The reader against the writer (and against the `netcdf3` crate's reader, the one it
//! replaced), against files built by hand after the spec, and against hostile files.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;
use std::time::Instant;

use netcdf3::DataSet;

use super::*;
use crate::netcdf::{CUBE, FILL, FlagVar, FloatVar, MAP, Values, band_names, define_vars, write_file};

/// The reader this one replaced (the `netcdf3` crate's), kept as an oracle.
fn oracle(path: &Path, wanted: &[&str]) -> Result<Maps, String> {
    let mut reader = netcdf3::FileReader::open(path).map_err(|e| format!("{e:?}"))?;
    let ds = reader.data_set();
    let names: Vec<String> = ds.get_var_names();
    let (lines, pixels) = match (ds.dim_size("line"), ds.dim_size("pixel")) {
        (Some(l), Some(p)) => (l, p),
        _ => return Err("needs dimensions `line` and `pixel`".into()),
    };
    let mut present = Vec::new();
    for &name in wanted {
        let Some(var) = ds.get_var(name) else { continue };
        let dims: Vec<String> = var.dim_names();
        if dims != ["line", "pixel"] {
            return Err(format!("`{name}` has dimensions ({}); expected (line, pixel)", dims.join(", ")));
        }
        let attr = |a: &str| {
            ds.get_var_attr_f32(name, a)
                .and_then(|v| v.first().map(|x| f64::from(*x)))
                .or_else(|| ds.get_var_attr_f64(name, a).and_then(|v| v.first().copied()))
        };
        present.push((name, attr("_FillValue").or_else(|| attr("missing_value"))));
    }
    let mut maps = Vec::new();
    for (name, fill) in present {
        let values = match reader.read_var_f32(name) {
            Ok(v) => v.into_iter().map(f64::from).collect::<Vec<f64>>(),
            Err(_) => reader.read_var_f64(name).map_err(|e| format!("`{name}` is not a float variable ({e:?})"))?,
        };
        let values =
            values.into_iter().map(|v| if v.is_finite() && Some(v) != fill { Some(v) } else { None }).collect();
        maps.push((name.to_string(), values));
    }
    Ok(Maps { shape: (lines, pixels), maps, names })
}

fn tempdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shoal-netcdf-read-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Bytes built by hand after the spec: big-endian words, names and values padded to 4 bytes.
#[derive(Default)]
struct B(Vec<u8>);

impl B {
    fn raw(mut self, b: &[u8]) -> Self {
        self.0.extend_from_slice(b);
        self.0.resize(self.0.len().next_multiple_of(4), 0);
        self
    }
    fn u32(self, v: u32) -> Self {
        self.raw(&v.to_be_bytes())
    }
    fn u64(self, v: u64) -> Self {
        self.raw(&v.to_be_bytes())
    }
    fn f32(self, v: f32) -> Self {
        self.raw(&v.to_be_bytes())
    }
    fn f64(self, v: f64) -> Self {
        self.raw(&v.to_be_bytes())
    }
    fn name(self, s: &str) -> Self {
        self.u32(len32(s.as_bytes())).raw(s.as_bytes())
    }
}

fn len32(b: &[u8]) -> u32 {
    n32(b.len())
}

fn n32(n: usize) -> u32 {
    u32::try_from(n).unwrap()
}

/// A header built by `header(begin)` with its data after it (`begin`: the header's length
/// unless given).
fn file(header: impl Fn(u32) -> Vec<u8>, begin: Option<u32>, data: &[u8]) -> Vec<u8> {
    let mut bytes = header(begin.unwrap_or_else(|| len32(&header(0))));
    bytes.extend_from_slice(data);
    bytes
}

/// Classic (CDF-1): `line` 2, `pixel` 3, one double (line, pixel) variable `x` with
/// `missing_value` -1.
fn classic(begin: Option<u32>) -> Vec<u8> {
    let header = |begin| {
        let b = B::default().raw(b"CDF\x01").u32(0).u32(NC_DIMENSION).u32(2).name("line").u32(2).name("pixel");
        let b = b.u32(3).u32(0).u32(0).u32(NC_VARIABLE).u32(1).name("x").u32(2).u32(0).u32(1);
        b.u32(NC_ATTRIBUTE).u32(1).name("missing_value").u32(6).u32(1).f64(-1.0).u32(6).u32(48).u32(begin).0
    };
    let data: Vec<u8> = [1.5, -1.0, f64::NAN, 2.0, f64::INFINITY, 1e300].iter().flat_map(|v| v.to_be_bytes()).collect();
    file(header, begin, &data)
}

/// 64-bit offset (CDF-2), `line` the record dimension (2 records), `pixel` 3, a global text
/// attribute, and two record variables: float `a` with `_FillValue` -9999, double `b`.
fn records(numrecs: u32) -> Vec<u8> {
    let header = |begin: u32| {
        let b = B::default().raw(b"CDF\x02").u32(numrecs).u32(NC_DIMENSION).u32(2).name("line").u32(0);
        let b = b.name("pixel").u32(3).u32(NC_ATTRIBUTE).u32(1).name("title").u32(2).u32(5).raw(b"hello");
        let b = b.u32(NC_VARIABLE).u32(2).name("a").u32(2).u32(0).u32(1).u32(NC_ATTRIBUTE).u32(1).name("_FillValue");
        let b = b.u32(5).u32(1).f32(-9999.0).u32(5).u32(12).u64(u64::from(begin));
        b.name("b").u32(2).u32(0).u32(1).u32(0).u32(0).u32(6).u32(24).u64(u64::from(begin) + 12).0
    };
    let mut data = Vec::new();
    for (a, b) in [([1.0, -9999.0, 3.0], [10.0, 20.0, f64::NAN]), ([4.0, 5.0, f32::NAN], [40.0, -9999.0, 60.0])] {
        data.extend(a.iter().flat_map(|v: &f32| v.to_be_bytes()));
        data.extend(b.iter().flat_map(|v: &f64| v.to_be_bytes()));
    }
    file(header, None, &data)
}

/// Classic, `line` the record dimension (3 records), one short record variable `s` of 3 values
/// per record: the lone record variable is not padded between records.
fn lone_short(numrecs: u32) -> Vec<u8> {
    let header = |begin| {
        let b = B::default().raw(b"CDF\x01").u32(numrecs).u32(NC_DIMENSION).u32(2).name("line").u32(0);
        let b = b.name("pixel").u32(3).u32(0).u32(0).u32(NC_VARIABLE).u32(1).name("s").u32(2).u32(0).u32(1);
        b.u32(0).u32(0).u32(3).u32(8).u32(begin).0
    };
    file(header, None, &[7; 18])
}

/// Classic, with dimensions `dims` and a float variable of `var_dims` for each name of `vars`
/// (all at the header's end), `vsize` and type `ty`, and 64 bytes of data.
fn some_vars(dims: &[(&str, u32)], vars: &[&str], var_dims: &[u32], ty: u32, vsize: u32) -> Vec<u8> {
    let header = |begin| {
        let mut b = B::default().raw(b"CDF\x01").u32(0).u32(NC_DIMENSION).u32(n32(dims.len()));
        for (name, len) in dims {
            b = b.name(name).u32(*len);
        }
        b = b.u32(0).u32(0).u32(NC_VARIABLE).u32(n32(vars.len()));
        for name in vars {
            b = b.name(name).u32(n32(var_dims.len()));
            for d in var_dims {
                b = b.u32(*d);
            }
            b = b.u32(0).u32(0).u32(ty).u32(vsize).u32(begin);
        }
        b.0
    };
    file(header, None, &[0; 64])
}

#[test]
fn a_written_file_reads_back_as_the_crate_reader_read_it() {
    let dir = tempdir("round-trip");
    let path = dir.join("products.nc");
    let (lines, pixels) = (3, 4);
    let n = lines * pixels;
    let chl: Vec<f32> = (0..n)
        .map(|i| match i {
            1 => FILL,
            5 => f32::NAN,
            7 => f32::INFINITY,
            _ => 0.1 * i as f32 + 0.05,
        })
        .collect();
    let nap: Vec<f32> = (0..n).map(|i| if i % 3 == 0 { FILL } else { 1.0 / (i as f32 + 1.0) }).collect();
    let floats = vec![
        FloatVar {
            name: "wavelength".into(),
            dims: vec!["band"],
            attrs: vec![("units", "nm".into())],
            values: Values::ready(vec![443.0, 560.0]),
        },
        FloatVar { name: "chl_mg_m3".into(), dims: MAP.to_vec(), attrs: vec![], values: Values::ready(chl.clone()) },
        FloatVar {
            name: "nap_g_m3".into(),
            dims: MAP.to_vec(),
            attrs: crate::netcdf::attrs("suspended matter", "g m-3", None),
            values: Values::ready(nap.clone()),
        },
        FloatVar { name: "rrs".into(), dims: CUBE.to_vec(), attrs: vec![], values: Values::ready(vec![0.01; n * 2]) },
    ];
    let flags = vec![FlagVar {
        name: "land".into(),
        dims: MAP.to_vec(),
        long_name: "land".into(),
        flags: vec![(1, "land")],
        values: Values::ready(vec![0; n]),
        coordinates: "",
    }];
    let mut ds = DataSet::new();
    ds.add_fixed_dim("line", lines).unwrap();
    ds.add_fixed_dim("pixel", pixels).unwrap();
    ds.add_fixed_dim("band", 2).unwrap();
    define_vars(&mut ds, &floats, &flags).unwrap();
    let text = band_names(&mut ds, &["b1", "b2"]).unwrap();
    ds.add_global_attr_string("Conventions", "CF-1.8").unwrap();
    write_file(&path, &ds, (&floats, &flags, &[text]), false).unwrap();

    let wanted = ["nap_g_m3", "absent", "chl_mg_m3"];
    let new = read_maps(&path, &wanted, 1 << 20).unwrap();
    let old = oracle(&path, &wanted).unwrap();
    assert_eq!((new.shape, &new.names, &new.maps), (old.shape, &old.names, &old.maps));
    assert_eq!(new.shape, (lines, pixels));
    assert_eq!(new.names, ["wavelength", "chl_mg_m3", "nap_g_m3", "rrs", "land", "band_name"]);
    let expect = |w: &[f32]| -> Vec<Option<f64>> {
        w.iter().map(|&v| (v.to_bits() != FILL.to_bits() && v.is_finite()).then_some(f64::from(v))).collect()
    };
    assert_eq!(new.maps, vec![("nap_g_m3".to_string(), expect(&nap)), ("chl_mg_m3".to_string(), expect(&chl))]);
    assert_eq!(new.maps[1].1.iter().filter(|v| v.is_none()).count(), 3);
    // The refusals agree.
    for bad in ["rrs", "band_name", "wavelength"] {
        let e = read_maps(&path, &[bad], 1 << 20).unwrap_err();
        assert_eq!(e, oracle(&path, &[bad]).unwrap_err());
        assert!(e.ends_with("; expected (line, pixel)"), "{e}");
    }
    let e = read_maps(&path, &["land"], 1 << 20).unwrap_err();
    assert_eq!(e, "`land` is not a float variable (it is NC_INT)");
    assert!(oracle(&path, &["land"]).unwrap_err().starts_with("`land` is not a float variable"));
    assert!(read_maps(&path, &wanted, 100).unwrap_err().contains("allowed: at most"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_variables_written_by_the_crate_read_as_its_reader_reads_them() {
    let dir = tempdir("records");
    let path = dir.join("records.nc");
    let mut ds = DataSet::new();
    ds.set_unlimited_dim("line", 3).unwrap();
    ds.add_fixed_dim("pixel", 2).unwrap();
    ds.add_var_f32("a", &["line", "pixel"]).unwrap();
    ds.add_var_f64("b", &["line", "pixel"]).unwrap();
    ds.add_var_attr_f64("b", "missing_value", vec![-1.0]).unwrap();
    let mut w = netcdf3::FileWriter::open(&path).unwrap();
    w.set_def(&ds, netcdf3::Version::Classic, 0).unwrap();
    w.write_var_f32("a", &[1.0, 2.0, 3.0, 4.0, 5.0, f32::NAN]).unwrap();
    w.write_var_f64("b", &[-1.0, 20.0, 30.0, f64::NAN, 50.0, 60.0]).unwrap();
    w.close().unwrap();
    let new = read_maps(&path, &["b", "a"], 1 << 20).unwrap();
    let old = oracle(&path, &["b", "a"]).unwrap();
    assert_eq!((new.shape, &new.names, &new.maps), (old.shape, &old.names, &old.maps));
    assert_eq!(new.shape, (3, 2));
    assert_eq!(new.maps[0].1, [None, Some(20.0), Some(30.0), None, Some(50.0), Some(60.0)]);
    assert_eq!(new.maps[1].1, [Some(1.0), Some(2.0), Some(3.0), Some(4.0), Some(5.0), None]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_hand_built_classic_file_with_a_double_variable_and_missing_value() {
    let maps = parse_maps(&classic(None), &["x", "y"]).unwrap();
    assert_eq!(maps.shape, (2, 3));
    assert_eq!(maps.names, ["x"]);
    assert_eq!(maps.maps, [("x".to_string(), vec![Some(1.5), None, None, Some(2.0), None, Some(1e300)])]);
    let none = parse_maps(&some_vars(&[("line", 2)], &["v"], &[0], 5, 8), &["v"]).unwrap_err();
    assert_eq!(none, "needs dimensions `line` and `pixel`");
}

#[test]
fn a_hand_built_file_with_line_the_record_dimension() {
    for numrecs in [2, STREAMING] {
        let maps = parse_maps(&records(numrecs), &["b", "a"]).unwrap();
        assert_eq!(maps.shape, (2, 3));
        assert_eq!(maps.maps[0].1, [Some(10.0), Some(20.0), None, Some(40.0), Some(-9999.0), Some(60.0)]);
        assert_eq!(maps.maps[1].1, [Some(1.0), None, Some(3.0), Some(4.0), Some(5.0), None]);
    }
    // One short record variable: 6 bytes a record, no padding (18 bytes for 3 records, not 22).
    for numrecs in [3, STREAMING] {
        let bytes = lone_short(numrecs);
        assert_eq!(parse_maps(&bytes, &[]).unwrap().shape, (3, 3));
        assert_eq!(parse_maps(&bytes, &["s"]).unwrap_err(), "`s` is not a float variable (it is NC_SHORT)");
    }
    let bytes = lone_short(3);
    assert!(parse_maps(&bytes[..bytes.len() - 1], &[]).unwrap_err().contains("runs past the end of the file"));
}

#[test]
fn a_huge_dimension_count_is_refused_at_once() {
    let bytes = [b"CDF\x02".as_slice(), &[0; 4], &[0, 0, 0, 0x0A], &[0x7f, 0xff, 0xff, 0xff]].concat();
    assert_eq!(bytes.len(), 16);
    let start = Instant::now();
    let e = parse_maps(&bytes, &["x"]).unwrap_err();
    assert_eq!(e, "the header claims 2147483647 dimensions but the file has 16 bytes");
    assert!(start.elapsed().as_secs_f64() < 0.1);
}

#[test]
fn a_huge_variable_in_a_small_file_is_refused() {
    let mut bytes = some_vars(&[("line", 100_000), ("pixel", 100_000)], &["chl_mg_m3"], &[0, 1], 5, u32::MAX);
    let begin = bytes.len() - 64;
    bytes.resize(200, 0);
    let e = parse_maps(&bytes, &["chl_mg_m3"]).unwrap_err();
    assert_eq!(
        e,
        format!(
            "variable `chl_mg_m3`'s data (offset {begin}, 40000000000 bytes) runs past the end of the file (200 bytes)"
        )
    );
}

#[test]
fn offsets_inside_the_header_or_past_the_end_are_refused() {
    let e = parse_maps(&classic(Some(8)), &[]).unwrap_err();
    assert!(e.starts_with("variable `x` starts inside the header (offset 8;"), "{e}");
    let len = len32(&classic(None));
    let e = parse_maps(&classic(Some(len - 47)), &[]).unwrap_err();
    assert!(e.contains("48 bytes) runs past the end of the file"), "{e}");
}

#[test]
fn other_formats_are_refused_by_name() {
    let e = parse_maps(&[b"CDF\x05".as_slice(), &[0; 40]].concat(), &[]).unwrap_err();
    assert!(e.starts_with("is a CDF-5 file") && e.contains("NETCDF3_64BIT\""), "{e}");
    let e = parse_maps(&[b"\x89HDF\r\n\x1a\n".as_slice(), &[0; 40]].concat(), &[]).unwrap_err();
    assert!(e.starts_with("is a NetCDF-4 (HDF5) file") && e.contains("64-bit offset"), "{e}");
    assert!(parse_maps(b"GIF89a", &[]).unwrap_err().starts_with("is not a NetCDF file"));
    assert!(parse_maps(b"CD", &[]).unwrap_err().starts_with("is not a NetCDF file"));
}

#[test]
fn inconsistent_headers_are_refused() {
    let map = [("line", 2), ("pixel", 2)];
    let cases: [(Vec<u8>, &str); 8] = [
        (some_vars(&[("line", 2), ("line", 3)], &["v"], &[0], 5, 8), "two dimensions `line`"),
        (some_vars(&[("line", 0), ("t", 0)], &["v"], &[0], 5, 4), "two record (unlimited) dimensions"),
        (some_vars(&[("line", 2), ("t", 0)], &["v"], &[0, 1], 5, 8), "allows it only first"),
        (some_vars(&map, &["v", "v"], &[0, 1], 5, 16), "two variables `v`"),
        (some_vars(&map, &["v"], &[0, 7], 5, 16), "uses dimension 7, but the file has 2"),
        (some_vars(&map, &["v"], &[0, 1], 9, 16), "has type 9"),
        (some_vars(&map, &["v"], &[0, 1], 5, 12), "has size 12 in the header, but its dimensions and type make 16"),
        (some_vars(&[("line", u32::MAX), ("pixel", u32::MAX)], &["v"], &[0, 1, 0, 1], 6, u32::MAX), "overflows"),
    ];
    for (bytes, want) in cases {
        let e = parse_maps(&bytes, &["v"]).unwrap_err();
        assert!(e.contains(want), "{e} (wanted: {want})");
    }
    assert_eq!(parse_maps(&some_vars(&map, &["v"], &[0, 1], 5, 16), &["v"]).unwrap().maps[0].1, [Some(0.0); 4]);
}

#[test]
fn every_truncation_is_refused_without_panicking() {
    for bytes in [classic(None), records(2), lone_short(3)] {
        for n in 0..bytes.len() {
            assert!(parse_maps(&bytes[..n], &["x", "a", "b"]).is_err(), "{n}");
        }
        assert!(parse_maps(&bytes, &["x", "a", "b"]).is_ok());
    }
}

#[test]
fn random_byte_changes_never_panic() {
    let files = [classic(None), records(2), lone_short(3)];
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let (mut ok, mut refused) = (0, 0);
    for i in 0..2000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let mut m = files[i % files.len()].clone();
        let at = usize::try_from(x % u64::try_from(m.len()).unwrap()).unwrap();
        m[at] = x.to_be_bytes()[0];
        match parse_maps(&m, &["x", "a", "b", "s"]) {
            Ok(_) => ok += 1,
            Err(_) => refused += 1,
        }
    }
    assert!(ok > 0 && refused > 0, "{ok} read, {refused} refused");
}

#[test]
fn a_header_of_8000_variables_parses_in_linear_time() {
    let n = 8000u32;
    let header = |begin: u32| {
        let b = B::default().raw(b"CDF\x01").u32(0).u32(NC_DIMENSION).u32(2).name("line").u32(1).name("pixel");
        let mut b = b.u32(1).u32(0).u32(0).u32(NC_VARIABLE).u32(n);
        for i in 0..n {
            b = b.name(&format!("variable_{i}")).u32(2).u32(0).u32(1).u32(0).u32(0).u32(5).u32(4).u32(begin + 4 * i);
        }
        b.0
    };
    let data: Vec<u8> = (0..n).flat_map(|i| f32::from(u16::try_from(i).unwrap()).to_be_bytes()).collect();
    let bytes = file(header, None, &data);
    let start = Instant::now();
    let maps = parse_maps(&bytes, &["variable_7999", "variable_0"]).unwrap();
    let took = start.elapsed();
    assert_eq!(maps.names.len(), 8000);
    assert_eq!(maps.maps[0].1, [Some(7999.0)]);
    assert_eq!(maps.maps[1].1, [Some(0.0)]);
    assert!(took.as_secs_f64() < 0.5, "{took:?}");
}
