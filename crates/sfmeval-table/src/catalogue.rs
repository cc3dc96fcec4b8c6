//! The comparison's metrics, listed once: each with its key (a JSON path into
//! `{"report": <sfmeval.report/3>, "run": <the run's row>}`, `[*]` for one per threshold), its
//! column header and unit, its long name (chart titles), which end is best and its number format.
//! The wide table ([`WIDE`]), the page's Compare table ([`COMPARE`], through the wasm bindings)
//! and the runner's sweep charts ([`SWEEP`], [`SWEEP_VISIBILITY`]) are lists of these keys.

use serde::Serialize;
use serde_json::Value as Json;

use crate::row::Row;
use crate::text::one_line;

/// Which end of a metric is best.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Best {
    /// The lowest value (errors, distances, time).
    Lower,
    /// The highest value (scores, counts of registered images).
    Higher,
}

/// Where a metric's value comes from.
#[derive(Debug, Clone, Copy)]
pub enum Source {
    /// A number of the run's row (`k`: the threshold for a per-threshold metric).
    Number(fn(&Row, usize) -> Option<f64>),
    /// Text of the run's row (in full for CSV when the flag is set).
    Text(fn(&Row, bool) -> String),
    /// Only in the document at the key (the report's fields a row does not carry).
    Document,
}

/// One metric of the comparison.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Metric {
    /// JSON path into `{"report": ..., "run": ...}` (`report.accuracy.mean`); `[*]` stands for
    /// every threshold.
    pub key: &'static str,
    /// Short identifier of the column (`mean`; a per-threshold one gets its index: `f0`).
    pub id: &'static str,
    /// Column header without the unit (`mean`; a per-threshold one gets `@<τ in %>%`).
    pub header: &'static str,
    /// Unit (`m`, `°`, `s`), none for counts, fractions and text.
    pub unit: Option<&'static str>,
    /// Long name, for chart titles.
    pub name: &'static str,
    /// Which end is best, none for text.
    pub best: Option<Best>,
    /// Decimals in Markdown and HTML tables (CSV has numbers in full); none for text.
    pub digits: Option<usize>,
    /// Where the value is read.
    #[serde(skip)]
    pub source: Source,
    /// The cell's text instead of the number (`registered/total`), when set.
    #[serde(skip)]
    pub shown: Option<fn(&Row) -> String>,
}

impl Metric {
    /// Whether the metric has one value per threshold (`[*]` in its key).
    pub fn per_threshold(&self) -> bool {
        self.key.contains("[*]")
    }

    /// Whether the column holds text (no best end, not a number).
    pub fn is_text(&self) -> bool {
        matches!(self.source, Source::Text(_))
    }

    /// The header with its unit: `mean (m)`; `pct` names a per-threshold column's threshold in
    /// percent of the diagonal (`F@0.5%`).
    pub fn header_with_unit(&self, pct: Option<f64>) -> String {
        let head = self.header_at(pct);
        match self.unit {
            Some(u) => format!("{head} ({u})"),
            None => head,
        }
    }

    /// The header without the unit, `@pct%` after a per-threshold one.
    pub fn header_at(&self, pct: Option<f64>) -> String {
        match pct {
            Some(p) if self.per_threshold() => format!("{}@{p}%", self.header),
            _ => self.header.to_string(),
        }
    }

    /// The key of threshold `k` (`report.thresholds[1].f_score`), the key itself otherwise.
    pub fn key_at(&self, k: usize) -> String {
        self.key.replacen("[*]", &format!("[{k}]"), 1)
    }

    /// The id of threshold `k` (`f1`), the id itself otherwise.
    pub fn id_at(&self, k: usize) -> String {
        if self.per_threshold() {
            format!("{}{k}", self.id)
        } else {
            self.id.to_string()
        }
    }

    /// The number of `row` (threshold `k`), or the one at the key in `doc` for a metric only
    /// the report carries.
    pub fn number(&self, row: &Row, k: usize, doc: Option<&Json>) -> Option<f64> {
        match self.source {
            Source::Number(f) => f(row, k),
            Source::Text(_) => None,
            Source::Document => doc.and_then(|d| lookup(d, &self.key_at(k))),
        }
    }
}

