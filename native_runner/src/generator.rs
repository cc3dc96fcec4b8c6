//! The Blender dataset generator (`blender_scripts/generate.py`, run in the venv's bpy): where
//! it is, its resolved config, and one call of it.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use serde_json::Value as Json;

use crate::exec::{Step, run_step};

/// The `blender_scripts` folder: given, `$SFMEVAL_BLENDER_SCRIPTS`, beside an ancestor of the
/// binary, or under the working directory.
pub fn find_blender_scripts(given: Option<&Path>) -> Result<PathBuf> {
    let ok = |p: &Path| p.join("generate.py").is_file();
    if let Some(p) = given {
        if ok(p) {
            return Ok(p.to_path_buf());
        }
        bail!("{} has no generate.py", p.display());
    }
    let mut candidates: Vec<PathBuf> = Vec::new();
    if let Some(p) = std::env::var_os("SFMEVAL_BLENDER_SCRIPTS") {
        candidates.push(PathBuf::from(p));
    }
    if let Ok(exe) = std::env::current_exe() {
        candidates.extend(exe.ancestors().skip(1).map(|d| d.join("blender_scripts")));
    }
    candidates.push(PathBuf::from("blender_scripts"));
    candidates
        .into_iter()
        .find(|p| ok(p))
        .context("blender_scripts/generate.py not found: pass --blender-scripts DIR")
}

/// One call of the Blender generator: `generate.py ARGS --out OUT` run from `cwd` (where the
/// relative model paths of `--set` are read), in its own process group, its output appended
/// to `log`; returns its wall seconds. A failure names the generator's last error line.
pub fn run_generator(
    label: &str,
    python: &Path,
    scripts: &Path,
    args: &[String],
    out: &Path,
    cwd: &Path,
    log: &Path,
) -> Result<f64> {
    let mut argv = vec![
        python.to_string_lossy().to_string(),
        scripts.join("generate.py").to_string_lossy().to_string(),
    ];
    argv.extend(args.iter().cloned());
    argv.push("--out".into());
    argv.push(out.to_string_lossy().to_string());
    let step = Step::new(label, argv, cwd);
    // this call's part of the log: it may hold earlier calls' output
    let start = std::fs::metadata(log).map_or(0, |m| m.len());
    let r = run_step(&step, log, Instant::now() + Duration::from_secs(48 * 3600));
    if !r.success() {
        let tail = std::fs::read(log)
            .ok()
            .and_then(|bytes| {
                let mine = bytes.get(start as usize..).unwrap_or_default();
                String::from_utf8_lossy(mine)
                    .lines()
                    .rev()
                    .find(|l| l.contains("error"))
                    .map(str::to_string)
            })
            .unwrap_or_default();
        bail!("{} {tail} (see {})", r.failure_reason(), log.display());
    }
    Ok(r.wall_seconds)
}

/// The generator's resolved config for `args` (`generate.py [--preset P] [--config F] --set ...
/// --print-config`), as JSON.
pub fn resolved_config(python: &Path, scripts: &Path, base_args: &[String]) -> Result<Json> {
    let mut cmd = std::process::Command::new(python);
    cmd.arg(scripts.join("generate.py"))
        .args(base_args)
        .arg("--print-config");
    let out = cmd
        .output()
        .with_context(|| format!("running {}", python.display()))?;
    if !out.status.success() {
        bail!(
            "the generator rejected the base config: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    serde_json::from_slice(&out.stdout).context("reading the generator's --print-config output")
}
