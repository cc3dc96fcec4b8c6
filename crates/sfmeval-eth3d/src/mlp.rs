//! The MeshLab project (`.mlp`) that poses ETH3D's laser scans, read as the tool's
//! `ReadMeshLabProject` reads it: the `MeshLabProject` element's first `MeshGroup`, each of its
//! `MLMesh` elements in order with its `filename` (a path relative to the project's folder
//! unless it starts with `/`), an optional `label` and its `MLMatrix44`, the 4×4 row-major
//! `global_from_scan` parsed as `float`s.
//!
//! Stricter than the tool where it would go on with garbage: a matrix of other than 16 numbers,
//! a non-finite entry or a project without scans is an error here (the tool reads what it can
//! and leaves the rest uninitialised); a last row other than `0 0 0 1` is an error in both.

use sfmeval::{Error, Result};

/// The format name in errors.
pub const MLP_FORMAT: &str = "MeshLab project";

/// One scan of the project.
#[derive(Debug, Clone, PartialEq)]
pub struct MlpScan {
    /// The `label` attribute, if any.
    pub label: Option<String>,
    /// The `filename` attribute as written (relative to the project's folder unless absolute).
    pub filename: String,
    /// `global_from_scan`, row-major, in single precision as the tool parses it.
    pub global_from_scan: [[f32; 4]; 4],
}

fn malformed(detail: impl Into<String>) -> Error {
    Error::Malformed {
        format: MLP_FORMAT,
        detail: detail.into(),
    }
}

/// Reads a project's scans from its bytes.
pub fn read_mlp(bytes: &[u8]) -> Result<Vec<MlpScan>> {
    let text = std::str::from_utf8(bytes).map_err(|e| malformed(format!("not UTF-8 text: {e}")))?;
    // MeshLab starts its projects with `<!DOCTYPE MeshLabDocument>`.
    let options = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..roxmltree::ParsingOptions::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, options)
        .map_err(|e| malformed(format!("not XML: {e}")))?;
    let root = doc.root_element();
    if root.tag_name().name() != "MeshLabProject" {
        return Err(malformed(format!(
            "the root element is <{}>, not <MeshLabProject>",
            root.tag_name().name()
        )));
    }
    let group = root
        .children()
        .find(|n| n.is_element() && n.tag_name().name() == "MeshGroup")
        .ok_or_else(|| malformed("<MeshLabProject> has no <MeshGroup>"))?;
    let mut scans = Vec::new();
    for (k, mesh) in group
        .children()
        .filter(|n| n.is_element() && n.tag_name().name() == "MLMesh")
        .enumerate()
    {
        let label = mesh.attribute("label").map(str::to_string);
        let name = label.clone().unwrap_or_else(|| format!("#{}", k + 1));
        let filename = mesh
            .attribute("filename")
            .ok_or_else(|| malformed(format!("<MLMesh> {name} has no filename")))?
            .to_string();
        if filename.is_empty() {
            return Err(malformed(format!("<MLMesh> {name} has an empty filename")));
        }
        let matrix = mesh
            .children()
            .find(|n| n.is_element() && n.tag_name().name() == "MLMatrix44")
            .ok_or_else(|| malformed(format!("<MLMesh> {name} has no <MLMatrix44> (its pose)")))?;
        let words: Vec<&str> = matrix.text().unwrap_or("").split_whitespace().collect();
        if words.len() != 16 {
            return Err(malformed(format!(
                "the <MLMatrix44> of {name} has {} numbers, not 16",
                words.len()
            )));
        }
        let mut m = [[0f32; 4]; 4];
        for (i, w) in words.iter().enumerate() {
            let v: f32 = w.parse().map_err(|_| {
                malformed(format!(
                    "the <MLMatrix44> of {name} has '{w}', not a number"
                ))
            })?;
            if !v.is_finite() {
                return Err(Error::InvalidContent(format!(
                    "the pose of scan {name} has a non-finite entry ({w})"
                )));
            }
            m[i / 4][i % 4] = v;
        }
        if m[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(Error::InvalidContent(format!(
                "the last row of the pose of scan {name} is {:?}, not (0, 0, 0, 1)",
                m[3]
            )));
        }
        scans.push(MlpScan {
            label,
            filename,
            global_from_scan: m,
        });
    }
    if scans.is_empty() {
        return Err(Error::InvalidContent(
            "the project's <MeshGroup> has no <MLMesh>: no scans".into(),
        ));
    }
    Ok(scans)
}

