//! The subcommands without a module of their own — `run`, `merge`, `report`, `pipelines`:
//! each turns its arguments into the library calls and prints one summary line.

use anyhow::{Context, Result};

use crate::adapters::{self, Availability};
use crate::args::{MergeArgs, PipelinesArgs, ReportCmd, RunArgs};
use crate::dataset::Dataset;
use crate::env::make_env;
use crate::pipelines::{parse_customs, parse_list};
use crate::report::ReportArgs;

/// `run`: every (dataset, pipeline) of the grid into `OUT/<dataset>/<pipeline>/`.
pub fn run(a: &RunArgs) -> Result<()> {
    a.slurm.check_local(false)?;
    if !a.eval.is_default() {
        anyhow::bail!(
            "--crop, --samples, --tau, --tau-percent, --align and --eval-seed go with --executor \
             slurm (a local run does not evaluate: give them to `report`)"
        );
    }
    let customs = parse_customs(&a.batch.tools.customs)?;
    let specs = parse_list(&a.batch.pipelines, &customs)?;
    let datasets: Vec<Dataset> = a
        .datasets
        .iter()
        .map(|d| Dataset::open(d))
        .collect::<Result<_>>()?;
    // Absolute: the tools run inside their run folders, so a relative OUT (and the adapter
    // scripts installed under it) would resolve against the wrong folder.
    let out = std::path::absolute(&a.out)
        .with_context(|| format!("output folder {}", a.out.display()))?;
    let opts = a.batch.batch_options(&out)?;
    let env = make_env(&a.batch.tools, &out)?;
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

/// One pipeline of `pipelines --json`.
#[derive(serde::Serialize, Debug, PartialEq)]
pub struct PipelineStatus {
    /// Pipeline name (what `run --pipelines` takes).
    pub name: String,
    /// Whether its tool is installed here.
    pub installed: bool,
    /// The tool's version when installed, else why it is not.
    pub detail: String,
}

/// `pipelines`: every built-in and custom pipeline, installed or not (a text table, or JSON
/// with `--json`).
pub fn pipelines(a: &PipelinesArgs) -> Result<()> {
    let list = pipeline_statuses(&a.tools)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&list)?);
    } else {
        for p in &list {
            let state = if p.installed {
                "installed"
            } else {
                "missing  "
            };
            println!("{:18} {state}  {}", p.name, p.detail);
        }
    }
    Ok(())
}

/// The built-in and custom pipelines with their availability.
pub fn pipeline_statuses(a: &crate::args::ToolArgs) -> Result<Vec<PipelineStatus>> {
    let customs = parse_customs(&a.customs)?;
    let tmp = std::env::temp_dir().join(format!("sfmeval-runner-{}", std::process::id()));
    let env = make_env(a, &tmp)?;
    let mut out = Vec::new();
    for name in adapters::BUILTIN
        .iter()
        .map(|s| s.to_string())
        .chain(customs.keys().cloned())
    {
        let ad = adapters::adapter(&name, &name, &customs)?;
        let (installed, detail) = match ad.availability(&env) {
            Availability::Installed(v) => (true, v),
            Availability::Missing(r) => (false, r),
        };
        out.push(PipelineStatus {
            name,
            installed,
            detail,
        });
    }
    let _ = std::fs::remove_dir_all(&tmp);
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::args::ToolArgs;

    #[test]
    fn pipeline_statuses_json() {
        let tools = ToolArgs {
            python: None,
            colmap: "/nonexistent/colmap".into(),
            visualsfm: "/nonexistent/VisualSFM".into(),
            customs: vec!["mine=/bin/true {images} {out}".into()],
        };
        let list = pipeline_statuses(&tools).unwrap();
        let names: Vec<_> = list.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names.len(), adapters::BUILTIN.len() + 1);
        assert_eq!(names.last(), Some(&"mine"));
        let colmap = list.iter().find(|p| p.name == "colmap").unwrap();
        assert!(!colmap.installed, "{colmap:?}");
        assert!(colmap.detail.contains("/nonexistent/colmap"), "{colmap:?}");
        let v: serde_json::Value = serde_json::to_value(&list).unwrap();
        assert_eq!(v[0]["name"], "colmap");
        assert!(v[0]["installed"].is_boolean() && v[0]["detail"].is_string());
    }
}
