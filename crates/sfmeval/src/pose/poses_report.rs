//! One protocol's report (`sfmeval.poses/1`): the pairing shared by every protocol
//! ([`super::protocol`]), then the protocol's own numbers ([`super::colmap_benchmark`],
//! [`super::imc`], [`super::co3d`]), with the convention each names.

use serde::{Deserialize, Serialize};

use super::protocol::{Convention, PairRow, Protocol, ProtocolOptions, pair_poses};
use super::{co3d, colmap_benchmark, imc};
use crate::error::{Error, Result};
use crate::model::Reconstruction;
use crate::note::Note;

/// The schema name of a poses report.
pub const POSES_SCHEMA: &str = "sfmeval.poses/1";

/// The result of one protocol.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "protocol", rename_all = "lowercase")]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub enum ProtocolResult {
    /// COLMAP's reconstruction benchmark.
    Colmap(colmap_benchmark::ColmapResult),
    /// Image Matching Challenge mAA.
    Imc(imc::ImcResult),
    /// CO3D RRA / RTA / AUC.
    Co3d(co3d::Co3dResult),
}

/// A poses report (`sfmeval.poses/1`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct PosesReport {
    /// `sfmeval.poses/1`.
    #[cfg_attr(feature = "ts", ts(type = "\"sfmeval.poses/1\""))]
    pub schema: String,
    /// Ground-truth images.
    pub ground_truth: usize,
    /// Registered images of the (largest) estimated model.
    pub registered: usize,
    /// Registered images matched to a ground-truth image by name.
    pub matched: usize,
    /// Registered images whose name matches no ground-truth image.
    pub unmatched_estimated: usize,
    /// Estimated poses that are NaN or infinite.
    pub non_finite: usize,
    /// Separate models the SfM tool produced (the largest is evaluated).
    pub models: usize,
    /// The protocol's convention.
    pub convention: Convention,
    /// The protocol's numbers.
    pub result: ProtocolResult,
    /// Problems worth a line.
    pub notes: Vec<Note>,
    /// Every scored ground-truth pair, in the protocol's order (not serialized).
    #[serde(skip)]
    #[cfg_attr(feature = "ts", ts(skip))]
    pub pair_rows: Vec<PairRow>,
}

impl PosesReport {
    /// The report as `sfmeval poses --json` prints and `--report` writes it: pretty JSON and a
    /// final newline (the npm package's `evaluatePoses` returns the same bytes).
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }

    /// [`Self::pair_rows`] as CSV (`i` and `j` as ground-truth image names), numbers in Rust's
    /// shortest round-trip form.
    pub fn pairs_csv(&self, gt: &Reconstruction) -> String {
        let name = |k: usize| gt.images.get(k).map(|i| i.name.as_str()).unwrap_or("");
        let mut s = String::from(
            "image_i,image_j,registered,rotation_error_deg,translation_error_deg,error_deg\n",
        );
        for r in &self.pair_rows {
            s.push_str(&format!(
                "{},{},{},{},{},{}\n",
                name(r.i),
                name(r.j),
                u8::from(r.registered),
                r.rotation_deg,
                r.translation_deg,
                r.error_deg
            ));
        }
        s
    }
}

/// One protocol's numbers for `est` against `gt` (see the module docs).
///
/// Errors: [`Error::Empty`] when the ground truth has no images or no estimated image matches a
/// ground-truth name; [`Error::NonFinite`] for a non-finite ground-truth pose;
/// [`Error::InvalidOption`] for thresholds that are not positive and finite.
pub fn evaluate_protocol(
    gt: &Reconstruction,
    est: &Reconstruction,
    protocol: Protocol,
    options: &ProtocolOptions,
) -> Result<PosesReport> {
    let positive = |v: &[f64], what: &str| -> Result<()> {
        if v.is_empty() || v.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
            return Err(Error::InvalidOption(format!(
                "{what} must be positive and finite, got {v:?}"
            )));
        }
        Ok(())
    };
    positive(&options.colmap_thresholds_deg, "COLMAP thresholds")?;
    positive(&options.co3d_thresholds_deg, "CO3D thresholds")?;
    if !(options.co3d_auc_max_deg.is_finite() && options.co3d_auc_max_deg >= 1.0) {
        return Err(Error::InvalidOption(format!(
            "the CO3D AUC's largest threshold must be at least 1 degree, got {}",
            options.co3d_auc_max_deg
        )));
    }
    let pa = options.colmap_position_accuracy;
    if !(pa.is_finite() && pa >= 0.0) {
        return Err(Error::InvalidOption(format!(
            "the position accuracy must be finite and not negative, got {pa}"
        )));
    }
    let mut notes = Vec::new();
    let (paired, matched) = pair_poses(gt, est, &mut notes)?;
    let mut pair_rows = Vec::new();
    let (convention, result) = match protocol {
        Protocol::Colmap => {
            let (c, r) = colmap_benchmark::evaluate(&paired, options, &mut pair_rows);
            (c, ProtocolResult::Colmap(r))
        }
        Protocol::Imc => {
            let (c, r) = imc::evaluate(&paired, &mut pair_rows);
            (c, ProtocolResult::Imc(r))
        }
        Protocol::Co3d => {
            let (c, r) = co3d::evaluate(&paired, options, &mut pair_rows);
            (c, ProtocolResult::Co3d(r))
        }
    };
    Ok(PosesReport {
        schema: POSES_SCHEMA.into(),
        ground_truth: gt.images.len(),
        registered: est.images.len(),
        matched,
        unmatched_estimated: paired.outliers,
        non_finite: paired.non_finite,
        models: est.num_models(),
        convention,
        result,
        notes,
        pair_rows,
    })
}

/// The TypeScript declarations of [`PosesReport`] and the types it holds but `Note` and its
/// parts, which the `sfmeval.report/3` declarations hold and which are imported from there,
/// generated by ts-rs, and the check that the npm package ships them
/// (`crates/sfmeval-wasm/js/poses-report.d.ts`). `scripts/gen-report-types.sh` rewrites the file
/// (`SFMEVAL_WRITE_REPORT_TYPES=1`); without that variable the test fails when it is stale.
#[cfg(all(test, feature = "ts"))]
mod typescript {
    use super::{POSES_SCHEMA, PosesReport};
    use crate::note::Note;
    use crate::pose::SummaryRow;
    use crate::ts_declarations::{Declarations, check_committed};

    #[test]
    fn poses_report_types_are_the_committed_ones() {
        let shared = Declarations::new().add::<Note>();
        let text = Declarations::new()
            .add::<PosesReport>()
            .add::<SummaryRow>()
            .file_text(POSES_SCHEMA, "crates/sfmeval", "PosesReport", Some(&shared));
        let file = "../sfmeval-wasm/js/poses-report.d.ts";
        check_committed(env!("CARGO_MANIFEST_DIR"), file, POSES_SCHEMA, &text);
    }
}
