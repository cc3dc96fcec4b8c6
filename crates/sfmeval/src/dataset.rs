//! The ground-truth side of an evaluation, one type for every front end: the geometry (GLB,
//! glTF with its buffers, OBJ, PLY mesh or cloud), the ground-truth cameras (a dataset's
//! `cameras.json`, or any SfM model in the ground-truth frame) and their depth maps. Read from a
//! dataset folder (docs/dataset.md) or from loose files through a [`FileSource`]; its index and
//! completeness samples are prepared once and reused while the sample count and seed stay.

use std::collections::BTreeMap;

use crate::error::{Error, Result};
use crate::files::{self, FileSource};
use crate::gt_views::{GtView, build_views, depth_stem};
use crate::io::npy::DepthMap;
use crate::io::{self, LoadedGroundTruth, ReadLimits};
use crate::model::{self, Reconstruction};
use crate::prepared::PreparedGroundTruth;
use crate::progress::Progress;

/// The ground truth's file inside a dataset folder.
pub(crate) const GROUND_TRUTH_FILE: &str = "ground_truth.glb";
/// The ground-truth cameras inside a dataset folder.
pub const CAMERAS_FILE: &str = "cameras.json";
/// The folder of depth maps (`<image stem>.npy`) inside a dataset folder.
pub(crate) const DEPTH_DIR: &str = "depth";

/// Where an optional part of the ground truth comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Part {
    /// Not used.
    Off,
    /// Read when the path exists (a dataset folder's optional parts).
    IfPresent(String),
    /// Must exist (a path the user named).
    Required(String),
}

impl Part {
    fn resolve(&self, source: &dyn FileSource, folder: bool) -> Result<Option<&str>> {
        match self {
            Part::Off => Ok(None),
            Part::IfPresent(p) => {
                let present = if folder {
                    source.is_dir(p)
                } else {
                    source.is_dir(p) || source.read(p)?.is_some()
                };
                Ok(present.then_some(p.as_str()))
            }
            Part::Required(p) => Ok(Some(p.as_str())),
        }
    }
}

/// The paths of a ground truth's parts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DatasetPaths {
    /// The geometry file.
    pub ground_truth: String,
    /// The ground-truth cameras: a `cameras.json` or an SfM model (file or folder).
    pub cameras: Part,
    /// The depth-map folder (needs the cameras).
    pub depth: Part,
}

impl DatasetPaths {
    /// The parts of the dataset folder `dir`: `ground_truth.glb`, and `cameras.json` and
    /// `depth/` when present.
    pub fn folder(dir: &str) -> DatasetPaths {
        DatasetPaths {
            ground_truth: files::join(dir, GROUND_TRUTH_FILE),
            cameras: Part::IfPresent(files::join(dir, CAMERAS_FILE)),
            depth: Part::IfPresent(files::join(dir, DEPTH_DIR)),
        }
    }

    /// A ground-truth geometry file alone.
    pub fn ground_truth(path: &str) -> DatasetPaths {
        DatasetPaths {
            ground_truth: path.to_string(),
            cameras: Part::Off,
            depth: Part::Off,
        }
    }
}

/// A ground truth ready to evaluate against.
pub struct Dataset {
    /// The geometry as read.
    pub loaded: LoadedGroundTruth,
    /// The geometry's file name (no folders), for reports.
    pub name: String,
    cameras: Option<Reconstruction>,
    views: Option<Vec<GtView>>,
    prepared: Option<PreparedGroundTruth>,
}

impl Dataset {
    /// A ground truth from its geometry alone; `name` is its file name.
    pub fn new(name: &str, loaded: LoadedGroundTruth) -> Dataset {
        Dataset {
            loaded,
            name: files::file_name(name).to_string(),
            cameras: None,
            views: None,
            prepared: None,
        }
    }

    /// Reads the parts named by `paths` from `source` with the default [`ReadLimits`]. Every
    /// error names the file and its role.
    pub fn read(source: &dyn FileSource, paths: &DatasetPaths) -> Result<Dataset> {
        Dataset::read_with_limits(source, paths, &ReadLimits::default())
    }

