//! Retrievals run in-process (`shoal::retrieval::function`, what the Python package registers):
//! given the external program's input in memory, scored exactly as a program that writes the same
//! maps, and every way it can go wrong costing its own product only.

use std::sync::{Arc, Mutex};

use shoal::engine::RunOutput;
use shoal::netcdf::{Column, InMemory, Maps};
use shoal::retrieval::RetrievalSpec;
use shoal::retrieval::external::ExternalSpec;
use shoal::retrieval::function;

use super::external::{assert_almi_kept, external, run_with};
use super::netcdf::{product_file, tempfile_dir::Dir};

/// A retrieval calling the function registered as `registered`.
fn calling(name: &str, registered: &str) -> RetrievalSpec {
    RetrievalSpec::External(ExternalSpec {
        name: name.into(),
        command: Vec::new(),
        function: Some(registered.into()),
        products: vec!["chl_mg_m3".into()],
        bands: None,
        time_limit_s: ExternalSpec::DEFAULT_TIME_LIMIT_S,
    })
}

/// The truth's chl × 1.1 on water and `None` elsewhere, as a (line, pixel) list.
fn truth_times_1_1(out: &RunOutput) -> Vec<Option<f64>> {
    let t = &out.truth;
    t.chl_mg_m3
        .indexed_iter()
        .map(|((r, c), v)| (t.surface.codes()[[r, c]] == 0).then_some(f64::from(v * 1.1)))
        .collect()
}

#[test]
fn a_function_scores_as_the_program_that_writes_the_same_maps() {
    let reference = run_with(external("copy_missing_f", &["true"], &["chl_mg_m3"]));
    let values = truth_times_1_1(&reference);
    let shape = reference.truth.chl_mg_m3.dim();
    // The program copies a file of these values (f32, the fill value off water) ...
    let dir = Dir::new("function-vs-program");
    let file = dir.path().join("made.nc");
    let as_f32: Vec<f32> = values.iter().map(|v| v.map_or(-9999.0, |x| x as f32)).collect();
    product_file(&file, shape, &[("chl_mg_m3", as_f32.clone())]);
    let program = run_with(external("same", &["cp", file.to_str().unwrap(), "{output}"], &["chl_mg_m3"]));
    // ... the function returns them, through f32 as the file stores them.
    let maps = Maps {
        shape,
        maps: vec![("chl_mg_m3".into(), as_f32.iter().map(|&v| (v != -9999.0).then_some(f64::from(v))).collect())],
        names: vec!["chl_mg_m3".into()],
    };
    function::register("same_maps", Arc::new(move |_: &InMemory, _: &_| Ok(maps.clone())));
    let here = run_with(calling("same", "same_maps"));
    assert_almi_kept(&here);
    let (a, b) = (&here.retrievals[1], &program.retrievals[1]);
    assert!(a.failure.is_none() && b.failure.is_none(), "{:?} {:?}", a.failure, b.failure);
    assert_eq!(a.product.flags, b.product.flags);
    assert_eq!(a.product.chl_mg_m3, b.product.chl_mg_m3);
    assert_eq!(format!("{:?}", a.metrics), format!("{:?}", b.metrics));
    let m = a.metrics.get("chl_mg_m3").unwrap();
    assert!(m.n > 100 && (m.mae_pct() - 10.0).abs() < 1e-4, "{} px, MAE {} %", m.n, m.mae_pct());
}

#[test]
fn a_function_is_given_the_programs_input_and_never_the_truth() {
    let seen: Arc<Mutex<Option<InMemory>>> = Arc::default();
    let keep = Arc::clone(&seen);
    function::register(
        "keeps_its_input",
        Arc::new(move |input: &InMemory, _: &_| {
            *keep.lock().unwrap() = Some(input.clone());
            Err("kept the input".into())
        }),
    );
    let out = run_with(calling("keeper", "keeps_its_input"));
    // Its error costs its own product only, and says which function.
    assert_almi_kept(&out);
    let failure = out.retrievals[1].failure.as_deref().unwrap();
    assert!(failure.contains("keeps_its_input") && failure.contains("kept the input"), "{failure}");
    let input = seen.lock().unwrap().take().unwrap();
    let names: Vec<&str> = input.variables.iter().map(|v| v.name.as_str()).collect();
    for wanted in ["wavelength", "bandwidth", "nedr", "solar_zenith_angle", "sensor_zenith_angle", "rrs"] {
        assert!(names.contains(&wanted), "{wanted} missing from {names:?}");
    }
    assert!(names.iter().all(|n| !n.contains("true")), "{names:?}");
    let cubes = out.cubes.as_ref().expect("the test engine keeps its cubes");
    let (rows, cols, bands) = cubes.rrs.rrs.dim();
    let dims: Vec<(&str, usize)> = input.dims.iter().map(|(n, s)| (n.as_str(), *s)).collect();
    assert_eq!(&dims[..3], &[("line", rows), ("pixel", cols), ("band", bands)]);
    let rrs = input.variables.iter().find(|v| v.name == "rrs").unwrap();
    let Column::Float(values) = &rrs.values else { panic!("rrs is not float") };
    assert_eq!(values.len(), rows * cols * bands);
    // The water pixels' Rrs as the correction made it, band-interleaved.
    let i = values.iter().position(|&v| v != -9999.0).unwrap();
    let (r, c, b) = (i / (cols * bands), (i / bands) % cols, i % bands);
    assert_eq!(values[i], cubes.rrs.rrs[[r, c, b]]);
    assert!(input.attrs.iter().any(|(k, _)| k == "products_wanted"));
}

#[test]
fn an_unregistered_function_or_a_wrong_answer_costs_its_own_product_only() {
    let out = run_with(calling("nobody", "never_registered"));
    assert_almi_kept(&out);
    let failure = out.retrievals[1].failure.as_deref().unwrap();
    assert!(failure.contains("no function `never_registered` is registered"), "{failure}");
    function::register(
        "too_small",
        Arc::new(|_: &InMemory, _: &_| {
            Ok(Maps {
                shape: (2, 2),
                maps: vec![("chl_mg_m3".into(), vec![Some(1.0); 4])],
                names: vec!["chl_mg_m3".into()],
            })
        }),
    );
    let out = run_with(calling("small", "too_small"));
    let failure = out.retrievals[1].failure.as_deref().unwrap();
    assert!(failure.contains("2 × 2"), "{failure}");
    function::unregister("too_small");
    let out = run_with(calling("small", "too_small"));
    assert!(out.retrievals[1].failure.as_deref().unwrap().contains("no function `too_small`"));
}

#[test]
fn a_spec_names_a_program_or_a_function_never_both() {
    let both = ExternalSpec {
        name: "both".into(),
        command: vec!["true".into()],
        function: Some("f".into()),
        products: vec!["chl_mg_m3".into()],
        bands: None,
        time_limit_s: 10.0,
    };
    assert!(both.validate().unwrap_err().to_string().contains("External.function"));
    let empty = ExternalSpec { command: Vec::new(), function: Some(" ".into()), ..both.clone() };
    assert!(empty.validate().unwrap_err().to_string().contains("External.function"));
    let function_only = ExternalSpec { command: Vec::new(), ..both };
    assert!(function_only.validate().is_ok());
    // A registered function needs no consent; the file form leaves the empty command out.
    assert!(function_only.may_run());
    let text = ron::to_string(&function_only).unwrap();
    assert!(!text.contains("command") && text.contains("function:Some(\"f\")"), "{text}");
    let back: ExternalSpec = ron::from_str(&text).unwrap();
    assert_eq!(back, function_only);
}
