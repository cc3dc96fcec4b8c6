//! Named files as the core reads them. The core never touches a filesystem: a front end hands it
//! a [`FileSource`] (a folder on disk in the CLI and the runner, the files dropped on the page,
//! or an in-memory map) and the core asks it for the files an input needs, by `/`-separated
//! path. An in-memory `BTreeMap<String, Vec<u8>>` is a source.

use std::collections::BTreeMap;

use crate::error::Result;
use crate::io::LoadedCloud;

/// Files readable by path.
pub trait FileSource {
    /// The bytes of the file at `path`; `Ok(None)` when there is no such file (a folder is not
    /// a file). A file that exists but cannot be read is an [`crate::Error::Io`].
    fn read(&self, path: &str) -> Result<Option<Vec<u8>>>;
    /// Every file under the folder `dir`, at any depth, as paths [`Self::read`] takes, sorted;
    /// empty when `dir` is not a folder.
    fn list(&self, dir: &str) -> Result<Vec<String>>;
    /// Whether `path` is a folder.
    fn is_dir(&self, path: &str) -> bool;
    /// The point cloud in the file at `path` as [`crate::io::read_point_cloud`] reads the
    /// file's bytes (named by `path`); `Ok(None)` when there is no such file. A source may read
    /// it in pieces: the disk streams binary PLY clouds, so that the file's bytes never sit in
    /// memory beside its points.
    fn read_point_cloud(&self, path: &str) -> Result<Option<LoadedCloud>> {
        read_whole_point_cloud(self, path)
    }
}

/// The point cloud in the file at `path`, read whole through [`FileSource::read`] and parsed by
/// [`crate::io::read_point_cloud`]: [`FileSource::read_point_cloud`]'s default, and the
/// fallback of a source that streams only some formats.
pub fn read_whole_point_cloud<S: FileSource + ?Sized>(
    source: &S,
    path: &str,
) -> Result<Option<LoadedCloud>> {
    source
        .read(path)?
        .map(|bytes| crate::io::read_point_cloud(path, &bytes))
        .transpose()
}

/// `dir/name` (`name` when `dir` is empty).
pub fn join(dir: &str, name: &str) -> String {
    if dir.is_empty() || dir == "." {
        name.to_string()
    } else if dir.ends_with('/') {
        format!("{dir}{name}")
    } else {
        format!("{dir}/{name}")
    }
}

/// The folder part of `path` (`""` for a bare name).
pub fn parent(path: &str) -> &str {
    path.rfind('/').map_or("", |i| &path[..i])
}

/// The last component of `path`.
pub fn file_name(path: &str) -> &str {
    let trimmed = path.trim_end_matches('/');
    trimmed.rfind('/').map_or(trimmed, |i| &trimmed[i + 1..])
}

/// The base name of a dropped file's name or path, `/` or `\\` separated (a browser's
/// `webkitRelativePath`, a Windows path typed into a script).
pub fn base_name(path: &str) -> &str {
    path.rsplit(['/', '\\']).next().unwrap_or(path)
}

impl FileSource for BTreeMap<String, Vec<u8>> {
    fn read(&self, path: &str) -> Result<Option<Vec<u8>>> {
        Ok(self.get(path).cloned())
    }

    fn list(&self, dir: &str) -> Result<Vec<String>> {
        let prefix = join(dir, "");
        Ok(self
            .keys()
            .filter(|k| prefix.is_empty() || k.starts_with(&prefix))
            .cloned()
            .collect())
    }

    fn is_dir(&self, path: &str) -> bool {
        let prefix = join(path, "");
        !self.contains_key(path) && self.keys().any(|k| k.starts_with(&prefix))
    }
}

/// Reads the files of one input given by path: every file under a folder that can be part of
/// an SfM model or a cloud (keyed relative to the folder, `/`-separated, so COLMAP's
/// `sparse/N/` layout survives), or a single file with the neighbours its format refers to
/// (a Bundler `.out` brings its `list.txt`). Errors name the path.
pub fn read_input_files(source: &dyn FileSource, path: &str) -> Result<BTreeMap<String, Vec<u8>>> {
    let mut files = BTreeMap::new();
    if source.is_dir(path) {
        let prefix = join(path, "");
        for p in source.list(path)? {
            if !is_model_file(&p) {
                continue;
            }
            let rel = p.strip_prefix(&prefix).unwrap_or(&p).to_string();
            if let Some(bytes) = source.read(&p)? {
                files.insert(rel, bytes);
            }
        }
        if files.is_empty() {
            return Err(crate::Error::Missing {
                what: "SfM model or point cloud file in".into(),
                file: path.to_string(),
            });
        }
        return Ok(files);
    }
    let name = file_name(path).to_string();
    let bytes = source.read(path)?.ok_or_else(|| crate::Error::Missing {
        what: "file".into(),
        file: path.to_string(),
    })?;
    files.insert(name.clone(), bytes);
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".out") {
        let stem_len = lower
            .trim_end_matches(".out")
            .trim_end_matches(".bundle")
            .len();
        let stem = &name[..stem_len.min(name.len())];
        for list in [format!("{stem}.list.txt"), "list.txt".to_string()] {
            if let Some(b) = source.read(&join(parent(path), &list))? {
                files.insert(list, b);
            }
        }
    }
    Ok(files)
}

/// Whether a file can be part of an SfM model or a cloud, by its extension (a model folder's
/// images and logs are not): the files [`read_input_files`] reads from a folder.
pub fn is_model_file(path: &str) -> bool {
    let n = path.to_ascii_lowercase();
    [".bin", ".txt", ".nvm", ".out", ".json", ".ply"]
        .iter()
        .any(|e| n.ends_with(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(names: &[&str]) -> BTreeMap<String, Vec<u8>> {
        names
            .iter()
            .map(|n| (n.to_string(), n.as_bytes().to_vec()))
            .collect()
    }

    #[test]
    fn paths_join_and_split() {
        assert_eq!(join("", "a.ply"), "a.ply");
        assert_eq!(join("d", "a.ply"), "d/a.ply");
        assert_eq!(join("/d/", "a.ply"), "/d/a.ply");
        assert_eq!(parent("/d/e/a.ply"), "/d/e");
        assert_eq!(parent("a.ply"), "");
        assert_eq!(file_name("/d/e/a.ply"), "a.ply");
        assert_eq!(file_name("/d/e/"), "e");
    }

    #[test]
    fn a_folder_gives_its_model_files_relative_to_it() {
        let s = source(&[
            "run/sparse/0/cameras.bin",
            "run/sparse/0/images.bin",
            "run/images/a.jpg",
            "run/log.txt",
            "other/x.ply",
        ]);
        assert!(s.is_dir("run") && !s.is_dir("run/log.txt"));
        let files = read_input_files(&s, "run").unwrap();
        let names: Vec<&str> = files.keys().map(String::as_str).collect();
        assert_eq!(
            names,
            ["log.txt", "sparse/0/cameras.bin", "sparse/0/images.bin"]
        );
        let e = read_input_files(&s, "run/images").unwrap_err().to_string();
        assert!(e.contains("run/images"), "{e}");
    }

    #[test]
    fn a_bundler_file_brings_its_list() {
        let s = source(&["d/bundle.out", "d/list.txt", "d/other.txt"]);
        let files = read_input_files(&s, "d/bundle.out").unwrap();
        let names: Vec<&str> = files.keys().map(String::as_str).collect();
        assert_eq!(names, ["bundle.out", "list.txt"]);
        let e = read_input_files(&s, "d/none.ply").unwrap_err().to_string();
        assert!(e.contains("d/none.ply"), "{e}");
    }
}