#[allow(clippy::too_many_arguments)] // one argument per field, in the fields' order
const fn metric(
    key: &'static str,
    id: &'static str,
    header: &'static str,
    unit: Option<&'static str>,
    name: &'static str,
    best: Option<Best>,
    digits: Option<usize>,
    source: Source,
) -> Metric {
    Metric {
        key,
        id,
        header,
        unit,
        name,
        best,
        digits,
        source,
        shown: None,
    }
}

const M: Option<&str> = Some("m");
const MM: Option<&str> = Some("mm");
const PCT: Option<&str> = Some("%");
const LOWER: Option<Best> = Some(Best::Lower);
const HIGHER: Option<Best> = Some(Best::Higher);

/// The ETH3D numbers of tolerance `k` of a row.
fn eth3d_at(r: &Row, k: usize) -> Option<&crate::row::Eth3dTolerance> {
    r.eth3d.as_ref().and_then(|e| e.tolerances.get(k))
}

fn registered_of_total(r: &Row) -> String {
    format!("{}/{}", r.images_registered, r.images_total)
}

fn tool_text(r: &Row, _csv: bool) -> String {
    format!("{} {}", r.tool, r.version.as_deref().unwrap_or(""))
        .trim()
        .to_string()
}

fn reason_text(r: &Row, csv: bool) -> String {
    if csv {
        r.reason.clone().unwrap_or_default()
    } else {
        short(r.reason.as_deref().unwrap_or(""))
    }
}

/// A reason on one line for a Markdown cell: no line breaks or `|`, at most 120 characters.
pub(crate) fn short(s: &str) -> String {
    one_line(&s.replace('|', " "), 120)
}