    /// [`Self::read`] with explicit limits on the ground-truth mesh's expanded size.
    pub fn read_with_limits(
        source: &dyn FileSource,
        paths: &DatasetPaths,
        limits: &ReadLimits,
    ) -> Result<Dataset> {
        let gt_path = paths.ground_truth.as_str();
        let in_gt = |e: Error| e.in_file("ground truth", gt_path);
        let bytes = source.read(gt_path)?.ok_or_else(|| Error::Missing {
            what: "ground truth".into(),
            file: gt_path.to_string(),
        })?;
        let external = gltf_buffers(source, gt_path, &bytes)?;
        let loaded =
            io::read_ground_truth_with_limits(gt_path, &bytes, &external, limits).map_err(in_gt)?;
        drop(bytes);
        let mut dataset = Dataset::new(gt_path, loaded);
        if let Some(p) = paths.cameras.resolve(source, false)? {
            let cameras = model::read_model_files(&files::read_input_files(source, p)?)
                .map_err(|e| e.in_file("ground-truth cameras", p))?;
            dataset.set_cameras(Some(cameras));
        }
        if let Some(dir) = paths.depth.resolve(source, true)? {
            let Some(cameras) = dataset.cameras.as_ref() else {
                return Err(Error::InvalidContent(format!(
                    "the depth maps '{dir}' need the ground-truth cameras (cameras.json)"
                )));
            };
            let mut maps = BTreeMap::new();
            for im in &cameras.images {
                let stem = depth_stem(&im.name);
                let path = files::join(dir, &format!("{stem}.npy"));
                let bytes = source.read(&path)?.ok_or_else(|| Error::Missing {
                    what: format!("depth map for image '{}',", im.name),
                    file: path.clone(),
                })?;
                let map = DepthMap::from_npy(&bytes).map_err(|e| e.in_file("depth map", &path))?;
                maps.insert(stem, map);
            }
            dataset
                .set_depth_maps(&maps)
                .map_err(|e| e.in_file("depth maps", dir))?;
        }
        Ok(dataset)
    }

    /// The ground-truth cameras, when attached.
    pub fn cameras(&self) -> Option<&Reconstruction> {
        self.cameras.as_ref()
    }

    /// The ground-truth views (cameras with depth maps), when attached.
    pub fn views(&self) -> Option<&[GtView]> {
        self.views.as_deref()
    }

    /// Attaches (or removes) the ground-truth cameras; the depth maps, which belong to the
    /// cameras, are removed.
    pub fn set_cameras(&mut self, cameras: Option<Reconstruction>) {
        self.cameras = cameras;
        self.views = None;
    }

    /// Attaches depth maps keyed by image stem ([`depth_stem`]), one for every ground-truth
    /// image; needs the cameras.
    pub fn set_depth_maps(&mut self, maps: &BTreeMap<String, DepthMap>) -> Result<()> {
        let cameras = self.cameras.as_ref().ok_or_else(|| {
            Error::InvalidOption(
                "depth maps need the ground-truth cameras (cameras.json) first".into(),
            )
        })?;
        self.views = Some(build_views(cameras, maps)?);
        Ok(())
    }

    /// Attaches views built elsewhere (tests build them from synthetic renders).
    #[cfg(test)]
    pub(crate) fn set_views(&mut self, views: Vec<GtView>) {
        self.views = Some(views);
    }

    /// Removes the depth maps.
    pub fn clear_depth_maps(&mut self) {
        self.views = None;
    }

    /// Indexes the geometry and draws `samples` completeness samples with `seed`, unless that
    /// was done already with the same two.
    pub(crate) fn prepare(
        &mut self,
        samples: usize,
        seed: u64,
        progress: &dyn Progress,
    ) -> Result<()> {
        if self
            .prepared
            .as_ref()
            .is_some_and(|p| p.prepared_with(samples, seed))
        {
            return Ok(());
        }
        self.prepared = None;
        let prepared = PreparedGroundTruth::new(&self.loaded.ground_truth, samples, seed, progress)
            .map_err(|e| e.in_file("ground truth", self.name.clone()))?;
        self.prepared = Some(prepared);
        Ok(())
    }

