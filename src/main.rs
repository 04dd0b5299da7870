//! The `shoal` binary: with no arguments (or `shoal app`), the desktop app when built with the
//! `gui` feature; otherwise the headless command line (`shoal --help`).

use std::process::ExitCode;

use shoal::cli::AppArgs;

fn main() -> ExitCode {
    if let Err(e) = shoal::simd::check_env() {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    if std::env::args().len() <= 1 {
        return app(&AppArgs::default());
    }
    shoal::cli::main(app)
}

#[cfg(feature = "gui")]
fn app(args: &AppArgs) -> ExitCode {
    let options = shoal::app::AppOptions {
        fresh: args.fresh || args.screenshot.is_some(),
        screenshot: args.screenshot.clone(),
        size: args.size,
        study: args.study.clone(),
        ..shoal::app::AppOptions::default()
    };
    match shoal::app::run(options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}

#[cfg(not(feature = "gui"))]
fn app(_args: &AppArgs) -> ExitCode {
    eprintln!(
        "error: this build has no desktop app (the `gui` feature is off); run `shoal study` for the headless study, or `shoal --help`"
    );
    ExitCode::from(2)
}
