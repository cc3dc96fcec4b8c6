//! A dataset folder (`sfmeval.dataset/1`, docs/dataset.md) as the runner sees it: the images
//! the tools run on and the intrinsics of its cameras.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// A dataset to run pipelines on.
#[derive(Debug, Clone)]
pub struct Dataset {
    /// Its name (the folder name), the first level of the run folders.
    pub name: String,
    /// The folder (absolute).
    pub dir: PathBuf,
    /// Its images: `images/`, or the only subfolder of `images/` holding them (ETH3D).
    pub images: PathBuf,
    /// Number of images.
    pub image_count: usize,
    /// `[fx, fy, cx, cy]` of its single camera in `cameras.json` (COLMAP pixel convention).
    pub known: Option<[f64; 4]>,
}

impl Dataset {
    /// Reads a dataset folder: `images/` must hold images; `cameras.json` is optional here
    /// (needed for known intrinsics and for the report).
    pub fn open(dir: &Path) -> Result<Dataset> {
        let dir = std::path::absolute(dir)
            .with_context(|| format!("dataset folder {}", dir.display()))?;
        let (images, image_count) = images_folder(&dir.join("images"))
            .with_context(|| format!("{} is not a dataset", dir.display()))?;
        let name = dir
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .filter(|n| !n.is_empty() && !n.starts_with('.'))
            .with_context(|| format!("dataset folder {} has no usable name", dir.display()))?;
        // The ground-truth side (geometry, depth maps) is the core's `Dataset`, read by `report`;
        // running the tools needs only the intrinsics of the dataset's cameras.
        let cameras = dir.join(sfmeval::dataset::CAMERAS_FILE);
        let known = if cameras.is_file() {
            let rec = sfmeval::model::read_model_files(&sfmeval_fs::read_input_files(&cameras)?)
                .with_context(|| format!("{}", cameras.display()))?;
            match rec.cameras.as_slice() {
                [c] => Some([c.fx, c.fy, c.cx, c.cy]),
                _ => None,
            }
        } else {
            None
        };
        Ok(Dataset {
            name,
            dir,
            images,
            image_count,
            known,
        })
    }
}

/// The number of image files directly in `dir`.
fn count_images(dir: &Path) -> Result<usize> {
    Ok(std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok())
        .filter(|e| {
            e.path()
                .extension()
                .and_then(|x| x.to_str())
                .is_some_and(|x| {
                    sfmeval_fs::IMAGE_EXTENSIONS.contains(&x.to_ascii_lowercase().as_str())
                })
        })
        .count())
}

/// The folder of a dataset's images and their number: `images/` itself, or its only subfolder
/// when `images/` holds no images but one folder of them (ETH3D ships
/// `images/dslr_images_undistorted/`; the tools then name the images without that folder,
/// which the core's name matching ignores anyway).
fn images_folder(images: &Path) -> Result<(PathBuf, usize)> {
    if !images.is_dir() {
        bail!("no images/ folder");
    }
    let direct = count_images(images)?;
    if direct > 0 {
        return Ok((images.to_path_buf(), direct));
    }
    let subfolders: Vec<PathBuf> = std::fs::read_dir(images)
        .with_context(|| format!("reading {}", images.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    if let [only] = subfolders.as_slice() {
        let n = count_images(only)?;
        if n > 0 {
            return Ok((only.clone(), n));
        }
    }
    bail!(
        "{} holds no images (nor one subfolder of them)",
        images.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("sfmeval-dataset-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("images")).unwrap();
        d
    }

    #[test]
    fn images_directly_in_images_or_in_its_only_subfolder() {
        let flat = scratch("flat");
        std::fs::write(flat.join("images/0000.jpg"), b"x").unwrap();
        std::fs::write(flat.join("images/notes.txt"), b"x").unwrap();
        let d = Dataset::open(&flat).unwrap();
        assert_eq!((d.image_count, d.images.ends_with("images")), (1, true));

        // ETH3D's layout: images/dslr_images_undistorted/DSC_*.JPG.
        let eth3d = scratch("eth3d");
        let sub = eth3d.join("images/dslr_images_undistorted");
        std::fs::create_dir_all(&sub).unwrap();
        for k in 0..3 {
            std::fs::write(sub.join(format!("DSC_{k:04}.JPG")), b"x").unwrap();
        }
        let d = Dataset::open(&eth3d).unwrap();
        assert_eq!(
            (d.image_count, d.images),
            (3, std::path::absolute(&sub).unwrap())
        );

        // Two subfolders: which one is meant is not known.
        std::fs::create_dir_all(eth3d.join("images/other")).unwrap();
        std::fs::write(eth3d.join("images/other/a.png"), b"x").unwrap();
        let e = format!("{:#}", Dataset::open(&eth3d).unwrap_err());
        assert!(
            e.contains("holds no images") && e.contains("not a dataset"),
            "{e}"
        );

        let empty = scratch("empty");
        let e = format!("{:#}", Dataset::open(&empty).unwrap_err());
        assert!(e.contains("holds no images"), "{e}");
        for d in [flat, eth3d, empty] {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}
