//! One adapter per SfM tool, all behind [`Adapter`]: what the tool needs (availability and
//! version), the commands to run, and where the model lands. The runner executes the commands
//! (timeout, log, resources) and turns whatever model the tool wrote into the run folder's
//! files, so an adapter never writes run files itself.

mod colmap;
mod custom;
mod openmvg;
mod pycolmap;
mod theia;
mod visualsfm;

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

use anyhow::{Result, bail};

use crate::dataset::Dataset;
use crate::exec::{Step, probe};

pub use custom::Custom;

/// Whether the tool can run here.
#[derive(Debug, Clone, PartialEq)]
pub enum Availability {
    /// Installed, with its version.
    Installed(String),
    /// Not installed (or not usable), with the reason.
    Missing(String),
}

/// Where the intrinsics given to the tool come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Intrinsics {
    /// The images' EXIF, as a user would run the tool.
    Exif,
    /// The dataset's `cameras.json` (exact intrinsics).
    Known,
}

impl Intrinsics {
    /// `exif` or `known`.
    pub fn name(self) -> &'static str {
        match self {
            Intrinsics::Exif => "exif",
            Intrinsics::Known => "known",
        }
    }
}

/// Paths and programs shared by all adapters.
#[derive(Debug)]
pub struct Env {
    /// The Python interpreter of the venv holding pycolmap, pytheia, openmvg-rs.
    pub python: PathBuf,
    /// Folder the adapter scripts were written to.
    pub scripts: PathBuf,
    /// The COLMAP executable.
    pub colmap: String,
    /// The VisualSfM executable.
    pub visualsfm: String,
    cache: Mutex<HashMap<String, Availability>>,
}

impl Env {
    /// An environment; availability checks are cached per probe.
    pub fn new(python: PathBuf, scripts: PathBuf, colmap: String, visualsfm: String) -> Env {
        Env {
            python,
            scripts,
            colmap,
            visualsfm,
            cache: Mutex::new(HashMap::new()),
        }
    }

    /// Availability of a Python module, by importing it and printing `version_expr`.
    pub fn python_module(&self, module: &str, version_expr: &str) -> Availability {
        let key = format!("py:{module}");
        if let Some(a) = self.cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
            return a;
        }
        let python = self.python.to_string_lossy().to_string();
        let code = format!("import {module}; print({version_expr})");
        let a = if !self.python.exists() && crate::exec::which(&python).is_none() {
            Availability::Missing(format!(
                "Python interpreter {python} not found (run `sfmeval-runner setup`)"
            ))
        } else {
            match probe(&[&python, "-c", &code], Duration::from_secs(120)) {
                Some(v) => {
                    Availability::Installed(v.lines().last().unwrap_or_default().trim().to_string())
                }
                None => Availability::Missing(format!(
                    "Python module '{module}' not importable by {python} (run `sfmeval-runner setup`)"
                )),
            }
        };
        if let Ok(mut c) = self.cache.lock() {
            c.insert(key, a.clone());
        }
        a
    }

    /// The adapter script `name` as an argv prefix (`python script.py`).
    pub fn script(&self, name: &str) -> Vec<String> {
        vec![
            self.python.to_string_lossy().to_string(),
            self.scripts.join(name).to_string_lossy().to_string(),
        ]
    }
}

/// One run of one tool on one dataset.
#[derive(Debug)]
pub struct Job<'a> {
    /// The dataset.
    pub dataset: &'a Dataset,
    /// The run's (temporary) folder.
    pub work: PathBuf,
    /// Where the tool must leave its final model (COLMAP text/binary, NVM, Bundler or PLY).
    pub output: PathBuf,
    /// `output` relative to `work` (the commands run in `work`, so run.json's commands stay
    /// valid inside the finished run folder).
    pub output_rel: String,
    /// `scratch` relative to `work`.
    pub scratch_rel: String,
    /// Scratch space deleted after the run (databases, features).
    pub scratch: PathBuf,
    /// Intrinsics source.
    pub intrinsics: Intrinsics,
    /// Pipeline options (`key=value` from the pipeline spec).
    pub options: &'a BTreeMap<String, String>,
    /// Seed for the tools that take one.
    pub seed: u64,
}

