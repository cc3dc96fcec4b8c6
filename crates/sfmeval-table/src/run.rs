//! What a run's `run.json` (`sfmeval.run/1`, written by `sfmeval-runner run`) tells the tables:
//! how the run ended, its tool, images, points and resources; and the row built from it and its
//! evaluation.

use serde::{Deserialize, Serialize};
use sfmeval::report::Report;

use crate::row::{DtuNumbers, Eth3dNumbers, Prf, Row};

/// Schema id of run.json.
pub const RUN_SCHEMA: &str = "sfmeval.run/1";

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The tool produced a model; sparse.ply and cameras.json are written.
    Ok,
    /// A command failed or its output could not be read.
    Failed,
    /// The run hit its timeout.
    Timeout,
    /// The tool is not installed here.
    NotInstalled,
}

impl Status {
    /// `ok`, `failed`, `timeout`, `not installed`.
    pub fn label(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
            Status::Timeout => "timeout",
            Status::NotInstalled => "not installed",
        }
    }
}

/// The fields of `run.json` the tables use (the runner's full record has more; unknown fields
/// are ignored when parsing).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RunFacts {
    /// Dataset name (first folder level).
    pub dataset: String,
    /// Pipeline name (second folder level).
    pub pipeline: String,
    /// Tool name.
    pub tool: String,
    /// Tool version (as the tool reports it).
    pub version: Option<String>,
    /// Outcome.
    pub status: Status,
    /// Why it did not succeed.
    pub reason: Option<String>,
    /// Wall-clock seconds of the tool's commands.
    pub wall_seconds: f64,
    /// User + system CPU seconds of the tool's commands.
    pub cpu_seconds: f64,
    /// Peak resident memory of the largest process, bytes.
    pub peak_memory_bytes: u64,
    /// Images in the dataset.
    pub images_total: usize,
    /// Images with a pose in the model.
    pub images_registered: usize,
    /// 3D points of the model.
    pub points: usize,
}

impl RunFacts {
    /// Parses `run.json` text; errors say which field is wrong.
    pub fn parse(text: &str) -> Result<RunFacts, serde_json::Error> {
        serde_json::from_str(text)
    }
}

/// The alignment of a row measured by the Tanks and Temples protocol (its own registration).
pub const TNT_ALIGNMENT: &str = "tanksandtemples";

/// The row of a reconstruction measured outside a runner's runs folder (the Blender panel, a
/// script): `pipeline` on `dataset`, evaluated by `report` (its images, points and numbers);
/// `report_file` is the report's path as the tables should name it. No run record: tool,
/// version and resources are unknown (empty, 0).
pub fn report_row(dataset: &str, pipeline: &str, report: &Report, report_file: &str) -> Row {
    let mut row = base_row(&RunFacts {
        dataset: dataset.to_string(),
        pipeline: pipeline.to_string(),
        tool: String::new(),
        version: None,
        status: Status::Ok,
        reason: None,
        wall_seconds: 0.0,
        cpu_seconds: 0.0,
        peak_memory_bytes: 0,
        images_total: report.cameras.as_ref().map_or(0, |c| c.errors.ground_truth),
        images_registered: report.inputs.reconstruction.images as usize,
        points: report.inputs.reconstruction.points as usize,
    });
    fill_row(&mut row, report);
    row.report = Some(report_file.to_string());
    row
}

/// The row of a reconstruction that has no evaluation: `status` (`failed`, ...) and why.
pub fn failed_row(dataset: &str, pipeline: &str, status: &str, reason: &str) -> Row {
    let mut row = base_row(&RunFacts {
        dataset: dataset.to_string(),
        pipeline: pipeline.to_string(),
        tool: String::new(),
        version: None,
        status: Status::Failed,
        reason: Some(reason.to_string()),
        wall_seconds: 0.0,
        cpu_seconds: 0.0,
        peak_memory_bytes: 0,
        images_total: 0,
        images_registered: 0,
        points: 0,
    });
    row.status = status.to_string();
    row
}

