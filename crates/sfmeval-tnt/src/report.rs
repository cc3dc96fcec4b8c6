//! The protocol's report, `sfmeval.tanksandtemples/2`: the protocol and every parameter, the
//! inputs, each registration step with its transform and score, precision / recall / F at the
//! scene's τ, and the cumulative curves. Matrices are row-major 4×4.

use serde::{Deserialize, Serialize};

use super::icp::{IcpCriteria, IcpResult};
use super::matrix::Matrix4;
use super::trajectory_alignment::{TrajectoryAlignment, TrajectoryAlignmentOptions};
use sfmeval::note::Note;
use sfmeval::report::Tool;

/// Schema id of the report.
pub const TNT_SCHEMA: &str = "sfmeval.tanksandtemples/2";

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct TntReport {
    /// `sfmeval.tanksandtemples/2` ([`TNT_SCHEMA`] in Rust).
    #[cfg_attr(feature = "ts", ts(type = "\"sfmeval.tanksandtemples/2\""))]
    pub schema: String,
    /// The program that wrote it.
    pub tool: Tool,
    /// What was run, with every parameter.
    pub protocol: ProtocolSection,
    /// What was read.
    pub inputs: InputsSection,
    /// How the reconstruction was brought into the ground-truth frame.
    pub registration: RegistrationSection,
    /// Reconstruction → ground truth.
    pub precision: SideSection,
    /// Ground truth → reconstruction.
    pub recall: SideSection,
    /// `2PR / (P + R)`.
    pub f_score: f64,
    /// Cumulative distance curves (the toolbox's `cum_source` / `cum_target`).
    pub curves: CurvesSection,
    /// What the reader should know besides the numbers: typed notes (`sfmeval::note`), the
    /// reading's and the protocol's (`/1` had them as strings, in `warnings`).
    pub notes: Vec<Note>,
}

/// The protocol's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ProtocolSection {
    /// `"tanksandtemples"`.
    pub name: String,
    /// Which implementation it follows.
    pub reference: String,
    /// The scene's name.
    pub scene: String,
    /// τ in ground-truth units.
    pub tau: f64,
    /// `"scene table"` (the toolbox's τ of the scene) or `"option"`.
    pub tau_source: String,
    /// The crop volume (an Open3D `SelectionPolygonVolume`).
    pub crop: CropSection,
    /// The trajectory alignment's parameters (absent when the final transform was given).
    pub trajectory_alignment: Option<TrajectoryParams>,
    /// The three ICP refinements (empty when the final transform was given).
    pub refinement: Vec<StageParams>,
    /// The evaluation step's parameters.
    pub evaluation: EvaluationParams,
}

/// The crop of the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct CropSection {
    /// The crop file.
    pub file: String,
    /// `"polygon_prism"` for the benchmark's files.
    pub kind: String,
    /// The axis across the polygon.
    pub axis: String,
    /// Range along it.
    pub axis_min: f64,
    /// Range along it.
    pub axis_max: f64,
    /// Polygon vertices.
    pub polygon_vertices: usize,
}

/// Trajectory-alignment parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct TrajectoryParams {
    /// Correspondence distance in ground-truth units.
    pub max_correspondence_distance: f64,
    /// Pairs per sample.
    pub ransac_n: usize,
    /// Samples drawn and scored (all of them, as Open3D 0.9 did).
    pub max_iterations: u32,
    /// Seed of the sample stream.
    pub seed: u64,
    /// Above this many frames the trajectory is a video's, sampled through the mapping file.
    pub mapping_above_frames: usize,
}

impl From<&TrajectoryAlignmentOptions> for TrajectoryParams {
    fn from(o: &TrajectoryAlignmentOptions) -> Self {
        TrajectoryParams {
            max_correspondence_distance: o.max_correspondence_distance,
            ransac_n: o.ransac_n,
            max_iterations: o.max_iterations,
            seed: o.seed,
            mapping_above_frames: super::trajectory::MAPPING_ABOVE_FRAMES,
        }
    }
}