/// Every metric of the comparison.
pub const CATALOGUE: &[Metric] = &[
    metric(
        "run.dataset",
        "dataset",
        "dataset",
        None,
        "dataset",
        None,
        None,
        Source::Text(|r, _| r.dataset.clone()),
    ),
    metric(
        "run.pipeline",
        "pipeline",
        "pipeline",
        None,
        "pipeline",
        None,
        None,
        Source::Text(|r, _| r.pipeline.clone()),
    ),
    metric(
        "run.status",
        "status",
        "status",
        None,
        "status",
        None,
        None,
        Source::Text(|r, _| r.status.clone()),
    ),
    metric(
        "run.points",
        "points",
        "points",
        None,
        "points",
        HIGHER,
        Some(0),
        // the points measured: none for a run that was not evaluated
        Source::Number(|r, _| (r.status == "ok").then_some(r.points as f64)),
    ),
    Metric {
        shown: Some(registered_of_total),
        ..metric(
            "run.images_registered",
            "registered",
            "registered",
            None,
            "registered images",
            HIGHER,
            Some(0),
            Source::Number(|r, _| Some(r.images_registered as f64)),
        )
    },
    metric(
        "run.registered_fraction",
        "registered_fraction",
        "registered",
        None,
        "registered images (fraction)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| {
            (r.images_total > 0).then(|| r.images_registered as f64 / r.images_total as f64)
        }),
    ),
    metric(
        "report.accuracy.min",
        "min",
        "min",
        M,
        "accuracy: smallest distance (m)",
        LOWER,
        Some(6),
        Source::Document,
    ),
    metric(
        "report.accuracy.max",
        "max",
        "max",
        M,
        "accuracy: largest distance (m)",
        LOWER,
        Some(6),
        Source::Document,
    ),
    metric(
        "report.accuracy.mean",
        "mean",
        "mean",
        M,
        "accuracy: mean distance (m)",
        LOWER,
        Some(6),
        Source::Number(|r, _| r.mean),
    ),
    metric(
        "report.accuracy.median",
        "median",
        "median",
        M,
        "accuracy: median distance (m)",
        LOWER,
        Some(6),
        Source::Number(|r, _| r.median),
    ),
    metric(
        "report.accuracy.std",
        "std",
        "std",
        M,
        "accuracy: standard deviation of the distances (m)",
        LOWER,
        Some(6),
        Source::Document,
    ),
    metric(
        "report.accuracy.rms",
        "rms",
        "RMS",
        M,
        "accuracy: RMS distance (m)",
        LOWER,
        Some(6),
        Source::Number(|r, _| r.rms),
    ),
    metric(
        "report.completeness.mean",
        "completeness",
        "completeness (mean)",
        M,
        "completeness: mean distance GT → reconstruction (m)",
        LOWER,
        Some(6),
        Source::Number(|r, _| r.completeness_mean),
    ),
    metric(
        "report.completeness.median",
        "completeness_median",
        "completeness (median)",
        M,
        "completeness: median distance GT → reconstruction (m)",
        LOWER,
        Some(6),
        Source::Document,
    ),
    metric(
        "report.thresholds[*].precision",
        "p",
        "P",
        None,
        "precision",
        HIGHER,
        Some(3),
        Source::Number(|r, k| r.thresholds.get(k).map(|t| t.precision)),
    ),
    metric(
        "report.thresholds[*].recall",
        "r",
        "R",
        None,
        "completeness (recall)",
        HIGHER,
        Some(3),
        Source::Number(|r, k| r.thresholds.get(k).map(|t| t.recall)),
    ),
    metric(
        "report.thresholds[*].f_score",
        "f",
        "F",
        None,
        "F-score",
        HIGHER,
        Some(3),
        Source::Number(|r, k| r.thresholds.get(k).map(|t| t.f_score)),
    ),
    metric(
        "report.cameras.rotation_error_deg.median",
        "rotation_median",
        "rot. median",
        Some("°"),
        "median rotation error (°)",
        LOWER,
        Some(3),
        Source::Number(|r, _| r.rotation_median_deg),
    ),
    metric(
        "report.cameras.center_error.median",
        "centre_median",
        "centre median",
        M,
        "median camera-centre error (m)",
        LOWER,
        Some(5),
        Source::Number(|r, _| r.center_median),
    ),
    metric(
        "report.cameras.center_error_percent.median",
        "centre_median_percent",
        "centre median",
        Some("% radius"),
        "median camera-centre error (% of the scene radius)",
        LOWER,
        Some(3),
        Source::Number(|r, _| r.center_median_percent),
    ),
    metric(
        "report.cameras.center_error_percent.max",
        "centre_max_percent",
        "centre max",
        Some("% radius"),
        "largest camera-centre error (% of the scene radius)",
        LOWER,
        Some(3),
        Source::Number(|r, _| r.center_max_percent),
    ),
    metric(
        "report.cameras.ate_rmse",
        "ate",
        "pose ATE",
        M,
        "ATE RMSE (m)",
        LOWER,
        Some(6),
        Source::Document,
    ),
    metric(
        "run.wall_seconds",
        "wall",
        "wall",
        Some("s"),
        "run time (s, wall)",
        LOWER,
        Some(1),
        Source::Number(|r, _| Some(r.wall_seconds)),
    ),
    metric(
        "run.cpu_seconds",
        "cpu",
        "CPU",
        Some("s"),
        "CPU time (s)",
        LOWER,
        Some(1),
        Source::Number(|r, _| Some(r.cpu_seconds)),
    ),
    metric(
        "run.peak_memory_mb",
        "peak_memory",
        "peak mem",
        Some("MB"),
        "peak memory (MB)",
        LOWER,
        Some(0),
        Source::Number(|r, _| Some(r.peak_memory_mb)),
    ),
    metric(
        "run.tool",
        "tool",
        "tool",
        None,
        "tool and version",
        None,
        None,
        Source::Text(tool_text),
    ),
    metric(
        "run.reason",
        "reason",
        "reason",
        None,
        "why the run did not end ok",
        None,
        None,
        Source::Text(reason_text),
    ),
    metric(
        "report.completeness_visible.thresholds[*].recall_visible",
        "recall_visible",
        "R visible",
        None,
        "completeness of the visible surface (recall)",
        HIGHER,
        Some(3),
        Source::Document,
    ),
    metric(
        "report.completeness_visible.visible_fraction",
        "visible_fraction",
        "visible share",
        None,
        "visible share of the surface (≥ k images)",
        HIGHER,
        Some(3),
        Source::Document,
    ),
    metric(
        "report.track_error.median",
        "track_error_median",
        "track error median",
        M,
        "track-based true error: median (m)",
        LOWER,
        Some(6),
        Source::Document,
    ),
    metric(
        "report.track_error.thresholds[*].sliding_fraction",
        "sliding",
        "sliding",
        None,
        "sliding points (true error − surface distance > τ)",
        LOWER,
        Some(3),
        Source::Document,
    ),
    metric(
        "report.mean_accuracy",
        "dtu_accuracy",
        "DTU accuracy",
        MM,
        "DTU: mean accuracy (mm)",
        LOWER,
        Some(3),
        Source::Number(|r, _| r.dtu.as_ref().and_then(|d| d.mean_accuracy)),
    ),
    metric(
        "report.mean_completeness",
        "dtu_completeness",
        "DTU completeness",
        MM,
        "DTU: mean completeness (mm)",
        LOWER,
        Some(3),
        Source::Number(|r, _| r.dtu.as_ref().and_then(|d| d.mean_completeness)),
    ),
    metric(
        "report.overall",
        "dtu_overall",
        "DTU overall",
        MM,
        "DTU: overall, the mean of accuracy and completeness (mm)",
        LOWER,
        Some(3),
        Source::Number(|r, _| r.dtu.as_ref().and_then(|d| d.overall)),
    ),
    metric(
        "run.poses.colmap.auc_percent[0]",
        "colmap_auc0",
        "COLMAP AUC@0.5°",
        PCT,
        "COLMAP benchmark: pose AUC up to 0.5° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.colmap.auc_percent.first().copied())
        }),
    ),
    metric(
        "run.poses.colmap.auc_percent[1]",
        "colmap_auc1",
        "COLMAP AUC@1°",
        PCT,
        "COLMAP benchmark: pose AUC up to 1° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.colmap.auc_percent.get(1).copied())
        }),
    ),
    metric(
        "run.poses.colmap.auc_percent[2]",
        "colmap_auc2",
        "COLMAP AUC@5°",
        PCT,
        "COLMAP benchmark: pose AUC up to 5° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.colmap.auc_percent.get(2).copied())
        }),
    ),
    metric(
        "run.poses.colmap.auc_percent[3]",
        "colmap_auc3",
        "COLMAP AUC@10°",
        PCT,
        "COLMAP benchmark: pose AUC up to 10° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.colmap.auc_percent.get(3).copied())
        }),
    ),
    metric(
        "run.poses.imc.maa_10",
        "imc_maa",
        "IMC mAA@10°",
        None,
        "Image Matching Challenge: pose mAA up to 10°",
        HIGHER,
        Some(3),
        Source::Number(|r, _| r.poses.as_ref().map(|p| p.imc.maa_10)),
    ),
    metric(
        "run.poses.co3d.rra_percent[0]",
        "co3d_rra0",
        "CO3D RRA@5°",
        PCT,
        "CO3D: relative rotation accuracy at 5° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.co3d.rra_percent.first().copied())
        }),
    ),
    metric(
        "run.poses.co3d.rra_percent[1]",
        "co3d_rra1",
        "CO3D RRA@15°",
        PCT,
        "CO3D: relative rotation accuracy at 15° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.co3d.rra_percent.get(1).copied())
        }),
    ),
    metric(
        "run.poses.co3d.rra_percent[2]",
        "co3d_rra2",
        "CO3D RRA@30°",
        PCT,
        "CO3D: relative rotation accuracy at 30° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.co3d.rra_percent.get(2).copied())
        }),
    ),
    metric(
        "run.poses.co3d.rta_percent[0]",
        "co3d_rta0",
        "CO3D RTA@5°",
        PCT,
        "CO3D: relative translation accuracy at 5° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.co3d.rta_percent.first().copied())
        }),
    ),
    metric(
        "run.poses.co3d.rta_percent[1]",
        "co3d_rta1",
        "CO3D RTA@15°",
        PCT,
        "CO3D: relative translation accuracy at 15° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.co3d.rta_percent.get(1).copied())
        }),
    ),
    metric(
        "run.poses.co3d.rta_percent[2]",
        "co3d_rta2",
        "CO3D RTA@30°",
        PCT,
        "CO3D: relative translation accuracy at 30° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| {
            r.poses
                .as_ref()
                .and_then(|p| p.co3d.rta_percent.get(2).copied())
        }),
    ),
    metric(
        "run.poses.co3d.auc_percent",
        "co3d_auc",
        "CO3D AUC@30°",
        PCT,
        "CO3D: pose AUC up to 30° (%)",
        HIGHER,
        Some(2),
        Source::Number(|r, _| r.poses.as_ref().map(|p| p.co3d.auc_percent)),
    ),
    metric(
        "report.tolerances[0].accuracy",
        "eth3d_acc0",
        "ETH3D accuracy@0.01m",
        None,
        "ETH3D: accuracy (share of the reconstruction within 0.01 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 0).map(|t| t.accuracy)),
    ),
    metric(
        "report.tolerances[0].completeness",
        "eth3d_comp0",
        "ETH3D completeness@0.01m",
        None,
        "ETH3D: completeness (share of the scans within 0.01 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 0).map(|t| t.completeness)),
    ),
    metric(
        "report.tolerances[0].f1",
        "eth3d_f10",
        "ETH3D F1@0.01m",
        None,
        "ETH3D: F1 score at 0.01 m",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 0).map(|t| t.f1)),
    ),
    metric(
        "report.tolerances[1].accuracy",
        "eth3d_acc1",
        "ETH3D accuracy@0.02m",
        None,
        "ETH3D: accuracy (share of the reconstruction within 0.02 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 1).map(|t| t.accuracy)),
    ),
    metric(
        "report.tolerances[1].completeness",
        "eth3d_comp1",
        "ETH3D completeness@0.02m",
        None,
        "ETH3D: completeness (share of the scans within 0.02 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 1).map(|t| t.completeness)),
    ),
    metric(
        "report.tolerances[1].f1",
        "eth3d_f11",
        "ETH3D F1@0.02m",
        None,
        "ETH3D: F1 score at 0.02 m",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 1).map(|t| t.f1)),
    ),
    metric(
        "report.tolerances[2].accuracy",
        "eth3d_acc2",
        "ETH3D accuracy@0.05m",
        None,
        "ETH3D: accuracy (share of the reconstruction within 0.05 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 2).map(|t| t.accuracy)),
    ),
    metric(
        "report.tolerances[2].completeness",
        "eth3d_comp2",
        "ETH3D completeness@0.05m",
        None,
        "ETH3D: completeness (share of the scans within 0.05 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 2).map(|t| t.completeness)),
    ),
    metric(
        "report.tolerances[2].f1",
        "eth3d_f12",
        "ETH3D F1@0.05m",
        None,
        "ETH3D: F1 score at 0.05 m",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 2).map(|t| t.f1)),
    ),
    metric(
        "report.tolerances[3].accuracy",
        "eth3d_acc3",
        "ETH3D accuracy@0.1m",
        None,
        "ETH3D: accuracy (share of the reconstruction within 0.1 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 3).map(|t| t.accuracy)),
    ),
    metric(
        "report.tolerances[3].completeness",
        "eth3d_comp3",
        "ETH3D completeness@0.1m",
        None,
        "ETH3D: completeness (share of the scans within 0.1 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 3).map(|t| t.completeness)),
    ),
    metric(
        "report.tolerances[3].f1",
        "eth3d_f13",
        "ETH3D F1@0.1m",
        None,
        "ETH3D: F1 score at 0.1 m",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 3).map(|t| t.f1)),
    ),
    metric(
        "report.tolerances[4].accuracy",
        "eth3d_acc4",
        "ETH3D accuracy@0.2m",
        None,
        "ETH3D: accuracy (share of the reconstruction within 0.2 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 4).map(|t| t.accuracy)),
    ),
    metric(
        "report.tolerances[4].completeness",
        "eth3d_comp4",
        "ETH3D completeness@0.2m",
        None,
        "ETH3D: completeness (share of the scans within 0.2 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 4).map(|t| t.completeness)),
    ),
    metric(
        "report.tolerances[4].f1",
        "eth3d_f14",
        "ETH3D F1@0.2m",
        None,
        "ETH3D: F1 score at 0.2 m",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 4).map(|t| t.f1)),
    ),
    metric(
        "report.tolerances[5].accuracy",
        "eth3d_acc5",
        "ETH3D accuracy@0.5m",
        None,
        "ETH3D: accuracy (share of the reconstruction within 0.5 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 5).map(|t| t.accuracy)),
    ),
    metric(
        "report.tolerances[5].completeness",
        "eth3d_comp5",
        "ETH3D completeness@0.5m",
        None,
        "ETH3D: completeness (share of the scans within 0.5 m)",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 5).map(|t| t.completeness)),
    ),
    metric(
        "report.tolerances[5].f1",
        "eth3d_f15",
        "ETH3D F1@0.5m",
        None,
        "ETH3D: F1 score at 0.5 m",
        HIGHER,
        Some(3),
        Source::Number(|r, _| eth3d_at(r, 5).map(|t| t.f1)),
    ),
];

