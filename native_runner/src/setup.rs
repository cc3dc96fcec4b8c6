//! `sfmeval-runner setup`: creates (or updates) the Python venv the adapters run in, with the
//! pinned versions of requirements/runner.txt (embedded in the binary).

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

/// requirements/runner.txt, as built into this binary.
pub const REQUIREMENTS: &str = include_str!("../../requirements/runner.txt");

/// Creates `venv` with `python` if it does not exist, then installs the pinned requirements.
pub fn setup(venv: &Path, python: &str) -> Result<()> {
    let py = venv.join("bin").join("python");
    if !py.exists() {
        eprintln!("setup: creating {} with {python}", venv.display());
        let st = Command::new(python)
            .args(["-m", "venv"])
            .arg(venv)
            .status()
            .with_context(|| {
                format!("running {python} (bpy 5.0 needs CPython 3.11: pass --python)")
            })?;
        if !st.success() {
            bail!("{python} -m venv {} failed", venv.display());
        }
    }
    let req = std::env::temp_dir().join(format!(
        "sfmeval-runner-requirements-{}.txt",
        std::process::id()
    ));
    std::fs::write(&req, REQUIREMENTS).with_context(|| format!("writing {}", req.display()))?;
    eprintln!(
        "setup: pip install -r requirements/runner.txt into {}",
        venv.display()
    );
    let st = Command::new(&py)
        .args(["-m", "pip", "install", "--disable-pip-version-check", "-r"])
        .arg(&req)
        .status()
        .with_context(|| format!("running {}", py.display()))?;
    let _ = std::fs::remove_file(&req);
    if !st.success() {
        bail!("pip install failed");
    }
    if crate::exec::which("colmap").is_none() {
        eprintln!("setup: the COLMAP CLI is not on PATH; on Debian/Ubuntu: apt-get install colmap");
    }
    eprintln!(
        "setup: done. Use --python {} (or run from the folder holding .venv).",
        py.display()
    );
    Ok(())
}
