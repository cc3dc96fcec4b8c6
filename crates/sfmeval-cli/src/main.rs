//! `sfmeval`: evaluate SfM reconstructions against ground truth from the command line.

mod commands;
mod concurrent;
mod dtu;
mod eth3d;
mod progress;
mod summary;
mod table;
mod tanksandtemples;

use std::process::ExitCode;

use clap::Parser as _;

fn main() -> ExitCode {
    let cli = commands::Cli::parse();
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
