//! VisualSfM (closed binary, needs SiftGPU; in no package registry): `VisualSFM sfm+shared
//! <images> <out.nvm>` when on PATH. Absent, the run is recorded as not installed.

use anyhow::Result;

use super::{Adapter, Availability, Env, Job, path_str};
use crate::exec::Step;

/// VisualSfM.
pub struct VisualSfm {
    /// Pipeline name.
    pub name: String,
}

impl Adapter for VisualSfm {
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        "VisualSfM"
    }
    fn options(&self) -> &[&'static str] {
        &[]
    }
    fn availability(&self, env: &Env) -> Availability {
        match crate::exec::which(&env.visualsfm) {
            // VisualSfM has no version flag; its first log line names the build.
            Some(p) => Availability::Installed(format!("VisualSfM ({})", p.display())),
            None => Availability::Missing(format!(
                "not installed: '{}' is not on PATH (VisualSfM is a closed binary needing SiftGPU, in no package registry; put it on PATH or pass --visualsfm PATH)",
                env.visualsfm
            )),
        }
    }
    fn steps(&self, env: &Env, job: &Job) -> Result<Vec<Step>> {
        // VisualSfM takes the calibration as fx,cx,fy,cy with the principal point relative to
        // the image's top-left corner; it reads EXIF focal lengths otherwise.
        let mode = match job.known()? {
            Some([fx, fy, cx, cy]) => format!("sfm+shared+k={fx},{cx},{fy},{cy}"),
            None => "sfm+shared".into(),
        };
        let argv = vec![
            env.visualsfm.clone(),
            mode,
            path_str(&job.dataset.images),
            format!("{}/result.nvm", job.output_rel),
        ];
        Ok(vec![Step::new("VisualSFM", argv, &job.work)])
    }
}