/// One refinement stage's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct StageParams {
    /// `"voxel"` (both clouds cropped and voxel down-sampled) or `"uniform"` (cropped, every
    /// k-th point kept above `max_points`).
    pub downsample: String,
    /// Voxel edge for `"voxel"`.
    pub voxel_size: Option<f64>,
    /// Point budget for `"uniform"`.
    pub max_points: Option<u64>,
    /// ICP correspondence distance.
    pub max_correspondence_distance: f64,
    /// Stop rule (Open3D's `ICPConvergenceCriteria` as the toolbox sets it).
    pub relative_fitness: f64,
    /// Stop rule.
    pub relative_rmse: f64,
    /// Stop rule.
    pub max_iterations: u32,
}

impl StageParams {
    pub(crate) fn new(
        downsample: &str,
        voxel_size: Option<f64>,
        max_points: Option<u64>,
        max_correspondence_distance: f64,
        c: IcpCriteria,
    ) -> StageParams {
        StageParams {
            downsample: downsample.into(),
            voxel_size,
            max_points,
            max_correspondence_distance,
            relative_fitness: c.relative_fitness,
            relative_rmse: c.relative_rmse,
            max_iterations: c.max_iterations,
        }
    }
}

/// The evaluation step's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct EvaluationParams {
    /// Both clouds are voxel down-sampled at this edge (τ/2) after the crop.
    pub voxel_size: f64,
    /// τ.
    pub threshold: f64,
    /// The curves run to `threshold · plot_stretch`.
    pub plot_stretch: f64,
    /// Curve bin width (τ/100).
    pub bin_width: f64,
    /// The coloured clouds saturate at this distance (3τ).
    pub color_max_distance: f64,
    /// Their colour map.
    pub colormap: String,
}

/// The inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct InputsSection {
    /// The reconstructed cloud.
    pub reconstruction: NamedCount,
    /// Its `.log` trajectory (absent when the final transform was given).
    pub trajectory: Option<TrajectoryInput>,
    /// The ground-truth cloud.
    pub ground_truth: NamedCount,
    /// The reference trajectory's frame count.
    pub reference_frames: usize,
    /// `<scene>_trans.txt`.
    pub gt_from_reference: Matrix4,
}

/// A file and its point count.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct NamedCount {
    /// As the front end named it.
    pub name: String,
    /// Points read.
    pub points: usize,
}

/// The reconstruction's trajectory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct TrajectoryInput {
    /// As the front end named it.
    pub name: String,
    /// Frames read.
    pub frames: usize,
    /// Frames whose metadata says the image was registered (second integer ≥ 0).
    pub registered: usize,
    /// Whether the mapping file picked the reference frames out of a video trajectory.
    pub mapped: bool,
}

/// How the reconstruction reached the ground-truth frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct RegistrationSection {
    /// `"protocol"` (trajectory alignment + three ICP refinements) or `"given"`.
    pub mode: String,
    /// The trajectory alignment's result.
    pub trajectory_alignment: Option<TrajectoryAlignment>,
    /// Each refinement's result.
    pub refinement: Vec<StageResult>,
    /// The transform the evaluation used.
    pub gt_from_recon: Matrix4,
}

/// One refinement's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct StageResult {
    /// Reconstruction points the ICP used (after crop and down-sampling).
    pub source_points: usize,
    /// Ground-truth points it used.
    pub target_points: usize,
    /// ICP updates made.
    pub iterations: u32,
    /// Matched share at the end.
    pub fitness: f64,
    /// RMSE of the matches at the end.
    pub inlier_rmse: f64,
    /// `gt_from_recon` after this stage.
    pub gt_from_recon: Matrix4,
}

impl StageResult {
    /// The result of a refinement whose ICP ran on `source_points` against `target_points` and
    /// left `gt_from_recon`.
    pub(crate) fn of_icp(
        source_points: usize,
        target_points: usize,
        icp: &IcpResult,
        gt_from_recon: Matrix4,
    ) -> StageResult {
        StageResult {
            source_points,
            target_points,
            iterations: icp.iterations,
            fitness: icp.fitness,
            inlier_rmse: icp.inlier_rmse,
            gt_from_recon,
        }
    }
}

