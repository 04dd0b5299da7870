//! The `shoal` binary: with no arguments (or `shoal app`), the desktop app when built with the
//! `gui` feature; otherwise the headless command line (`shoal --help`).

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() || args[0] == "app" {
        return app(&args);
    }
    shoal::cli::main()
}

#[cfg(feature = "gui")]
fn app(args: &[String]) -> std::process::ExitCode {
    let mut options = shoal::app::AppOptions::default();
    let mut i = 1;
    while i < args.len() {
        match args[i].as_str() {
            "--screenshot" if i + 1 < args.len() => {
                options.screenshot = Some(args[i + 1].clone().into());
                options.fresh = true;
                i += 1;
            }
            "--fresh" => options.fresh = true,
            "--help" | "-h" => {
                println!(
                    "shoal app [--fresh] [--screenshot FILE.png]\n  --fresh       start from the built-in default study, not the saved session\n  --screenshot  save the window once the results are in, then quit"
                );
                return std::process::ExitCode::SUCCESS;
            }
            other => {
                eprintln!("error: unknown option `{other}` for `shoal app` (try `shoal app --help`)");
                return std::process::ExitCode::from(2);
            }
        }
        i += 1;
    }
    match shoal::app::run(options) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::from(1)
        }
    }
}

#[cfg(not(feature = "gui"))]
fn app(_args: &[String]) -> std::process::ExitCode {
    eprintln!(
        "error: this build has no desktop app (the `gui` feature is off); run `shoal study` for the headless study, or `shoal --help`"
    );
    std::process::ExitCode::from(2)
}
