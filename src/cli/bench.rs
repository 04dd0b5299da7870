//! `shoal bench`: what Shoal's physics costs in time and what it buys in accuracy, side by side
//! with the reference codes' figures, each printed with where and when it was measured
//! ([`super::bench_reference`]; OSOAA: 1–3.5 s per wavelength and geometry), and the whole chain
//! against its targets ([`super::bench_chain`]).

use std::time::{Duration, Instant};

use clap::Args;

use std::fmt::Write as _;

use super::CliError;

/// Append a line to a report (writing to a `String` cannot fail).
macro_rules! say {
    ($out:expr) => {
        $out.push('\n')
    };
    ($out:expr, $($t:tt)*) => {{
        let _ = writeln!($out, $($t)*);
    }};
}
use super::output::emit;
use crate::atmosphere::{AerosolType, AtmosphereLut, AtmosphereSpec, LutAxes, RtAccuracy};
use crate::spectral::{BandSet, BandSetSpec, WavelengthGrid};
use crate::validation::{Comparison, compare_paths, compare_water_runs};
use crate::water::{
    Bottom, SingleScratch, SingleWater, SiopSpec, SubstrateLibrary, SubstrateMix, WaterColumn, WaterGeometry,
    WaterModel,
};

/// The configuration `shoal bench --accuracy` prices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AccuracyCase {
    /// aLMI (eight SIOP sets) on the CubeSat over Lake Hume, full resolution.
    Almi,
    /// SAMBUCA (Acropora, sand, turf algae) on the nominal instrument over the Heron Island reef
    /// with the spatial response switched on, at 1/2 resolution.
    Sambuca,
}

/// Flags of `shoal bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Fewer repetitions (a smoke run; figures are noisier).
    #[arg(long)]
    pub quick: bool,
    /// Only the cost-of-accuracy table: time and error of each fidelity setting against the
    /// full-fidelity run.
    #[arg(long)]
    pub accuracy: bool,
    /// With `--accuracy`: also print the settings on the time–error Pareto front.
    #[arg(long)]
    pub pareto: bool,
    /// With `--accuracy`: name the cheapest setting whose chl error from the full-fidelity run
    /// stays within this many percent (median per-pixel difference; |ΔMAE| for a coarser grid).
    #[arg(long, value_name = "PCT")]
    pub tolerance_pct: Option<f64>,
    /// With `--accuracy`: the product whose per-pixel error from the full-fidelity run the
    /// Pareto front and `--tolerance-pct` read (bottom: % of pixels whose bottom type changes).
    #[arg(long, default_value = "chl", value_parser = ["chl", "nap", "cdom", "depth", "bottom"])]
    pub error_of: String,
    /// With `--accuracy`: interleaved rounds (each setting timed once per round, paired with
    /// the reference's runs either side): at least 5 for any claim at 90 % coverage, 8 or more
    /// to tolerate one slow run.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=50))]
    pub rounds: u32,
    /// With `--accuracy`: the case priced — aLMI on the CubeSat over Lake Hume, or SAMBUCA on
    /// the nominal instrument over the Heron Island reef with its spatial response (at 1/2 of
    /// full resolution: a full-resolution SAMBUCA run takes ~20 s, and the table runs 28
    /// settings × the rounds).
    #[arg(long, value_enum, default_value_t = AccuracyCase::Almi)]
    pub case: AccuracyCase,
    /// Skip the app rows (slider-to-preview latency and frame time; only with the `gui` feature).
    #[arg(long)]
    pub no_app: bool,
    /// Only these sections (comma-separated; default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub only: Vec<Section>,
}

/// A section of `shoal bench`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Section {
    /// The water model's evaluations per second.
    Water,
    /// Atmosphere LUT builds and their errors against OSOAA.
    Atmosphere,
    /// The whole chain over Lake Hume, and the preview after each kind of change.
    Chain,
    /// Retrieval pixels per second, and the default study end to end.
    Retrieval,
    /// The app: slider to preview on screen (`gui` build only).
    App,
}

/// The CPU's model name (`/proc/cpuinfo`, read once), or "unknown CPU".
pub(super) fn cpu_model() -> &'static str {
    static MODEL: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    MODEL.get_or_init(|| {
        std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split(':').nth(1))
                    .map(|s| s.trim().to_string())
            })
            .unwrap_or_else(|| "unknown CPU".into())
    })
}

