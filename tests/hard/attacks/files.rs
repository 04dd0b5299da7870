//! The attack categories about files a colleague or a cluster job hands over: forged shard
//! records, NetCDF bombs, FIFOs where a file should be, files read before they are sized, heavy
//! commands without a budget, and the smaller causes the last attack found.

use super::*;

/// `tally` a refusal (exit 2, one line naming `said`, within `limit_s`) of the command `(dir,
/// args, env)`.
fn refused(
    tally: &mut Tally,
    (category, case): (&'static str, &str),
    (dir, args, env): (&Path, &[&str], &[(&str, &str)]),
    said: &str,
    limit_s: f64,
) {
    let o = run(dir, args, env, Duration::from_secs_f64(limit_s + 30.0));
    tally.record(category, case, o.refused(said, limit_s));
}

/// A FIFO at `path` (none is ever opened for writing: a reader would wait for ever).
fn fifo(path: &Path) {
    let _ = std::fs::remove_file(path);
    assert!(Command::new("mkfifo").arg(path).status().unwrap().success());
}

/// A sparse file of `bytes` zeros (costs no disk).
fn sparse(path: &Path, bytes: u64) {
    std::fs::File::create(path).unwrap().set_len(bytes).unwrap();
}

/// A study whose only product requirement is a returned share (no MAE requirement: the fronts
/// are drawn for the retrieval's own variables), searched over the aperture.
const DESIGN_STUDY: &str = r#"StudySpec(
    name: "shard",
    scene: Preset("lake_hume_bloom"),
    instruments: [Preset("cubesat")],
    retrievals: [Almi()],
    seeds: [1],
    budgets: Some(Preset("cubesat_class")),
    requirements: Some((products: [(variable: "chl_mg_m3", returned_pct: Some(50))], snr: Some(20))),
)"#;

fn design_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec![
        "design",
        "s.ron",
        "--vary",
        "aperture_mm=40:200",
        "--evaluations",
        "4",
        "--initial",
        "3",
        "--decimation",
        "64",
        "--confirm-decimation",
        "0",
        "--no-figures",
        "--out",
        out,
    ];
    v.extend_from_slice(extra);
    v
}

