//! The Blender dataset generator (`blender_scripts/generate.py`, run in the venv's bpy): where
//! it is, its resolved config, and rendering one dataset into a folder.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use serde_json::Value as Json;

use crate::exec::{Step, run_step};
use crate::files::{partial_name, replace_dir};

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

/// Runs the Blender generator (`generate.py ARGS --out TMP`) into a temporary folder beside
/// `dest`, logging to `dest.log`, and moves the dataset into `dest` when it succeeded; returns
/// the seconds spent. A failure names the generator's last error line. `who` prefixes the
/// progress line (`table1`, `sweep`).
pub fn render_dataset(
    who: &str,
    python: &Path,
    scripts: &Path,
    args: &[String],
    dest: &Path,
) -> Result<f64> {
    let tmp = partial_name(dest);
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp)?;
    }
    let mut argv = vec![
        python.to_string_lossy().to_string(),
        scripts.join("generate.py").to_string_lossy().to_string(),
    ];
    argv.extend(args.iter().cloned());
    argv.push("--out".into());
    argv.push(tmp.to_string_lossy().to_string());
    let parent = dest.parent().unwrap_or(Path::new("."));
    let name = dest
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let log = parent.join(format!("{name}.log"));
    eprintln!(
        "{who}: rendering {name} → {} (log {})",
        dest.display(),
        log.display()
    );
    let step = Step::new(&format!("generate {name}"), argv, parent);
    let r = run_step(&step, &log, Instant::now() + Duration::from_secs(48 * 3600));
    if !r.success() {
        let _ = std::fs::remove_dir_all(&tmp);
        let tail = std::fs::read_to_string(&log)
            .ok()
            .and_then(|t| {
                t.lines()
                    .rev()
                    .find(|l| l.contains("error"))
                    .map(str::to_string)
            })
            .unwrap_or_default();
        bail!("{} {tail} (see {})", r.failure_reason(), log.display());
    }
    replace_dir(&tmp, dest)?;
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
