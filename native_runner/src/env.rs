//! Where the runner finds its programs: the venv's Python interpreter, and the adapters'
//! [`Env`] of a batch (interpreter, adapter scripts, tool executables).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::adapters::Env;
use crate::args::ToolArgs;
use crate::run::install_scripts;

/// The venv interpreter: flag, $SFMEVAL_PYTHON, ./.venv, a .venv beside an ancestor of the
/// binary (the repository's), then `python3`. The commands run in other folders (the run
/// folders, the generator's datasets folder), so a relative path with a folder part
/// (`.venv/bin/python`) is made absolute here; a bare name is searched on PATH as it is.
pub fn find_python(given: Option<&Path>) -> Result<PathBuf> {
    let python = candidate_python(given);
    if python.is_relative() && python.components().count() > 1 {
        return std::path::absolute(&python)
            .with_context(|| format!("resolving the Python path {}", python.display()));
    }
    Ok(python)
}

fn candidate_python(given: Option<&Path>) -> PathBuf {
    if let Some(p) = given {
        return p.to_path_buf();
    }
    if let Some(p) = std::env::var_os("SFMEVAL_PYTHON") {
        return PathBuf::from(p);
    }
    let local = PathBuf::from(".venv/bin/python");
    if local.exists() {
        return local;
    }
    if let Ok(exe) = std::env::current_exe() {
        for dir in exe.ancestors().skip(1) {
            let p = dir.join(".venv/bin/python");
            if p.exists() {
                return p;
            }
        }
    }
    PathBuf::from("python3")
}

/// The adapters' environment of a batch writing into `out`: the adapter scripts installed
/// under `out`, the interpreter ([`find_python`]) and the tools' executables.
pub fn make_env(tools: &ToolArgs, out: &Path) -> Result<Env> {
    let scripts = install_scripts(out)?;
    let python = find_python(tools.python.as_deref())?;
    Ok(Env::new(
        python,
        scripts,
        tools.colmap.clone(),
        tools.visualsfm.clone(),
    ))
}
