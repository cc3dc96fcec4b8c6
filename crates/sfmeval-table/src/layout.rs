//! The run folder's layout (`<runs>/<dataset>/<pipeline>/`, written by `sfmeval-runner run`):
//! its record is `run.json`, its reconstruction the model files under `model/` (any depth, so
//! COLMAP's `sparse/N/` survives), else `sparse.ply`. Defined here once for the runner's
//! `report` (through [`read_run_reconstruction`]) and the page (through the wasm bindings, on
//! the files of a picked folder).

use std::collections::BTreeMap;

use sfmeval::files::{FileSource, is_model_file, join};

/// The run's record.
pub const RUN_JSON: &str = "run.json";
/// The folder of the tool's model.
pub const MODEL_DIR: &str = "model";
/// The reconstructed points, when there is no model.
pub const SPARSE_PLY: &str = "sparse.ply";

/// Which of a run folder's files (paths relative to it, `/`-separated) form its reconstruction:
/// `(path, name)` pairs, the name as the reconstruction's readers key it (relative to `model/`),
/// the model's files when `model/` has some, else `sparse.ply` when present, else none.
pub fn reconstruction_files<S: AsRef<str>>(paths: &[S]) -> Vec<(String, String)> {
    let prefix = format!("{MODEL_DIR}/");
    let model: Vec<(String, String)> = paths
        .iter()
        .map(AsRef::as_ref)
        .filter_map(|p| {
            let rel = p.strip_prefix(&prefix)?;
            is_model_file(rel).then(|| (p.to_string(), rel.to_string()))
        })
        .collect();
    if !model.is_empty() {
        return model;
    }
    paths
        .iter()
        .map(AsRef::as_ref)
        .filter(|p| *p == SPARSE_PLY)
        .map(|p| (p.to_string(), p.to_string()))
        .collect()
}

/// The reconstruction's files of the run folder `run_dir`, keyed as [`reconstruction_files`]
/// names them; an error names the folder when it has none.
pub fn read_run_reconstruction(
    source: &dyn FileSource,
    run_dir: &str,
) -> sfmeval::Result<BTreeMap<String, Vec<u8>>> {
    let prefix = join(run_dir, "");
    let mut paths: Vec<String> = source
        .list(&join(run_dir, MODEL_DIR))?
        .iter()
        .map(|p| p.strip_prefix(&prefix).unwrap_or(p).to_string())
        .collect();
    paths.push(SPARSE_PLY.to_string());
    let mut files = BTreeMap::new();
    for (path, name) in reconstruction_files(&paths) {
        if let Some(bytes) = source.read(&join(run_dir, &path))? {
            files.insert(name, bytes);
        }
    }
    if files.is_empty() {
        return Err(sfmeval::Error::Missing {
            what: format!("model files in {MODEL_DIR}/ or {SPARSE_PLY} in run folder"),
            file: run_dir.to_string(),
        });
    }
    Ok(files)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn the_model_first_then_the_points() {
        let run = [
            "run.json",
            "log.txt",
            "sparse.ply",
            "model/sparse/0/cameras.bin",
            "model/sparse/0/images.bin",
            "model/notes.md",
            "model/frame.jpg",
        ];
        assert_eq!(
            reconstruction_files(&run),
            [
                (
                    "model/sparse/0/cameras.bin".into(),
                    "sparse/0/cameras.bin".into()
                ),
                (
                    "model/sparse/0/images.bin".into(),
                    "sparse/0/images.bin".into()
                )
            ]
        );
        assert_eq!(
            reconstruction_files(&["run.json", "sparse.ply", "model/readme.md"]),
            [("sparse.ply".to_string(), "sparse.ply".to_string())]
        );
        assert!(reconstruction_files(&["run.json", "other/sparse.ply"]).is_empty());
    }

    struct Mem(BTreeMap<String, Vec<u8>>);
    impl FileSource for Mem {
        fn read(&self, path: &str) -> sfmeval::Result<Option<Vec<u8>>> {
            Ok(self.0.get(path).cloned())
        }
        fn list(&self, dir: &str) -> sfmeval::Result<Vec<String>> {
            let p = format!("{dir}/");
            Ok(self
                .0
                .keys()
                .filter(|k| k.starts_with(&p))
                .cloned()
                .collect())
        }
        fn is_dir(&self, path: &str) -> bool {
            self.0.keys().any(|k| k.starts_with(&format!("{path}/")))
        }
    }

    #[test]
    fn reads_a_run_folder_and_names_it_when_empty() {
        let mem = Mem(BTreeMap::from([
            ("r/p/run.json".to_string(), b"{}".to_vec()),
            ("r/p/sparse.ply".to_string(), b"ply".to_vec()),
            ("r/q/run.json".to_string(), b"{}".to_vec()),
        ]));
        let files = read_run_reconstruction(&mem, "r/p").unwrap();
        assert_eq!(files.keys().collect::<Vec<_>>(), ["sparse.ply"]);
        let e = read_run_reconstruction(&mem, "r/q")
            .unwrap_err()
            .to_string();
        assert!(e.contains("r/q") && e.contains("sparse.ply"), "{e}");
    }
}
