//! Submitting the written scripts with `sbatch`, in stage order, each with its dependency on
//! the job ids of the stages before it; and the record of every submission
//! (`OUT/slurm/jobs.json`).

use std::collections::BTreeMap;
use std::process::Command;

use anyhow::{Context, Result, bail};
use sfmeval_fs::write_atomic;

use crate::slurm::plan::{Plan, Stage};
use crate::slurm::script::{Submission, dependency_args};

/// The job id in `sbatch --parsable`'s output (`ID` or `ID;CLUSTER`).
pub fn parse_job_id(stdout: &str) -> Result<String> {
    let id = stdout
        .trim()
        .split(';')
        .next()
        .unwrap_or_default()
        .trim()
        .to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        bail!("sbatch printed no job id: '{}'", stdout.trim());
    }
    Ok(id)
}

/// Submits the scripts of `subs` in order; returns each stage's job id.
pub fn submit(plan: &Plan, subs: &[Submission], sbatch: &str) -> Result<BTreeMap<Stage, String>> {
    let mut jobs: BTreeMap<Stage, String> = BTreeMap::new();
    for sub in subs {
        let deps = dependency_args(&sub.dependency, |st| jobs.get(&st).cloned());
        let script = plan.script(sub.stage);
        let out = Command::new(sbatch)
            .arg("--parsable")
            .args(&deps)
            .arg(&script)
            .output()
            .with_context(|| format!("running {sbatch} (is Slurm installed here?)"))?;
        if !out.status.success() {
            bail!(
                "{sbatch} {} {} failed ({}): {}{}",
                deps.join(" "),
                script.display(),
                out.status,
                String::from_utf8_lossy(&out.stderr).trim(),
                if jobs.is_empty() {
                    String::new()
                } else {
                    format!(
                        " (already submitted: {}; scancel them or let them run, then --resume)",
                        jobs.values().cloned().collect::<Vec<_>>().join(" ")
                    )
                }
            );
        }
        let id = parse_job_id(&String::from_utf8_lossy(&out.stdout))?;
        eprintln!(
            "slurm: {} ({} task(s)) submitted as job {id} {}",
            sub.stage.name(),
            sub.tasks.len(),
            deps.join(" ")
        );
        jobs.insert(sub.stage, id);
    }
    Ok(jobs)
}

/// Appends one submission (time, stages, job ids, tasks) to `OUT/slurm/jobs.json`.
pub fn record(plan: &Plan, subs: &[Submission], jobs: &BTreeMap<Stage, String>) -> Result<()> {
    let path = plan.slurm_dir().join("jobs.json");
    let mut all: Vec<serde_json::Value> = std::fs::read(&path)
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
        .unwrap_or_default();
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    all.push(serde_json::json!({
        "submitted_unix": now,
        "stages": subs.iter().map(|s| serde_json::json!({
            "stage": s.stage.name(),
            "job": jobs.get(&s.stage),
            "tasks": s.tasks,
        })).collect::<Vec<_>>(),
    }));
    let mut text = serde_json::to_string_pretty(&all)?;
    text.push('\n');
    write_atomic(&path, text.as_bytes())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn job_ids_from_parsable_output() {
        assert_eq!(parse_job_id("1234\n").unwrap(), "1234");
        assert_eq!(parse_job_id("77;cluster\n").unwrap(), "77");
        assert!(parse_job_id("sbatch: error: x").is_err());
        assert!(parse_job_id("").is_err());
    }
}
