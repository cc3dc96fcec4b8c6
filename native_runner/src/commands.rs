//! The subcommands: the batches (`table1`, `sweep`, `run`: a plan and an executor), `merge`,
//! `report` and `pipelines`; each turns its arguments into the library calls.

use anyhow::Result;

use crate::adapters::{self, Availability};
use crate::args::{MergeArgs, PipelinesArgs, ReportCmd};
use crate::batch::plan::{Job, Plan};
use crate::env::make_env;
use crate::local;
use crate::pipelines::parse_customs;
use crate::report::ReportArgs;
use crate::slurm;
use crate::summary::{Executor, unix_now};

/// `table1`, `sweep` and `run`: the command's plan, run by the executor it names (locally
/// stage by stage, or submitted to Slurm).
pub fn batch(job: Job) -> Result<()> {
    let started_unix = unix_now();
    match job.executor() {
        Executor::Local => {
            local::check(&job)?;
            let (plan, sweep) = Plan::of(&job)?;
            local::execute(&plan, &job, sweep.as_ref(), started_unix)
        }
        Executor::Slurm => {
            slurm::check(&job)?;
            let (plan, _) = Plan::of(&job)?;
            slurm::submit_plan(&plan, &job)
        }
    }
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
