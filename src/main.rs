//! The `shoal` binary: the command line (and, with the `gui` feature, later the app).

fn main() -> std::process::ExitCode {
    shoal::cli::main()
}
