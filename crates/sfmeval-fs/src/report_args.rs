//! The `[PIPELINE=]REPORT` arguments of `sfmeval table` (and `sfmeval.table` in Python): which
//! pipeline a report argument names, and where the report is.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

/// `NAME=VALUE` split at the first `=`, or `None` when there is no `=` (or the name is empty).
pub fn named(s: &str) -> Option<(&str, &str)> {
    s.split_once('=').filter(|(n, _)| !n.is_empty())
}

/// The pipeline a report argument names and the report's path: `PIPELINE=PATH` (unless the
/// whole argument is an existing path), else the report's parent folder names the pipeline
/// (`compare/colmap/report.json` → `colmap`).
pub fn pipeline_and_path(arg: &str) -> Result<(String, PathBuf)> {
    if let Some((name, path)) = named(arg)
        && !Path::new(arg).exists()
    {
        return Ok((name.to_string(), PathBuf::from(path)));
    }
    let path = PathBuf::from(arg);
    let parent = path
        .parent()
        .and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .filter(|n| !n.is_empty());
    match parent {
        Some(name) => Ok((name, path)),
        None => bail!(
            "cannot tell the pipeline of '{arg}': give it as PIPELINE={arg} (or put the report in a folder named after it)"
        ),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn report_arguments_name_their_pipeline() {
        let (p, path) = pipeline_and_path("colmap=/x/report.json").unwrap();
        assert_eq!(
            (p.as_str(), path),
            ("colmap", PathBuf::from("/x/report.json"))
        );
        let (p, _) = pipeline_and_path("compare/theia/report.json").unwrap();
        assert_eq!(p, "theia");
        assert!(pipeline_and_path("report.json").is_err());
        assert_eq!(named("=x"), None);
    }
}
