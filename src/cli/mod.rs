//! The headless command line.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Shoal: end-to-end simulation of satellite optical instruments over water.
#[derive(Debug, Parser)]
#[command(name = "shoal", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Developer tools that regenerate computed assets.
    #[command(subcommand, hide = true)]
    Dev(DevCommand),
}

#[derive(Debug, Subcommand)]
enum DevCommand {
    /// Print the WMO aerosol component Mie table (assets/atmosphere/wmo_aerosol_mie.csv).
    AerosolTable,
}

/// Entry point of the `shoal` binary.
#[must_use]
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    match cli.command {
        Command::Dev(DevCommand::AerosolTable) => {
            print!("{}", crate::atmosphere::component_table_csv());
            ExitCode::SUCCESS
        }
    }
}
