//! The scan's files recognised by name, for front ends that take dropped files (the page, the
//! npm package): the STL points `stl{NNN}_total.ply`, the observation mask `ObsMask{N}_10.mat`,
//! the ground plane `Plane{N}.mat` (the names the benchmark ships them under, `scan`), and the
//! reconstruction, any other `.ply`; and the reconstruction read as a mesh or as points.

use serde::Serialize;
use sfmeval::Result;
use sfmeval::dropped::{self, FilesSummary};
use sfmeval::files::base_name;

use crate::DtuMode;
use crate::protocol::DtuInput;

/// What the DTU evaluation makes of a set of file names.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct DtuFiles {
    /// The scan number the ground-truth files' names give (when they agree).
    pub scan: Option<u32>,
    /// The STL points' file.
    pub stl: Option<String>,
    /// The observation mask's file.
    pub obs_mask: Option<String>,
    /// The ground plane's file.
    pub plane: Option<String>,
    /// The reconstruction's file.
    pub reconstruction: Option<String>,
    /// What is still needed, one sentence each (empty when the evaluation can run).
    pub missing: Vec<String>,
    /// What is wrong with the names given, one sentence each (files of two scans, two
    /// reconstructions); empty when the evaluation can run.
    pub problems: Vec<String>,
    /// Names that are none of the above.
    pub ignored: Vec<String>,
    /// The files recognised that the evaluation reads, in the order STL points, observation mask, ground plane, reconstruction.
    pub inputs: Vec<String>,
    /// What a front end says of these files (worded by the core).
    pub summary: FilesSummary,
}

impl DtuFiles {
    /// Whether the four files are there and agree.
    pub fn complete(&self) -> bool {
        self.missing.is_empty() && self.problems.is_empty()
    }

    /// Fills [`Self::inputs`] and [`Self::summary`] from the rest.
    fn summarised(mut self) -> Self {
        let named = [
            ("STL points", &self.stl),
            ("observation mask", &self.obs_mask),
            ("ground plane", &self.plane),
            ("reconstruction", &self.reconstruction),
        ];
        self.inputs = named.iter().filter_map(|(_, n)| (*n).clone()).collect();
        let files: Vec<(&str, Option<&str>)> =
            named.iter().map(|(k, n)| (*k, n.as_deref())).collect();
        let found = [
            self.scan.map_or_else(String::new, |n| format!("scan {n}")),
            dropped::named_files(&files),
        ];
        self.summary = dropped::summarise(&found, &self.problems, &self.missing, &self.ignored);
        self
    }
}

/// The number between `prefix` and `suffix` in `name` (ASCII case-insensitive), if that is all.
fn number_in(name: &str, prefix: &str, suffix: &str) -> Option<u32> {
    let lower = name.to_ascii_lowercase();
    let mid = lower.strip_prefix(prefix)?.strip_suffix(suffix)?;
    if mid.is_empty() || !mid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    mid.parse().ok()
}