fn machine() -> String {
    let cpu = cpu_model();
    let threads = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    format!(
        "{cpu}, {threads} logical cores, rayon pool {} threads, vector kernels at {}",
        rayon::current_num_threads(),
        crate::simd::widest_level()
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median rate (calls per second) of `f` over `reps` repetitions of about `each`.
fn rate(reps: usize, each: Duration, mut f: impl FnMut(usize)) -> f64 {
    let samples = (0..reps)
        .map(|_| {
            let start = Instant::now();
            let mut n = 0;
            while start.elapsed() < each {
                for _ in 0..100 {
                    f(n);
                    n += 1;
                }
            }
            n as f64 / start.elapsed().as_secs_f64()
        })
        .collect();
    median(samples)
}

fn water_rows(out: &mut String, quick: bool) -> Result<(), CliError> {
    // SAMBUCA's benchmark configuration: 350–800 nm at 1 nm (451 bands), its default SIOPs.
    let grid = WavelengthGrid::uniform(350.0, 800.0, 1.0)?;
    let model = WaterModel::new(SiopSpec::sambuca_default().resolve(&grid, None)?);
    let rb =
        SubstrateLibrary::embedded()?.mix_on_grid(&SubstrateMix::parse("ncc_sand:0.5,brown_acropora:0.5")?, &grid)?;
    let geo = WaterGeometry::from_degrees(30.0, 0.0);
    let mut rrs = vec![0.0; grid.len()];
    let (reps, each) = if quick { (3, Duration::from_millis(100)) } else { (7, Duration::from_millis(400)) };
    let mut sink = 0.0;
    let column = |n: usize, bottom| WaterColumn {
        chl_mg_m3: 1.0 + (n % 7) as f64 * 0.1,
        cdom_per_m: 0.05,
        nap_g_m3: 2.0,
        bottom,
    };
    let shallow = |n: usize| Bottom::Shallow { depth_m: 5.0 + (n % 5) as f64, reflectance: &rb };
    let fast_shallow = rate(reps, each, |n| {
        let _ = model.rrs_above_into(&column(n, shallow(n)), &geo, &mut rrs);
        sink += rrs[100];
    });
    let fast_deep = rate(reps, each, |n| {
        let _ = model.rrs_above_into(&column(n, Bottom::OpticallyDeep), &geo, &mut rrs);
        sink += rrs[100];
    });
    // The single-precision kernel (the fidelity setting `water_single_precision`).
    let single = SingleWater::new(&model);
    let mut work = SingleScratch::default();
    let single_shallow = rate(reps, each, |n| {
        let _ = single.rrs_above_into(&column(n, shallow(n)), &geo, &mut work, &mut rrs);
        sink += rrs[100];
    });
    let single_deep = rate(reps, each, |n| {
        let _ = single.rrs_above_into(&column(n, Bottom::OpticallyDeep), &geo, &mut work, &mut rrs);
        sink += rrs[100];
    });
    let full = rate(reps, each, |n| {
        if let Ok(r) = model.evaluate(&column(n, shallow(n)), &geo) {
            sink += r.rrs[100];
        }
    });
    std::hint::black_box(sink);
    say!(out, "## Water model (Lee 1998/1999), 451 bands, one thread");
    say!(out);
    let (shallow_ref, deep_ref) =
        (super::bench_reference::SAMBUCA_FORWARD, super::bench_reference::SAMBUCA_FORWARD_DEEP);
    say!(
        out,
        "| evaluation | evaluations/s | {} (deep rows: {}), calls/s | × reference |",
        shallow_ref.what,
        deep_ref.what
    );
    say!(out, "|---|---|---|---|");
    // Deep rows against the reference's deep call, shallow rows against its shallow call.
    for (label, r, reference) in [
        ("shallow, Rrs only (per-pixel path)", fast_shallow, shallow_ref),
        ("optically deep, Rrs only", fast_deep, deep_ref),
        ("shallow, every intermediate", full, shallow_ref),
        ("shallow, Rrs only, single precision (setting `water_single_precision`)", single_shallow, shallow_ref),
        ("optically deep, Rrs only, single precision", single_deep, deep_ref),
    ] {
        say!(out, "| {label} | {:.0} | {} | {} |", r, reference.text(), reference.ratio_here(r));
    }
    say!(out);
    say!(out, "{}", super::bench_reference::SIDE_BY_SIDE);
    if let Some(w) = super::bench_reference::other_machine(cpu_model()) {
        say!(out);
        say!(out, "{w}");
    }
    say!(out);
    Ok(())
}

fn max_abs(c: &[Comparison], keep: impl Fn(&Comparison) -> bool) -> f64 {
    c.iter().filter(|x| keep(x)).map(|x| x.error_pct().abs()).fold(0.0, f64::max)
}

fn atmosphere_rows(out: &mut String, quick: bool) -> Result<(), CliError> {
    let olci = BandSet::from_spec(&BandSetSpec::parse_cli("olci")?)?;
    let axes = LutAxes::covering(olci.centres_nm(), (55.0, 65.0), 40.0, (5.0, 5.0, 10.0));
    let nodes = axes.wavelengths_nm.len() * axes.sun_zenith_deg.len();
    say!(out, "## Atmosphere LUT, 19 OLCI bands (Lake Hume scene: continental AOT 0.1, sun 55–65°, view 0–40°)");
    say!(out);
    say!(
        out,
        "LUT nodes: {} wavelengths × {} sun × {} view × {} azimuth; OSOAA would need {nodes} runs × 1–3.5 s = {}–{} s.",
        axes.wavelengths_nm.len(),
        axes.sun_zenith_deg.len(),
        axes.view_zenith_deg.len(),
        axes.relative_azimuth_deg.len(),
        nodes,
        (nodes as f64 * 3.5).round()
    );
    say!(
        out,
        "Errors are max |Shoal/OSOAA − 1| over the reference rows (OSOAA's Rayleigh depth, relative azimuth 90°)."
    );
    say!(out);
    say!(
        out,
        "| accuracy | LUT build (median) | × faster than OSOAA | ρ_path Rayleigh | ρ_path aerosol | t_down | Ed(0+) coupled | T_up Heron | T_up Hume |"
    );
    say!(out, "|---|---|---|---|---|---|---|---|---|");
    for preset in ["single", "fast", "default", "high"] {
        let acc = RtAccuracy::preset(preset).ok_or_else(|| CliError::Run(format!("preset {preset}")))?;
        let atm =
            AtmosphereSpec { aerosol: AerosolType::Continental, aot550: 0.1, accuracy: acc, ..Default::default() }
                .build()?;
        let reps = if quick { 1 } else { 5 };
        let times: Vec<f64> = (0..reps)
            .map(|_| {
                let start = Instant::now();
                let lut = AtmosphereLut::build(&atm, axes.clone());
                std::hint::black_box(&lut);
                start.elapsed().as_secs_f64()
            })
            .collect();
        let t = median(times);
        let paths = compare_paths(&acc)?;
        let water = compare_water_runs(&acc)?;
        let aerosol = |c: &Comparison| c.aerosol != AerosolType::None;
        say!(
            out,
            "| {preset} | {:.3} s | {:.0}–{:.0} | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.2} % |",
            t,
            nodes as f64 / t,
            nodes as f64 * 3.5 / t,
            max_abs(&paths, |c| c.quantity == "rho_path" && !aerosol(c)),
            max_abs(&paths, |c| c.quantity == "rho_path" && aerosol(c)),
            max_abs(&paths, |c| c.quantity == "t_down"),
            max_abs(&water, |c| c.quantity == "ed_0plus"),
            max_abs(&water, |c| c.quantity == "t_up"
                && c.case.starts_with("heron")
                && c.lw_fraction.unwrap_or(0.0) > 0.1),
            max_abs(&water, |c| c.quantity == "t_up"
                && c.case.starts_with("hume")
                && c.lw_fraction.unwrap_or(0.0) > 0.1),
        );
    }
    say!(out);
    say!(
        out,
        "T_up columns use rows where the water-leaving radiance is above 10 % of the TOA radiance (OSOAA's T_up_eff is a difference of two large numbers otherwise). Hume's T_up_eff includes the bidirectional shape of that turbid water's radiance at 60° sun, which Shoal's water-leaving radiance (an isotropic in-water field) does not have: see docs/PHYSICS.md, \"Accuracy against OSOAA\"."
    );
    Ok(())
}

/// Print the per-band comparison with OSOAA as a Markdown table (worst case over the reference
/// geometries of each band), at default accuracy.
pub fn osoaa_table() -> Result<(), CliError> {
    let mut out = String::new();
    let acc = RtAccuracy::default();
    let paths = compare_paths(&acc)?;
    let water = compare_water_runs(&acc)?;
    say!(
        out,
        "| band | nm | ρ_path Rayleigh (4 geometries) | ρ_path continental (sun 60°) | t_down (5) | Ed(0+) coupled Heron / Hume | T_up Heron / Hume | L_path Heron / Hume |"
    );
    say!(out, "|---|---|---|---|---|---|---|---|");
    let worst = |c: &[Comparison], keep: &dyn Fn(&Comparison) -> bool| -> String {
        c.iter()
            .filter(|x| keep(x))
            .map(Comparison::error_pct)
            .fold(None, |a: Option<f64>, e| Some(a.map_or(e, |a| if e.abs() > a.abs() { e } else { a })))
            .map_or_else(|| "–".into(), |e| format!("{e:+.2} %"))
    };
    let olci = BandSet::from_spec(&BandSetSpec::parse_cli("olci")?)?;
    let nominal = [
        400.0, 411.8, 442.9, 490.5, 510.5, 560.5, 620.4, 665.3, 674.0, 681.6, 709.1, 754.2, 761.7, 764.8, 767.9, 779.2,
        865.4, 884.3, 897.4,
    ];
    for (band, wl) in olci.bands.iter().zip(nominal) {
        let at = |x: &Comparison| (x.wavelength_nm - wl).abs() < 0.05;
        let scen = |x: &Comparison, s: &str| at(x) && x.case.starts_with(s);
        say!(
            out,
            "| {} | {wl} | {} | {} | {} | {} / {} | {} / {} | {} / {} |",
            band.name,
            worst(&paths, &|x| at(x) && x.quantity == "rho_path" && x.aerosol == AerosolType::None),
            worst(&paths, &|x| at(x) && x.quantity == "rho_path" && x.aerosol != AerosolType::None),
            worst(&paths, &|x| at(x) && x.quantity == "t_down"),
            worst(&water, &|x| scen(x, "heron") && x.quantity == "ed_0plus"),
            worst(&water, &|x| scen(x, "hume") && x.quantity == "ed_0plus"),
            worst(&water, &|x| scen(x, "heron") && x.quantity == "t_up"),
            worst(&water, &|x| scen(x, "hume") && x.quantity == "t_up"),
            worst(&water, &|x| scen(x, "heron") && x.quantity == "l_path"),
            worst(&water, &|x| scen(x, "hume") && x.quantity == "l_path"),
        );
    }
    emit(&out, None)
}

/// Run `shoal bench`.
pub fn run(args: &BenchArgs) -> Result<(), CliError> {
    let mut out = String::new();
    say!(out, "# shoal bench");
    say!(out);
    say!(out, "Machine: {}", machine());
    say!(out);
    emit(&std::mem::take(&mut out), None)?;
    if args.accuracy {
        super::bench_accuracy::accuracy_rows(&mut out, args)?;
        return emit(&out, None);
    }
    let wanted = |s: Section| args.only.is_empty() || args.only.contains(&s);
    if wanted(Section::Water) {
        water_rows(&mut out, args.quick)?;
        emit(&std::mem::take(&mut out), None)?;
    }
    if wanted(Section::Atmosphere) {
        atmosphere_rows(&mut out, args.quick)?;
        emit(&std::mem::take(&mut out), None)?;
    }
    if wanted(Section::Chain) {
        super::bench_chain::chain_rows(&mut out, args.quick)?;
        emit(&std::mem::take(&mut out), None)?;
    }
    if wanted(Section::Retrieval) {
        super::bench_retrieval::retrieval_rows(&mut out, args.quick)?;
        emit(&std::mem::take(&mut out), None)?;
    }
    // The app rows need egui, which only the `gui` build has.
    #[cfg(feature = "gui")]
    if !args.no_app && wanted(Section::App) {
        out = crate::app::bench::rows(args.quick).map_err(CliError::Run)?;
    }
    emit(&out, None)
}
