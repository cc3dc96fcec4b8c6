//! A user's own command, from `--custom NAME='COMMAND'`. The template is run by `sh -c` after
//! substituting (shell-quoted) `{images}` (the image folder), `{out}` (the folder the command
//! must write its model into: a COLMAP model (text or binary, optionally under `sparse/N`),
//! an `.nvm`, a Bundler `.out` with its `list.txt`, or a `.ply` cloud), `{dataset}` (the
//! dataset folder), `{cameras}` (its cameras.json), `{known}` (`fx,fy,cx,cy`, empty without
//! known intrinsics) and `{seed}`.

use anyhow::Result;

use super::{Adapter, Availability, Env, Job, path_str};
use crate::exec::{Step, shell_quote};

/// A custom command.
pub struct Custom {
    /// Pipeline name.
    pub name: String,
    /// The command template.
    pub template: String,
}

impl Custom {
    /// The template with its placeholders filled in.
    pub fn expand(&self, job: &Job) -> Result<String> {
        let known = job
            .known()?
            .map(|k| k.map(|x| format!("{x}")).join(","))
            .unwrap_or_default();
        let q = |p: &std::path::Path| shell_quote(&path_str(p));
        Ok(self
            .template
            .replace("{images}", &q(&job.dataset.images))
            .replace("{out}", &q(&job.output))
            .replace("{dataset}", &q(&job.dataset.dir))
            .replace("{cameras}", &q(&job.dataset.dir.join("cameras.json")))
            .replace("{known}", &shell_quote(&known))
            .replace("{seed}", &job.seed.to_string()))
    }
}

impl Adapter for Custom {
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        "custom"
    }
    fn options(&self) -> &[&'static str] {
        &[]
    }
    fn availability(&self, _env: &Env) -> Availability {
        Availability::Installed("custom command".into())
    }
    fn steps(&self, _env: &Env, job: &Job) -> Result<Vec<Step>> {
        let cmd = self.expand(job)?;
        Ok(vec![Step::new(
            "custom",
            vec!["sh".into(), "-c".into(), cmd],
            &job.work,
        )])
    }
}