/// The wide table's columns (`runs.csv`, `table.md`, the runner's page), in order; [`WIDE_DTU`]
/// follows the per-threshold columns when a row has DTU numbers.
pub const WIDE: &[&str] = &[
    "run.dataset",
    "run.pipeline",
    "run.status",
    "run.points",
    "run.images_registered",
    "report.accuracy.mean",
    "report.accuracy.median",
    "report.accuracy.rms",
    "report.thresholds[*].precision",
    "report.thresholds[*].recall",
    "report.thresholds[*].f_score",
    "report.cameras.rotation_error_deg.median",
    "report.cameras.center_error.median",
    "report.cameras.center_error_percent.median",
    "report.cameras.center_error_percent.max",
    "run.wall_seconds",
    "run.cpu_seconds",
    "run.peak_memory_mb",
    "run.tool",
    "run.reason",
];

/// The DTU protocol's columns of the wide table (`sfmeval.dtu/1` keys), shown when some row
/// was evaluated on a DTU scan.
pub const WIDE_DTU: &[&str] = &[
    "report.mean_accuracy",
    "report.mean_completeness",
    "report.overall",
];

/// ETH3D's columns of the wide table (`sfmeval.eth3d/1` keys: accuracy, completeness and F1 at
/// each of the benchmark's tolerances, 0.01 … 0.5 m, the runner's), shown when some row was
/// evaluated on an ETH3D scene.
pub const WIDE_ETH3D: &[&str] = &[
    "report.tolerances[0].accuracy",
    "report.tolerances[0].completeness",
    "report.tolerances[0].f1",
    "report.tolerances[1].accuracy",
    "report.tolerances[1].completeness",
    "report.tolerances[1].f1",
    "report.tolerances[2].accuracy",
    "report.tolerances[2].completeness",
    "report.tolerances[2].f1",
    "report.tolerances[3].accuracy",
    "report.tolerances[3].completeness",
    "report.tolerances[3].f1",
    "report.tolerances[4].accuracy",
    "report.tolerances[4].completeness",
    "report.tolerances[4].f1",
    "report.tolerances[5].accuracy",
    "report.tolerances[5].completeness",
    "report.tolerances[5].f1",
];