/// Sorts `names` into the scan's files by their base names: `stl{NNN}_total.ply`,
/// `ObsMask{N}_10.mat`, `Plane{N}.mat` (case-insensitive), and any other `.ply` the
/// reconstruction. Says what is missing and what does not fit together.
pub fn recognise<S: AsRef<str>>(names: &[S]) -> DtuFiles {
    let mut f = DtuFiles::default();
    let mut scans: Vec<(u32, String)> = Vec::new();
    let mut recons: Vec<String> = Vec::new();
    for name in names {
        let name = name.as_ref();
        let b = base_name(name);
        let lower = b.to_ascii_lowercase();
        let slot = if let Some(n) = number_in(b, "stl", "_total.ply") {
            Some((n, &mut f.stl))
        } else if let Some(n) = number_in(b, "obsmask", "_10.mat") {
            Some((n, &mut f.obs_mask))
        } else if let Some(n) = number_in(b, "plane", ".mat") {
            Some((n, &mut f.plane))
        } else {
            None
        };
        match slot {
            Some((n, slot)) => {
                if let Some(earlier) = slot.as_ref() {
                    f.problems.push(format!(
                        "two files of the same kind: '{earlier}' and '{name}'; drop one scan's files"
                    ));
                }
                *slot = Some(name.to_string());
                scans.push((n, name.to_string()));
            }
            None if lower.ends_with(".ply") => recons.push(name.to_string()),
            None => f.ignored.push(name.to_string()),
        }
    }
    if let Some((first, first_name)) = scans.first() {
        if let Some((other, other_name)) = scans.iter().find(|(n, _)| n != first) {
            f.problems.push(format!(
                "the files are of two scans: '{first_name}' is scan {first}, '{other_name}' scan {other}"
            ));
        } else {
            f.scan = Some(*first);
        }
    }
    match recons.as_slice() {
        [] => {}
        [one] => f.reconstruction = Some(one.clone()),
        more => f.problems.push(format!(
            "{} PLY files could be the reconstruction ({}); drop one at a time",
            more.len(),
            more.iter()
                .map(|n| format!("'{n}'"))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
    let scan = f.scan.map_or_else(|| "N".to_string(), |n| n.to_string());
    let stl_scan = f
        .scan
        .map_or_else(|| "NNN".to_string(), |n| format!("{n:03}"));
    if f.stl.is_none() {
        f.missing.push(format!(
            "the STL points, stl{stl_scan}_total.ply (Points.zip, Points/stl/)"
        ));
    }
    if f.obs_mask.is_none() {
        f.missing.push(format!(
            "the observation mask, ObsMask{scan}_10.mat (SampleSet.zip, MVS Data/ObsMask/)"
        ));
    }
    if f.plane.is_none() {
        f.missing.push(format!(
            "the ground plane, Plane{scan}.mat (SampleSet.zip, MVS Data/ObsMask/)"
        ));
    }
    if f.reconstruction.is_none() && recons.len() < 2 {
        f.missing.push(
            "the reconstruction: a PLY point cloud or mesh in the scan's frame, in mm".to_string(),
        );
    }
    f.summarised()
}

/// Reads the reconstruction's PLY bytes as `mode` says; also returns whether it is a mesh.
pub fn read_reconstruction(bytes: &[u8], mode: DtuMode) -> Result<(DtuInput, bool)> {
    let ply = sfmeval::io::ply::read_ply(bytes)?;
    mode.input(ply.vertices.into_f64(), ply.triangles, "the PLY")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recognises_the_benchmark_names() {
        let f = recognise(&[
            "Points/stl/stl024_total.ply",
            "ObsMask/ObsMask24_10.mat",
            "ObsMask/Plane24.mat",
            "mvsnet024_l3.ply",
            "notes.txt",
        ]);
        assert!(f.complete(), "{f:?}");
        assert_eq!(f.scan, Some(24));
        assert_eq!(f.stl.as_deref(), Some("Points/stl/stl024_total.ply"));
        assert_eq!(f.obs_mask.as_deref(), Some("ObsMask/ObsMask24_10.mat"));
        assert_eq!(f.plane.as_deref(), Some("ObsMask/Plane24.mat"));
        assert_eq!(f.reconstruction.as_deref(), Some("mvsnet024_l3.ply"));
        assert_eq!(f.ignored, ["notes.txt"]);
        assert_eq!(
            f.inputs,
            [
                "Points/stl/stl024_total.ply",
                "ObsMask/ObsMask24_10.mat",
                "ObsMask/Plane24.mat",
                "mvsnet024_l3.ply"
            ]
        );
        assert_eq!(
            f.summary.line,
            "scan 24 · STL points: Points/stl/stl024_total.ply, observation mask: \
             ObsMask/ObsMask24_10.mat, ground plane: ObsMask/Plane24.mat, reconstruction: \
             mvsnet024_l3.ply · not used: notes.txt"
        );
        assert_eq!(f.summary.status, "ready");
        assert!(f.summary.complete && !f.summary.problem);
    }

    #[test]
    fn says_what_is_missing_and_what_disagrees() {
        let f = recognise(&["stl001_total.ply", "Plane1.mat"]);
        assert!(!f.complete());
        assert_eq!(f.scan, Some(1));
        assert_eq!(f.missing.len(), 2, "{:?}", f.missing);
        assert!(f.missing[0].contains("ObsMask1_10.mat"), "{:?}", f.missing);
        assert!(f.missing[1].contains("reconstruction"), "{:?}", f.missing);
        assert_eq!(f.summary.status, "2 files missing: see above");
        assert!(
            f.summary
                .line
                .contains("still needed: the observation mask")
        );
        assert!(!f.summary.complete);
        let f = recognise(&[
            "stl001_total.ply",
            "ObsMask2_10.mat",
            "Plane1.mat",
            "a.ply",
            "b.ply",
        ]);
        assert_eq!(f.scan, None);
        assert_eq!(f.problems.len(), 2, "{:?}", f.problems);
        assert!(f.problems[0].contains("two scans"), "{:?}", f.problems);
        assert!(
            f.problems[1].contains("'a.ply', 'b.ply'"),
            "{:?}",
            f.problems
        );
        assert!(f.missing.is_empty(), "{:?}", f.missing);
        assert_eq!(
            f.summary.status,
            "these files do not fit together: see above"
        );
        assert!(f.summary.problem);
        let none: [&str; 0] = [];
        assert_eq!(recognise(&none).missing.len(), 4);
    }

    #[test]
    fn mesh_mode_needs_faces() {
        let cloud = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
        let (input, mesh) = read_reconstruction(cloud, DtuMode::Auto).unwrap();
        assert!(!mesh);
        assert_eq!(input, DtuInput::Cloud(vec![[1.0, 2.0, 3.0]]));
        let e = read_reconstruction(cloud, DtuMode::Mesh).unwrap_err();
        assert!(e.to_string().contains("no faces"), "{e}");
    }
}
