//! The human summary printed on stdout.

use std::fmt::Write as _;

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
            t.tau_relative_to_diagonal * 100.0,
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
        let v = serde_json::json!({"cameras": c, "alignment": r.alignment});
        s.push_str(&render_cameras(&v));
    }
    for w in &r.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}

/// Formats the `sfmeval cameras` result (alignment + cameras sections) for a person.
pub fn render_cameras(v: &serde_json::Value) -> String {
    let mut s = String::new();
    let num = |p: &str| v.pointer(p).and_then(|x| x.as_f64()).unwrap_or(f64::NAN);
    let _ = writeln!(
        s,
        "cameras         {} ground truth, {} registered, {} matched, {} model(s)",
        num("/cameras/ground_truth"),
        num("/cameras/registered"),
        num("/cameras/matched"),
        num("/cameras/models")
    );
    let _ = writeln!(
        s,
        "pose alignment  {} (scale {}); focal error {} %",
        v.pointer("/cameras/alignment/stage")
            .or_else(|| v.pointer("/alignment/method"))
            .and_then(|m| m.as_str())
            .unwrap_or("?"),
        g(v.pointer("/cameras/alignment/scale")
            .and_then(|x| x.as_f64())
            .unwrap_or(num("/alignment/scale"))),
        v.pointer("/cameras/focal")
            .and_then(|f| f.as_array())
            .map(|f| f
                .iter()
                .filter_map(|c| c.get("error_percent").and_then(|e| e.as_f64()))
                .map(|e| format!("{e:.3}"))
                .collect::<Vec<_>>()
                .join(", "))
            .unwrap_or_default()
    );
    let _ = writeln!(
        s,
        "rotation error  mean {}°  median {}°  max {}°",
        g(num("/cameras/rotation_error_deg/mean")),
        g(num("/cameras/rotation_error_deg/median")),
        g(num("/cameras/rotation_error_deg/max"))
    );
    let _ = writeln!(
        s,
        "centre error    mean {}  median {}  max {}  (ATE RMSE {}, mean {} % of scene radius)",
        g(num("/cameras/center_error/mean")),
        g(num("/cameras/center_error/median")),
        g(num("/cameras/center_error/max")),
        g(num("/cameras/ate_rmse")),
        g(num("/cameras/center_error_percent/mean"))
    );
    if let Some(w) = v.pointer("/cameras/warnings").and_then(|w| w.as_array()) {
        for w in w.iter().filter_map(|w| w.as_str()) {
            let _ = writeln!(s, "warning: {w}");
        }
    }
    s
}
