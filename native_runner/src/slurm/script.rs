//! The text of the sbatch scripts (one per stage) and of `submit.sh`, which submits them in
//! order with their dependencies, as `sfmeval-runner` itself does without `--dry-run`.

use std::path::Path;

use anyhow::{Result, bail};

use crate::batch::plan::{Plan, Stage};
use crate::exec::shell_quote;
use crate::slurm::resources::Resources;

/// How a submission waits for the ones before it (indices into the list of submissions).
#[derive(Debug, Clone, PartialEq)]
pub enum Dependency {
    /// Starts at once.
    None,
    /// `afterok`: every task of that submission succeeded. The job is cancelled when that can
    /// no longer happen (`--kill-on-invalid-dep=yes`), so nothing waits forever.
    AfterOk(usize),
    /// `afterany`: those submissions ended, however (the collect stage: a failed, cancelled or
    /// timed-out task becomes a failed cell of the table).
    AfterAny(Vec<usize>),
}

/// One `sbatch` call: a stage's script for some of its tasks (one dataset's), and what it
/// waits for. The datasets are chained separately, so one dataset's runs start when its own
/// render is finished and a failed render holds back only its own runs.
#[derive(Debug, Clone)]
pub struct Submission {
    /// The stage.
    pub stage: Stage,
    /// Its name in `submit.sh` and `jobs.json`: `render_0`, `run_2`, `collect`.
    pub label: String,
    /// The task indices (the array), all or the missing ones on `--resume`.
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

/// The sbatch script of one stage (the array of tasks is given at submission).
pub fn sbatch_script(plan: &Plan, stage: Stage, res: &Resources) -> Result<String> {
    let name = stage.name();
    let logs = plan.slurm_dir().join("logs");
    let mut s = String::from("#!/bin/bash\n");
    s.push_str(&format!(
        "# sfmeval-runner {}: stage '{name}' of the batch in {} ({} task(s); submit.sh gives\n\
         # each sbatch call its --array of task indices).\n",
        env!("CARGO_PKG_VERSION"),
        plan.out.display(),
        plan.task_count(stage)
    ));
    s.push_str(&format!("#SBATCH --job-name=sfmeval-{name}\n"));
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
    let log = match stage {
        Stage::Collect => "collect.out".to_string(),
        _ => format!("{name}-%a.out"),
    };
    s.push_str(&format!("#SBATCH --output={}/{log}\n", sbatch_path(&logs)?));
    s.push_str("#SBATCH --open-mode=append\n");
    let index = match stage {
        Stage::Collect => "0".to_string(),
        _ => "\"$SLURM_ARRAY_TASK_ID\"".to_string(),
    };
    s.push_str("set -eu\n");
    s.push_str(&format!(
        "echo \"# sfmeval {name} task {} (job ${{SLURM_JOB_ID}}) on $(hostname) at $(date -u +%FT%TZ)\"\n",
        if stage == Stage::Collect {
            "0".to_string()
        } else {
            "${SLURM_ARRAY_TASK_ID}".to_string()
        }
    ));
    let pgids = match stage {
        Stage::Collect => "collect.pgids".to_string(),
        _ => format!("{name}-${{SLURM_ARRAY_TASK_ID}}.pgids"),
    };
    s.push_str(&format!(
        "export {}={}/{pgids}\n",
        crate::exec::PROCESS_GROUPS_VAR,
        sbatch_path(&logs)?
    ));
    let task = format!(
        "{} slurm-task --plan {} --stage {name} --index {index}",
        shell_quote(&plan.runner.to_string_lossy()),
        shell_quote(&Plan::path(&plan.out).to_string_lossy()),
    );
    // A runner killed outside Slurm (SIGKILL by the kernel for memory) leaves its tools'
    // process groups behind: the script ends them, says so in the log, and ends by the same
    // signal, so that Slurm records it (ExitCode 0:<signal>).
    s.push_str(&format!("{task} && exit 0\n"));
    s.push_str("rc=$?\n");
    s.push_str(&format!("{task} --ended \"$rc\" || true\n"));
    s.push_str("if [ \"$rc\" -gt 128 ]; then kill -\"$((rc - 128))\" \"$$\"; fi\n");
    s.push_str("exit \"$rc\"\n");
    Ok(s)
}

/// The `sbatch` options of one call: its array (not for collect) and its dependency, given
/// the job ids of the submissions before it.
pub fn sbatch_args(sub: &Submission, job_of: impl Fn(usize) -> Option<String>) -> Vec<String> {
    let mut args = Vec::new();
    if sub.stage != Stage::Collect {
        args.push(format!("--array={}", array_spec(&sub.tasks)));
    }
    match &sub.dependency {
        Dependency::None => {}
        Dependency::AfterOk(i) => {
            if let Some(id) = job_of(*i) {
                args.push(format!("--dependency=afterok:{id}"));
                args.push("--kill-on-invalid-dep=yes".into());
            }
        }
        Dependency::AfterAny(list) => {
            let ids: Vec<String> = list.iter().filter_map(|i| job_of(*i)).collect();
            if !ids.is_empty() {
                args.push(format!("--dependency=afterany:{}", ids.join(":")));
            }
        }
    }
    args
}

/// `submit.sh`: submits the written scripts in order, each with its array and dependency.
pub fn submit_sh(plan: &Plan, subs: &[Submission], sbatch: &str) -> String {
    let mut s = String::from("#!/bin/bash\n");
    s.push_str(&format!(
        "# Submits the stages of {} in order (what `sfmeval-runner ... --executor slurm` does\n# without --dry-run).\nset -euo pipefail\n",
        Plan::path(&plan.out).display()
    ));
    for sub in subs {
        let args = sbatch_args(sub, |i| subs.get(i).map(|x| format!("${}", x.label)));
        let mut cmd = vec![shell_quote(sbatch), "--parsable".to_string()];
        cmd.extend(args);
        cmd.push(shell_quote(&plan.script(sub.stage).to_string_lossy()));
        let var = &sub.label;
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
    fn sbatch_args_name_the_array_and_only_submitted_jobs() {
        let sub = |stage, dependency| Submission {
            stage,
            label: "x".into(),
            tasks: vec![0, 1, 3],
            dependency,
        };
        let job = |i: usize| (i != 1).then(|| format!("{}", i + 10));
        assert_eq!(
            sbatch_args(&sub(Stage::Run, Dependency::AfterOk(0)), job),
            [
                "--array=0-1,3",
                "--dependency=afterok:10",
                "--kill-on-invalid-dep=yes"
            ]
        );
        assert_eq!(
            sbatch_args(&sub(Stage::Run, Dependency::AfterOk(1)), job),
            ["--array=0-1,3"]
        );
        assert_eq!(
            sbatch_args(
                &sub(Stage::Collect, Dependency::AfterAny(vec![0, 1, 2])),
                job
            ),
            ["--dependency=afterany:10:12"]
        );
    }
}
