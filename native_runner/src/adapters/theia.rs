//! pytheia (TheiaSfM, PyPI): OpenCV SIFT + ratio test, focal from EXIF, Theia's global or
//! incremental estimator. Runs `adapters/theia_run.py` in the venv.

use anyhow::Result;

use super::{Adapter, Availability, Env, Job};
use crate::exec::Step;

/// pytheia, global or incremental.
pub struct Theia {
    /// Pipeline name.
    pub name: String,
    /// Incremental instead of global.
    pub incremental: bool,
}

impl Adapter for Theia {
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        "pytheia"
    }
    fn options(&self) -> &[&'static str] {
        &[
            "max_features",
            "ratio",
            "min_inliers",
            "matcher",
            "overlap",
            "min_track",
            "max_track",
            "max_sampson_error",
            "loss",
            "loss_width",
            "threads",
        ]
    }
    fn availability(&self, env: &Env) -> Availability {
        match env.python_module("cv2", "cv2.__version__") {
            Availability::Installed(_) => env.python_module(
                "pytheia",
                "__import__('importlib.metadata').metadata.version('pytheia')",
            ),
            missing => missing,
        }
    }
    fn steps(&self, env: &Env, job: &Job) -> Result<Vec<Step>> {
        let mode = if self.incremental {
            "incremental"
        } else {
            "global"
        };
        let mut argv = env.script("theia_run.py");
        argv.extend(job.python_args(mode)?);
        Ok(vec![Step::new(&format!("pytheia {mode}"), argv, &job.work)])
    }
}
