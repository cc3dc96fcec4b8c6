//! The pose protocols of a run (`sfmeval poses --protocol colmap|imc|co3d`, the core's
//! [`evaluate_protocol`] with its default options): the three `sfmeval.poses/1` reports of a
//! reconstruction's cameras against the dataset's, their files beside the evaluation's report
//! (`<report stem>.poses-<protocol>.json`, each what `sfmeval poses --json` prints) and the
//! numbers a row carries ([`RowPoses`], the wide table's [`crate::catalogue::WIDE_POSES`]).

use serde::{Deserialize, Serialize};
use sfmeval::files::FileSource;
use sfmeval::model::Reconstruction;
use sfmeval::pose::{
    Co3dResult, ColmapResult, ImcResult, PosesReport, Protocol, ProtocolOptions, ProtocolResult,
    evaluate_protocol,
};

/// The protocols' numbers of a run (their `result` sections, as `sfmeval poses` reports them).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RowPoses {
    /// COLMAP's reconstruction benchmark: AUC and recall at each threshold (percent).
    pub colmap: ColmapResult,
    /// The Image Matching Challenge's mAA.
    pub imc: ImcResult,
    /// CO3D's RRA / RTA at each threshold and AUC@30 (percent).
    pub co3d: Co3dResult,
}

/// The three protocols' reports of one reconstruction, in [`Protocol::ALL`]'s order.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseReports {
    /// `(protocol, report)` for colmap, imc, co3d.
    pub reports: Vec<(Protocol, PosesReport)>,
}

impl PoseReports {
    /// Every protocol of `est`'s cameras against `gt`'s, with the default options (what
    /// `sfmeval poses --protocol P` computes without other flags).
    pub fn evaluate(gt: &Reconstruction, est: &Reconstruction) -> sfmeval::Result<PoseReports> {
        let options = ProtocolOptions::default();
        let reports = Protocol::ALL
            .into_iter()
            .map(|p| Ok((p, evaluate_protocol(gt, est, p, &options)?)))
            .collect::<sfmeval::Result<_>>()?;
        Ok(PoseReports { reports })
    }

    /// Each report's file name beside the report `report_file` and its text, byte for byte what
    /// `sfmeval poses --protocol P --json` prints.
    pub fn files(&self, report_file: &str) -> Result<Vec<(String, String)>, serde_json::Error> {
        self.reports
            .iter()
            .map(|(p, r)| {
                let mut text = serde_json::to_string_pretty(r)?;
                text.push('\n');
                Ok((poses_file(report_file, *p), text))
            })
            .collect()
    }

    /// The numbers a row carries.
    pub fn row_poses(&self) -> Option<RowPoses> {
        let (mut colmap, mut imc, mut co3d) = (None, None, None);
        for (_, r) in &self.reports {
            match &r.result {
                ProtocolResult::Colmap(c) => colmap = Some(c.clone()),
                ProtocolResult::Imc(i) => imc = Some(i.clone()),
                ProtocolResult::Co3d(c) => co3d = Some(c.clone()),
            }
        }
        Some(RowPoses {
            colmap: colmap?,
            imc: imc?,
            co3d: co3d?,
        })
    }
}

/// The file of `protocol`'s report beside the evaluation report `report_file`
/// (`reports/ds/colmap.json` → `reports/ds/colmap.poses-imc.json`).
pub fn poses_file(report_file: &str, protocol: Protocol) -> String {
    let stem = report_file.strip_suffix(".json").unwrap_or(report_file);
    format!("{stem}.poses-{}.json", protocol.name())
}

/// The protocols' numbers of the files beside the report `report_file`, when all three are
/// there (none when one is missing: the run has no ground-truth cameras, or predates them);
/// an error names a file that is not an `sfmeval.poses/1` report of its protocol.
pub fn read_row_poses(
    source: &dyn FileSource,
    report_file: &str,
) -> sfmeval::Result<Option<RowPoses>> {
    let mut reports = Vec::new();
    for p in Protocol::ALL {
        let path = poses_file(report_file, p);
        let Some(bytes) = source.read(&path)? else {
            return Ok(None);
        };
        let report: PosesReport = serde_json::from_slice(&bytes)
            .ok()
            .filter(|r: &PosesReport| {
                r.schema == sfmeval::pose::POSES_SCHEMA && result_protocol(&r.result) == p
            })
            .ok_or_else(|| sfmeval::Error::InvalidContent(format!(
                "'{path}' is not an {} report of the {} protocol (sfmeval poses --protocol {} --json)",
                sfmeval::pose::POSES_SCHEMA,
                p.name(),
                p.name()
            )))?;
        reports.push((p, report));
    }
    Ok(PoseReports { reports }.row_poses())
}

fn result_protocol(r: &ProtocolResult) -> Protocol {
    match r {
        ProtocolResult::Colmap(_) => Protocol::Colmap,
        ProtocolResult::Imc(_) => Protocol::Imc,
        ProtocolResult::Co3d(_) => Protocol::Co3d,
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn files_sit_beside_the_report() {
        assert_eq!(
            poses_file("reports/ds/colmap.json", Protocol::Imc),
            "reports/ds/colmap.poses-imc.json"
        );
        assert_eq!(
            poses_file("run/report.json", Protocol::Co3d),
            "run/report.poses-co3d.json"
        );
    }
}
