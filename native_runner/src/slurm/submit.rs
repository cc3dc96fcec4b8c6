//! Submitting the written scripts with `sbatch`, in stage order, each with its dependency on
//! the job ids of the stages before it; and the record of every submission
//! (`OUT/slurm/jobs.json`), written again after every `sbatch` call, so a job that is queued
//! is recorded even when a later call of the same submission fails.

use std::path::PathBuf;
use std::process::Command;

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use sfmeval_fs::write_atomic;

use crate::batch::plan::{Plan, Stage};
use crate::slurm::resources::slurm_program;
use crate::slurm::script::{Submission, sbatch_args};

/// One `sbatch` call of a submission in `jobs.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QueuedJob {
    /// The stage's name.
    pub stage: String,
    /// The submission's label (`render_0`, `run_1`, `collect`).
    pub label: String,
    /// The job id `sbatch` printed (array task `k` is `<job>_<k>`).
    pub job: String,
    /// The task indices of its array.
    pub tasks: Vec<usize>,
}

/// One submission of the batch in `jobs.json`: the jobs queued so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubmissionRecord {
    /// When it began (seconds since the Unix epoch).
    pub submitted_unix: f64,
    /// Whether every `sbatch` call of it succeeded (false while it runs and after one failed;
    /// a record written before this field existed was complete).
    #[serde(default = "complete_by_default")]
    pub complete: bool,
    /// The jobs queued, in submission order.
    pub stages: Vec<QueuedJob>,
}

fn complete_by_default() -> bool {
    true
}

/// `OUT/slurm/jobs.json`.
fn jobs_path(plan: &Plan) -> PathBuf {
    plan.slurm_dir().join("jobs.json")
}

/// Every submission recorded for the batch (none when `jobs.json` is absent).
pub fn read_records(plan: &Plan) -> Result<Vec<SubmissionRecord>> {
    let path = jobs_path(plan);
    match std::fs::read(&path) {
        Ok(b) => serde_json::from_slice(&b).with_context(|| format!("parsing {}", path.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
        Err(e) => Err(e).with_context(|| format!("reading {}", path.display())),
    }
}

fn write_records(plan: &Plan, all: &[SubmissionRecord]) -> Result<()> {
    let mut text = serde_json::to_string_pretty(all)?;
    text.push('\n');
    write_atomic(&jobs_path(plan), text.as_bytes())
}

/// The Slurm job of task `k` of `stage` in its latest submission (`<job>_<k>` for an array,
/// `<job>` for the collect), if it was ever queued.
pub fn job_of_task(records: &[SubmissionRecord], stage: Stage, k: usize) -> Option<String> {
    records
        .iter()
        .flat_map(|r| &r.stages)
        .rfind(|q| q.stage == stage.name() && q.tasks.contains(&k))
        .map(|q| match stage {
            Stage::Collect => q.job.clone(),
            _ => format!("{}_{k}", q.job),
        })
}

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

/// Submits `subs` in order, recording each job in `jobs.json` as soon as it is queued (a new
/// submission record, marked complete after the last call); returns their job ids.
pub fn submit(plan: &Plan, subs: &[Submission], sbatch: &str) -> Result<Vec<String>> {
    let mut all = read_records(plan)?;
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    all.push(SubmissionRecord {
        submitted_unix: now,
        complete: false,
        stages: Vec::new(),
    });
    write_records(plan, &all)?;
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
        let id = if out.status.success() {
            parse_job_id(&String::from_utf8_lossy(&out.stdout))
        } else {
            Err(anyhow::anyhow!(
                "failed ({}): {}",
                out.status,
                String::from_utf8_lossy(&out.stderr).trim()
            ))
        };
        let id = match id {
            Ok(id) => id,
            Err(e) => bail!(
                "{sbatch} {} {}: {e:#}{}",
                args.join(" "),
                script.display(),
                if jobs.is_empty() {
                    " (nothing of this submission was queued: run the same command again)"
                        .to_string()
                } else {
                    format!(
                        " (already queued and recorded in {}: jobs {}; the same command \
                         submits the rest once they have left the queue, or scancel them)",
                        jobs_path(plan).display(),
                        jobs.join(" ")
                    )
                }
            ),
        };
        eprintln!(
            "slurm: {} submitted as job {id}: {}",
            sub.label,
            args.join(" ")
        );
        if let Some(rec) = all.last_mut() {
            rec.stages.push(QueuedJob {
                stage: sub.stage.name().to_string(),
                label: sub.label.clone(),
                job: id.clone(),
                tasks: sub.tasks.clone(),
            });
        }
        write_records(plan, &all)?;
        jobs.push(id);
    }
    if let Some(rec) = all.last_mut() {
        rec.complete = true;
    }
    write_records(plan, &all)?;
    Ok(jobs)
}

/// The jobs of earlier submissions (`OUT/slurm/jobs.json`) still in the queue: a resumed
/// batch must not run a task twice at once.
pub fn still_queued(plan: &Plan, sbatch: &str) -> Result<Vec<String>> {
    let ids: Vec<String> = read_records(plan)?
        .into_iter()
        .flat_map(|r| r.stages)
        .map(|q| q.job)
        .collect();
    if ids.is_empty() {
        return Ok(Vec::new());
    }
    let squeue = slurm_program(sbatch, "squeue");
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

    #[test]
    fn a_task_is_found_in_its_latest_submission() {
        let q = |stage: &str, job: &str, tasks: Vec<usize>| QueuedJob {
            stage: stage.into(),
            label: stage.into(),
            job: job.into(),
            tasks,
        };
        let recs = vec![
            SubmissionRecord {
                submitted_unix: 1.0,
                complete: true,
                stages: vec![q("run", "10", vec![0, 1]), q("collect", "11", vec![0])],
            },
            SubmissionRecord {
                submitted_unix: 2.0,
                complete: false,
                stages: vec![q("run", "20", vec![1])],
            },
        ];
        assert_eq!(job_of_task(&recs, Stage::Run, 0).as_deref(), Some("10_0"));
        assert_eq!(job_of_task(&recs, Stage::Run, 1).as_deref(), Some("20_1"));
        assert_eq!(job_of_task(&recs, Stage::Collect, 0).as_deref(), Some("11"));
        assert_eq!(job_of_task(&recs, Stage::Render, 0), None);
        // a record of an older runner (no `complete`) was complete
        let old: Vec<SubmissionRecord> =
            serde_json::from_str(r#"[{"submitted_unix": 1, "stages": []}]"#).unwrap();
        assert!(old[0].complete);
    }
}
