//! What the integration crates share (`#[path = "../common/mod.rs"] mod common;` in each
//! `main.rs`): how a `src/ranges.rs` path is reached in a run configuration.
//!
//! Each crate uses a part of it; the rest is unused there.
#![allow(dead_code)]

use shoal::retrieval::RetrievalSpec;

/// The built-in instrument in which the `ranges` path exists: a spectrograph's or filter
/// imager's `kind` fields need that kind; everything else is on the Table 1 CubeSat.
#[must_use]
pub fn instrument_for(path: &str) -> &'static str {
    if path.contains("Spectrograph") || path.contains("smile_pct") || path.contains("Binning.spectral") {
        "hyperspectral"
    } else if path.contains("FilterImager") {
        "filter_imager"
    } else if path.contains("focal_planes") || path.contains("dark_temperature") {
        "smallsat_swir"
    } else {
        "cubesat"
    }
}

/// Both retrievals with their defaults, aLMI first and SAMBUCA second, so every
/// `retrievals[i]` path of the ranges table exists ([`sweep_path`] picks the index).
#[must_use]
pub fn both_retrievals() -> Vec<RetrievalSpec> {
    vec![ron::from_str("Almi()").unwrap(), ron::from_str("Sambuca()").unwrap()]
}

/// An external retrieval running `command` (allowed for this process), placed third after
/// [`both_retrievals`] where a ranges path names `External`.
#[must_use]
pub fn external_retrieval(command: &[&str]) -> RetrievalSpec {
    let command: Vec<String> = command.iter().map(|s| (*s).to_string()).collect();
    shoal::retrieval::external::allow(&command);
    RetrievalSpec::External(shoal::retrieval::external::ExternalSpec {
        name: "mine".into(),
        command,
        products: vec!["chl_mg_m3".into()],
        bands: None,
        function: None,
        time_limit_s: 300.0,
    })
}

/// A ranges-table path as `sweep::apply` walks it: `[i]` becomes the index of the retrieval
/// the path names in [`both_retrievals`] (an external one is third: [`external_retrieval`]).
#[must_use]
pub fn sweep_path(path: &str) -> String {
    let index = if path.contains("Sambuca") {
        ".1"
    } else if path.contains("External") {
        ".2"
    } else {
        ".0"
    };
    // The ranges table names a further focal plane `focal_planes[]`; the SWIR SmallSat has one.
    // The dark-current laws: the first plane's doubles ([`with_dark_laws`]), the SWIR plane's is
    // Arrhenius.
    // The instrument's effects: stray light, polarisation, the MTF budget, spectral stray light,
    // non-linearity, fixed patterns, misregistration, compression, spectral knowledge, binning,
    // TDI ([`with_optical_effects`]).
    let path = path
        .replace("[i]", index)
        .replace("focal_planes[]", "focal_planes.0")
        .replace("effects[].StrayLight", "effects.0.StrayLight")
        .replace("effects[].Polarisation", "effects.1.Polarisation")
        .replace("effects[].SpatialResponse", "effects.2.SpatialResponse")
        .replace("effects[].SpectralStrayLight", "effects.3.SpectralStrayLight")
        .replace("effects[].NonLinearity", "effects.4.NonLinearity")
        .replace("effects[].FixedPatterns", "effects.5.FixedPatterns")
        .replace("effects[].Misregistration", "effects.6.Misregistration")
        .replace("effects[].Compression", "effects.7.Compression")
        .replace("effects[].SpectralKnowledge", "effects.8.SpectralKnowledge")
        .replace("effects[].Binning", "effects.9.Binning")
        // Last: a spectrograph's list has no TDI ([`with_optical_effects`]).
        .replace("effects[].Tdi", "effects.10.Tdi");
    // The image-based correction's lists: the pair's long band, the AOT node 0.2, the start of
    // dark-spectrum fitting's band range.
    let path = match path.as_str() {
        "correction.image.pair_nm" => "correction.image.pair_nm.1".to_string(),
        "correction.image.dark.wave_range_nm" => "correction.image.dark.wave_range_nm.0".to_string(),
        "correction.image.aot_nodes" => "correction.image.aot_nodes.2".to_string(),
        _ => path,
    };
    match path.strip_prefix("instrument.dark_temperature.law.Arrhenius") {
        Some(rest) => format!("instrument.focal_planes.0.dark_temperature.law.Arrhenius{rest}"),
        None => path,
    }
}

/// Give an instrument with further focal planes every optional field the ranges table names:
/// the first plane a dark current specified at 20 °C with silicon's doubling law, run at 0 °C
/// (the SWIR SmallSat's SWIR plane has the Arrhenius law), and each further plane its own
/// integration time (by default it follows the first's).
pub fn with_dark_laws(instrument: &mut shoal::instrument::InstrumentSpec) {
    if !instrument.focal_planes.is_empty() {
        instrument.dark_temperature = Some(shoal::instrument::DarkTemperature {
            reference_c: 20.0,
            operating_c: 0.0,
            law: shoal::instrument::DarkLaw::Doubling { delta_c: 6.3 },
        });
        let t = instrument.exposure_s;
        for p in &mut instrument.focal_planes {
            p.exposure_s = Some(2.0 * t);
        }
    }
}

