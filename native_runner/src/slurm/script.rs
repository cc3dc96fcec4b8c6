//! The text of the sbatch scripts (one per stage) and of `submit.sh`, which submits them in
//! order with their dependencies, as `sfmeval-runner` itself does without `--dry-run`.

use std::path::Path;

use anyhow::{Result, bail};

use crate::exec::shell_quote;
use crate::slurm::plan::{Plan, Stage};
use crate::slurm::resources::Resources;

/// How a stage waits for the ones before it.
#[derive(Debug, Clone, PartialEq)]
pub enum Dependency {
    /// Starts at once.
    None,
    /// `afterok` on a stage: every task of it succeeded. The job is cancelled when that can
    /// no longer happen (`--kill-on-invalid-dep=yes`), so nothing waits forever.
    AfterOk(Stage),
    /// `afterany` on stages: they ended, however (the collect stage: a failed, cancelled or
    /// timed-out task becomes a failed cell of the table).
    AfterAny(Vec<Stage>),
}

/// One stage to submit: its tasks (array indices) and what it waits for.
#[derive(Debug, Clone)]
pub struct Submission {
    /// The stage.
    pub stage: Stage,
    /// Its task indices to run (all of them, or the missing ones on `--resume`).
    pub tasks: Vec<usize>,
    /// What it waits for.
    pub dependency: Dependency,
}

/// A Slurm array spec from indices: `0-3,7,9-10`.
pub fn array_spec(tasks: &[usize]) -> String {
    let mut sorted = tasks.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < sorted.len() {
        let start = sorted[i];
        let mut end = start;
        while i + 1 < sorted.len() && sorted[i + 1] == end + 1 {
            i += 1;
            end = sorted[i];
        }
        parts.push(if end == start {
            start.to_string()
        } else {
            format!("{start}-{end}")
        });
        i += 1;
    }
    parts.join(",")
}

/// A path that can stand in an `#SBATCH` line (no whitespace, quotes or `%`).
fn sbatch_path(p: &Path) -> Result<String> {
    let s = p.to_string_lossy().to_string();
    if s.chars()
        .any(|c| c.is_whitespace() || c == '"' || c == '\'' || c == '%' || c == '\\')
    {
        bail!(
            "{s}: a Slurm batch needs paths without spaces, quotes, % or backslashes (sbatch \
             options cannot quote them)"
        );
    }
    Ok(s)
}

