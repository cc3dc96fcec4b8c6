//! The COLMAP command line (Debian `colmap` 3.8 or newer): feature_extractor, exhaustive or
//! sequential matcher, mapper, then model_converter of the largest sub-model to text (the
//! binary sub-model itself is kept as the run folder's `raw/sparse/N`). CPU only:
//! SIFT extraction and matching need `use_gpu 0` (no OpenGL context headless).

use std::collections::BTreeMap;

use anyhow::{Context, Result, bail};

use super::{Adapter, Availability, Env, Job, path_str};
use crate::exec::Step;

/// COLMAP CLI.
pub struct Colmap {
    /// Pipeline name.
    pub name: String,
}

fn opt<'a>(o: &'a BTreeMap<String, String>, k: &str) -> Option<&'a String> {
    o.get(k)
}

impl Adapter for Colmap {
    fn name(&self) -> &str {
        &self.name
    }
    fn tool(&self) -> &str {
        "COLMAP"
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
        if crate::exec::which(&env.colmap).is_none() {
            return Availability::Missing(format!(
                "'{}' not on PATH (Debian: apt-get install colmap)",
                env.colmap
            ));
        }
        match crate::exec::probe(&[&env.colmap, "-h"], std::time::Duration::from_secs(30)) {
            Some(out) => Availability::Installed(
                out.lines()
                    .next()
                    .unwrap_or("COLMAP")
                    .split(" -- ")
                    .next()
                    .unwrap_or("COLMAP")
                    .trim()
                    .to_string(),
            ),
            None => Availability::Missing(format!("'{} -h' failed", env.colmap)),
        }
    }
    fn steps(&self, env: &Env, job: &Job) -> Result<Vec<Step>> {
        let o = job.options;
        let db = format!("{}/database.db", job.scratch_rel);
        let images = path_str(&job.dataset.images);
        let sparse = job.scratch.join("sparse");
        std::fs::create_dir_all(&sparse)
            .with_context(|| format!("creating {}", sparse.display()))?;
        let c = |args: &[&str]| -> Vec<String> {
            std::iter::once(env.colmap.clone())
                .chain(args.iter().map(|s| s.to_string()))
                .collect()
        };
        let threads = opt(o, "threads").cloned().unwrap_or_else(|| "-1".into());
        let mut extract = c(&[
            "feature_extractor",
            "--database_path",
            &db,
            "--image_path",
            &images,
            "--ImageReader.single_camera",
            opt(o, "single_camera").map_or("1", |s| s.as_str()),
            "--SiftExtraction.use_gpu",
            "0",
            "--SiftExtraction.num_threads",
            &threads,
        ]);
        if let Some(n) = opt(o, "max_features") {
            extract.extend(["--SiftExtraction.max_num_features".into(), n.clone()]);
        }
        let known = job.known()?;
        if let Some([fx, fy, cx, cy]) = known {
            extract.extend([
                "--ImageReader.camera_model".into(),
                "PINHOLE".into(),
                "--ImageReader.camera_params".into(),
                format!("{fx},{fy},{cx},{cy}"),
            ]);
        }
        let matcher = opt(o, "matcher").map_or("exhaustive", |s| s.as_str());
        let mut matching = match matcher {
            "exhaustive" => c(&["exhaustive_matcher", "--database_path", &db]),
            "sequential" => c(&[
                "sequential_matcher",
                "--database_path",
                &db,
                "--SequentialMatching.overlap",
                opt(o, "overlap").map_or("10", |s| s.as_str()),
            ]),
            other => bail!("colmap: unknown matcher '{other}' (exhaustive, sequential)"),
        };
        matching.extend([
            "--SiftMatching.use_gpu".into(),
            "0".into(),
            "--SiftMatching.num_threads".into(),
            threads.clone(),
        ]);
        let mut mapper = c(&[
            "mapper",
            "--database_path",
            &db,
            "--image_path",
            &images,
            "--output_path",
            &format!("{}/sparse", job.scratch_rel),
            "--random_seed",
            &job.seed.to_string(),
            "--Mapper.num_threads",
            &threads,
        ]);
        if known.is_some() {
            for k in [
                "--Mapper.ba_refine_focal_length",
                "--Mapper.ba_refine_principal_point",
                "--Mapper.ba_refine_extra_params",
            ] {
                mapper.extend([k.into(), "0".into()]);
            }
        }
        let cwd = &job.work;
        Ok(vec![
            Step::new("feature_extractor", extract, cwd),
            Step::new(&format!("{matcher}_matcher"), matching, cwd),
            Step::new("mapper", mapper, cwd),
        ])
    }
    fn after(&self, env: &Env, job: &Job) -> Result<Vec<Step>> {
        let sparse = job.scratch.join("sparse");
        let mut best: Option<(usize, std::path::PathBuf)> = None;
        let entries =
            std::fs::read_dir(&sparse).with_context(|| format!("reading {}", sparse.display()))?;
        let mut dirs: Vec<_> = entries.filter_map(|e| e.ok()).map(|e| e.path()).collect();
        dirs.sort();
        for d in dirs.into_iter().filter(|d| d.is_dir()) {
            let files = sfmeval_fs::read_input_files(&d)?;
            let Ok(rec) = sfmeval::model::read_model_files(&files) else {
                continue;
            };
            if best.as_ref().is_none_or(|(n, _)| rec.images.len() > *n) {
                best = Some((rec.images.len(), d));
            }
        }
        let Some((_, dir)) = best else {
            bail!("the mapper wrote no model (no image pair could be registered)");
        };
        let sub = dir
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let model = format!("{}/sparse/{sub}", job.scratch_rel);
        // The mapper's own binary model (the largest) is kept as raw/sparse/N (a few MB at
        // most): scratch/ is deleted after the run.
        let raw = job.work.join("raw").join("sparse");
        std::fs::create_dir_all(&raw).with_context(|| format!("creating {}", raw.display()))?;
        Ok(vec![
            Step::new(
                "model_converter",
                vec![
                    env.colmap.clone(),
                    "model_converter".into(),
                    "--input_path".into(),
                    model.clone(),
                    "--output_path".into(),
                    job.output_rel.clone(),
                    "--output_type".into(),
                    "TXT".into(),
                ],
                &job.work,
            ),
            Step::new(
                "copy_binary_model",
                vec!["cp".into(), "-R".into(), model, format!("raw/sparse/{sub}")],
                &job.work,
            ),
        ])
    }
}