/// The report file of a run, relative to the table folder: `reports/<dataset>/<pipeline>.json`.
pub fn report_path(dataset: &str, pipeline: &str) -> String {
    format!("reports/{dataset}/{pipeline}.json")
}

/// A run's row before evaluation: what `run.json` says.
pub fn base_row(rec: &RunFacts) -> Row {
    Row {
        dataset: rec.dataset.clone(),
        pipeline: rec.pipeline.clone(),
        tool: rec.tool.clone(),
        version: rec.version.clone(),
        status: rec.status.label().to_string(),
        reason: rec.reason.clone(),
        images_total: rec.images_total,
        images_registered: rec.images_registered,
        points: rec.points as u64,
        wall_seconds: rec.wall_seconds,
        cpu_seconds: rec.cpu_seconds,
        peak_memory_mb: rec.peak_memory_bytes as f64 / 1e6,
        mean: None,
        median: None,
        rms: None,
        completeness_mean: None,
        thresholds: Vec::new(),
        rotation_median_deg: None,
        center_median: None,
        center_median_percent: None,
        center_max_percent: None,
        cdf: Vec::new(),
        report: None,
        alignment: None,
        dtu: None,
        poses: None,
        eth3d: None,
    }
}

/// Adds an evaluation's numbers to a row: accuracy, completeness, P/R/F, camera errors.
pub fn fill_row(row: &mut Row, r: &Report) {
    let a = &r.accuracy.stats;
    row.alignment = Some(r.options.align.clone());
    row.points = r.inputs.reconstruction.points;
    row.mean = Some(a.mean);
    row.median = Some(a.median);
    row.rms = Some(a.rms);
    row.completeness_mean = Some(r.completeness.stats.mean);
    row.thresholds = r
        .thresholds
        .iter()
        .map(|t| Prf {
            tau: t.tau,
            tau_percent_of_diagonal: t.tau_percent_of_diagonal,
            precision: t.precision,
            recall: t.recall,
            f_score: t.f_score,
        })
        .collect();
    if let Some(c) = &r.cameras {
        let c = &c.errors;
        row.rotation_median_deg = Some(c.rotation_error_deg.median);
        row.center_median = Some(c.center_error.median);
        row.center_median_percent = Some(c.center_error_percent.median);
        row.center_max_percent = Some(c.center_error_percent.max);
        row.images_registered = c.registered;
    }
}

/// Points of the cumulative distribution of `distances` (non-finite ones dropped): 201
/// quantiles `(distance, share)`, none for no distance.
pub fn cdf_points(distances: &[f64]) -> Vec<(f64, f64)> {
    let mut d: Vec<f64> = distances
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    if d.is_empty() {
        return Vec::new();
    }
    d.sort_by(f64::total_cmp);
    let n = d.len();
    (0..=200)
        .map(|k| {
            let i = ((k as f64 / 200.0) * (n - 1) as f64).round() as usize;
            (d[i.min(n - 1)], (i + 1) as f64 / n as f64)
        })
        .collect()
}

/// The row of an evaluated run: [`base_row`], [`fill_row`], the cumulative distribution of the
/// kept points' distances and the report path.
pub fn evaluated_row(rec: &RunFacts, report: &Report, kept_distances: &[f64]) -> Row {
    let mut row = base_row(rec);
    fill_row(&mut row, report);
    row.cdf = cdf_points(kept_distances);
    row.report = Some(report_path(&rec.dataset, &rec.pipeline));
    row
}

