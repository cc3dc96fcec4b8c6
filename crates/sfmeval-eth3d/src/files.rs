//! The scene's files recognised among dropped files, for front ends without a filesystem (the
//! page, the npm package): the MeshLab project (the one `.mlp`), the scans it names (matched by
//! their file names, folders aside), and the reconstruction, the one other `.ply`.
//! Without the project's bytes only the project is found; with them, the scans and the
//! reconstruction too.

use serde::Serialize;
use sfmeval::dropped::{self, FilesSummary};
use sfmeval::files::base_name;

use crate::mlp::read_mlp;

/// One scan of the project and the dropped file that holds it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Eth3dScanFile {
    /// The scan's `filename` in the project, as written: the name the report gives it (the
    /// CLI's, run in the project's folder).
    pub filename: String,
    /// The dropped file's name.
    pub file: String,
}

/// What the ETH3D evaluation makes of a set of file names (and the project's bytes).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct Eth3dFiles {
    /// The MeshLab project's file.
    pub project: Option<String>,
    /// The project's scans found, in its order.
    pub scans: Vec<Eth3dScanFile>,
    /// The reconstruction's file.
    pub reconstruction: Option<String>,
    /// What is still needed, one sentence each (empty when the evaluation can run).
    pub missing: Vec<String>,
    /// What is wrong with the files given, one sentence each.
    pub problems: Vec<String>,
    /// Names that are none of the above.
    pub ignored: Vec<String>,
    /// The files recognised that the evaluation reads, in the order project, scans, reconstruction.
    pub inputs: Vec<String>,
    /// What a front end says of these files (worded by the core).
    pub summary: FilesSummary,
}

impl Eth3dFiles {
    /// Whether the project, all its scans and the reconstruction are there.
    pub fn complete(&self) -> bool {
        self.missing.is_empty() && self.problems.is_empty()
    }

    /// Fills [`Self::inputs`] and [`Self::summary`] from the rest.
    fn summarised(mut self) -> Self {
        let scans: Vec<&str> = self.scans.iter().map(|s| s.file.as_str()).collect();
        self.inputs = self
            .project
            .iter()
            .cloned()
            .chain(scans.iter().map(|s| s.to_string()))
            .chain(self.reconstruction.iter().cloned())
            .collect();
        let found = [
            dropped::named_files(&[("project", self.project.as_deref())]),
            if scans.is_empty() {
                String::new()
            } else {
                format!("scans: {}", scans.join(", "))
            },
            dropped::named_files(&[("reconstruction", self.reconstruction.as_deref())]),
        ];
        self.summary = dropped::summarise(&found, &self.problems, &self.missing, &self.ignored);
        self
    }
}

fn has_ext(name: &str, ext: &str) -> bool {
    base_name(name).to_ascii_lowercase().ends_with(ext)
}

/// Sorts `names` into the scene's files: the one `.mlp` is the project; given its bytes
/// (`project`), each scan it names is the dropped `.ply` of that base name, and the one `.ply`
/// left is the reconstruction. Says what is missing and what does not fit together.
pub fn recognise<S: AsRef<str>>(names: &[S], project: Option<&[u8]>) -> Eth3dFiles {
    sort_names(names, project).summarised()
}