/// Give an instrument the effects the ranges table names, every field set away from its
/// default: stray light (a 5 % halo over 600 m, a 1 % veil, the processor 10 % wrong), a 2 %
/// polarisation sensitivity at 10° (the processor 10 % wrong), an MTF budget, 1 % spectral stray
/// light (the processor 10 % wrong), a 2 % non-linearity (the calibration 10 % wrong), fixed
/// patterns (15 % dead and 15 % hot elements, so that a 10 % change of either share changes
/// which elements of a small image are), a 0.2 px misregistration, a near-lossless coder,
/// bands 0.3 nm off what the processor believes (0.2 nm rms more, 5 % wider, the smile 10 %
/// larger), binning of 1 (none: a change to 2 bins) and 4 TDI stages with a 0.5 % line-rate error
/// and a CTE of 0.9999 (last, and not on a spectrograph, which refuses TDI).
pub fn with_optical_effects(instrument: &mut shoal::instrument::InstrumentSpec) {
    instrument.effects = ron::from_str(
        "[StrayLight((halo_fraction: 0.05, knee_m: 60.0, slope: 2.5, radius_m: 600.0, out_of_field_fraction: 0.01, \
          wavelength_exponent: 2.0, correction: (corrected: true, error: 0.1))), \
          Polarisation((sensitivity: 0.02, axis_deg: 10.0, correction: (corrected: true, error: 0.1))), \
          SpatialResponse((obstruction: 0.3, wavefront_rms_nm: 30.0, pixel_fill: 0.9, diffusion_um: 2.0, \
          crosstalk: 0.02, jitter_urad: 3.0)), \
          SpectralStrayLight((fraction: 0.01, width_nm: 80.0, correction: (corrected: true, error: 0.1))), \
          NonLinearity((quadratic: -0.02, cubic: 0.004, column_spread: 0.1, correction: (corrected: true, error: 0.1))), \
          FixedPatterns((gain_drift: 0.002, offset_drift_e: 5.0, dead_fraction: 0.15, hot_fraction: 0.15, \
          hot_dark_current_e_s: 5000.0)), \
          Misregistration((sigma_px: 0.2, correction: (corrected: true, error: 0.1))), \
          Compression((max_error_dn: 2)), \
          SpectralKnowledge((centre_nm: 0.3, sigma_nm: 0.2, width_pct: 5.0, smile_pct: 10.0)), \
          Binning((factor: 1)), \
          Tdi((stages: 4, line_rate_error: 0.005, cte: 0.9999))]",
    )
    .unwrap();
    if matches!(instrument.kind, shoal::instrument::InstrumentKind::Spectrograph { .. }) {
        instrument.effects.retain(|e| !matches!(e, shoal::instrument::InstrumentEffect::Tdi(_)));
    }
}

/// Does the Debian tool `tool` (package `package`) run on this machine? The README's test
/// command must pass on a machine with the Rust toolchain only, so a test that needs one prints
/// one line naming the package and skips when it is absent. Under `.ci/run`, which installs the
/// packages and sets `SHOAL_REQUIRE_TOOLS=1`, absence is a failure instead.
#[must_use]
pub fn tool_available(tool: &str, package: &str) -> bool {
    let runs = std::process::Command::new(tool)
        .arg("--version")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok();
    if !runs {
        assert!(
            std::env::var_os("SHOAL_REQUIRE_TOOLS").is_none(),
            "{tool} does not run and SHOAL_REQUIRE_TOOLS is set: install {package} (`apt-get install {package}`)"
        );
        eprintln!("skipped: needs {tool}; install {package} (`apt-get install {package}`) to run this test");
    }
    runs
}

/// A Python interpreter that imports `modules` (Debian's `/usr/bin/python3` first: a user's
/// pyenv or virtualenv `python3` may lack the Debian packages), or `None` after one line naming
/// the packages; under `SHOAL_REQUIRE_TOOLS` their absence fails, as in [`tool_available`].
#[must_use]
pub fn python_with(modules: &str, packages: &str) -> Option<&'static str> {
    let found = ["/usr/bin/python3", "python3"].into_iter().find(|python| {
        std::process::Command::new(python)
            .args(["-c", &format!("import {modules}")])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    });
    if found.is_none() {
        assert!(
            std::env::var_os("SHOAL_REQUIRE_TOOLS").is_none(),
            "no python3 imports {modules} and SHOAL_REQUIRE_TOOLS is set: install {packages} (`apt-get install {packages}`)"
        );
        eprintln!(
            "skipped: needs python3 with {modules}; install {packages} (`apt-get install {packages}`) to run this test"
        );
    }
    found
}

/// The cubes of a run of an engine that keeps them (`Engine::new`), for tests that read them.
pub trait Kept {
    /// The run's cubes.
    fn kept(&self) -> &shoal::engine::Cubes;
}

impl Kept for shoal::engine::RunOutput {
    fn kept(&self) -> &shoal::engine::Cubes {
        self.cubes.as_ref().expect("an engine made by Engine::new keeps its cubes")
    }
}

/// A directory of its own under the system's temporary directory, made empty when created and
/// removed with everything in it when dropped, so a test run leaves nothing behind (it derefs to
/// its path).
pub struct TempDir(std::path::PathBuf);

impl TempDir {
    /// `shoal-{kind}-{name}-{process id}`, empty.
    #[must_use]
    pub fn new(kind: &str, name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("shoal-{kind}-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl std::ops::Deref for TempDir {
    type Target = std::path::PathBuf;
    fn deref(&self) -> &std::path::PathBuf {
        &self.0
    }
}

impl AsRef<std::path::Path> for TempDir {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for TempDir {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
