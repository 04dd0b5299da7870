//! The user's data always wins, or the clash is refused with a message: substrate spectra,
//! CSV tables, SIOP sets, band sets and the preset library (app and CLI). And with `SHOAL_HOME`
//! set, what Shoal writes for the user stays under it.

use std::path::{Path, PathBuf};
use std::process::Command;

use shoal::engine::RunConfig;
use shoal::instrument::InstrumentSpec;
use shoal::library::{Library, LibraryError, PresetKind};
use shoal::retrieval::RetrievalSpec;
use shoal::scene::SceneSpec;
use shoal::spectral::Extrapolation::Clamp;
use shoal::spectral::{BandSet, BandSetSpec, GaussianBand, Table};
use shoal::water::{SiopSpec, SubstrateLibrary};

fn temp(name: &str) -> crate::common::TempDir {
    crate::common::TempDir::new("user", name)
}

fn shoal(home: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_shoal"));
    c.env("SHOAL_HOME", home);
    c
}

/// A flat 0.9 reflectance under the user's names `coral` (an alias of the built-in Acropora),
/// `Sand` (a built-in name) and `kelp` (new).
fn user_substrates(dir: &Path) -> PathBuf {
    let path = dir.join("mine.csv");
    let rows: String = (350..=1000).step_by(50).map(|w| format!("{w},0.9,0.5,0.2\n")).collect();
    std::fs::write(&path, format!("wavelength_nm,coral,Sand,kelp\n{rows}")).unwrap();
    path
}

#[test]
fn a_users_substrate_column_wins_over_the_built_in_name_and_the_alias() {
    let dir = temp("substrates");
    let mut lib = SubstrateLibrary::embedded().unwrap();
    // Before: `coral` is the alias of Acropora, dark (≈ 0.03 at 450 nm, SAMBUCA HI_3).
    let acropora_450 = lib.get("coral").unwrap().spectrum.value_at(450.0, Clamp).unwrap();
    assert!(acropora_450 < 0.1, "{acropora_450}");
    lib.add_csv(&user_substrates(&dir)).unwrap();
    // The oracle is the file: the user's constants, exactly.
    assert_eq!(lib.get("coral").unwrap().spectrum.value_at(450.0, Clamp).unwrap(), 0.9);
    assert_eq!(lib.get("CORAL").unwrap().spectrum.value_at(700.0, Clamp).unwrap(), 0.9);
    assert_eq!(lib.get("sand").unwrap().spectrum.value_at(450.0, Clamp).unwrap(), 0.5);
    assert_eq!(lib.get("kelp").unwrap().spectrum.value_at(450.0, Clamp).unwrap(), 0.2);
    assert!(lib.get("sand").unwrap().description.contains("replaces the built-in `sand`"));
    assert!(lib.get("coral").unwrap().description.contains("replaces the alias `coral`"));
    // The other alias and the built-ins the user did not name are untouched.
    assert!(lib.get("algae").unwrap().description.contains("turf algae"));
    assert!((lib.get("acropora").unwrap().spectrum.value_at(450.0, Clamp).unwrap() - acropora_450).abs() < 1e-12);
    // Two columns that are one name once lower-cased: refused, naming both.
    let dup = dir.join("dup.csv");
    std::fs::write(&dup, "wavelength_nm,Kelp,kelp\n400,0.1,0.2\n700,0.1,0.2\n").unwrap();
    let e = SubstrateLibrary::embedded().unwrap().add_csv(&dup).unwrap_err().to_string();
    assert!(e.contains("`Kelp`") && e.contains("`kelp`") && e.contains("dup.csv"), "{e}");
}

#[test]
fn shoal_water_uses_the_users_coral_column() {
    let dir = temp("water-cli");
    let csv = user_substrates(&dir);
    let out = shoal(&dir)
        .args(["water", "--depth", "2", "--substrate", "coral:1", "--wavelengths", "450,550"])
        .arg("--substrate-csv")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    let table = Table::parse(&text, "shoal water").unwrap();
    assert_eq!(table.column_f64("r_substratum").unwrap(), vec![0.9, 0.9], "{text}");
}

#[test]
fn a_table_with_a_repeated_column_is_refused() {
    let e = Table::parse("wavelength_nm,sand,sand\n400,1,2\n", "t.csv").unwrap_err().to_string();
    assert!(e.contains("`sand` appears twice") && e.contains("t.csv"), "{e}");
}

