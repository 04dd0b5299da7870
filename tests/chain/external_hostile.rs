//! An external program that misbehaves the ways a hostile or careless one would: its output a
//! FIFO, children left running after a normal exit, a name of a built-in retrieval, paths that
//! hold a placeholder's name. Each costs its own product only, never the run, and never hangs.

use shoal::retrieval::RetrievalSpec;
use shoal::retrieval::external::ExternalSpec;

use super::external::{assert_almi_kept, external, gone, run_with};
use super::netcdf::tempfile_dir::Dir;

#[test]
fn an_output_that_is_a_fifo_is_refused_at_once_not_waited_on() {
    // The program makes its output a FIFO and exits: reading it would block for ever (no writer).
    let mut spec = external("fifo_out", &["mkfifo", "{output}"], &["chl_mg_m3"]);
    if let RetrievalSpec::External(e) = &mut spec {
        e.time_limit_s = 30.0;
    }
    let start = std::time::Instant::now();
    let out = run_with(spec);
    assert!(start.elapsed().as_secs_f64() < 25.0, "waited {:?}", start.elapsed());
    let why = out.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("FIFO"), "{why}");
    assert_almi_kept(&out);
}

#[test]
fn what_a_program_leaves_running_ends_with_it_after_a_normal_exit() {
    let dir = Dir::new("external-orphans");
    let pid_file = dir.path().join("child.pid");
    // Starts a long sleep in the background, writes no output and exits 0 at once.
    let script = format!("sleep 60 & echo $! > '{}'; exit 0", pid_file.display());
    let out = run_with(external("orphaner", &["sh", "-c", &script], &["chl_mg_m3"]));
    let why = out.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("without writing its output"), "{why}");
    let pid = std::fs::read_to_string(&pid_file).unwrap().trim().to_string();
    assert!(gone(&pid), "the program's background child {pid} outlived it");
}

#[test]
fn placeholders_are_expanded_once_from_left_to_right() {
    // Each argument is echoed to a file: `{output}` inside an expanded value, an unknown
    // `{example:…}` and a lone brace stay text; nothing is expanded twice.
    let dir = Dir::new("external-placeholders");
    let seen = dir.path().join("args.txt");
    let script = format!("printf '%s\\n' \"$@\" > '{}'", seen.display());
    let out = run_with(external(
        "echoer",
        &["sh", "-c", &script, "sh", "{input}", "{output}{output}", "{ x", "{input", "a}{b"],
        &["chl_mg_m3"],
    ));
    assert!(out.retrievals[1].failure.is_some(), "it writes no product");
    let args: Vec<String> = std::fs::read_to_string(&seen).unwrap().lines().map(str::to_string).collect();
    assert_eq!(args.len(), 5, "{args:?}");
    assert!(args[0].ends_with("input.nc") && !args[0].contains('{'), "{args:?}");
    assert!(args[1].ends_with("output.nc") && args[1].matches("output.nc").count() == 2, "{args:?}");
    assert_eq!(&args[2..], ["{ x", "{input", "a}{b"]);
}

#[test]
fn a_built_in_retrieval_s_name_is_reserved_in_any_case() {
    for name in ["alm", "sambuca", "qaa", "QAA", "Sambuca"] {
        let spec = ExternalSpec {
            name: name.into(),
            command: vec!["true".into()],
            products: vec!["chl_mg_m3".into()],
            bands: None,
            function: None,
            time_limit_s: 10.0,
        };
        let e = spec.validate().unwrap_err().to_string();
        assert!(e.contains("External.name") && e.contains("qaa"), "{name}: {e}");
    }
    // Every built-in's name is in the reserved list, and each spec is called by its identity.
    let builtins = [
        RetrievalSpec::Almi { siop_sets: shoal::retrieval::sets::default_almi_sets(), settings: Default::default() },
        RetrievalSpec::Sambuca { siop: None, substrates: None, settings: Default::default() },
        RetrievalSpec::Qaa { settings: Default::default() },
    ];
    assert_eq!(builtins.len(), shoal::retrieval::algorithm::BUILT_IN.len(), "a built-in missing from this list");
    for (b, identity) in builtins.iter().zip(shoal::retrieval::algorithm::BUILT_IN) {
        assert_eq!(b.identity(), Some(identity));
        assert_eq!((b.name(), b.title()), (identity.name, identity.title));
        assert!(shoal::retrieval::run::BUILT_IN_NAMES.contains(&b.name()), "{}", b.name());
    }
}

#[test]
fn dir_is_the_study_s_folder_even_for_a_bare_file_name() {
    let spec = ExternalSpec {
        name: "mine".into(),
        command: vec!["{dir}/prog.py".into()],
        products: vec!["chl_mg_m3".into()],
        bands: None,
        function: None,
        time_limit_s: 10.0,
    };
    // `Path::new("s.ron").parent()` is the empty path: the current directory.
    let resolved = spec.with_dir(Some(std::path::Path::new(""))).unwrap();
    let cwd = std::env::current_dir().unwrap();
    assert_eq!(resolved.command, vec![cwd.join("prog.py").display().to_string()]);
    // A folder whose name holds a brace would be expanded again: refused, naming the field.
    let e = spec.with_dir(Some(std::path::Path::new("/studies/{output}"))).unwrap_err().to_string();
    assert!(e.contains("External.command") && e.contains("brace"), "{e}");
}
