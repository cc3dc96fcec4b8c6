//! The subcommands without a module of their own — `run`, `merge`, `report`, `pipelines`:
//! each turns its arguments into the library calls and prints one summary line.

use anyhow::Result;

use crate::adapters::{self, Availability};
use crate::args::{MergeArgs, ReportCmd, RunArgs, ToolArgs};
use crate::dataset::Dataset;
use crate::env::make_env;
use crate::pipelines::{parse_customs, parse_list};
use crate::report::ReportArgs;

/// `run`: every (dataset, pipeline) of the grid into `OUT/<dataset>/<pipeline>/`.
pub fn run(a: &RunArgs) -> Result<()> {
    let customs = parse_customs(&a.batch.tools.customs)?;
    let specs = parse_list(&a.batch.pipelines, &customs)?;
    let datasets: Vec<Dataset> = a
        .datasets
        .iter()
        .map(|d| Dataset::open(d))
        .collect::<Result<_>>()?;
    let opts = a.batch.batch_options(&a.out)?;
    let env = make_env(&a.batch.tools, &a.out)?;
    let t = std::time::Instant::now();
    let s = crate::run::run_batch(&datasets, &specs, &customs, &env, &opts)?;
    eprintln!(
        "run: {} in {:.1} s; skipped {} finished run(s); output {}",
        if s.ran.is_empty() {
            "nothing to do".to_string()
        } else {
            s.ran
                .iter()
                .map(|(k, v)| format!("{v} {k}"))
                .collect::<Vec<_>>()
                .join(", ")
        },
        t.elapsed().as_secs_f64(),
        s.skipped,
        a.out.display()
    );
    Ok(())
}

/// `merge`: the shards' run folders joined into one.
pub fn merge(a: &MergeArgs) -> Result<()> {
    crate::run::merge(&a.shards, &a.out, a.force).map(|n| {
        eprintln!("merged {n} run(s) into {}", a.out.display());
    })
}

/// `report`: every run evaluated, the tables written.
pub fn report(a: &ReportCmd) -> Result<()> {
    let args = ReportArgs {
        runs: a.runs.clone(),
        out: a.out.clone(),
        datasets: a.datasets.clone(),
        eval: a.eval.eval_options()?,
        align: a.eval.align_request()?,
        verbose: true,
    };
    let rows = crate::report::report(&args)?;
    eprintln!(
        "report: {} run(s) → {}/{{table1.md,table1.csv,table.md,runs.csv,index.html,summary.json,reports/}}",
        rows.len(),
        a.out.display()
    );
    Ok(())
}

/// `pipelines`: every built-in and custom pipeline, installed or not.
pub fn pipelines(a: &ToolArgs) -> Result<()> {
    let customs = parse_customs(&a.customs)?;
    let tmp = std::env::temp_dir().join(format!("sfmeval-runner-{}", std::process::id()));
    let env = make_env(a, &tmp)?;
    for name in adapters::BUILTIN
        .iter()
        .map(|s| s.to_string())
        .chain(customs.keys().cloned())
    {
        let ad = adapters::adapter(&name, &name, &customs)?;
        match ad.availability(&env) {
            Availability::Installed(v) => println!("{name:18} installed  {v}"),
            Availability::Missing(r) => println!("{name:18} missing    {r}"),
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    Ok(())
}
