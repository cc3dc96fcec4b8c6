//! A Tanks and Temples scene folder as the benchmark ships it and its toolbox reads it:
//! `<scene>.ply` (ground-truth points), `<scene>.json` (crop: Open3D's
//! `SelectionPolygonVolume`), `<scene>_trans.txt` (the reference SfM frame → ground-truth
//! frame), `<scene>_COLMAP_SfM.log` (the reference SfM trajectory) and, for video trajectories,
//! `<scene>_mapping_reference.txt`. The scene's name is the folder's, as in the toolbox.

use super::matrix::{self, Matrix4};
use super::trajectory::{LogFrame, Mapping, read_log, read_mapping};
use sfmeval::crop::{Crop, Volume};
use sfmeval::files::{FileSource, file_name, join};
use sfmeval::geometry::Point3;
use sfmeval::{Error, Result};

/// The toolbox's τ per scene (`config.py`'s `scenes_tau_dict`), in the scene's units (metres).
pub const SCENE_TAU: [(&str, f64); 7] = [
    ("Barn", 0.01),
    ("Caterpillar", 0.005),
    ("Church", 0.025),
    ("Courthouse", 0.025),
    ("Ignatius", 0.003),
    ("Meetingroom", 0.01),
    ("Truck", 0.005),
];

/// τ of a benchmark scene by name.
pub fn scene_tau(name: &str) -> Option<f64> {
    SCENE_TAU.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The files of one scene, read and checked.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene's name (its folder's name unless given).
    pub name: String,
    /// Path of `<scene>.ply` as the source names it.
    pub ground_truth_path: String,
    /// The ground-truth points.
    pub ground_truth: Vec<Point3>,
    /// The crop volume of `<scene>.json`.
    pub crop: Volume,
    /// `<scene>_trans.txt`: reference SfM frame → ground-truth frame.
    pub gt_from_reference: Matrix4,
    /// `<scene>_COLMAP_SfM.log`: the reference trajectory.
    pub reference_trajectory: Vec<LogFrame>,
    /// `<scene>_mapping_reference.txt` when present.
    pub mapping: Option<Mapping>,
}

impl Scene {
    /// Reads the scene in folder `dir`; `name` overrides the folder's name as the files' stem.
    /// Errors name the file and its role.
    pub fn read(source: &dyn FileSource, dir: &str, name: Option<&str>) -> Result<Scene> {
        let name = match name {
            Some(n) => n.to_string(),
            None => file_name(dir).to_string(),
        };
        if name.is_empty() || name == "." || name == ".." {
            return Err(Error::InvalidOption(format!(
                "cannot take the scene's name from the folder '{dir}'; give it"
            )));
        }
        let file = |suffix: &str| join(dir, &format!("{name}{suffix}"));
        let missing = |path: &str, what: &str| Error::Missing {
            what: format!("Tanks and Temples {what}"),
            file: path.to_string(),
        };
        let need = |path: &str, what: &str| -> Result<Vec<u8>> {
            source.read(path)?.ok_or_else(|| missing(path, what))
        };

        let ground_truth_path = file(".ply");
        let ground_truth = source
            .read_point_cloud(&ground_truth_path)
            .map_err(|e| match e {
                // The source's own errors name the file already.
                Error::Io { .. } => e,
                e => e.in_file("ground truth", &ground_truth_path),
            })?
            .ok_or_else(|| missing(&ground_truth_path, "ground truth"))?
            .cloud
            .points
            .into_f64();

        let crop_path = file(".json");
        let crop =
            Crop::parse(&need(&crop_path, "crop")?).map_err(|e| e.in_file("crop", &crop_path))?;
        let Some(crop) = crop.volume else {
            return Err(Error::InvalidContent(
                "a crop file without a volume (the scene's crop must be an Open3D SelectionPolygonVolume or an sfmeval.crop/1 with a volume)".into(),
            )
            .in_file("crop", crop_path));
        };

        let trans_path = file("_trans.txt");
        let gt_from_reference = matrix::parse(&need(&trans_path, "alignment")?, "alignment")
            .map_err(|e| e.in_file("alignment", &trans_path))?;

        let log_path = file("_COLMAP_SfM.log");
        let reference_trajectory = read_log(&need(&log_path, "reference trajectory")?)
            .map_err(|e| e.in_file("reference trajectory", &log_path))?;

        let map_path = file("_mapping_reference.txt");
        let mapping = match source.read(&map_path)? {
            Some(b) => {
                Some(read_mapping(&b).map_err(|e| e.in_file("mapping reference", &map_path))?)
            }
            None => None,
        };
        Ok(Scene {
            name,
            ground_truth_path,
            ground_truth,
            crop,
            gt_from_reference,
            reference_trajectory,
            mapping,
        })
    }
}
