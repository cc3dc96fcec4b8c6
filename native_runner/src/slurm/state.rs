//! Why a task that left no result ended: Slurm's last message in its output file (cancelled,
//! time limit, node failure, out of memory), else Slurm's record of its job (state and exit
//! signal).

use std::path::Path;

use crate::run::Status;

/// How Slurm says a job ended (`scontrol show job`, else `sacct`).
#[derive(Debug, Clone, PartialEq)]
pub struct SlurmEnd {
    /// The job (`<array job>_<task>` for an array task).
    pub job: String,
    /// `JobState` (`FAILED`, `TIMEOUT`, `CANCELLED`, `OUT_OF_MEMORY`, `NODE_FAIL`, ...).
    pub state: String,
    /// `ExitCode` as `status:signal`.
    pub exit_code: String,
}

impl SlurmEnd {
    /// The signal of the exit code (`0:9` is 9), 0 for none.
    pub fn signal(&self) -> i32 {
        self.exit_code
            .split_once(':')
            .and_then(|(_, s)| s.parse().ok())
            .unwrap_or(0)
    }
}

/// The end of `job` from `scontrol show job -o` (while Slurm keeps the record, `MinJobAge`),
/// else from `sacct` (where accounting is on); `None` when neither knows it.
pub fn slurm_end(job: &str) -> Option<SlurmEnd> {
    let run = |prog: &str, args: &[&str]| {
        std::process::Command::new(prog)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).to_string())
    };
    if let Some(text) = run("scontrol", &["show", "job", "-o", job]) {
        let field = |k: &str| {
            text.split_whitespace()
                .find_map(|w| w.strip_prefix(k))
                .map(str::to_string)
        };
        if let (Some(state), Some(exit_code)) = (field("JobState="), field("ExitCode=")) {
            return Some(SlurmEnd {
                job: job.to_string(),
                state,
                exit_code,
            });
        }
    }
    let text = run(
        "sacct",
        &["-n", "-P", "-X", "-j", job, "-o", "State,ExitCode"],
    )?;
    let line = text.lines().find(|l| !l.trim().is_empty())?;
    let (state, exit_code) = line.split_once('|')?;
    Some(SlurmEnd {
        job: job.to_string(),
        // `CANCELLED by 0` in sacct
        state: state.split_whitespace().next()?.to_string(),
        exit_code: exit_code.trim().to_string(),
    })
}

