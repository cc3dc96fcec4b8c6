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
    /// Its `images/` folder.
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
        let images = dir.join("images");
        if !images.is_dir() {
            bail!("{} is not a dataset: no images/ folder", dir.display());
        }
        let image_count = std::fs::read_dir(&images)
            .with_context(|| format!("reading {}", images.display()))?
            .filter_map(|e| e.ok())
            .filter(|e| {
                e.path()
                    .extension()
                    .and_then(|x| x.to_str())
                    .is_some_and(|x| {
                        sfmeval_fs::IMAGE_EXTENSIONS.contains(&x.to_ascii_lowercase().as_str())
                    })
            })
            .count();
        if image_count == 0 {
            bail!("{} holds no images", images.display());
        }
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
