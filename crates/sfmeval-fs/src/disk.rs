//! The filesystem as a [`FileSource`]: paths are the operating system's, given as UTF-8 strings.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context as _, Result};
use sfmeval::align::{PointPair, parse_point_pairs};
use sfmeval::dataset::{Dataset, DatasetPaths};
use sfmeval::files::FileSource;
use sfmeval::io::{LoadedCloud, ReadLimits};
use sfmeval::transform::Similarity;

/// The real filesystem. Paths are read as given (relative to the working directory or
/// absolute).
#[derive(Debug, Clone, Copy, Default)]
pub struct Disk;

impl FileSource for Disk {
    fn read(&self, path: &str) -> sfmeval::Result<Option<Vec<u8>>> {
        let p = Path::new(path);
        if !p.is_file() {
            return Ok(None);
        }
        std::fs::read(p).map(Some).map_err(|e| sfmeval::Error::Io {
            file: path.to_string(),
            message: e.to_string(),
        })
    }

    fn list(&self, dir: &str) -> sfmeval::Result<Vec<String>> {
        let mut out = Vec::new();
        if Path::new(dir).is_dir() {
            walk(Path::new(dir), &mut out).map_err(|(p, e)| sfmeval::Error::Io {
                file: p,
                message: e.to_string(),
            })?;
        }
        out.sort();
        Ok(out)
    }

    fn is_dir(&self, path: &str) -> bool {
        Path::new(path).is_dir()
    }

    /// A binary PLY cloud is read in pieces (the next read while the last is decoded); any
    /// other file whole.
    fn read_point_cloud(&self, path: &str) -> sfmeval::Result<Option<LoadedCloud>> {
        let p = Path::new(path);
        if !p.is_file() {
            return Ok(None);
        }
        if let Some(loaded) = crate::stream::read_streamed_cloud(p, path)? {
            return Ok(Some(loaded));
        }
        sfmeval::files::read_whole_point_cloud(self, path)
    }
}

fn walk(dir: &Path, out: &mut Vec<String>) -> Result<(), (String, std::io::Error)> {
    let err = |e| (dir.display().to_string(), e);
    for entry in std::fs::read_dir(dir).map_err(err)? {
        let p = entry.map_err(err)?.path();
        if p.is_dir() {
            walk(&p, out)?;
        } else if let Some(s) = p.to_str() {
            out.push(s.to_string());
        }
    }
    Ok(())
}

/// `path` as the UTF-8 string the core's sources take.
pub fn path_str(path: &Path) -> Result<&str> {
    path.to_str()
        .with_context(|| format!("'{}' is not a UTF-8 path", path.display()))
}

/// Reads a whole file, naming it in the error.
pub fn read(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).with_context(|| format!("cannot read '{}'", path.display()))
}

/// The file name without folders, for reports.
pub fn name_of(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// The files of one input (a model folder, or a file with the neighbours its format refers
/// to), keyed as the core's readers expect ([`sfmeval::files::read_input_files`]).
pub fn read_input_files(path: &Path) -> Result<BTreeMap<String, Vec<u8>>> {
    Ok(sfmeval::files::read_input_files(&Disk, path_str(path)?)?)
}

/// Image file extensions (lower case) an image folder's listing keeps.
pub const IMAGE_EXTENSIONS: [&str; 6] = ["jpg", "jpeg", "png", "tif", "tiff", "bmp"];

/// The image files directly inside `dir` (by extension, any case), by name in sorted order: the
/// input-image order of a Tanks and Temples `.log` trajectory.
pub fn image_names(dir: &Path) -> Result<Vec<String>> {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir)
        .with_context(|| format!("cannot list the images folder '{}'", dir.display()))?
    {
        let path = entry
            .with_context(|| format!("cannot list the images folder '{}'", dir.display()))?
            .path();
        let is_image = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| IMAGE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()));
        if is_image && path.is_file() {
            names.push(name_of(&path));
        }
    }
    names.sort();
    Ok(names)
}