/// Why a task ended without a result: Slurm's own message in its output file (time limit,
/// node failure, preemption, cancelled, out of memory), else how Slurm recorded the job
/// (`slurm`: its state and exit signal) with the runner's `# sfmeval-runner:` line about a
/// killed runner, else an error line of the log. The status its cell gets (`timeout` for
/// Slurm's time limit, else `failed`) and a reason naming the file.
pub fn end_reason(log: &Path, slurm: Option<&SlurmEnd>) -> (Status, String) {
    let slurm_says = slurm.map_or(String::new(), |e| {
        format!(
            " (Slurm job {}: JobState={} ExitCode={})",
            e.job, e.state, e.exit_code
        )
    });
    let Ok(text) = std::fs::read_to_string(log) else {
        return (
            Status::Failed,
            format!(
                "never started{slurm_says} (no output file {})",
                log.display()
            ),
        );
    };
    // The last submission's lines only: each begins with the `# sfmeval <stage> task` line.
    let last = text
        .rfind("# sfmeval ")
        .map_or(text.as_str(), |i| &text[i..]);
    let line = |pat: &str| {
        last.lines()
            .rev()
            .find(|l| l.contains(pat))
            .map(|l| l.trim().to_string())
    };
    let state = slurm.map(|e| e.state.as_str()).unwrap_or_default();
    let runner_line = line("# sfmeval-runner: ").map(|l| {
        l.split_once("its runner ")
            .map_or(l.clone(), |(_, r)| format!("its runner {r}"))
    });
    let (status, what) = if let Some(l) = line("DUE TO TIME LIMIT") {
        (Status::Timeout, format!("Slurm time limit ({l})"))
    } else if let Some(l) = line("DUE TO NODE FAIL") {
        (Status::Failed, format!("node failure ({l})"))
    } else if let Some(l) = line("DUE TO PREEMPTION") {
        (Status::Failed, format!("preempted ({l})"))
    } else if let Some(l) = line("CANCELLED") {
        (Status::Failed, format!("cancelled ({l})"))
    } else if let Some(l) = line("oom-kill").or_else(|| line("Exceeded job memory limit")) {
        (Status::Failed, format!("out of memory ({l})"))
    } else if state == "TIMEOUT" {
        (Status::Timeout, format!("Slurm time limit{slurm_says}"))
    } else if matches!(
        state,
        "OUT_OF_MEMORY" | "NODE_FAIL" | "PREEMPTED" | "CANCELLED"
    ) {
        (
            Status::Failed,
            format!(
                "{}{slurm_says}",
                state.to_ascii_lowercase().replace('_', " ")
            ),
        )
    } else if let Some(e) = slurm.filter(|e| e.signal() != 0) {
        let sig = e.signal();
        let name = nix::sys::signal::Signal::try_from(sig).map_or(String::new(), |s| {
            let oom = if sig == 9 {
                ": the kernel's out-of-memory killer, or a kill outside Slurm"
            } else {
                ""
            };
            format!("{}{oom}; ", s.as_str())
        });
        let mut what = format!(
            "killed by signal {sig} ({name}Slurm job {}: JobState={} ExitCode={})",
            e.job, e.state, e.exit_code
        );
        // what the task's script ended after its runner
        if let Some((_, ended)) = runner_line.as_deref().and_then(|r| r.split_once("; ")) {
            what.push_str(&format!("; {ended}"));
        }
        (Status::Failed, what)
    } else if let Some(r) = runner_line {
        (Status::Failed, format!("{r}{slurm_says}"))
    } else if let Some(l) = last
        .lines()
        .rev()
        .find(|l| l.to_ascii_lowercase().contains("error"))
    {
        (Status::Failed, format!("failed: {}{slurm_says}", l.trim()))
    } else {
        (
            Status::Failed,
            format!("ended without a result{slurm_says}"),
        )
    };
    (status, format!("{what}; see {}", log.display()))
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn the_last_submission_of_a_log_says_why() {
        let dir = std::env::temp_dir().join(format!("sfmeval-state-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let log = dir.join("run-3.out");
        std::fs::write(
            &log,
            "# sfmeval run task 3 (job 7)\nslurmstepd: error: *** JOB 8 ON vm CANCELLED AT 2026-12-02T12:00:00 DUE TO TIME LIMIT ***\n\
             # sfmeval run task 3 (job 9)\nslurmstepd: error: *** JOB 10 ON vm CANCELLED AT 2026-12-02T13:00:00 ***\n",
        )
        .unwrap();
        let (st, why) = end_reason(&log, None);
        assert_eq!(st, Status::Failed);
        assert!(
            why.starts_with("cancelled (slurmstepd: error: *** JOB 10"),
            "{why}"
        );
        std::fs::write(
            &log,
            "# sfmeval run task 3\n*** JOB 8 ON vm CANCELLED AT x DUE TO TIME LIMIT ***\n",
        )
        .unwrap();
        assert_eq!(end_reason(&log, None).0, Status::Timeout);
        let (st, why) = end_reason(&dir.join("absent.out"), None);
        assert!(
            st == Status::Failed && why.starts_with("never started"),
            "{why}"
        );
        // a runner killed by SIGKILL: Slurm's exit signal and the script's line
        std::fs::write(
            &log,
            "# sfmeval run task 3 (job 9)\n# sfmeval-runner: run task 3: its runner was killed by signal 9 (SIGKILL); ended its tools' process group(s) 77 (2 process(es))\n",
        )
        .unwrap();
        let end = SlurmEnd {
            job: "9_3".into(),
            state: "FAILED".into(),
            exit_code: "0:9".into(),
        };
        let (st, why) = end_reason(&log, Some(&end));
        assert_eq!(st, Status::Failed);
        assert!(
            why.starts_with(
                "killed by signal 9 (SIGKILL: the kernel's out-of-memory killer, or a kill \
                 outside Slurm; Slurm job 9_3: JobState=FAILED ExitCode=0:9); ended its tools' \
                 process group(s) 77 (2 process(es)); see "
            ),
            "{why}"
        );
        let end = SlurmEnd {
            state: "TIMEOUT".into(),
            exit_code: "0:15".into(),
            ..end
        };
        std::fs::write(&log, "# sfmeval run task 3 (job 9)\n").unwrap();
        assert_eq!(end_reason(&log, Some(&end)).0, Status::Timeout);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
