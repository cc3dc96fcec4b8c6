//! pycolmap (COLMAP as a Python library, PyPI): incremental mapper, or its global mapper
//! (GLOMAP). Runs `adapters/pycolmap_run.py` in the venv.

use anyhow::Result;

use super::{Adapter, Availability, Env, Job};
use crate::exec::Step;

/// pycolmap, incremental or global.
pub struct Pycolmap {
    /// Pipeline name.
    pub name: String,
    /// GLOMAP instead of the incremental mapper.
    pub global: bool,
}

impl Adapter for Pycolmap {
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        if self.global {
            "pycolmap (GLOMAP)"
        } else {
            "pycolmap"
        }
    }
    fn options(&self) -> &[&'static str] {
        &[
            "matcher",
            "overlap",
            "max_features",
            "single_camera",
            "threads",
        ]
    }
    fn availability(&self, env: &Env) -> Availability {
        env.python_module("pycolmap", "pycolmap.__version__")
    }
    fn steps(&self, env: &Env, job: &Job) -> Result<Vec<Step>> {
        let mode = if self.global { "global" } else { "incremental" };
        let mut argv = env.script("pycolmap_run.py");
        argv.extend(job.python_args(mode)?);
        Ok(vec![Step::new(
            &format!("pycolmap {mode}"),
            argv,
            &job.work,
        )])
    }
}