/// [`recognise`] without the summary.
fn sort_names<S: AsRef<str>>(names: &[S], project: Option<&[u8]>) -> Eth3dFiles {
    let mut f = Eth3dFiles::default();
    let mut projects = Vec::new();
    let mut plys: Vec<String> = Vec::new();
    for name in names {
        let name = name.as_ref();
        if has_ext(name, ".mlp") {
            projects.push(name.to_string());
        } else if has_ext(name, ".ply") {
            plys.push(name.to_string());
        } else {
            f.ignored.push(name.to_string());
        }
    }
    match projects.as_slice() {
        [] => f.missing.push(
            "the ground truth's MeshLab project, dslr_scan_eval/scan_alignment.mlp (with the scan PLYs it names)"
                .to_string(),
        ),
        [one] => f.project = Some(one.clone()),
        more => f.problems.push(format!(
            "{} MeshLab projects ({}); drop one scene's files",
            more.len(),
            more.iter()
                .map(|n| format!("'{n}'"))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
    let Some(project_name) = f.project.clone() else {
        return f;
    };
    let Some(bytes) = project else {
        f.missing
            .push(format!("the contents of the project '{project_name}'"));
        return f;
    };
    let entries = match read_mlp(bytes) {
        Ok(e) => e,
        Err(e) => {
            f.problems
                .push(format!("ground-truth project '{project_name}': {e}"));
            return f;
        }
    };
    for entry in &entries {
        let want = base_name(&entry.filename);
        let found: Vec<usize> = plys
            .iter()
            .enumerate()
            .filter(|(_, p)| base_name(p) == want)
            .map(|(k, _)| k)
            .collect();
        match found.as_slice() {
            [] => f.missing.push(format!(
                "the scan '{}' the project '{project_name}' names",
                entry.filename
            )),
            [k] => {
                let file = plys.remove(*k);
                f.scans.push(Eth3dScanFile {
                    filename: entry.filename.clone(),
                    file,
                });
            }
            more => f.problems.push(format!(
                "{} files could be the scan '{}' ({}); drop one",
                more.len(),
                entry.filename,
                more.iter()
                    .map(|&k| format!("'{}'", plys[k]))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
    match plys.as_slice() {
        [] => f.missing.push(
            "the reconstruction: a PLY in the scene's frame, in metres".to_string(),
        ),
        [one] => f.reconstruction = Some(one.clone()),
        more => f.problems.push(format!(
            "{} PLY files are not scans of the project and could be the reconstruction ({}); drop one at a time",
            more.len(),
            more.iter()
                .map(|n| format!("'{n}'"))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    const MLP: &str = r#"<!DOCTYPE MeshLabDocument>
<MeshLabProject>
 <MeshGroup>
  <MLMesh label="scan1.ply" filename="scan1.ply">
   <MLMatrix44>
1 0 0 0 
0 1 0 0 
0 0 1 0 
0 0 0 1 
</MLMatrix44>
  </MLMesh>
  <MLMesh label="scan2.ply" filename="scans/scan2.ply">
   <MLMatrix44>
1 0 0 0 
0 1 0 0 
0 0 1 0 
0 0 0 1 
</MLMatrix44>
  </MLMesh>
 </MeshGroup>
</MeshLabProject>
"#;

    #[test]
    fn finds_the_project_scans_and_reconstruction() {
        let names = [
            "x/scan2.ply",
            "scan_alignment.mlp",
            "dense.ply",
            "scan1.ply",
            "a.txt",
        ];
        let f = recognise(&names, Some(MLP.as_bytes()));
        assert!(f.complete(), "{f:?}");
        assert_eq!(f.project.as_deref(), Some("scan_alignment.mlp"));
        assert_eq!(
            f.scans
                .iter()
                .map(|s| (s.filename.as_str(), s.file.as_str()))
                .collect::<Vec<_>>(),
            [
                ("scan1.ply", "scan1.ply"),
                ("scans/scan2.ply", "x/scan2.ply")
            ]
        );
        assert_eq!(f.reconstruction.as_deref(), Some("dense.ply"));
        assert_eq!(f.ignored, ["a.txt"]);
        assert_eq!(
            f.inputs,
            [
                "scan_alignment.mlp",
                "scan1.ply",
                "x/scan2.ply",
                "dense.ply"
            ]
        );
        assert_eq!(
            f.summary.line,
            "project: scan_alignment.mlp · scans: scan1.ply, x/scan2.ply · reconstruction: \
             dense.ply · not used: a.txt"
        );
        assert_eq!(f.summary.status, "ready");
    }

    #[test]
    fn says_what_is_missing_and_what_does_not_fit() {
        let f = recognise(&["scan1.ply", "dense.ply"], None);
        assert!(f.missing[0].contains("scan_alignment.mlp"), "{f:?}");
        let f = recognise(&["p.mlp", "scan1.ply"], None);
        assert!(f.missing[0].contains("contents of the project 'p.mlp'"));
        assert_eq!(f.summary.status, "1 file missing: see above");
        assert!(
            f.summary
                .line
                .starts_with("project: p.mlp · still needed: ")
        );
        let f = recognise(&["p.mlp", "scan1.ply", "dense.ply"], Some(MLP.as_bytes()));
        assert_eq!(f.missing.len(), 1);
        assert!(f.missing[0].contains("'scans/scan2.ply'"), "{f:?}");
        let f = recognise(
            &["p.mlp", "scan1.ply", "scan2.ply", "a.ply", "b.ply"],
            Some(MLP.as_bytes()),
        );
        assert!(f.problems[0].contains("'a.ply', 'b.ply'"), "{f:?}");
        let f = recognise(&["p.mlp", "q.mlp"], None);
        assert!(f.problems[0].contains("2 MeshLab projects"));
        let f = recognise(&["p.mlp"], Some(b"<html/>"));
        assert!(f.problems[0].contains("'p.mlp'"), "{f:?}");
    }
}