/// The sbatch script of one stage.
pub fn sbatch_script(plan: &Plan, sub: &Submission, res: &Resources) -> Result<String> {
    let stage = sub.stage.name();
    let logs = plan.slurm_dir().join("logs");
    let mut s = String::from("#!/bin/bash\n");
    s.push_str(&format!(
        "# sfmeval-runner {}: stage '{stage}' of the batch in {} ({} of {} task(s)).\n",
        env!("CARGO_PKG_VERSION"),
        plan.out.display(),
        sub.tasks.len(),
        plan.task_count(sub.stage)
    ));
    s.push_str(&format!("#SBATCH --job-name=sfmeval-{stage}\n"));
    if sub.stage != Stage::Collect {
        s.push_str(&format!("#SBATCH --array={}\n", array_spec(&sub.tasks)));
    }
    s.push_str(&format!("#SBATCH --cpus-per-task={}\n", res.cpus));
    s.push_str(&format!("#SBATCH --mem={}\n", res.mem));
    s.push_str(&format!("#SBATCH --time={}\n", res.time));
    if let Some(p) = &res.partition {
        s.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    if let Some(a) = &res.account {
        s.push_str(&format!("#SBATCH --account={a}\n"));
    }
    s.push_str(&format!("#SBATCH --chdir={}\n", sbatch_path(&plan.cwd)?));
    let log = match sub.stage {
        Stage::Collect => "collect.out".to_string(),
        _ => format!("{stage}-%a.out"),
    };
    s.push_str(&format!("#SBATCH --output={}/{log}\n", sbatch_path(&logs)?));
    s.push_str("#SBATCH --open-mode=append\n");
    let index = match sub.stage {
        Stage::Collect => "0".to_string(),
        _ => "\"$SLURM_ARRAY_TASK_ID\"".to_string(),
    };
    s.push_str("set -eu\n");
    s.push_str(&format!(
        "echo \"# sfmeval {stage} task {} (job ${{SLURM_JOB_ID}}) on $(hostname) at $(date -u +%FT%TZ)\"\n",
        if sub.stage == Stage::Collect { "0".to_string() } else { "${SLURM_ARRAY_TASK_ID}".to_string() }
    ));
    s.push_str(&format!(
        "exec {} slurm-task --plan {} --stage {stage} --index {index}\n",
        shell_quote(&plan.runner.to_string_lossy()),
        shell_quote(&Plan::path(&plan.out).to_string_lossy()),
    ));
    Ok(s)
}

/// The `sbatch` options of a submission's dependency, given the job ids of the stages
/// submitted before it.
pub fn dependency_args(dep: &Dependency, job_of: impl Fn(Stage) -> Option<String>) -> Vec<String> {
    match dep {
        Dependency::None => Vec::new(),
        Dependency::AfterOk(st) => match job_of(*st) {
            Some(id) => vec![
                format!("--dependency=afterok:{id}"),
                "--kill-on-invalid-dep=yes".into(),
            ],
            None => Vec::new(),
        },
        Dependency::AfterAny(sts) => {
            let ids: Vec<String> = sts.iter().filter_map(|s| job_of(*s)).collect();
            if ids.is_empty() {
                Vec::new()
            } else {
                vec![format!("--dependency=afterany:{}", ids.join(":"))]
            }
        }
    }
}

/// `submit.sh`: submits the written scripts in order, each with its dependency.
pub fn submit_sh(plan: &Plan, subs: &[Submission], sbatch: &str) -> String {
    let mut s = String::from("#!/bin/bash\n");
    s.push_str(&format!(
        "# Submits the stages of {} in order (what `sfmeval-runner table1 --executor slurm` does\n# without --dry-run).\nset -euo pipefail\n",
        Plan::path(&plan.out).display()
    ));
    for sub in subs {
        let var = sub.stage.name();
        let deps = dependency_args(&sub.dependency, |st| {
            subs.iter()
                .any(|x| x.stage == st)
                .then(|| format!("${}", st.name()))
        });
        let mut cmd = vec![shell_quote(sbatch), "--parsable".to_string()];
        cmd.extend(deps);
        cmd.push(shell_quote(&plan.script(sub.stage).to_string_lossy()));
        s.push_str(&format!("{var}=$({} | cut -d';' -f1)\n", cmd.join(" ")));
        s.push_str(&format!("echo \"{var}: job ${var}\"\n"));
    }
    s
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn array_specs_join_runs_of_indices() {
        assert_eq!(array_spec(&[0, 1, 2, 3]), "0-3");
        assert_eq!(array_spec(&[9, 0, 2, 3, 4, 7, 10]), "0,2-4,7,9-10");
        assert_eq!(array_spec(&[5]), "5");
    }

    #[test]
    fn dependencies_name_only_submitted_stages() {
        let job = |st: Stage| (st != Stage::Finalize).then(|| format!("{}", st as u8 + 10));
        assert_eq!(
            dependency_args(&Dependency::AfterOk(Stage::Render), job),
            ["--dependency=afterok:10", "--kill-on-invalid-dep=yes"]
        );
        assert!(dependency_args(&Dependency::AfterOk(Stage::Finalize), job).is_empty());
        assert_eq!(
            dependency_args(
                &Dependency::AfterAny(vec![Stage::Render, Stage::Finalize, Stage::Run]),
                job
            ),
            ["--dependency=afterany:10:12"]
        );
    }
}