/// One direction's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct SideSection {
    /// The share within τ.
    pub value: f64,
    /// Points inside the crop.
    pub cropped_points: usize,
    /// Points measured (after the τ/2 voxel down-sampling).
    pub points: usize,
    /// Mean distance of the measured points.
    pub mean_distance: f64,
    /// Median distance.
    pub median_distance: f64,
}

/// The cumulative curves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct CurvesSection {
    /// Bin edges.
    pub edges: Vec<f64>,
    /// Cumulative share of reconstruction points below each edge after the first.
    pub precision: Vec<f64>,
    /// Cumulative share of ground-truth points below each edge after the first.
    pub recall: Vec<f64>,
}

impl TntReport {
    /// The summary `sfmeval tnt` prints (without its last line, where the files went): the
    /// scene and τ, the trajectory alignment, each refinement, precision / recall / F-score and
    /// the notes, one line each.
    pub fn summary_lines(&self) -> Vec<String> {
        let r = self;
        let mut lines = vec![format!(
            "Tanks and Temples protocol, scene {} (τ = {} from the {})",
            r.protocol.scene, r.protocol.tau, r.protocol.tau_source
        )];
        if let Some(a) = &r.registration.trajectory_alignment {
            lines.push(format!(
                "trajectory alignment: {:.1} % of the cameras within {} (RMSE {:.4}), {} samples",
                100.0 * a.fitness,
                r.protocol
                    .trajectory_alignment
                    .as_ref()
                    .map_or(0.0, |t| t.max_correspondence_distance),
                a.inlier_rmse,
                a.iterations
            ));
        }
        for (i, st) in r.registration.refinement.iter().enumerate() {
            lines.push(format!(
                "refinement {}: {} → {} points, {} iteration(s), fitness {:.4}, RMSE {:.6}",
                i + 1,
                st.source_points,
                st.target_points,
                st.iterations,
                st.fitness,
                st.inlier_rmse
            ));
        }
        if r.registration.mode == "given" {
            lines.push("registration: the given transform".into());
        }
        lines.push(format!(
            "precision {:.4}  recall {:.4}  F-score {:.4}  ({} reconstruction / {} ground-truth points measured)",
            r.precision.value, r.recall.value, r.f_score, r.precision.points, r.recall.points
        ));
        for n in &r.notes {
            lines.push(format!("{}: {}", n.level.as_str(), n.message));
        }
        lines
    }

    /// [`Self::summary_lines`] as `sfmeval tnt` prints them: the first flush left, the others
    /// indented by two spaces.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        for (k, line) in self.summary_lines().iter().enumerate() {
            if k > 0 {
                s += "  ";
            }
            s += line;
            s.push('\n');
        }
        s
    }
}

/// The TypeScript declarations of [`TntReport`] and the types it holds but those the
/// `sfmeval.report/3` declarations hold (`Tool`, `Note` and its parts, imported from there),
/// generated by ts-rs, and the check that the npm package ships them
/// (`crates/sfmeval-wasm/js/tnt-report.d.ts`). `scripts/gen-report-types.sh` rewrites the file
/// (`SFMEVAL_WRITE_REPORT_TYPES=1`); without that variable the test fails when it is stale.
#[cfg(all(test, feature = "ts"))]
mod typescript {
    use sfmeval::note::Note;
    use sfmeval::report::Tool;
    use sfmeval::ts_declarations::{Declarations, check_committed};

    use super::TntReport;

    #[test]
    fn tnt_report_types_are_the_committed_ones() {
        let schema = "sfmeval.tanksandtemples/2";
        let shared = Declarations::new().add::<Note>().add::<Tool>();
        let text = Declarations::new().add::<TntReport>().file_text(
            schema,
            "crates/sfmeval-tnt",
            "TntReport",
            Some(&shared),
        );
        let file = "../sfmeval-wasm/js/tnt-report.d.ts";
        check_committed(env!("CARGO_MANIFEST_DIR"), file, schema, &text);
    }
}
