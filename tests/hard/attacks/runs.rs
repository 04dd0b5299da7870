//! The attack categories about what Shoal writes and what it may use: `--out` folders that are
//! not Shoal's, runs sized to exhaust memory or time, and values at the range table's former gaps.

use super::*;

/// A folder reused for another study, an interrupted rerun, a killed run's leftovers.
pub(super) fn folders(tally: &mut Tally) {
    let dir = tempdir("folders");
    let study = |name: &str| {
        run(
            &dir,
            &["study", name, "--decimation", "16", "--no-cubes", "--out", "results"],
            &[],
            Duration::from_secs(180),
        )
    };
    let first = study("cubesat_vs_smallsat");
    assert_eq!(first.code, Some(0), "{}", first.stderr);
    let second = study("heron_island_depth");
    let result = second.clean(180.0).and_then(|()| {
        let files: Vec<String> = walk(&dir.join("results")).iter().map(|p| p.display().to_string()).collect();
        match files.iter().find(|f| f.contains("alm_") || f.contains("requirements.csv")) {
            Some(stale) => Err(format!("the Lake Hume study's {stale} is still there")),
            None => Ok(()),
        }
    });
    tally.record("reused and interrupted folders", "another study into the same --out", result);

    // Interrupted at full resolution: the folder keeps the complete results it had.
    let before = std::fs::read(dir.join("results/review.json")).unwrap();
    let mut child = Command::new(shoal_bin())
        .args(["study", "cubesat_vs_smallsat", "--no-figures", "--out", "results"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(2500));
    let _ = Command::new("kill").args(["-INT", &child.id().to_string()]).status();
    let status = child.wait().unwrap();
    let result = if status.code() != Some(130) {
        Err(format!("exit {status:?} after Ctrl-C, not 130"))
    } else if std::fs::read(dir.join("results/review.json")).ok() != Some(before.clone()) {
        Err("the interrupted run changed the results it did not finish".into())
    } else if walk(&dir).iter().any(|p| p.to_string_lossy().contains("shoal-partial")) {
        Err("a staging folder was left".into())
    } else {
        run(&dir, &["report", "results", "--out", "pack"], &[], Duration::from_secs(60)).clean(60.0)
    };
    tally.record("reused and interrupted folders", "Ctrl-C during a rerun", result);

    // Killed outright (SIGKILL, a second Ctrl-C): the next run cleans up after it.
    let mut child = Command::new(shoal_bin())
        .args(["study", "cubesat_vs_smallsat", "--decimation", "2", "--out", "results"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(2000));
    let _ = child.kill();
    let _ = child.wait();
    let after_kill = std::fs::read(dir.join("results/review.json")).ok() == Some(before);
    let next = study("cubesat_vs_smallsat");
    let leftovers: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("shoal-") || n.ends_with(".partial"))
        .collect();
    let result = if !after_kill {
        Err("the killed run changed the complete results".into())
    } else if !leftovers.is_empty() {
        Err(format!("left after the next run: {leftovers:?}"))
    } else {
        next.clean(180.0)
    };
    tally.record("reused and interrupted folders", "killed run, then a rerun", result);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs sized to exhaust the machine: refused within seconds under a 3 GB budget.
pub(super) fn resources(tally: &mut Tally) {
    let dir = tempdir("resources");
    let cubesat = std::fs::read_to_string(presets().join("instruments/cubesat.ron")).unwrap();
    std::fs::write(
        dir.join("big.ron"),
        cubesat.replace("detectors: 1024", "detectors: 20000").replace("lines: 2000", "lines: 100000"),
    )
    .unwrap();
    let hume = std::fs::read_to_string(presets().join("scenes/lake_hume_bloom.ron")).unwrap();
    let grf = |seed: u32| {
        format!("RandomField(distribution: LogNormal(median: 5.0, sigma_ln: 0.5), correlation_m: 1500.0, seed: {seed})")
    };
    let big_scene = hume
        .replace("width: 3000", "width: 20000")
        .replace("height: 2000", "height: 20000")
        .replace("nap_g_m3: Constant(10.0)", &format!("nap_g_m3: {}", grf(3)))
        .replace("cdom_per_m: Constant(1.0)", &format!("cdom_per_m: {}", grf(4)));
    std::fs::write(dir.join("big_scene.ron"), &big_scene).unwrap();
    let layers = |depth: &str, streams: u32| {
        hume.replace(
            "        latitude_deg: -36.1,",
            &format!("        latitude_deg: -36.1,\n        accuracy: (max_layer_depth: {depth}, streams: {streams}),"),
        )
    };
    std::fs::write(dir.join("thin_layers.ron"), layers("1e-9", 12)).unwrap();
    std::fs::write(dir.join("thin_wide.ron"), layers("0.0001", 48)).unwrap();
    // A 60 000 × 60 000 GeoTIFF in a few hundred bytes: a header that claims 3.6 G samples.
    std::fs::write(dir.join("bomb.tif"), tiff_claiming(60_000, 60_000)).unwrap();
    let mut bomb_scene =
        hume.replace("cdom_per_m: Constant(1.0)", "cdom_per_m: Raster(path: \"bomb.tif\", unit: \"m-1\")");
    bomb_scene = bomb_scene.replace(
        "    width: 3000,",
        "    georeference: Some(Epsg(code: 32755, centre: (500000.0, 6000000.0))),\n    width: 3000,",
    );
    std::fs::write(dir.join("bomb_scene.ron"), bomb_scene).unwrap();
    let cases: [(&str, Vec<&str>, &str); 6] = [
        (
            "largest instrument over the largest scene",
            vec!["simulate", "--instrument", "big.ron", "--scene", "big_scene.ron", "--out", "o"],
            "GB",
        ),
        (
            "three random fields on 20000² at 1/16",
            vec!["simulate", "--scene", "big_scene.ron", "--instrument", "cubesat", "--decimation", "16", "--out", "o"],
            "scene.width",
        ),
        (
            "max_layer_depth 1e-9",
            vec!["simulate", "--scene", "thin_layers.ron", "--decimation", "64", "--out", "o"],
            "max_layer_depth",
        ),
        (
            "thinnest layers and most streams",
            vec!["simulate", "--scene", "thin_wide.ron", "--decimation", "64", "--out", "o"],
            "max_layer_depth",
        ),
        (
            "deflate bomb GeoTIFF",
            vec!["simulate", "--scene", "bomb_scene.ron", "--decimation", "64", "--out", "o"],
            "bomb.tif",
        ),
        ("--threads 100000", vec!["study", "--threads", "100000", "--decimation", "64", "--out", "o"], "--threads"),
    ];
    for (what, args, said) in cases {
        let o = run(&dir, &args, &[("SHOAL_MEMORY_BUDGET", "3G")], Duration::from_secs(30));
        tally.record("memory and time", what, o.refused(said, 10.0));
        let _ = std::fs::remove_dir_all(dir.join("o"));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A minimal little-endian TIFF whose header claims `w` × `h` 64-bit samples in one strip of
/// 8 bytes (the decoder would allocate the whole image).
fn tiff_claiming(w: u32, h: u32) -> Vec<u8> {
    let mut b: Vec<u8> = b"II*\0".to_vec();
    b.extend(8u32.to_le_bytes());
    let entries: [(u16, u16, u32, u32); 9] = [
        (256, 4, 1, w),   // ImageWidth
        (257, 4, 1, h),   // ImageLength
        (258, 3, 1, 64),  // BitsPerSample
        (259, 3, 1, 8),   // Compression: deflate
        (262, 3, 1, 1),   // Photometric
        (273, 4, 1, 200), // StripOffsets
        (278, 4, 1, h),   // RowsPerStrip
        (279, 4, 1, 8),   // StripByteCounts
        (339, 3, 1, 3),   // SampleFormat: float
    ];
    b.extend((entries.len() as u16).to_le_bytes());
    for (tag, kind, count, value) in entries {
        b.extend(tag.to_le_bytes());
        b.extend(kind.to_le_bytes());
        b.extend(count.to_le_bytes());
        b.extend(value.to_le_bytes());
    }
    b.extend(0u32.to_le_bytes());
    b.resize(208, 0);
    b
}

/// Values at the gaps the range table had.
pub(super) fn gaps(tally: &mut Tally) {
    let dir = tempdir("gaps");
    let hume = std::fs::read_to_string(presets().join("scenes/lake_hume_bloom.ron")).unwrap();
    let land = hume.replace(
        "    effects: [],",
        "    land: Some((mask: Constant(0.0), reflectance: Constant(1000000.0))),\n    effects: [],",
    );
    std::fs::write(dir.join("land.ron"), land).unwrap();
    let cubesat = std::fs::read_to_string(presets().join("instruments/cubesat.ron")).unwrap();
    let bias = cubesat.replace("adc_bits: 16", "adc_bits: 8").replace("bias_dn: 10.4", "bias_dn: 300.0");
    std::fs::write(dir.join("bias.ron"), bias).unwrap();
    let qe = cubesat.replace(
        "    detectors:",
        "    quantum_efficiency: PowerLaw(coefficient: 0.7, reference_nm: -1e308, exponent: 1.0),\n    detectors:",
    );
    std::fs::write(dir.join("qe.ron"), qe).unwrap();
    let cases: [(&str, Vec<&str>, &str); 3] = [
        (
            "land reflectance 1e6",
            vec!["simulate", "--scene", "land.ron", "--decimation", "64", "--out", "o"],
            "reflectance",
        ),
        (
            "bias_dn above an 8-bit ADC",
            vec!["simulate", "--instrument", "bias.ron", "--decimation", "64", "--out", "o"],
            "bias_dn",
        ),
        (
            "reference_nm -1e308",
            vec!["simulate", "--instrument", "qe.ron", "--decimation", "64", "--out", "o"],
            "reference_nm",
        ),
    ];
    for (what, args, said) in cases {
        let o = run(&dir, &args, &[], Duration::from_secs(60));
        tally.record("range-table gaps", what, o.refused(said, 60.0));
        let _ = std::fs::remove_dir_all(dir.join("o"));
    }
    let _ = std::fs::remove_dir_all(&dir);
}