#[test]
fn a_siop_csv_with_an_unknown_column_is_refused_not_filled_from_heron_island() {
    let dir = temp("siop");
    let path = dir.join("my_siop.csv");
    // `aph_star` is a misspelling of `a_ph_star`: used to be skipped, leaving heron_island's a*_ph.
    std::fs::write(&path, "wavelength_nm,a_cdom_star,aph_star\n400,1.2,0.05\n800,0.1,0.001\n").unwrap();
    let e = SiopSpec::from_csv_columns(&path).unwrap_err().to_string();
    assert!(e.contains("`aph_star`") && e.contains("a_ph_star") && e.contains("my_siop.csv"), "{e}");
    std::fs::write(&path, "wavelength_nm,a_cdom_star,a_ph_star\n400,1.2,0.05\n800,0.1,0.001\n").unwrap();
    assert!(SiopSpec::from_csv_columns(&path).is_ok());
}

#[test]
fn two_siop_sets_of_one_name_are_refused_by_almi() {
    let dir = temp("sets");
    // The user's own set, written with the name of a built-in set.
    let mut set = SiopSpec::preset("almi_3").unwrap();
    set.description = "my lake".into();
    set.name = "almi_1".into();
    let path = dir.join("mine.ron");
    std::fs::write(&path, ron::ser::to_string(&set).unwrap()).unwrap();
    let mut c =
        RunConfig::new(SceneSpec::preset("lake_hume_bloom").unwrap(), InstrumentSpec::preset("cubesat").unwrap());
    c.instrument.detectors = 8;
    c.instrument.lines = 6;
    c.retrievals = vec![RetrievalSpec::Almi {
        siop_sets: vec![shoal::water::SiopSource::Preset("almi_1".into()), shoal::water::SiopSource::File(path)],
        settings: Default::default(),
    }];
    let e = shoal::engine::Engine::new().run(&c, &shoal::control::RunControl::new()).unwrap_err().to_string();
    assert!(e.contains("two SIOP sets are called `almi_1`"), "{e}");
}

#[test]
fn two_bands_of_one_name_are_refused() {
    let two = |a: Option<&str>, b: Option<&str>| {
        BandSetSpec::Gaussian(vec![
            GaussianBand { name: a.map(String::from), centre_nm: 443.0, fwhm_nm: 10.0 },
            GaussianBand { name: b.map(String::from), centre_nm: 560.0, fwhm_nm: 10.0 },
        ])
    };
    let e = BandSet::from_spec(&two(Some("blue"), Some("blue"))).unwrap_err().to_string();
    assert!(e.contains("two bands are called `blue`"), "{e}");
    assert_eq!(BandSet::from_spec(&two(Some("blue"), None)).unwrap().bands[1].name, "B560");
    let olci = BandSetSpec::Olci { platform: Default::default(), bands: Some(vec!["Oa08".into(), "Oa08".into()]) };
    assert!(BandSet::from_spec(&olci).unwrap_err().to_string().contains("`Oa08`"));
}

#[test]
fn the_preset_library_refuses_a_built_in_name_and_lets_a_users_file_win() {
    let home = temp("library");
    let lib = Library::at(&home.join("presets"));
    let mut spec = InstrumentSpec::preset("cubesat").unwrap();
    spec.aperture_mm = 95.0;
    let e = lib.save_instrument("cubesat", &spec, false).unwrap_err();
    assert!(matches!(e, LibraryError::Builtin { .. }), "{e}");
    assert_eq!(e.to_string(), "`cubesat` is a built-in instrument; save yours under another name");
    assert!(lib.save_instrument("cubesat", &spec, true).is_err(), "overwrite does not apply to built-ins");
    // A file with a built-in name put there by hand (or by an older Shoal): the user's wins, and
    // the name appears once.
    let dir = home.join("presets").join("instruments");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("cubesat.ron"), ron::ser::to_string(&spec).unwrap()).unwrap();
    let entries = lib.list(PresetKind::Instrument);
    assert_eq!(entries.iter().filter(|e| e.name == "cubesat").count(), 1);
    let entry = lib.find(PresetKind::Instrument, "cubesat").unwrap();
    assert!(!entry.builtin);
    assert_eq!(lib.load_instrument(&entry).unwrap().aperture_mm, 95.0);
}

#[test]
fn the_cli_resolves_a_preset_name_as_the_library_does() {
    let home = temp("cli-library");
    let lib = Library::at(&home.join("presets"));
    let mut spec = InstrumentSpec::preset("cubesat").unwrap();
    spec.name = "my_cube".into();
    spec.detectors = 6;
    spec.lines = 4;
    lib.save_instrument("my_cube", &spec, false).unwrap();
    let out_dir = home.join("out");
    let out = shoal(&home)
        .args(["simulate", "--scene", "lake_hume_bloom", "--instrument", "my_cube", "--out"])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let config = std::fs::read_to_string(out_dir.join("config.ron")).unwrap();
    assert!(config.contains("detectors: 6"), "the user's preset ran: {config}");
    // An unknown name still exits 2 with the names there are.
    let bad = shoal(&home).args(["simulate", "--instrument", "nosuch", "--out"]).arg(&out_dir).output().unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
