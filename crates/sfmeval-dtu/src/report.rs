//! The `sfmeval.dtu/1` report: the three numbers, the counts behind them and the options.

use serde::Serialize;

use crate::protocol::{DtuEvaluation, Shuffle};

/// The report's schema name.
pub const DTU_SCHEMA: &str = "sfmeval.dtu/1";

/// One evaluation's report.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct DtuReport {
    /// [`DTU_SCHEMA`].
    #[cfg_attr(feature = "ts", ts(type = "\"sfmeval.dtu/1\""))]
    pub schema: &'static str,
    /// The scan number.
    pub scan: u32,
    /// The reconstruction's name.
    pub reconstruction: String,
    /// `"mesh"` (sampled) or `"pcd"`.
    #[cfg_attr(feature = "ts", ts(type = "\"mesh\" | \"pcd\""))]
    pub mode: &'static str,
    /// The options (mm).
    pub options: DtuReportOptions,
    /// Mean accuracy (reconstruction to STL, mm), `null` when no distance is below `max_dist`.
    pub mean_accuracy: Option<f64>,
    /// Mean completeness (STL to reconstruction, mm), `null` likewise.
    pub mean_completeness: Option<f64>,
    /// The mean of the two.
    pub overall: Option<f64>,
    /// The counts behind the numbers.
    pub counts: DtuCounts,
}

/// The options of a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct DtuReportOptions {
    /// Down-sampling density (mm).
    pub downsample_density: f64,
    /// Patch size (mm).
    pub patch_size: f64,
    /// Distance cap (mm).
    pub max_dist: f64,
    /// Visualisation threshold (mm).
    pub visualize_threshold: f64,
    /// The shuffle's seed; `null` when the input's order was kept.
    pub shuffle_seed: Option<u64>,
}

/// The counts of a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct DtuCounts {
    /// Points before down-sampling (a mesh's vertices and samples).
    pub points: usize,
    /// After down-sampling.
    pub downsampled: usize,
    /// In the bounding box widened by the patch size.
    pub in_bounding_box: usize,
    /// Of those, in an observed cell: the accuracy's points.
    pub observed: usize,
    /// Accuracy distances below `max_dist` (averaged).
    pub accuracy_below_max_dist: usize,
    /// STL points.
    pub stl_points: usize,
    /// STL points above the ground plane: the completeness's points.
    pub stl_above_plane: usize,
    /// Completeness distances below `max_dist` (averaged).
    pub completeness_below_max_dist: usize,
}

impl DtuReport {
    /// The report of evaluation `e` of `reconstruction` on scan `scan`.
    pub fn new(e: &DtuEvaluation, scan: u32, reconstruction: &str, mesh: bool) -> DtuReport {
        DtuReport {
            schema: DTU_SCHEMA,
            scan,
            reconstruction: reconstruction.to_string(),
            mode: if mesh { "mesh" } else { "pcd" },
            options: DtuReportOptions {
                downsample_density: e.options.downsample_density,
                patch_size: e.options.patch_size,
                max_dist: e.options.max_dist,
                visualize_threshold: e.options.visualize_threshold,
                shuffle_seed: match e.options.shuffle {
                    Shuffle::Seeded(s) => Some(s),
                    Shuffle::None => None,
                },
            },
            mean_accuracy: e.mean_d2s,
            mean_completeness: e.mean_s2d,
            overall: e.overall,
            counts: DtuCounts {
                points: e.sampled_points,
                downsampled: e.downsampled.len(),
                in_bounding_box: e.in_box,
                observed: e.observed.len(),
                accuracy_below_max_dist: e.d2s_counted,
                stl_points: e.stl_points,
                stl_above_plane: e.above.len(),
                completeness_below_max_dist: e.s2d_counted,
            },
        }
    }

    /// The summary `sfmeval dtu` prints (and the page shows): the scan and the counts, then mean
    /// accuracy, mean completeness and overall, one line each, in mm.
    pub fn summary(&self) -> String {
        format!(
            "{}\n{}\n{}\n{}\n",
            self.counts_line(),
            self.accuracy_line(),
            self.completeness_line(),
            self.overall_line(),
        )
    }

    /// The summary's first line: the scan, the input's kind and the point counts.
    pub fn counts_line(&self) -> String {
        let c = &self.counts;
        format!(
            "DTU evaluation, scan {} ({}: {} points, {} after down-sampling to {} mm, {} in the bounding box, {} observed)",
            self.scan,
            self.mode,
            c.points,
            c.downsampled,
            self.options.downsample_density,
            c.in_bounding_box,
            c.observed,
        )
    }

    /// The summary's mean accuracy line.
    pub fn accuracy_line(&self) -> String {
        let c = &self.counts;
        format!(
            "  mean accuracy      {}  ({} of {} distances below {} mm)",
            mm(self.mean_accuracy),
            c.accuracy_below_max_dist,
            c.observed,
            self.options.max_dist
        )
    }

    /// The summary's mean completeness line.
    pub fn completeness_line(&self) -> String {
        let c = &self.counts;
        format!(
            "  mean completeness  {}  ({} of {} STL points above the plane below {} mm)",
            mm(self.mean_completeness),
            c.completeness_below_max_dist,
            c.stl_above_plane,
            self.options.max_dist
        )
    }

    /// The summary's overall line.
    pub fn overall_line(&self) -> String {
        format!("  overall            {}", mm(self.overall))
    }

    /// The report as pretty JSON with a final newline.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }
}

/// A mean in the summary: six decimals in mm, or why there is none.
fn mm(v: Option<f64>) -> String {
    v.map_or_else(
        || "none (no distance below max_dist)".into(),
        |v| format!("{v:.6} mm"),
    )
}

/// The TypeScript declarations of [`DtuReport`] and the types it holds, generated by ts-rs, and
/// the check that the npm package ships them (`crates/sfmeval-wasm/js/dtu-report.d.ts`).
/// `scripts/gen-report-types.sh` rewrites the file (`SFMEVAL_WRITE_REPORT_TYPES=1`); without
/// that variable the test fails when the file is stale.
#[cfg(all(test, feature = "ts"))]
mod typescript {
    use sfmeval::ts_declarations::{Declarations, check_committed};

    use super::{DTU_SCHEMA, DtuReport};

    #[test]
    fn dtu_report_types_are_the_committed_ones() {
        let text = Declarations::new().add::<DtuReport>().file_text(
            DTU_SCHEMA,
            "crates/sfmeval-dtu",
            "DtuReport",
            None,
        );
        let file = "../sfmeval-wasm/js/dtu-report.d.ts";
        check_committed(env!("CARGO_MANIFEST_DIR"), file, DTU_SCHEMA, &text);
    }
}