/// The pose protocols' columns of the wide table (`sfmeval poses` with its default options:
/// COLMAP's AUC at 0.5, 1, 5 and 10°, IMC's mAA up to 10°, CO3D's RRA / RTA at 5, 15 and 30° and
/// AUC@30), shown after the camera columns when some row has them (and in the page's Compare).
pub const WIDE_POSES: &[&str] = &[
    "run.poses.colmap.auc_percent[0]",
    "run.poses.colmap.auc_percent[1]",
    "run.poses.colmap.auc_percent[2]",
    "run.poses.colmap.auc_percent[3]",
    "run.poses.imc.maa_10",
    "run.poses.co3d.rra_percent[0]",
    "run.poses.co3d.rra_percent[1]",
    "run.poses.co3d.rra_percent[2]",
    "run.poses.co3d.rta_percent[0]",
    "run.poses.co3d.rta_percent[1]",
    "run.poses.co3d.rta_percent[2]",
    "run.poses.co3d.auc_percent",
];

/// The page's Compare table's columns, in order (per-threshold ones grouped by threshold).
pub const COMPARE: &[&str] = &[
    "run.pipeline",
    "run.images_registered",
    "run.points",
    "report.accuracy.min",
    "report.accuracy.max",
    "report.accuracy.mean",
    "report.accuracy.median",
    "report.accuracy.std",
    "report.completeness.mean",
    "report.thresholds[*].f_score",
    "report.cameras.ate_rmse",
    "run.status",
];