    /// The prepared index, once [`crate::pipeline::run`] has prepared it.
    pub fn prepared(&self) -> Option<&PreparedGroundTruth> {
        self.prepared.as_ref()
    }
}

/// The external buffers a `.gltf` refers to, read from beside it (data URIs and paths leaving
/// the folder are left to the glTF reader, which names what is missing).
fn gltf_buffers(
    source: &dyn FileSource,
    gt_path: &str,
    bytes: &[u8],
) -> Result<BTreeMap<String, Vec<u8>>> {
    let mut out = BTreeMap::new();
    if io::gltf::is_glb(bytes) || !gt_path.to_ascii_lowercase().ends_with(".gltf") {
        return Ok(out);
    }
    let Ok(v) = serde_json::from_slice::<serde_json::Value>(bytes) else {
        return Ok(out);
    };
    let uris = v
        .get("buffers")
        .and_then(|b| b.as_array())
        .into_iter()
        .flatten()
        .filter_map(|b| b.get("uri").and_then(|u| u.as_str()))
        .filter(|u| !u.starts_with("data:") && !u.contains(".."));
    for uri in uris {
        if let Some(data) = source.read(&files::join(files::parent(gt_path), uri))? {
            out.insert(uri.to_string(), data);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    const TRIANGLE_OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

    #[test]
    fn a_dataset_folder_gives_geometry_and_cameras() {
        let src = BTreeMap::from([
            (
                "d/ground_truth.glb".to_string(),
                include_bytes!("../../../data/demo/ground_truth.glb").to_vec(),
            ),
            (
                "d/cameras.json".to_string(),
                include_bytes!("../../../data/demo/cameras.json").to_vec(),
            ),
        ]);
        let d = Dataset::read(&src, &DatasetPaths::folder("d")).unwrap();
        assert_eq!(d.name, "ground_truth.glb");
        assert_eq!(d.cameras().map(|c| c.images.len()), Some(36));
        assert!(d.views().is_none());
        let bad = BTreeMap::from([("d/ground_truth.glb".to_string(), b"glTF junk".to_vec())]);
        let e = Dataset::read(&bad, &DatasetPaths::folder("d"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.starts_with("ground truth 'd/ground_truth.glb': "), "{e}");
    }

    #[test]
    fn missing_parts_are_named() {
        let src = BTreeMap::from([("m.obj".to_string(), TRIANGLE_OBJ.to_vec())]);
        let e = Dataset::read(&src, &DatasetPaths::folder("d"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert_eq!(e, "missing ground truth 'd/ground_truth.glb'");
        let paths = DatasetPaths {
            cameras: Part::Required("cams/cameras.json".into()),
            ..DatasetPaths::ground_truth("m.obj")
        };
        let e = Dataset::read(&src, &paths)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("cams/cameras.json"), "{e}");
        let paths = DatasetPaths {
            depth: Part::Required("depth".into()),
            ..DatasetPaths::ground_truth("m.obj")
        };
        let e = Dataset::read(&src, &paths)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("need the ground-truth cameras"), "{e}");
    }

    #[test]
    fn preparing_twice_with_the_same_options_reuses_the_index() {
        let src = BTreeMap::from([("m.obj".to_string(), TRIANGLE_OBJ.to_vec())]);
        let mut d = Dataset::read(&src, &DatasetPaths::ground_truth("m.obj")).unwrap();
        assert_eq!(d.name, "m.obj");
        d.prepare(100, 1, &NoProgress).unwrap();
        let first = d.prepared().map(|p| p.samples().as_ptr());
        d.prepare(100, 1, &NoProgress).unwrap();
        assert_eq!(d.prepared().map(|p| p.samples().as_ptr()), first);
        d.prepare(100, 2, &NoProgress).unwrap();
        assert!(d.prepared().is_some_and(|p| p.prepared_with(100, 2)));
    }
}
