//! The human summary printed on stdout.

use std::fmt::Write as _;

use sfmeval::pose::CamerasReport;
use sfmeval::report::Report;

fn g(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e5 {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

/// One statistics line: the same fields for every distance block, `extra` in parentheses.
fn stats_line(s: &mut String, label: &str, st: &sfmeval::stats::Statistics, extra: &str) {
    let _ = writeln!(
        s,
        "{label:<15} mean {}  median {}  rms {}  std {}  p90 {}  p99 {}  max {}  ({extra})",
        g(st.mean),
        g(st.median),
        g(st.rms),
        g(st.std),
        g(st.percentiles.p90),
        g(st.percentiles.p99),
        g(st.max)
    );
}

/// Formats the report for a person.
pub fn render(r: &Report) -> String {
    let mut s = String::new();
    let i = &r.inputs;
    let _ = writeln!(
        s,
        "sfmeval {}: {} vs {}",
        r.tool.version, i.reconstruction.name, i.ground_truth.name
    );
    let _ = writeln!(
        s,
        "ground truth    {} ({}), {} vertices, {} triangles, bbox diagonal {}",
        i.ground_truth.name,
        i.ground_truth.format,
        i.ground_truth.vertices,
        i.ground_truth.triangles,
        g(i.ground_truth.diagonal)
    );
    let _ = writeln!(
        s,
        "reconstruction  {} ({}), {} points",
        i.reconstruction.name, i.reconstruction.format, i.reconstruction.points
    );
    let c = &r.crop;
    let _ = writeln!(
        s,
        "crop            {}: kept {}, discarded {} (outside volume {}, farther than max distance {})",
        c.kind,
        c.kept,
        c.discarded,
        c.discarded_outside_volume,
        c.discarded_farther_than_max_distance
    );
    let a = &r.alignment;
    let _ = write!(s, "alignment       {} (scale {})", a.method, g(a.scale));
    if let Some(rmse) = a.rmse {
        let _ = write!(s, ", rmse {}", g(rmse));
    }
    s.push('\n');
    for (label, st, extra) in [
        (
            "accuracy",
            &r.accuracy.stats,
            format!("recon → GT, {}", r.accuracy.metric),
        ),
        (
            "completeness",
            &r.completeness.stats,
            format!("GT → recon, {} samples", r.completeness.samples),
        ),
    ] {
        stats_line(&mut s, label, st, &extra);
    }
    if let Some(sg) = &r.accuracy.signed {
        let _ = writeln!(
            s,
            "signed accuracy mean {}  std {}  min {}  max {}",
            g(sg.mean),
            g(sg.std),
            g(sg.min),
            g(sg.max)
        );
    }
    let _ = writeln!(
        s,
        "{:>14} {:>10} {:>10} {:>10} {:>10}",
        "tau", "% diag", "precision", "recall", "F-score"
    );
    for t in &r.thresholds {
        let _ = writeln!(
            s,
            "{:>14} {:>10.3} {:>10.4} {:>10.4} {:>10.4}",
            g(t.tau),
            t.tau_percent_of_diagonal,
            t.precision,
            t.recall,
            t.f_score
        );
    }
    if let Some(v) = &r.completeness_visible {
        let _ = writeln!(
            s,
            "visible surface {:.2} % of the samples seen in ≥ {} of {} images ({} of {}){}",
            v.visible_fraction * 100.0,
            v.min_views,
            v.views,
            v.visible_samples,
            v.samples,
            v.visible_area
                .map(|a| format!(", area {}", g(a)))
                .unwrap_or_default()
        );
        stats_line(&mut s, "compl. visible", &v.stats, "GT visible → recon");
        let _ = writeln!(
            s,
            "{:>14} {:>10} {:>14} {:>14}",
            "tau", "recall", "recall visible", "F visible"
        );
        for t in &v.thresholds {
            let _ = writeln!(
                s,
                "{:>14} {:>10.4} {:>14.4} {:>14.4}",
                g(t.tau),
                t.recall,
                t.recall_visible,
                t.f_score_visible
            );
        }
    }
    if let Some(t) = &r.track_error {
        stats_line(
            &mut s,
            "track error",
            &t.stats,
            &format!(
                "{} of {} points measured; their surface distance: mean {}, median {}",
                t.measured,
                t.points,
                g(t.surface_distance.mean),
                g(t.surface_distance.median)
            ),
        );
        let _ = writeln!(
            s,
            "observations    {} used of {} ({} trimmed; rejected: {} unmatched image, {} outside, {} silhouette, {} depth step; {})",
            t.observations_used,
            t.observations,
            t.observations_trimmed,
            t.rejected_unmatched_image,
            t.rejected_outside_image,
            t.rejected_background,
            t.rejected_discontinuity,
            t.observation_convention
        );
        let _ = writeln!(
            s,
            "{:>14} {:>10} {:>16}",
            "tau", "sliding", "true err < tau"
        );
        for th in &t.thresholds {
            let _ = writeln!(
                s,
                "{:>14} {:>10.4} {:>16.4}",
                g(th.tau),
                th.sliding_fraction,
                th.true_error_below
            );
        }
    }
    if let Some(c) = &r.cameras {
        s.push_str(&render_cameras(
            &c.errors,
            &c.alignment.stage,
            c.alignment.scale,
        ));
    }
    for n in &r.notes {
        let _ = writeln!(s, "{}: {}", n.level.as_str(), n.message);
    }
    s
}

/// Formats camera-pose errors measured after the alignment `stage` of scale `scale` for a
/// person (the `cameras` section of `eval`, and `sfmeval cameras`).
pub fn render_cameras(c: &CamerasReport, stage: &str, scale: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "cameras         {} ground truth, {} registered, {} matched, {} model(s)",
        c.ground_truth, c.registered, c.matched, c.models
    );
    let focal: Vec<String> = c
        .focal
        .iter()
        .map(|f| format!("{:.3}", f.error_percent))
        .collect();
    let _ = writeln!(
        s,
        "pose alignment  {stage} (scale {}); focal error {} %",
        g(scale),
        focal.join(", ")
    );
    let _ = writeln!(
        s,
        "rotation error  mean {}°  median {}°  max {}°",
        g(c.rotation_error_deg.mean),
        g(c.rotation_error_deg.median),
        g(c.rotation_error_deg.max)
    );
    let _ = writeln!(
        s,
        "centre error    mean {}  median {}  max {}  (ATE RMSE {}, mean {} % of scene radius)",
        g(c.center_error.mean),
        g(c.center_error.median),
        g(c.center_error.max),
        g(c.ate_rmse),
        g(c.center_error_percent.mean)
    );
    for n in &c.notes {
        let _ = writeln!(s, "{}: {}", n.level.as_str(), n.message);
    }
    s
}
