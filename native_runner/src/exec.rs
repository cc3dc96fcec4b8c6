//! Running one tool command: its own process group, stdout and stderr appended to the run's log,
//! a deadline (SIGTERM to the whole group, SIGKILL 5 s later), and the resources it used from
//! `wait4(2)` (CPU time and peak resident memory of the process and the descendants it waited
//! for).

use std::fs::File;
use std::io::Write;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, killpg};
use nix::unistd::Pid;
use serde::{Deserialize, Serialize};
use wait4::Wait4;

/// One command of a pipeline.
#[derive(Debug, Clone)]
pub struct Step {
    /// Short label (`feature_extractor`, `mapper`, ...).
    pub label: String,
    /// Program and arguments.
    pub argv: Vec<String>,
    /// Working directory.
    pub cwd: PathBuf,
    /// Extra environment variables.
    pub env: Vec<(String, String)>,
}

impl Step {
    /// A step running `argv` in `cwd`.
    pub fn new(label: &str, argv: Vec<String>, cwd: &Path) -> Step {
        Step {
            label: label.to_string(),
            argv,
            cwd: cwd.to_path_buf(),
            env: Vec::new(),
        }
    }

    /// The command as one shell-quoted line (for run.json and the log).
    pub fn command_line(&self) -> String {
        self.argv
            .iter()
            .map(|a| shell_quote(a))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Quotes `s` for a POSIX shell when needed.
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// How a step ended.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct StepResult {
    /// The step's label.
    pub label: String,
    /// The exact command.
    pub command: String,
    /// Exit code (null when killed by a signal or not started).
    pub exit_code: Option<i32>,
    /// The signal that ended it, if any.
    pub signal: Option<i32>,
    /// Whether the deadline killed it.
    pub timed_out: bool,
    /// Why it could not start, if it did not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spawn_error: Option<String>,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// User CPU seconds (process and waited-for descendants).
    pub user_seconds: f64,
    /// System CPU seconds.
    pub system_seconds: f64,
    /// Peak resident set size in bytes (the largest single process).
    pub peak_memory_bytes: u64,
}

impl StepResult {
    /// Exited with status 0.
    pub fn success(&self) -> bool {
        self.exit_code == Some(0) && !self.timed_out
    }

    /// A one-line description of a failure.
    pub fn failure_reason(&self) -> String {
        if let Some(e) = &self.spawn_error {
            return format!("{}: could not start: {e}", self.label);
        }
        if self.timed_out {
            return format!("{}: timed out after {:.0} s", self.label, self.wall_seconds);
        }
        match (self.exit_code, self.signal) {
            (Some(c), _) => format!("{}: exit status {c}", self.label),
            (None, Some(s)) => format!("{}: killed by signal {s}", self.label),
            _ => format!("{}: failed", self.label),
        }
    }
}

/// The variable naming the file where every tool's process group is appended (set by a
/// Slurm task's script, which ends those groups when the runner itself was killed).
pub const PROCESS_GROUPS_VAR: &str = "SFMEVAL_PROCESS_GROUPS";

/// Appends `pgid` to the file `$SFMEVAL_PROCESS_GROUPS` names, if any (best effort: the
/// record only lets the task's script clean up after a killed runner).
fn record_process_group(pgid: u32) {
    if let Some(path) = std::env::var_os(PROCESS_GROUPS_VAR)
        && let Ok(mut f) = File::options().create(true).append(true).open(path)
    {
        let _ = writeln!(f, "{pgid}");
    }
}

/// Runs `step`, appending its output to `log`, until it exits or `deadline` passes.
pub fn run_step(step: &Step, log: &Path, deadline: Instant) -> StepResult {
    let started = Instant::now();
    let mut result = StepResult {
        label: step.label.clone(),
        command: step.command_line(),
        exit_code: None,
        signal: None,
        timed_out: false,
        spawn_error: None,
        wall_seconds: 0.0,
        user_seconds: 0.0,
        system_seconds: 0.0,
        peak_memory_bytes: 0,
    };
    let open = || File::options().create(true).append(true).open(log);
    let (mut out, err) = match (open(), open()) {
        (Ok(o), Ok(e)) => (o, e),
        (Err(e), _) | (_, Err(e)) => {
            result.spawn_error = Some(format!("cannot open log {}: {e}", log.display()));
            return result;
        }
    };
    // Best effort: the header only helps a reader of the log.
    let _ = writeln!(out, "\n$ {}   # {}", result.command, step.label);
    let Some((program, args)) = step.argv.split_first() else {
        result.spawn_error = Some("empty command".into());
        return result;
    };
    let mut cmd = Command::new(program);
    cmd.args(args)
        .current_dir(&step.cwd)
        .stdin(Stdio::null())
        .stdout(Stdio::from(out))
        .stderr(Stdio::from(err))
        .process_group(0);
    for (k, v) in &step.env {
        cmd.env(k, v);
    }
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            result.spawn_error = Some(e.to_string());
            return result;
        }
    };
    let pgid = Pid::from_raw(child.id() as i32);
    record_process_group(child.id());
    // A watchdog thread enforces the deadline on the whole process group while this thread
    // blocks in wait4(2).
    let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
    let watchdog = std::thread::spawn(move || {
        let wait = deadline.saturating_duration_since(Instant::now());
        if done_rx.recv_timeout(wait).is_ok() {
            return false;
        }
        let _ = killpg(pgid, Signal::SIGTERM);
        if done_rx.recv_timeout(Duration::from_secs(5)).is_err() {
            let _ = killpg(pgid, Signal::SIGKILL);
        }
        true
    });
    let usage = match child.wait4() {
        Ok(u) => Some(u),
        Err(e) => {
            result.spawn_error = Some(format!("waiting for the process: {e}"));
            let _ = killpg(pgid, Signal::SIGKILL);
            let _ = child.wait();
            None
        }
    };
    let _ = done_tx.send(());
    result.timed_out = watchdog.join().unwrap_or(false);
    // Descendants that outlived their parent (a tool's background helpers) go with the group.
    let _ = killpg(pgid, Signal::SIGKILL);
    result.wall_seconds = started.elapsed().as_secs_f64();
    if let Some(u) = usage {
        result.exit_code = u.status.code();
        result.signal = u.status.signal();
        result.user_seconds = u.rusage.utime.as_secs_f64();
        result.system_seconds = u.rusage.stime.as_secs_f64();
        result.peak_memory_bytes = u.rusage.maxrss;
    }
    if let Ok(mut f) = File::options().append(true).open(log) {
        let _ = writeln!(
            f,
            "# {} finished: exit {:?}, signal {:?}, timed out {}, {:.1} s",
            step.label, result.exit_code, result.signal, result.timed_out, result.wall_seconds
        );
    }
    result
}