impl Job<'_> {
    /// The dataset's intrinsics `[fx, fy, cx, cy]` (COLMAP convention) when the job uses them.
    pub fn known(&self) -> Result<Option<[f64; 4]>> {
        match self.intrinsics {
            Intrinsics::Exif => Ok(None),
            Intrinsics::Known => match self.dataset.known {
                Some(k) => Ok(Some(k)),
                None => bail!(
                    "--intrinsics known needs the dataset's cameras.json with one camera ({})",
                    self.dataset.dir.display()
                ),
            },
        }
    }

    /// `--known fx,fy,cx,cy` for the Python adapters, and the common arguments.
    pub fn python_args(&self, mode: &str) -> Result<Vec<String>> {
        let mut v = vec![
            "--images".into(),
            path_str(&self.dataset.images),
            "--out".into(),
            self.output_rel.clone(),
            "--mode".into(),
            mode.into(),
            "--seed".into(),
            self.seed.to_string(),
        ];
        if let Some(k) = self.known()? {
            v.push("--known".into());
            v.push(k.map(|x| format!("{x}")).join(","));
        }
        for (k, val) in self.options {
            if !RUNNER_OPTIONS.contains(&k.as_str()) {
                v.push("--option".into());
                v.push(format!("{k}={val}"));
            }
        }
        Ok(v)
    }
}

/// A path as a string for a command line.
pub fn path_str(p: &Path) -> String {
    p.to_string_lossy().to_string()
}

/// Pipeline options handled by the runner itself, valid for every pipeline (and not passed
/// to the tool).
pub const RUNNER_OPTIONS: [&str; 3] = ["timeout", "name", "intrinsics"];

/// What every SfM tool adapter provides.
pub trait Adapter: Send + Sync {
    /// The pipeline name (`colmap`, `pycolmap-global`, ...).
    fn name(&self) -> &str;
    /// The tool, for run.json and the tables.
    fn tool(&self) -> &str;
    /// Options this adapter understands (besides the runner's own, `timeout` and `name`).
    fn options(&self) -> &[&'static str];
    /// Whether the tool is installed, and its version.
    fn availability(&self, env: &Env) -> Availability;
    /// The commands to run, in order.
    fn steps(&self, env: &Env, job: &Job) -> Result<Vec<Step>>;
    /// More commands once [`Adapter::steps`] succeeded (e.g. converting the largest sub-model).
    fn after(&self, _env: &Env, _job: &Job) -> Result<Vec<Step>> {
        Ok(Vec::new())
    }
}

/// The built-in pipelines, in table order (the list the tables order by).
pub const BUILTIN: [&str; 8] = sfmeval_table::BUILTIN_PIPELINES;

/// The adapter of a built-in pipeline, or of a custom one defined by `customs`.
pub fn adapter(
    kind: &str,
    name: &str,
    customs: &BTreeMap<String, String>,
) -> Result<Box<dyn Adapter>> {
    let n = name.to_string();
    Ok(match kind {
        "colmap" => Box::new(colmap::Colmap { name: n }),
        "pycolmap" => Box::new(pycolmap::Pycolmap {
            name: n,
            global: false,
        }),
        "pycolmap-global" => Box::new(pycolmap::Pycolmap {
            name: n,
            global: true,
        }),
        "theia" => Box::new(theia::Theia {
            name: n,
            incremental: false,
        }),
        "theia-incremental" => Box::new(theia::Theia {
            name: n,
            incremental: true,
        }),
        "openmvg" => Box::new(openmvg::Openmvg {
            name: n,
            global: false,
        }),
        "openmvg-global" => Box::new(openmvg::Openmvg {
            name: n,
            global: true,
        }),
        "visualsfm" => Box::new(visualsfm::VisualSfm { name: n }),
        other => match customs.get(other) {
            Some(template) => Box::new(Custom {
                name: n,
                template: template.clone(),
            }),
            None => bail!(
                "unknown pipeline '{other}' (built-in: {}; define others with --custom NAME=COMMAND)",
                BUILTIN.join(", ")
            ),
        },
    })
}

/// The adapter scripts, embedded so the binary works from anywhere.
pub const SCRIPTS: [(&str, &str); 4] = [
    ("common.py", include_str!("../../adapters/common.py")),
    (
        "pycolmap_run.py",
        include_str!("../../adapters/pycolmap_run.py"),
    ),
    ("theia_run.py", include_str!("../../adapters/theia_run.py")),
    (
        "openmvg_run.py",
        include_str!("../../adapters/openmvg_run.py"),
    ),
];