/// Reads a ground truth and its optional parts from disk ([`Dataset::read_with_limits`]).
pub fn read_dataset(paths: &DatasetPaths, limits: &ReadLimits) -> Result<Dataset> {
    Ok(Dataset::read_with_limits(&Disk, paths, limits)?)
}

/// The `gt_from_recon` file at `path` (JSON or 16 numbers); errors name it.
pub fn read_transform(path: &Path) -> Result<Similarity> {
    Similarity::parse(&read(path)?).with_context(|| format!("transform file '{}'", path.display()))
}

/// The point pairs file at `path`; errors name it.
pub fn read_point_pairs(path: &Path) -> Result<Vec<PointPair>> {
    parse_point_pairs(&read(path)?).with_context(|| format!("point pairs '{}'", path.display()))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn lists_files_at_any_depth_and_reads_them() {
        let dir = std::env::temp_dir().join(format!("sfmeval-fs-disk-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sparse/0")).unwrap();
        std::fs::write(dir.join("sparse/0/cameras.txt"), b"c").unwrap();
        std::fs::write(dir.join("a.ply"), b"p").unwrap();
        let root = path_str(&dir).unwrap();
        let listed = Disk.list(root).unwrap();
        assert_eq!(
            listed,
            [
                format!("{root}/a.ply"),
                format!("{root}/sparse/0/cameras.txt")
            ]
        );
        assert!(Disk.is_dir(root));
        assert_eq!(Disk.read(&listed[0]).unwrap(), Some(b"p".to_vec()));
        assert_eq!(Disk.read(&format!("{root}/none")).unwrap(), None);
        assert_eq!(Disk.read(root).unwrap(), None, "a folder is not a file");
        let files = read_input_files(&dir).unwrap();
        assert_eq!(
            files.keys().collect::<Vec<_>>(),
            ["a.ply", "sparse/0/cameras.txt"]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The disk's clouds equal the core's reading of the file's bytes, streamed or not, and
    /// name the path as the bytes' reader names it.
    #[test]
    fn point_clouds_read_as_the_core_reads_their_bytes() {
        let dir = std::env::temp_dir().join(format!("sfmeval-fs-cloud-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut binary = b"ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
        for v in [1.0f32, 2.0, 3.0, -4.0, 5.5, 6.25] {
            binary.extend_from_slice(&v.to_be_bytes());
        }
        let files: [(&str, &[u8]); 3] = [
            ("binary.ply", &binary),
            ("ascii.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\nproperty double z\nend_header\n1 2 3\n"),
            ("mesh.obj", b"v 1 2 3\nv 4 5 6\nv 0 1 0\nf 1 2 3\n"),
        ];
        for (name, bytes) in files {
            let path = dir.join(name);
            std::fs::write(&path, bytes).unwrap();
            let path = path_str(&path).unwrap();
            let disk = Disk.read_point_cloud(path).unwrap().unwrap();
            let core = sfmeval::io::read_point_cloud(path, bytes).unwrap();
            assert_eq!(
                disk.cloud.points.as_f64(),
                core.cloud.points.as_f64(),
                "{name}"
            );
            assert_eq!(disk.format, core.format, "{name}");
            assert_eq!(disk.notes.len(), core.notes.len(), "{name}");
        }
        let broken = dir.join("broken.ply");
        std::fs::write(&broken, &binary[..binary.len() - 5]).unwrap();
        let broken = path_str(&broken).unwrap();
        assert_eq!(
            Disk.read_point_cloud(broken).unwrap_err().to_string(),
            sfmeval::io::read_point_cloud(broken, &binary[..binary.len() - 5])
                .unwrap_err()
                .to_string()
        );
        assert!(
            Disk.read_point_cloud(path_str(&dir.join("none.ply")).unwrap())
                .unwrap()
                .is_none()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
