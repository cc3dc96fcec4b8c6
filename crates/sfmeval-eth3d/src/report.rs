//! The `sfmeval.eth3d/1` report: per tolerance the tool's three numbers (as the `float`s it
//! computes, written in their shortest form) and the counts behind them; the scans and options.

use serde::Serialize;

use crate::protocol::Eth3dEvaluation;
use crate::scene::Eth3dScene;

/// The report's schema name.
pub const ETH3D_SCHEMA: &str = "sfmeval.eth3d/1";

/// One evaluation's report.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Eth3dReport {
    /// `sfmeval.eth3d/1` ([`ETH3D_SCHEMA`] in Rust).
    #[cfg_attr(feature = "ts", ts(type = "\"sfmeval.eth3d/1\""))]
    pub schema: &'static str,
    /// The MeshLab project's name.
    pub ground_truth: String,
    /// The reconstruction's name.
    pub reconstruction: String,
    /// The options.
    pub options: Eth3dReportOptions,
    /// Points of the reconstruction.
    pub reconstruction_points: usize,
    /// The scans in the project's order.
    pub scans: Vec<Eth3dReportScan>,
    /// Voxel cells (both grids) holding scan points: the completeness's denominator.
    pub completeness_cells: usize,
    /// One entry per tolerance, smallest first.
    pub tolerances: Vec<Eth3dTolerance>,
}

/// The tool's options.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Eth3dReportOptions {
    /// Voxel size (m).
    pub voxel_size: f32,
    /// Beam radius at the scanner (m).
    pub beam_start_radius: f32,
    /// Beam divergence half-angle (degrees).
    pub beam_divergence_halfangle_deg: f32,
}

/// One scan.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Eth3dReportScan {
    /// Its label in the project, if any.
    pub label: Option<String>,
    /// Its file.
    pub file: String,
    /// Its points.
    pub points: usize,
}

/// One tolerance's results.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Eth3dTolerance {
    /// The tolerance (m).
    pub tolerance: f32,
    /// Accuracy in [0, 1]: the mean over voxel cells of accurate / (accurate + inaccurate).
    pub accuracy: f32,
    /// Completeness in [0, 1]: the mean over voxel cells of complete / scan points.
    pub completeness: f32,
    /// F1 of the two.
    pub f1: f32,
    /// Reconstruction points within the tolerance of a scan point on whose beam they lie.
    pub accurate_points: usize,
    /// Reconstruction points in front of scan points (seen through), not accurate.
    pub inaccurate_points: usize,
    /// Reconstruction points neither: left out of the accuracy.
    pub unobserved_points: usize,
    /// Scan points with a reconstruction point within the tolerance.
    pub complete_points: usize,
    /// Voxel cells (both grids) with an accurate or inaccurate point: the accuracy's
    /// denominator.
    pub accuracy_cells: usize,
}

impl Eth3dReport {
    /// The report of evaluation `e` on `scene` (named `ground_truth`) of `reconstruction`.
    pub fn new(
        e: &Eth3dEvaluation,
        scene: &Eth3dScene,
        ground_truth: &str,
        reconstruction: &str,
    ) -> Eth3dReport {
        let tolerances = (0..e.tolerances.len())
            .map(|t| {
                let t32 = t as u32;
                let accurate = e.first_accurate.iter().filter(|&&f| t32 >= f).count();
                let inaccurate = e
                    .first_accurate
                    .iter()
                    .zip(&e.inaccurate)
                    .filter(|&(&f, &i)| t32 < f && i)
                    .count();
                Eth3dTolerance {
                    tolerance: e.tolerances[t],
                    accuracy: e.accuracy[t],
                    completeness: e.completeness[t],
                    f1: e.f1[t],
                    accurate_points: accurate,
                    inaccurate_points: inaccurate,
                    unobserved_points: e.first_accurate.len() - accurate - inaccurate,
                    complete_points: e.first_complete.iter().filter(|&&f| t32 >= f).count(),
                    accuracy_cells: e.accuracy_cells[t],
                }
            })
            .collect();
        Eth3dReport {
            schema: ETH3D_SCHEMA,
            ground_truth: ground_truth.to_string(),
            reconstruction: reconstruction.to_string(),
            options: Eth3dReportOptions {
                voxel_size: e.options.voxel_size,
                beam_start_radius: e.options.beam_start_radius,
                beam_divergence_halfangle_deg: e.options.beam_divergence_halfangle_deg,
            },
            reconstruction_points: e.first_accurate.len(),
            scans: scene
                .scans
                .iter()
                .map(|s| Eth3dReportScan {
                    label: s.entry.label.clone(),
                    file: s.file.clone(),
                    points: s.points.len(),
                })
                .collect(),
            completeness_cells: e.completeness_cells,
            tolerances,
        }
    }

