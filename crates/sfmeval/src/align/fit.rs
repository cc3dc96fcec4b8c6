//! The verdict on the final alignment stage's fit, decided once here for every front end: few
//! points inside the stage's distance gate, or a stage that stopped before settling with a
//! tight or a loose fit. The thresholds travel in the notes' values.

use super::{Alignment, StageKind};
use crate::note::{Code, Note};

/// Below this share of the points inside the final stage's distance gate, the fit is doubtful.
pub(crate) const MIN_INLIER_RATIO: f64 = 0.5;
/// An rmse of at most this percentage of the ground-truth diagonal is a tight fit.
pub(crate) const TIGHT_RMSE_PERCENT_OF_DIAGONAL: f64 = 0.5;

/// The notes on the fit of the last stage of `alignment` when it is a search against the
/// surface (`icp` or `global`) and was not rejected; `diagonal` is the ground truth's
/// bounding-box diagonal.
pub(crate) fn fit_verdict(alignment: &Alignment, diagonal: f64) -> Vec<Note> {
    let Some(last) = alignment.stages.last() else {
        return Vec::new();
    };
    let rejected = last.notes.iter().any(|n| n.code == Code::IcpRejected);
    let name = match last.kind {
        StageKind::Icp => "ICP",
        StageKind::Global => "the global search",
        _ => return Vec::new(),
    };
    if rejected {
        return Vec::new();
    }
    let ratio = last.inlier_ratio;
    let rmse_percent = match last.rmse {
        Some(r) if diagonal > 0.0 => Some(100.0 * r / diagonal),
        _ => None,
    };
    let with_fit = |mut n: Note| {
        n = n
            .with("stage", last.kind.name())
            .with("iterations", last.iterations)
            .with_number("min_inlier_ratio", MIN_INLIER_RATIO)
            .with_number(
                "tight_rmse_percent_of_diagonal",
                TIGHT_RMSE_PERCENT_OF_DIAGONAL,
            );
        if let Some(r) = last.rmse {
            n = n.with_number("rmse", r);
        }
        if let Some(p) = rmse_percent {
            n = n.with_number("rmse_percent_of_diagonal", p);
        }
        if let Some(r) = ratio {
            n = n.with_number("inlier_ratio", r);
        }
        n
    };
    let fit = {
        let mut s = format!("rmse {}", last.rmse.map_or("—".into(), short));
        if let Some(p) = rmse_percent {
            s.push_str(&format!(" = {} % of the diagonal", precision2(p)));
        }
        if let Some(r) = ratio {
            s.push_str(&format!(
                ", {:.0} % of the points within its distance gate",
                100.0 * r
            ));
        }
        s
    };
    let mut notes = Vec::new();
    let few = ratio.is_some_and(|r| r < MIN_INLIER_RATIO);
    if let (true, Some(r)) = (few, ratio) {
        notes.push(with_fit(Note::new(
            Code::FewInliers,
            format!(
                "{name} fitted only {:.0} % of the reconstruction's points: the others lie outside its distance gate of the ground truth (background, outliers, or part of the cloud misaligned); check the view",
                100.0 * r
            ),
        )));
    }
    if !last.converged {
        let tight = !few
            && ratio.is_some()
            && rmse_percent.is_some_and(|p| p <= TIGHT_RMSE_PERCENT_OF_DIAGONAL);
        notes.push(with_fit(if tight {
            Note::new(
                Code::UnsettledTightFit,
                format!(
                    "{name} stopped after {} iterations before its steps fell below the stopping tolerance; its fit is tight ({fit}), so this is unlikely to matter",
                    last.iterations
                ),
            )
        } else {
            Note::new(
                Code::UnsettledLooseFit,
                format!(
                    "{name} stopped after {} iterations without settling, and its fit is loose ({fit}): the transform may be imprecise; check the points against the ground truth in the viewer",
                    last.iterations
                ),
            )
        }));
    }
    notes
}

/// A length with 4 significant digits (`1.235e-3` style below 0.01).
fn short(v: f64) -> String {
    if v != 0.0 && (v.abs() < 0.01 || v.abs() >= 1e5) {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// Two significant digits, as a percentage is read.
fn precision2(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (1 - libm::floor(libm::log10(v.abs())) as i32).max(0) as usize;
    format!("{v:.digits$}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::align::{AlignMode, AlignStage};
    use crate::transform::Similarity;

    fn report(kind: StageKind, rmse: f64, ratio: f64, converged: bool) -> Alignment {
        Alignment {
            gt_from_recon: Similarity::IDENTITY,
            stages: vec![AlignStage {
                kind,
                gt_from_recon: Similarity::IDENTITY,
                rmse: Some(rmse),
                inlier_ratio: Some(ratio),
                iterations: 100,
                converged,
                notes: Vec::new(),
            }],
            requested: AlignMode::Auto,
        }
    }

    fn codes(notes: &[Note]) -> Vec<Code> {
        notes.iter().map(|n| n.code).collect()
    }

    #[test]
    fn verdicts_follow_the_thresholds() {
        // diagonal 10: the tight limit is an rmse of 0.05
        assert!(fit_verdict(&report(StageKind::Icp, 0.2, 0.9, true), 10.0).is_empty());
        assert_eq!(
            codes(&fit_verdict(
                &report(StageKind::Icp, 0.05, 0.5, false),
                10.0
            )),
            [Code::UnsettledTightFit]
        );
        assert_eq!(
            codes(&fit_verdict(
                &report(StageKind::Icp, 0.0501, 0.9, false),
                10.0
            )),
            [Code::UnsettledLooseFit]
        );
        let few = fit_verdict(&report(StageKind::Global, 0.01, 0.49, false), 10.0);
        assert_eq!(codes(&few), [Code::FewInliers, Code::UnsettledLooseFit]);
        assert_eq!(few[0].values["min_inlier_ratio"], 0.5);
        assert_eq!(few[0].values["inlier_ratio"], 0.49);
        assert_eq!(few[0].values["stage"], "global");
        assert!(few[0].message.contains("49 %"), "{}", few[0].message);
        // camera and given stages have no surface fit
        assert!(fit_verdict(&report(StageKind::Cameras, 1.0, 0.1, false), 10.0).is_empty());
    }

    #[test]
    fn a_rejected_refinement_has_no_verdict() {
        let mut r = report(StageKind::Icp, 1.0, 0.1, false);
        r.stages[0]
            .notes
            .push(Note::new(Code::IcpRejected, "rejected"));
        assert!(fit_verdict(&r, 10.0).is_empty());
    }

    #[test]
    fn percentages_read_with_two_digits() {
        assert_eq!(precision2(0.4567), "0.46");
        assert_eq!(precision2(3.0), "3.0");
        assert_eq!(precision2(12.3), "12");
    }
}
