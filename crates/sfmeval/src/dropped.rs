//! What a front end says of the files a benchmark recognised among dropped files (the page, the
//! npm package): one line naming what each file is, what does not fit together, what is still
//! needed and what is not used, and a short status, worded here once for every benchmark
//! (`sfmeval-dtu`, `sfmeval-eth3d`, `sfmeval-tnt` recognise the files; this module words them).

use serde::Serialize;

/// The wording of a set of dropped files, as a front end shows it.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct FilesSummary {
    /// One line: what was found, what does not fit together, what is still needed, what is not
    /// used, joined by ` · `.
    pub line: String,
    /// The state in a few words: `ready`, `N files missing: see above`, or `these files do not
    /// fit together: see above`.
    pub status: String,
    /// Whether the evaluation can run (nothing missing, nothing that does not fit).
    pub complete: bool,
    /// Whether some files do not fit together (a front end shows the line as an error).
    pub problem: bool,
}

/// Words a benchmark's dropped files: `found`, the parts naming what was recognised (already
/// worded by the benchmark: `scan 24`, `STL points: stl024_total.ply, …`), then the sentences of
/// what does not fit (`problems`), of what is still needed (`missing`) and the names not used
/// (`ignored`).
pub fn summarise(
    found: &[String],
    problems: &[String],
    missing: &[String],
    ignored: &[String],
) -> FilesSummary {
    let mut parts: Vec<String> = found.iter().filter(|s| !s.is_empty()).cloned().collect();
    if !problems.is_empty() {
        parts.push(problems.join(" "));
    }
    if !missing.is_empty() {
        parts.push(format!("still needed: {}", missing.join("; ")));
    }
    if !ignored.is_empty() {
        parts.push(format!("not used: {}", ignored.join(", ")));
    }
    let status = if !problems.is_empty() {
        "these files do not fit together: see above".to_string()
    } else if missing.len() == 1 {
        "1 file missing: see above".to_string()
    } else if !missing.is_empty() {
        format!("{} files missing: see above", missing.len())
    } else {
        "ready".to_string()
    };
    FilesSummary {
        line: parts.join(" · "),
        status,
        complete: problems.is_empty() && missing.is_empty(),
        problem: !problems.is_empty(),
    }
}

/// `kind: name` for each recognised file (in the order given, the absent ones left out), joined
/// by `, `: the part of [`summarise`]'s line that names the files.
pub fn named_files(files: &[(&str, Option<&str>)]) -> String {
    files
        .iter()
        .filter_map(|(kind, name)| name.map(|n| format!("{kind}: {n}")))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_complete_set_is_ready() {
        let s = summarise(&strings(&["scan 24", "STL points: a.ply"]), &[], &[], &[]);
        assert_eq!(s.line, "scan 24 · STL points: a.ply");
        assert_eq!(s.status, "ready");
        assert!(s.complete && !s.problem);
    }

    #[test]
    fn missing_files_are_counted_and_ignored_names_listed() {
        let one = summarise(&[], &[], &strings(&["the plane"]), &strings(&["x.md"]));
        assert_eq!(one.line, "still needed: the plane · not used: x.md");
        assert_eq!(one.status, "1 file missing: see above");
        assert!(!one.complete && !one.problem);
        let two = summarise(&[], &[], &strings(&["a", "b"]), &[]);
        assert_eq!(two.line, "still needed: a; b");
        assert_eq!(two.status, "2 files missing: see above");
    }

    #[test]
    fn problems_come_before_what_is_missing_and_decide_the_status() {
        let s = summarise(
            &strings(&["", "scene Barn"]),
            &strings(&["two scans.", "two PLYs."]),
            &strings(&["a"]),
            &[],
        );
        assert_eq!(
            s.line,
            "scene Barn · two scans. two PLYs. · still needed: a"
        );
        assert_eq!(s.status, "these files do not fit together: see above");
        assert!(!s.complete && s.problem);
    }

    #[test]
    fn named_files_leaves_out_the_absent_ones() {
        assert_eq!(
            named_files(&[
                ("crop", Some("b.json")),
                ("mapping", None),
                ("log", Some("c.log"))
            ]),
            "crop: b.json, log: c.log"
        );
        assert_eq!(named_files(&[("crop", None)]), "");
    }
}