    /// The report as pretty JSON with a final newline.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }

    /// The summary's first line: points, scans, voxel size.
    pub fn headline(&self) -> String {
        let scan_points: usize = self.scans.iter().map(|s| s.points).sum();
        format!(
            "ETH3D multi-view evaluation: {} reconstruction points, {} scan points in {} scan(s), voxel {} m",
            self.reconstruction_points,
            scan_points,
            self.scans.len(),
            self.options.voxel_size
        )
    }

    /// The per-tolerance table as the page shows it: its column headers and, per tolerance
    /// (smallest first), the cells' texts (numbers as the summary prints them).
    pub fn table(&self) -> Eth3dTable {
        Eth3dTable {
            columns: [
                "tolerance",
                "accuracy",
                "completeness",
                "F1",
                "accurate",
                "inaccurate",
                "unobserved",
            ]
            .map(String::from)
            .to_vec(),
            rows: self
                .tolerances
                .iter()
                .map(|t| {
                    vec![
                        format!("{} m", t.tolerance),
                        format!("{:.6}", t.accuracy),
                        format!("{:.6}", t.completeness),
                        format!("{:.6}", t.f1),
                        t.accurate_points.to_string(),
                        t.inaccurate_points.to_string(),
                        t.unobserved_points.to_string(),
                    ]
                })
                .collect(),
        }
    }

    /// The summary `sfmeval eth3d` prints: [`Self::headline`], then one line per tolerance.
    pub fn summary(&self) -> String {
        let mut s = self.headline();
        s += "\n  tolerance     accuracy  completeness        F1   reconstruction points accurate / inaccurate / unobserved\n";
        for t in &self.tolerances {
            s += &format!(
                "  {:<10}  {:>10.6}  {:>12.6}  {:>8.6}   {} / {} / {}\n",
                format!("{} m", t.tolerance),
                t.accuracy,
                t.completeness,
                t.f1,
                t.accurate_points,
                t.inaccurate_points,
                t.unobserved_points
            );
        }
        s
    }
}

/// The per-tolerance table of [`Eth3dReport::table`]: headers and cell texts.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Eth3dTable {
    /// Column headers.
    pub columns: Vec<String>,
    /// One row per tolerance.
    pub rows: Vec<Vec<String>>,
}

/// The TypeScript declarations of [`Eth3dReport`] and the types it holds, generated by ts-rs,
/// and the check that the npm package ships them (`crates/sfmeval-wasm/js/eth3d-report.d.ts`).
/// `scripts/gen-report-types.sh` rewrites the file (`SFMEVAL_WRITE_REPORT_TYPES=1`); without
/// that variable the test fails when the file is stale.
#[cfg(all(test, feature = "ts"))]
mod typescript {
    use sfmeval::ts_declarations::{Declarations, check_committed};

    use super::{ETH3D_SCHEMA, Eth3dReport};

    #[test]
    fn eth3d_report_types_are_the_committed_ones() {
        let text = Declarations::new().add::<Eth3dReport>().file_text(
            ETH3D_SCHEMA,
            "crates/sfmeval-eth3d",
            "Eth3dReport",
            None,
        );
        let file = "../sfmeval-wasm/js/eth3d-report.d.ts";
        check_committed(env!("CARGO_MANIFEST_DIR"), file, ETH3D_SCHEMA, &text);
    }
}
