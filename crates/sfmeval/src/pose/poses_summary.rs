//! The person's summary of a poses report (`sfmeval poses` without `--json`, the page's table):
//! one row per line, a label and its text, with the protocol's numbers and its convention in
//! words. The CLI prints [`PosesReport::summary`]; the page shows [`PosesReport::summary_rows`].

use serde::Serialize;

use super::poses_report::{PosesReport, ProtocolResult};
use super::protocol::{PairError, TranslationSign};

/// One line of the summary: a label (`AUC`, `mAA@5`, `convention`, ...) and its text.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct SummaryRow {
    /// What the line is about.
    pub label: String,
    /// The numbers or words, units included.
    pub text: String,
}

/// A number as the summaries print it: 0, six decimals between 1e-3 and 1e5, else scientific.
fn g(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e5 {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

/// Numbers joined by ` / `.
fn list(v: &[f64]) -> String {
    v.iter().map(|x| g(*x)).collect::<Vec<_>>().join(" / ")
}

impl PosesReport {
    /// The summary's lines: counts, the protocol's pairs and numbers (per-threshold lists in
    /// the thresholds' order), the convention, then each note as `level: message`.
    pub fn summary_rows(&self) -> Vec<SummaryRow> {
        let mut rows = Vec::new();
        let mut row = |label: &str, text: String| {
            rows.push(SummaryRow {
                label: label.to_string(),
                text,
            });
        };
        row(
            "cameras",
            format!(
                "{} ground truth, {} registered, {} matched, {} model(s)",
                self.ground_truth, self.registered, self.matched, self.models
            ),
        );
        match &self.result {
            ProtocolResult::Colmap(r) => {
                row(
                    "protocol",
                    format!(
                        "colmap: {} ordered pairs ({} with an unregistered image, {} outside the ground truth)",
                        r.pairs, r.pairs_unregistered, r.pairs_outside_gt
                    ),
                );
                row("thresholds", format!("{} °", list(&r.thresholds_deg)));
                row("AUC", format!("{} %", list(&r.auc_percent)));
                row("recall", format!("{} %", list(&r.recall_percent)));
            }
            ProtocolResult::Imc(r) => {
                row(
                    "protocol",
                    format!(
                        "imc: {} pairs ({} with an unregistered image){}",
                        r.pairs,
                        r.pairs_unregistered,
                        if r.model_valid {
                            ""
                        } else {
                            ", model invalid (a non-finite pose)"
                        }
                    ),
                );
                row("mAA@5", g(r.maa_5));
                row("mAA@10", g(r.maa_10));
            }
            ProtocolResult::Co3d(r) => {
                row(
                    "protocol",
                    format!(
                        "co3d: {} pairs ({} with an unregistered image)",
                        r.pairs, r.pairs_unregistered
                    ),
                );
                row("thresholds", format!("{} °", list(&r.thresholds_deg)));
                row("RRA", format!("{} %", list(&r.rra_percent)));
                row("RTA", format!("{} %", list(&r.rta_percent)));
                row(
                    &format!("AUC@{}", r.auc_max_deg),
                    format!("{} %", g(r.auc_percent)),
                );
            }
        }
        let c = &self.convention;
        let pair_error = match c.pair_error {
            PairError::Max => "max(rotation, translation)",
            PairError::SeparateAccuraciesMaxAuc => {
                "RRA/RTA each error alone, AUC max(rotation, translation)"
            }
        };
        let sign = match c.translation_sign {
            TranslationSign::Signed => "signed",
            TranslationSign::Folded => "sign folded",
        };
        row(
            "convention",
            format!("{pair_error}; translation direction {sign}"),
        );
        row("unregistered", c.unregistered.clone());
        for n in &self.notes {
            row(n.level.as_str(), n.message.clone());
        }
        rows
    }

    /// The summary `sfmeval poses` prints: [`Self::summary_rows`], the label padded to 15
    /// columns (a note as `level: message`), one line each.
    pub fn summary(&self) -> String {
        let notes = self.notes.len();
        let rows = self.summary_rows();
        let numbers = rows.len() - notes;
        let mut s = String::new();
        for (k, r) in rows.iter().enumerate() {
            if k < numbers {
                s += &format!("{:<15} {}\n", r.label, r.text);
            } else {
                s += &format!("{}: {}\n", r.label, r.text);
            }
        }
        s
    }
}