/// Runs a short command and returns its trimmed stdout+stderr when it exits with 0.
pub fn probe(argv: &[&str], timeout: Duration) -> Option<String> {
    let (program, args) = argv.split_first()?;
    let mut child = Command::new(program)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0)
        .spawn()
        .ok()?;
    let deadline = Instant::now() + timeout;
    loop {
        match child.try_wait() {
            Ok(Some(_)) => break,
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(20)),
            _ => {
                let _ = killpg(Pid::from_raw(child.id() as i32), Signal::SIGKILL);
                let _ = child.wait();
                return None;
            }
        }
    }
    let out = child.wait_with_output().ok()?;
    if !out.status.success() {
        return None;
    }
    let mut s = String::from_utf8_lossy(&out.stdout).to_string();
    s.push_str(&String::from_utf8_lossy(&out.stderr));
    Some(s.trim().to_string())
}

/// The first directory of `PATH` holding an executable `name`.
pub fn which(name: &str) -> Option<PathBuf> {
    if name.contains('/') {
        let p = PathBuf::from(name);
        return is_executable(&p).then_some(p);
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| is_executable(p))
}

fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    p.metadata()
        .map(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
        .unwrap_or(false)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn quoting() {
        assert_eq!(shell_quote("abc/d.txt"), "abc/d.txt");
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
        assert_eq!(shell_quote(""), "''");
    }

    #[test]
    fn runs_measures_and_times_out() {
        let dir = std::env::temp_dir().join(format!("sfmeval-runner-exec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let log = dir.join("log.txt");
        let ok = Step::new(
            "echo",
            vec!["sh".into(), "-c".into(), "echo hi".into()],
            &dir,
        );
        let r = run_step(&ok, &log, Instant::now() + Duration::from_secs(30));
        assert!(r.success(), "{r:?}");
        assert!(std::fs::read_to_string(&log).unwrap().contains("hi"));
        let bad = Step::new(
            "false",
            vec!["sh".into(), "-c".into(), "exit 3".into()],
            &dir,
        );
        let r = run_step(&bad, &log, Instant::now() + Duration::from_secs(30));
        assert_eq!(r.exit_code, Some(3));
        assert!(r.failure_reason().contains("exit status 3"));
        let slow = Step::new(
            "sleep",
            vec!["sh".into(), "-c".into(), "sleep 30 & sleep 30".into()],
            &dir,
        );
        let t = Instant::now();
        let r = run_step(&slow, &log, Instant::now() + Duration::from_millis(300));
        assert!(
            r.timed_out && t.elapsed() < Duration::from_secs(10),
            "{r:?}"
        );
        assert!(r.failure_reason().contains("timed out"));
        let missing = Step::new("x", vec!["/nonexistent/tool".into()], &dir);
        let r = run_step(&missing, &log, Instant::now() + Duration::from_secs(5));
        assert!(r.spawn_error.is_some() && !r.success());
        std::fs::remove_dir_all(&dir).ok();
    }
}