/// Forged shard records: each refused naming its field, and nothing written outside `--out`.
pub(super) fn shard_records(tally: &mut Tally) {
    let dir = tempdir("shards");
    std::fs::write(dir.join("s.ron"), DESIGN_STUDY).unwrap();
    let first = run(&dir, &design_args("shard", &["--shard", "0/1"]), &[], Duration::from_secs(300));
    assert_eq!(first.code, Some(0), "{}", first.stderr);
    let record = std::fs::read_to_string(dir.join("shard/evaluations.ron")).unwrap();
    // The genuine record resumes.
    let genuine = run(&dir, &design_args("resumed", &["--resume", "shard"]), &[], Duration::from_secs(300));
    tally.record("forged shard records", "the genuine record", genuine.clean(300.0));
    let first_value = |key: &str| -> String {
        let at = record.find(key).unwrap() + key.len();
        record[at..].split([',', ')', '\n']).map(str::trim).find(|p| !p.is_empty()).unwrap().to_string()
    };
    let constraints_at = record.find("constraints: [").unwrap();
    let constraints_end = constraints_at + record[constraints_at..].find(']').unwrap() + 1;
    // The first constraint's excess: after its key, up to the closing parenthesis.
    let excess_at = constraints_at + record[constraints_at..].find("\", ").unwrap() + 3;
    let excess_end = excess_at + record[excess_at..].find(')').unwrap();
    let mae_var = "\"chl_mg_m3\"";
    let evaluation_decimation = "            decimation: 64,";
    let forged: Vec<(&str, String, &str)> = vec![
        ("a variable name that is a path", record.replacen(mae_var, "\"../../escaped\"", 1), "mae_pct"),
        ("an absolute path", record.replacen(mae_var, "\"/tmp/shoal-forged\"", 1), "mae_pct"),
        ("x outside --vary", record.replacen(&first_value("x: ["), "5000.0", 1), "x[0]"),
        (
            "an empty constraint list",
            format!("{}constraints: []{}", &record[..constraints_at], &record[constraints_end..]),
            "constraints",
        ),
        (
            "a negative cost",
            record.replacen(&format!("cost: Some({}", first_value("cost: Some(")), "cost: Some(-5.0", 1),
            "cost",
        ),
        (
            "NaN seconds",
            record.replacen(&format!("seconds: {}", first_value("seconds: ")), "seconds: NaN", 1),
            "seconds",
        ),
        ("a −1e308 constraint", format!("{}-1e308{}", &record[..excess_at], &record[excess_end..]), "constraints"),
        ("another decimation", record.replacen(evaluation_decimation, "            decimation: 8,", 1), "decimation"),
    ];
    for (case, text, field) in forged {
        std::fs::create_dir_all(dir.join("forged")).unwrap();
        std::fs::write(dir.join("forged/evaluations.ron"), &text).unwrap();
        let o = run(&dir, &design_args("out", &["--resume", "forged"]), &[], Duration::from_secs(300));
        let mut result = o.refused(field, 120.0);
        if text == record {
            result = Err(format!("the forgery did not change the record ({case})"));
        }
        let outside: Vec<String> = walk(&dir)
            .into_iter()
            .chain(walk(Path::new("/tmp")).into_iter().filter(|p| p.to_string_lossy().contains("shoal-forged")))
            .map(|p| p.display().to_string())
            .filter(|p| !["/s.ron", "/shard/", "/resumed/", "/forged/evaluations.ron"].iter().any(|k| p.contains(k)))
            .collect();
        if !outside.is_empty() {
            result = Err(format!("wrote {outside:?}"));
        }
        tally.record("forged shard records", case, result);
        let _ = std::fs::remove_dir_all(dir.join("out"));
    }
    // A record that is a FIFO, or a directory.
    fifo(&dir.join("forged/evaluations.ron"));
    refused(
        tally,
        ("FIFOs and special files", "a shard record that is a FIFO"),
        (&dir, &design_args("out", &["--resume", "forged"]), &[]),
        "FIFO",
        20.0,
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A NetCDF-3 header: `dims` (name, size), then one float variable of all of them at `begin`
/// with `vsize` (the 64-bit-offset form when `offset64`).
fn netcdf_claiming(dims: &[(&str, u32)], var: &str, begin: u64, vsize: u32, offset64: bool) -> Vec<u8> {
    let mut b: Vec<u8> = if offset64 { b"CDF\x02".to_vec() } else { b"CDF\x01".to_vec() };
    let name = |b: &mut Vec<u8>, n: &str| {
        b.extend((n.len() as u32).to_be_bytes());
        b.extend(n.as_bytes());
        b.resize(b.len().div_ceil(4) * 4, 0);
    };
    b.extend(0u32.to_be_bytes()); // numrecs
    b.extend(10u32.to_be_bytes()); // NC_DIMENSION
    b.extend((dims.len() as u32).to_be_bytes());
    for (n, size) in dims {
        name(&mut b, n);
        b.extend(size.to_be_bytes());
    }
    b.extend([0u8; 8]); // no global attributes
    b.extend(11u32.to_be_bytes()); // NC_VARIABLE
    b.extend(1u32.to_be_bytes());
    name(&mut b, var);
    b.extend((dims.len() as u32).to_be_bytes());
    for i in 0..dims.len() as u32 {
        b.extend(i.to_be_bytes());
    }
    b.extend([0u8; 8]); // no attributes
    b.extend(5u32.to_be_bytes()); // NC_FLOAT
    b.extend(vsize.to_be_bytes());
    if offset64 {
        b.extend(begin.to_be_bytes());
    } else {
        b.extend((begin as u32).to_be_bytes());
    }
    b
}

/// NetCDF files that claim more than they hold, as the product and as the truth of `shoal score`.
pub(super) fn netcdf_bombs(tally: &mut Tally) {
    let dir = tempdir("netcdf");
    let made = run(
        &dir,
        &["simulate", "--decimation", "64", "--format", "netcdf", "--out", "run"],
        &[],
        Duration::from_secs(300),
    );
    assert_eq!(made.code, Some(0), "{}", made.stderr);
    let mut dims_bomb = b"CDF\x02".to_vec();
    dims_bomb.extend(0u32.to_be_bytes());
    dims_bomb.extend(10u32.to_be_bytes());
    dims_bomb.extend(0x7fff_ffffu32.to_be_bytes());
    let mut cells = netcdf_claiming(&[("line", 100_000), ("pixel", 100_000)], "chl_mg_m3", 200, u32::MAX, false);
    cells.resize(200, 0);
    let mut inside = netcdf_claiming(&[("line", 2), ("pixel", 2)], "chl_mg_m3", 8, 16, false);
    inside.resize(160, 0);
    let mut truncated = std::fs::read(dir.join("run/products.nc")).unwrap();
    truncated.truncate(truncated.len() / 3);
    let bombs: [(&str, Vec<u8>); 6] = [
        ("16 bytes claiming 2³¹−1 dimensions", dims_bomb),
        ("200 bytes claiming 100000² cells", cells),
        ("data offset inside the header", inside),
        ("a CDF-5 file", b"CDF\x05\0\0\0\0\0\0\0\0\0\0\0\0".to_vec()),
        ("an HDF5 (NetCDF-4) file", b"\x89HDF\r\n\x1a\n\0\0\0\0\0\0\0\0".to_vec()),
        ("a products.nc cut to a third", truncated),
    ];
    for (case, bytes) in bombs {
        std::fs::write(dir.join("bomb.nc"), &bytes).unwrap();
        refused(
            tally,
            ("NetCDF bombs", &format!("{case}, as the product")),
            (&dir, &["score", "bomb.nc", "--truth", "run", "--out", "s"], &[]),
            "bomb.nc",
            10.0,
        );
        std::fs::create_dir_all(dir.join("bombrun")).unwrap();
        std::fs::write(dir.join("bombrun/products.nc"), &bytes).unwrap();
        refused(
            tally,
            ("NetCDF bombs", &format!("{case}, as the truth")),
            (&dir, &["score", "run/products.nc", "--truth", "bombrun", "--out", "s"], &[]),
            "products.nc",
            10.0,
        );
    }
    // A FIFO as either file.
    fifo(&dir.join("fifo.nc"));
    refused(
        tally,
        ("FIFOs and special files", "the product to score is a FIFO"),
        (&dir, &["score", "fifo.nc", "--truth", "run", "--out", "s"], &[]),
        "FIFO",
        10.0,
    );
    fifo(&dir.join("bombrun/products.nc"));
    refused(
        tally,
        ("FIFOs and special files", "the truth's products.nc is a FIFO"),
        (&dir, &["score", "run/products.nc", "--truth", "bombrun", "--out", "s"], &[]),
        "FIFO",
        10.0,
    );
    refused(
        tally,
        ("FIFOs and special files", "the product to score is a directory"),
        (&dir, &["score", "run", "--truth", "run", "--out", "s"], &[]),
        "directory",
        10.0,
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A results folder whose figures are FIFOs, and files read before they were sized.
pub(super) fn special_and_oversized(tally: &mut Tally) {
    let dir = tempdir("special");
    let o =
        run(&dir, &["study", "--decimation", "32", "--no-cubes", "--out", "results"], &[], Duration::from_secs(300));
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    fifo(&dir.join("results/figures/snr.png"));
    let o = run(&dir, &["report", "results", "--out", "pack"], &[], Duration::from_secs(60));
    tally.record("FIFOs and special files", "a listed figure's PNG is a FIFO (left out)", o.clean(30.0));
    fifo(&dir.join("results/figures/snr.svg"));
    refused(
        tally,
        ("FIFOs and special files", "a listed figure is a FIFO"),
        (&dir, &["report", "results", "--out", "pack2"], &[]),
        "FIFO",
        10.0,
    );
    let _ = std::fs::remove_file(dir.join("results/figures/snr.svg"));
    sparse(&dir.join("results/figures/snr.svg"), 100 << 20);
    refused(
        tally,
        ("read before sized", "a listed SVG of 100 MB"),
        (&dir, &["report", "results", "--out", "pack3"], &[]),
        "allowed: at most",
        10.0,
    );
    fifo(&dir.join("fifo.ron"));
    refused(
        tally,
        ("FIFOs and special files", "a study file that is a FIFO"),
        (&dir, &["study", "fifo.ron", "--out", "o"], &[]),
        "FIFO",
        10.0,
    );
    sparse(&dir.join("huge.ron"), 100 << 20);
    refused(
        tally,
        ("read before sized", "a study.ron of 100 MB"),
        (&dir, &["study", "huge.ron", "--out", "o"], &[]),
        "allowed: at most",
        10.0,
    );
    sparse(&dir.join("huge.csv"), 100 << 20);
    refused(
        tally,
        ("read before sized", "--toa spectra of 100 MB"),
        (&dir, &["correct", "--toa", "huge.csv", "--instrument", "cubesat", "--out", "o"], &[]),
        "allowed: at most",
        10.0,
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// TOA spectra of `rows` rows for the OLCI bands (radiance 40 W m⁻² sr⁻¹ µm⁻¹ everywhere).
fn toa_csv(rows: usize) -> String {
    let names: Vec<String> = (1..=21).map(|i| format!("Oa{i:02}")).collect();
    let mut s = format!("sun_zenith_deg,view_zenith_deg,relative_azimuth_deg,{}\n", names.join(","));
    for r in 0..rows {
        s.push_str(&format!("{},{},90{}\n", 20 + r, r % 30, ",40".repeat(names.len())));
    }
    s
}

/// Heavy commands under one resource plan, and the budget's variables refused alike.
pub(super) fn budgets_everywhere(tally: &mut Tally) {
    let dir = tempdir("budgets");
    std::fs::write(dir.join("toa.csv"), toa_csv(7)).unwrap();
    let hume = std::fs::read_to_string(presets().join("scenes/lake_hume_bloom.ron")).unwrap();
    let grf = "RandomField(distribution: LogNormal(median: 5.0, sigma_ln: 0.5), correlation_m: 1500.0, seed: 3)";
    let big = hume
        .replace("width: 3000", "width: 20000")
        .replace("height: 2000", "height: 20000")
        .replace("nap_g_m3: Constant(10.0)", &format!("nap_g_m3: {grf}"));
    std::fs::write(dir.join("big_scene.ron"), big).unwrap();
    std::fs::write(
        dir.join("thin.ron"),
        "AtmosphereRun(atmosphere: (accuracy: (max_layer_depth: 0.0001, streams: 48)))",
    )
    .unwrap();
    let nodes: Vec<String> = (1..=1000).map(|i| format!("{:.3}", f64::from(i) * 0.004)).collect();
    let many_nodes = format!("(aot_nodes: [{}])", nodes.join(", "));
    let correct = ["correct", "--toa", "toa.csv", "--instrument", "cubesat", "--out", "o"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> { correct.iter().chain(extra).copied().collect() };
    let mut nodes_case: Vec<&str> = correct.to_vec();
    nodes_case.extend(["--correction", many_nodes.as_str()]);
    type Case<'a> = (&'a str, Vec<&'a str>, Vec<(&'a str, &'a str)>, &'a str);
    let cases: Vec<Case<'_>> = vec![
        (
            "atmosphere: thinnest layers, most streams",
            vec!["atmosphere", "--spec", "thin.ron"],
            vec![],
            "max_layer_depth",
        ),
        (
            "atmosphere: SHOAL_TIME_BUDGET_S=0.01",
            vec!["atmosphere", "--accuracy", "high"],
            vec![("SHOAL_TIME_BUDGET_S", "0.01")],
            "SHOAL_TIME_BUDGET_S",
        ),
        (
            "correct: a 20000² random-field scene",
            with(&["--scene", "big_scene.ron"]),
            vec![("SHOAL_MEMORY_BUDGET", "3G")],
            "scene.width",
        ),
        ("correct: 1000 AOT nodes", nodes_case, vec![], "aot_nodes"),
        ("correct: dark-spectrum fitting on 7 spectra", with(&["--correction", "dark"]), vec![], "dark"),
    ];
    for (case, args, env, said) in cases {
        refused(tally, ("budgets on every command", case), (&dir, &args, &env), said, 20.0);
        let _ = std::fs::remove_dir_all(dir.join("o"));
    }
    for (what, args) in [
        ("ranges", vec!["ranges"]),
        ("atmosphere", vec!["atmosphere"]),
        ("correct", correct.to_vec()),
        ("score", vec!["score", "x.nc", "--truth", "run"]),
        ("study", vec!["study", "--decimation", "64", "--out", "o"]),
    ] {
        for (var, value) in [("SHOAL_MEMORY_BUDGET", "lots"), ("SHOAL_TIME_BUDGET_S", "-3")] {
            refused(
                tally,
                ("budgets on every command", &format!("{what} with {var}={value}")),
                (&dir, &args, &[(var, value)]),
                var,
                10.0,
            );
        }
    }
    let cubesat = std::fs::read_to_string(presets().join("instruments/cubesat.ron")).unwrap();
    let tiny_well = cubesat
        .lines()
        .map(|l| if l.trim_start().starts_with("well_depth_e:") { "    well_depth_e: 1e-300," } else { l })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("well.ron"), tiny_well).unwrap();
    refused(
        tally,
        ("range-table gaps", "well_depth_e 1e-300"),
        (&dir, &["simulate", "--instrument", "well.ron", "--decimation", "64", "--out", "o"], &[]),
        "well_depth_e",
        20.0,
    );
    let _ = std::fs::remove_dir_all(&dir);
}
