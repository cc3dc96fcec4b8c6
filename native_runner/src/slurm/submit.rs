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

/// The jobs of earlier submissions (`OUT/slurm/jobs.json`) still in the queue: a resumed
/// batch must not run a task twice at once.
pub fn still_queued(plan: &Plan, sbatch: &str) -> Result<Vec<String>> {
    let path = plan.slurm_dir().join("jobs.json");
    let all: Vec<serde_json::Value> = match std::fs::read(&path) {
        Ok(b) => {
            serde_json::from_slice(&b).with_context(|| format!("parsing {}", path.display()))?
        }
        Err(_) => return Ok(Vec::new()),
    };
    let ids: Vec<String> = all
        .iter()
        .flat_map(|s| s["stages"].as_array().cloned().unwrap_or_default())
        .filter_map(|st| st["job"].as_str().map(str::to_string))
        .collect();
    if ids.is_empty() {
        return Ok(Vec::new());
    }
    // squeue beside the given sbatch, else on PATH
    let sbatch_path = std::path::Path::new(sbatch);
    let squeue = match sbatch_path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join("squeue"),
        _ => std::path::PathBuf::from("squeue"),
    };
    // every job of this user (array tasks under their array's id), kept when it is ours
    let out = Command::new(&squeue)
        .args(["-h", "--me", "-o", "%F"])
        .output()
        .with_context(|| format!("running {}", squeue.display()))?;
    if !out.status.success() {
        bail!(
            "{} failed ({}): {}",
            squeue.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut queued: Vec<String> = text
        .lines()
        .map(|l| l.trim().to_string())
        .filter(|l| ids.contains(l))
        .collect();
    queued.sort();
    queued.dedup();
    Ok(queued)
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
