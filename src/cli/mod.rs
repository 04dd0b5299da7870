//! The headless command line.

/// Entry point of the `shoal` binary.
#[must_use]
pub fn main() -> std::process::ExitCode {
    std::process::ExitCode::SUCCESS
}