/// What a sweep plots by default (`sfmeval-runner sweep`), in order.
pub const SWEEP: &[&str] = &[
    "report.thresholds[*].recall",
    "report.thresholds[*].precision",
    "report.thresholds[*].f_score",
    "report.accuracy.mean",
    "report.accuracy.median",
    "report.completeness.median",
    "run.registered_fraction",
    "report.cameras.rotation_error_deg.median",
    "report.cameras.ate_rmse",
    "run.points",
    "run.wall_seconds",
];

/// What a sweep plots when some run's report has the section (runs with depth maps).
pub const SWEEP_VISIBILITY: &[&str] = &[
    "report.completeness_visible.thresholds[*].recall_visible",
    "report.completeness_visible.visible_fraction",
    "report.track_error.median",
    "report.track_error.thresholds[*].sliding_fraction",
];

/// The catalogue's metric of `key`.
pub fn find(key: &str) -> Option<&'static Metric> {
    CATALOGUE.iter().find(|m| m.key == key)
}

/// The metrics of a list of keys (every list above names catalogue keys: a test checks it).
pub fn metrics_of(keys: &[&str]) -> Vec<&'static Metric> {
    keys.iter().filter_map(|k| find(k)).collect()
}

/// The value at `path` (`a.b[2].c`) of `doc`, if a number.
pub fn lookup(doc: &Json, path: &str) -> Option<f64> {
    let mut cur = doc;
    for part in path.split('.') {
        let (key, rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            cur = cur.get(key)?;
        }
        let mut rest = rest;
        while let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']')?;
            let idx: usize = r[..end].parse().ok()?;
            cur = cur.get(idx)?;
            rest = &r[end + 1..];
        }
    }
    cur.as_f64()
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn every_list_names_catalogue_metrics_once() {
        for list in [
            WIDE,
            WIDE_DTU,
            WIDE_ETH3D,
            WIDE_POSES,
            COMPARE,
            SWEEP,
            SWEEP_VISIBILITY,
        ] {
            assert_eq!(metrics_of(list).len(), list.len(), "{list:?}");
        }
        for (i, m) in CATALOGUE.iter().enumerate() {
            assert!(
                CATALOGUE[i + 1..]
                    .iter()
                    .all(|o| o.key != m.key && o.id != m.id),
                "{} twice",
                m.key
            );
            assert_eq!(m.is_text(), m.best.is_none(), "{}", m.key);
            assert_eq!(m.is_text(), m.digits.is_none(), "{}", m.key);
        }
    }

    #[test]
    fn pose_headers_name_the_default_thresholds_of_sfmeval_poses() {
        let o = sfmeval::pose::ProtocolOptions::default();
        let header = |k: &str| find(k).unwrap().header;
        for (k, t) in o.colmap_thresholds_deg.iter().enumerate() {
            assert_eq!(
                header(&format!("run.poses.colmap.auc_percent[{k}]")),
                format!("COLMAP AUC@{t}°")
            );
        }
        for (k, t) in o.co3d_thresholds_deg.iter().enumerate() {
            for (field, what) in [("rra_percent", "RRA"), ("rta_percent", "RTA")] {
                assert_eq!(
                    header(&format!("run.poses.co3d.{field}[{k}]")),
                    format!("CO3D {what}@{t}°")
                );
            }
        }
        assert_eq!(
            header("run.poses.co3d.auc_percent"),
            format!("CO3D AUC@{}°", o.co3d_auc_max_deg)
        );
        assert_eq!(
            WIDE_POSES.len(),
            o.colmap_thresholds_deg.len() + 1 + 2 * o.co3d_thresholds_deg.len() + 1
        );
    }

    #[test]
    fn eth3d_headers_name_the_benchmark_tolerances() {
        let tolerances = sfmeval_eth3d::DEFAULT_TOLERANCES;
        assert_eq!(WIDE_ETH3D.len(), 3 * tolerances.len());
        for (k, t) in tolerances.iter().enumerate() {
            for (field, what) in [
                ("accuracy", "accuracy"),
                ("completeness", "completeness"),
                ("f1", "F1"),
            ] {
                let m = find(&format!("report.tolerances[{k}].{field}")).unwrap();
                assert_eq!(m.header, format!("ETH3D {what}@{t}m"));
            }
        }
    }

    #[test]
    fn headers_keys_and_lookup() {
        let f = find("report.thresholds[*].f_score").unwrap();
        assert_eq!(f.header_with_unit(Some(0.5)), "F@0.5%");
        assert_eq!(f.key_at(2), "report.thresholds[2].f_score");
        assert_eq!(f.id_at(2), "f2");
        let mean = find("report.accuracy.mean").unwrap();
        assert_eq!(mean.header_with_unit(None), "mean (m)");
        assert_eq!(mean.header_at(Some(1.0)), "mean");
        let doc = json!({"report": {"accuracy": {"std": 0.5},
            "thresholds": [{"recall": 0.1}, {"recall": 0.3}]}});
        assert_eq!(lookup(&doc, "report.accuracy.std"), Some(0.5));
        assert_eq!(lookup(&doc, "report.thresholds[1].recall"), Some(0.3));
        assert_eq!(lookup(&doc, "report.thresholds[2].recall"), None);
        assert_eq!(lookup(&Json::Null, "run.wall_seconds"), None);
    }
}
