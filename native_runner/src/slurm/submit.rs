//! Submitting the written scripts with `sbatch`, in stage order, each with its dependency on
//! the job ids of the stages before it; and the record of every submission
//! (`OUT/slurm/jobs.json`).

use std::process::Command;

use anyhow::{Context, Result, bail};
use sfmeval_fs::write_atomic;

use crate::slurm::plan::Plan;
use crate::slurm::script::{Submission, sbatch_args};

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

/// Submits `subs` in order; returns their job ids.
pub fn submit(plan: &Plan, subs: &[Submission], sbatch: &str) -> Result<Vec<String>> {
    let mut jobs: Vec<String> = Vec::new();
    for sub in subs {
        let args = sbatch_args(sub, |i| jobs.get(i).cloned());
        let script = plan.script(sub.stage);
        let out = Command::new(sbatch)
            .arg("--parsable")
            .args(&args)
            .arg(&script)
            .output()
            .with_context(|| format!("running {sbatch} (is Slurm installed here?)"))?;
        if !out.status.success() {
            bail!(
                "{sbatch} {} {} failed ({}): {}{}",
                args.join(" "),
                script.display(),
                out.status,
                String::from_utf8_lossy(&out.stderr).trim(),
                if jobs.is_empty() {
                    String::new()
                } else {
                    format!(
                        " (already submitted: jobs {}; scancel them or let them run, then --resume)",
                        jobs.join(" ")
                    )
                }
            );
        }
        let id = parse_job_id(&String::from_utf8_lossy(&out.stdout))?;
        eprintln!(
            "slurm: {} submitted as job {id}: {}",
            sub.label,
            args.join(" ")
        );
        jobs.push(id);
    }
    Ok(jobs)
}

/// Appends one submission (time; per sbatch call its stage, label, job id, tasks) to
/// `OUT/slurm/jobs.json`.
pub fn record(plan: &Plan, subs: &[Submission], jobs: &[String]) -> Result<()> {
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
        "stages": subs.iter().zip(jobs).map(|(s, job)| serde_json::json!({
            "stage": s.stage.name(),
            "label": s.label,
            "job": job,
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