/// The row of a run evaluated with the Tanks and Temples protocol: accuracy is the measured
/// reconstruction points' distances (mean, median), completeness the ground truth's, and the one
/// threshold is the scene's τ (`gt_diagonal` gives its percent); no camera errors (the scene has
/// no ground-truth cameras).
pub fn tnt_row(
    rec: &RunFacts,
    report: &sfmeval_tnt::TntReport,
    precision_distances: &[f64],
    gt_diagonal: f64,
) -> Row {
    let mut row = base_row(rec);
    let tau = report.protocol.tau;
    row.alignment = Some(TNT_ALIGNMENT.to_string());
    row.points = report.inputs.reconstruction.points as u64;
    row.mean = Some(report.precision.mean_distance);
    row.median = Some(report.precision.median_distance);
    let n = precision_distances.len().max(1) as f64;
    row.rms = Some((precision_distances.iter().map(|d| d * d).sum::<f64>() / n).sqrt());
    row.completeness_mean = Some(report.recall.mean_distance);
    row.thresholds = vec![Prf {
        tau,
        tau_percent_of_diagonal: 100.0 * tau / gt_diagonal,
        precision: report.precision.value,
        recall: report.recall.value,
        f_score: report.f_score,
    }];
    row.cdf = cdf_points(precision_distances);
    row.report = Some(report_path(&rec.dataset, &rec.pipeline));
    row
}

/// The row of a run evaluated with the DTU protocol (`sfmeval.dtu/1` numbers, `points` the
/// reconstruction's points before down-sampling) after the camera alignment its report names.
pub fn dtu_row(rec: &RunFacts, numbers: DtuNumbers, points: u64, alignment: &str) -> Row {
    let mut row = base_row(rec);
    row.alignment = Some(alignment.to_string());
    row.points = points;
    row.dtu = Some(numbers);
    row.report = Some(report_path(&rec.dataset, &rec.pipeline));
    row
}

/// The row of a run evaluated with ETH3D's protocol (`sfmeval.eth3d/1` numbers, `points` the
/// reconstruction's points) after the camera alignment its files name.
pub fn eth3d_row(rec: &RunFacts, numbers: Eth3dNumbers, points: u64, alignment: &str) -> Row {
    let mut row = base_row(rec);
    row.alignment = Some(alignment.to_string());
    row.points = points;
    row.eth3d = Some(numbers);
    row.report = Some(report_path(&rec.dataset, &rec.pipeline));
    row
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    const RUN: &str = r#"{"schema":"sfmeval.run/1","dataset":"statue","dataset_dir":"/d","pipeline":"colmap","kind":"colmap","tool":"colmap","version":"3.9","status":"not_installed","reason":"no colmap","command":[],"options":{},"wall_seconds":1.5,"cpu_seconds":2.0,"peak_memory_bytes":2500000,"exit_status":null,"images_total":36,"images_registered":0,"points":0,"models":0,"started_unix":0,"finished_unix":1,"log":"log.txt","steps":[],"warnings":[]}"#;

    #[test]
    fn parses_run_json_and_builds_the_base_row() {
        let f = RunFacts::parse(RUN).unwrap();
        assert_eq!(f.status, Status::NotInstalled);
        let r = base_row(&f);
        assert_eq!(r.status, "not installed");
        assert_eq!(r.peak_memory_mb, 2.5);
        assert_eq!((r.images_total, r.points), (36, 0));
        assert!(r.mean.is_none() && r.report.is_none());
    }

    #[test]
    fn run_json_errors_name_the_field() {
        let e = RunFacts::parse(r#"{"dataset":"x"}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing field"), "{e}");
        let bad = RUN.replace("\"not_installed\"", "\"maybe\"");
        assert!(RunFacts::parse(&bad).is_err());
    }

    #[test]
    fn cdf_has_201_quantiles_and_drops_non_finite() {
        assert!(cdf_points(&[f64::NAN]).is_empty());
        let c = cdf_points(&[3.0, 1.0, f64::INFINITY, 2.0]);
        assert_eq!(c.len(), 201);
        assert_eq!(c[0], (1.0, 1.0 / 3.0));
        assert_eq!(c[200], (3.0, 1.0));
        assert_eq!(c[100], (2.0, 2.0 / 3.0));
    }
}