/// The path of scan `filename` of the project at `project_path`, as the tool composes it: as
/// written when it starts with `/`, else relative to the project's folder.
pub fn scan_path(project_path: &std::path::Path, filename: &str) -> std::path::PathBuf {
    if filename.starts_with('/') {
        filename.into()
    } else {
        project_path
            .parent()
            .unwrap_or(std::path::Path::new(""))
            .join(filename)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"<!DOCTYPE MeshLabDocument>
<MeshLabProject>
 <MeshGroup>
  <MLMesh label="scan1.ply" filename="scan1.ply">
   <MLMatrix44>
1 0 0 0.5 
0 1 0 -2 
0 0 1 3 
0 0 0 1 
</MLMatrix44>
  </MLMesh>
  <MLMesh filename="/abs/scan2.ply">
   <MLMatrix44>0 -1 0 0 1 0 0 0 0 0 1 0 0 0 0 1</MLMatrix44>
  </MLMesh>
 </MeshGroup>
 <RasterGroup/>
</MeshLabProject>
"#;

    #[test]
    fn reads_scans_in_order() -> Result<()> {
        let scans = read_mlp(GOOD.as_bytes())?;
        assert_eq!(scans.len(), 2);
        assert_eq!(scans[0].label.as_deref(), Some("scan1.ply"));
        assert_eq!(scans[0].global_from_scan[0], [1.0, 0.0, 0.0, 0.5]);
        assert_eq!(scans[0].global_from_scan[1][3], -2.0);
        assert_eq!(scans[1].label, None);
        assert_eq!(scans[1].global_from_scan[1], [1.0, 0.0, 0.0, 0.0]);
        let p = std::path::Path::new("/data/scene/scan_alignment.mlp");
        assert_eq!(
            scan_path(p, &scans[0].filename),
            std::path::Path::new("/data/scene/scan1.ply")
        );
        assert_eq!(
            scan_path(p, &scans[1].filename),
            std::path::Path::new("/abs/scan2.ply")
        );
        Ok(())
    }

    fn err(text: &str) -> String {
        match read_mlp(text.as_bytes()) {
            Ok(s) => panic!("accepted: {s:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn refuses_what_the_tool_would_misread() {
        assert!(err("<MeshLabProject><MeshGroup>").contains("not XML"));
        assert!(err("<Other/>").contains("not <MeshLabProject>"));
        assert!(err("<MeshLabProject/>").contains("no <MeshGroup>"));
        assert!(err("<MeshLabProject><MeshGroup/></MeshLabProject>").contains("no scans"));
        let no_pose = GOOD.replace(
            "<MLMatrix44>0 -1 0 0 1 0 0 0 0 0 1 0 0 0 0 1</MLMatrix44>",
            "",
        );
        assert!(err(&no_pose).contains("#2 has no <MLMatrix44>"));
        let short = GOOD.replace(" 0 0 0 1</MLMatrix44>", "</MLMatrix44>");
        assert!(err(&short).contains("12 numbers, not 16"));
        let nan = GOOD.replace("0.5", "nan");
        assert!(err(&nan).contains("non-finite"));
        let word = GOOD.replace("0.5", "x");
        assert!(err(&word).contains("'x', not a number"));
        let row = GOOD.replace("0 0 0 1 \n", "0 0 1 1 \n");
        assert!(err(&row).contains("not (0, 0, 0, 1)"));
        let nofile = GOOD.replace(" filename=\"scan1.ply\"", "");
        assert!(err(&nofile).contains("scan1.ply has no filename"));
    }
}
