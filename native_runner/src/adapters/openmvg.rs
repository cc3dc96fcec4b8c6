//! openmvg-rs (a Rust port of OpenMVG, PyPI): incremental or global engine. Runs
//! `adapters/openmvg_run.py` in the venv.

use anyhow::Result;

use super::{Adapter, Availability, Env, Job};
use crate::exec::Step;

/// openmvg-rs, incremental or global.
pub struct Openmvg {
    /// Pipeline name.
    pub name: String,
    /// Global engine instead of incremental.
    pub global: bool,
}

impl Adapter for Openmvg {
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        "openmvg-rs"
    }
    fn options(&self) -> &[&'static str] {
        &["features", "threads"]
    }
    fn availability(&self, env: &Env) -> Availability {
        env.python_module("openmvg_rs", "openmvg_rs.__version__")
    }
    fn steps(&self, env: &Env, job: &Job) -> Result<Vec<Step>> {
        let mode = if self.global { "global" } else { "incremental" };
        let mut argv = env.script("openmvg_run.py");
        argv.extend(job.python_args(mode)?);
        Ok(vec![Step::new(
            &format!("openmvg-rs {mode}"),
            argv,
            &job.work,
        )])
    }
}
