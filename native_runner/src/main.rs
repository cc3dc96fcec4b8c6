//! `sfmeval-runner`: runs SfM pipelines on sfmeval datasets, evaluates every run with the
//! sfmeval core and writes the comparison tables (Table I: mean distance and points per
//! pipeline; and the wide table).
//!
//! ```text
//! sfmeval-runner setup [--venv .venv]
//! sfmeval-runner run --datasets DIR... --pipelines LIST --out runs/ [--jobs N] [--resume] [--shard i/n] [--executor slurm ...]
//! sfmeval-runner merge runs-0/ runs-1/ ... --out runs/
//! sfmeval-runner report runs/ --out table/
//! sfmeval-runner table1 [--quick] [--out table1/] [--executor slurm [--dry-run] [--resume]]
//! sfmeval-runner sweep --factor views=12,24,36 --dataset-preset statue --pipelines LIST --out sweep/ [--executor slurm ...]
//! ```

mod adapters;
mod args;
mod batch;
mod chart;
mod commands;
mod dataset;
mod dtu;
mod env;
mod eth3d;
mod exec;
mod files;
mod generator;
mod html;
mod local;
mod pipelines;
mod poses;
mod report;
mod run;
mod setup;
mod slurm;
mod summary;
mod sweep;
mod table;
mod table1;
mod tnt;

use std::process::ExitCode;

use clap::Parser;

use crate::args::{Cli, Command};
use crate::batch::plan::Job;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Setup(a) => setup::setup(&a.venv, &a.python),
        Command::Run(a) => commands::batch(Job::Run(Box::new(a))),
        Command::Merge(a) => commands::merge(&a),
        Command::Report(a) => commands::report(&a),
        Command::Table1(a) => commands::batch(Job::Table1(Box::new(a))),
        Command::SlurmTask(a) => slurm::task::slurm_task(&a),
        Command::Sweep(a) => commands::batch(Job::Sweep(Box::new(a))),
        Command::Pipelines(a) => commands::pipelines(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sfmeval-runner: {e:#}");
            ExitCode::from(1)
        }
    }
}
