//! The scene's files recognised among dropped files, for front ends without a filesystem (the
//! page, the npm package), by the names the benchmark ships them under: `SCENE.ply` (the ground
//! truth), `SCENE.json` (the crop), `SCENE_trans.txt` (the alignment),
//! `SCENE_COLMAP_SfM.log` (the reference trajectory) and the optional
//! `SCENE_mapping_reference.txt`; the scene's name comes from the last three. Any other `.log` is
//! the reconstruction's trajectory and any other `.ply` the reconstruction.

use serde::Serialize;
use sfmeval::dropped::{self, FilesSummary};
use sfmeval::files::base_name;

/// What the Tanks and Temples evaluation makes of a set of file names.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct TntFiles {
    /// The scene's name, from its files' names (when they agree).
    pub scene: Option<String>,
    /// `SCENE.ply`.
    pub ground_truth: Option<String>,
    /// `SCENE.json`.
    pub crop: Option<String>,
    /// `SCENE_trans.txt`.
    pub alignment: Option<String>,
    /// `SCENE_COLMAP_SfM.log`.
    pub reference_trajectory: Option<String>,
    /// `SCENE_mapping_reference.txt` (video scenes only).
    pub mapping: Option<String>,
    /// The reconstruction's camera trajectory (any other `.log`).
    pub trajectory: Option<String>,
    /// The reconstruction (any other `.ply`).
    pub reconstruction: Option<String>,
    /// What is still needed, one sentence each (empty when the evaluation can run).
    pub missing: Vec<String>,
    /// What does not fit together, one sentence each.
    pub problems: Vec<String>,
    /// Names that are none of the above.
    pub ignored: Vec<String>,
    /// The files recognised that the evaluation reads, in the order listed above.
    pub inputs: Vec<String>,
    /// What a front end says of these files (worded by the core).
    pub summary: FilesSummary,
}

impl TntFiles {
    /// Whether every file the evaluation needs is there and they agree.
    pub fn complete(&self) -> bool {
        self.missing.is_empty() && self.problems.is_empty()
    }

    /// Fills [`Self::inputs`] and [`Self::summary`] from the rest.
    fn summarised(mut self) -> Self {
        let named = [
            ("ground truth", &self.ground_truth),
            ("crop", &self.crop),
            ("alignment", &self.alignment),
            ("reference trajectory", &self.reference_trajectory),
            ("mapping", &self.mapping),
            ("trajectory", &self.trajectory),
            ("reconstruction", &self.reconstruction),
        ];
        self.inputs = named.iter().filter_map(|(_, n)| (*n).clone()).collect();
        let files: Vec<(&str, Option<&str>)> =
            named.iter().map(|(k, n)| (*k, n.as_deref())).collect();
        let found = [
            self.scene
                .as_ref()
                .map_or_else(String::new, |s| format!("scene {s}")),
            dropped::named_files(&files),
        ];
        self.summary = dropped::summarise(&found, &self.problems, &self.missing, &self.ignored);
        self
    }
}

/// The scene files' suffixes that name the scene, and the slot each fills.
const NAMING: [&str; 3] = ["_trans.txt", "_COLMAP_SfM.log", "_mapping_reference.txt"];

/// Sorts `names` into the scene's files by their base names (see the module docs). Says what is
/// missing and what does not fit together.
pub fn recognise<S: AsRef<str>>(names: &[S]) -> TntFiles {
    let mut f = TntFiles::default();
    let names: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
    // the scene's name from the files only a scene has
    let mut scenes: Vec<(String, &str)> = Vec::new();
    for &n in &names {
        for suffix in NAMING {
            if let Some(stem) = base_name(n).strip_suffix(suffix).filter(|s| !s.is_empty()) {
                scenes.push((stem.to_string(), n));
            }
        }
    }
    if let Some((first, first_file)) = scenes.first() {
        if let Some((other, other_file)) = scenes.iter().find(|(s, _)| s != first) {
            f.problems.push(format!(
                "the files are of two scenes: '{first_file}' is {first}'s, '{other_file}' {other}'s"
            ));
        } else {
            f.scene = Some(first.clone());
        }
    }
    let mut logs = Vec::new();
    let mut plys = Vec::new();
    for &n in &names {
        let b = base_name(n);
        let slot = f.scene.as_deref().and_then(|s| {
            if b == format!("{s}.ply") {
                Some(&mut f.ground_truth)
            } else if b == format!("{s}.json") {
                Some(&mut f.crop)
            } else if b == format!("{s}_trans.txt") {
                Some(&mut f.alignment)
            } else if b == format!("{s}_COLMAP_SfM.log") {
                Some(&mut f.reference_trajectory)
            } else if b == format!("{s}_mapping_reference.txt") {
                Some(&mut f.mapping)
            } else {
                None
            }
        });
        match slot {
            Some(slot) => {
                if let Some(earlier) = slot.as_ref() {
                    f.problems.push(format!(
                        "two files of the same kind: '{earlier}' and '{n}'; drop one scene's files"
                    ));
                }
                *slot = Some(n.to_string());
            }
            None if b.to_ascii_lowercase().ends_with(".log") => logs.push(n.to_string()),
            None if b.to_ascii_lowercase().ends_with(".ply") => plys.push(n.to_string()),
            None => f.ignored.push(n.to_string()),
        }
    }
    let one = |list: Vec<String>, what: &str, problems: &mut Vec<String>| match list.as_slice() {
        [] => None,
        [x] => Some(x.clone()),
        more => {
            problems.push(format!(
                "{} files could be {what} ({}); drop one",
                more.len(),
                more.iter()
                    .map(|n| format!("'{n}'"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
            None
        }
    };
    let (n_logs, n_plys) = (logs.len(), plys.len());
    f.trajectory = one(logs, "the reconstruction's trajectory", &mut f.problems);
    f.reconstruction = one(plys, "the reconstruction", &mut f.problems);
    let s = f.scene.clone().unwrap_or_else(|| "SCENE".into());
    let mut need = |have: bool, what: String| {
        if !have {
            f.missing.push(what);
        }
    };
    need(
        f.ground_truth.is_some(),
        format!("the ground truth, {s}.ply"),
    );
    need(f.crop.is_some(), format!("the crop, {s}.json"));
    need(
        f.alignment.is_some(),
        format!("the alignment, {s}_trans.txt"),
    );
    need(
        f.reference_trajectory.is_some(),
        format!("the reference trajectory, {s}_COLMAP_SfM.log"),
    );
    need(
        f.trajectory.is_some() || n_logs > 1,
        "the reconstruction's camera trajectory: a .log (sfmeval log writes one)".into(),
    );
    need(
        f.reconstruction.is_some() || n_plys > 1,
        "the reconstruction: a PLY point cloud".into(),
    );
    f.summarised()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recognises_the_benchmark_names() {
        let f = recognise(&[
            "Barn/Barn.ply",
            "Barn.json",
            "Barn_trans.txt",
            "Barn_COLMAP_SfM.log",
            "dense.ply",
            "traj.log",
            "readme.md",
        ]);
        assert!(f.complete(), "{f:?}");
        assert_eq!(f.scene.as_deref(), Some("Barn"));
        assert_eq!(f.ground_truth.as_deref(), Some("Barn/Barn.ply"));
        assert_eq!(f.reconstruction.as_deref(), Some("dense.ply"));
        assert_eq!(f.trajectory.as_deref(), Some("traj.log"));
        assert_eq!(f.mapping, None);
        assert_eq!(f.ignored, ["readme.md"]);
        assert_eq!(
            f.inputs,
            [
                "Barn/Barn.ply",
                "Barn.json",
                "Barn_trans.txt",
                "Barn_COLMAP_SfM.log",
                "traj.log",
                "dense.ply"
            ]
        );
        assert!(
            f.summary
                .line
                .starts_with("scene Barn · ground truth: Barn/Barn.ply, crop: Barn.json"),
            "{}",
            f.summary.line
        );
        assert!(f.summary.line.ends_with(" · not used: readme.md"));
        assert_eq!(f.summary.status, "ready");
    }

    #[test]
    fn says_what_is_missing_and_what_does_not_fit() {
        let f = recognise(&["Barn_trans.txt", "Barn.ply", "dense.ply"]);
        assert!(f.missing.iter().any(|m| m.contains("Barn.json")), "{f:?}");
        assert!(f.missing.iter().any(|m| m.contains("Barn_COLMAP_SfM.log")));
        assert!(f.missing.iter().any(|m| m.contains("trajectory: a .log")));
        assert_eq!(f.summary.status, "3 files missing: see above");
        assert!(
            f.summary
                .line
                .contains(" · still needed: the crop, Barn.json; ")
        );
        let f = recognise(&["Barn_trans.txt", "Truck_COLMAP_SfM.log"]);
        assert!(f.problems[0].contains("two scenes"), "{f:?}");
        let f = recognise(&["a.ply", "b.ply"]);
        assert_eq!(f.scene, None);
        assert!(f.problems[0].contains("'a.ply', 'b.ply'"), "{f:?}");
        assert!(f.missing.iter().any(|m| m.contains("SCENE_trans.txt")));
    }
}
