//! `sfmeval-runner sweep`: where does each pipeline break? Varies one condition of a
//! generated dataset (number of views, baseline, focal length, texture strength, lighting,
//! image noise or blur), renders one variant per value with the Blender generator, runs the
//! pipelines on every variant (the `run` machinery: resumable, failures recorded), evaluates
//! them (the `report` machinery) and plots each metric against the factor, one line per
//! pipeline: `sweep.csv`, `sweep.html` and `charts/<metric>.svg`. The batch is planned by
//! [`crate::batch::plan::Plan::sweep`] and run by either executor.
//!
//! The steps, one module each: [`factor`] (`--factor` parsing), [`overrides`] (a value as
//! generator overrides), [`variants`] (planning and rendering), [`cells`] (a cell per value
//! and pipeline), [`metrics`] (what is plotted), [`table`] (`sweep.csv`), [`charts`] and
//! [`page`] (`sweep.html`).

pub mod cells;
pub mod charts;
pub mod factor;
pub mod metrics;
pub mod overrides;
pub mod page;
pub mod table;
pub mod variants;

use std::path::Path;
use std::time::Instant;

use anyhow::Result;

use sfmeval_fs::write_atomic;

use crate::args::SweepArgs;
use crate::chart::line;
use crate::exec::shell_quote;
use crate::generator::resolved_config;
use crate::report::{ReportArgs, report};
use crate::summary::{Executor, TaskWithoutResult, unix_now};
use crate::sweep::factor::{Factor, parse_factor};
use crate::sweep::metrics::metric_file;
use sfmeval_table::Row;

/// A sweep before anything is rendered: its factor and values, the base dataset's generator
/// arguments and each value's variant (every value checked first: a bad one stops the sweep
/// before anything is rendered).
pub struct SweepPlan {
    /// The factor.
    pub factor: Factor,
    /// Its values, as given and as numbers.
    pub values: Vec<(String, f64)>,
    /// The base dataset's generator arguments.
    pub base_args: Vec<String>,
    /// One variant per value.
    pub planned: Vec<variants::Planned>,
}

impl SweepPlan {
    /// Plans the sweep of `a` with the generator (`python`, `scripts`), which resolves the
    /// base config.
    pub fn new(a: &SweepArgs, python: &Path, scripts: &Path) -> Result<SweepPlan> {
        let (factor, values) = parse_factor(&a.factor)?;
        // base: preset/config, no masks, depth maps only with --visibility, the user's --set
        let base_args = variants::base_args(
            a.dataset_preset.as_deref(),
            a.dataset_config.as_deref(),
            a.visibility,
            &a.generator.sets,
        )?;
        let base = resolved_config(python, scripts, &base_args)?;
        let planned = variants::plan(factor, &values, &base)?;
        Ok(SweepPlan {
            factor,
            values,
            base_args,
            planned,
        })
    }
}

/// How a sweep's runs were executed, for `sweep.json`.
pub struct Execution {
    /// Where.
    pub executor: Executor,
    /// The Slurm tasks that left no result (none locally).
    pub tasks_without_result: Vec<TaskWithoutResult>,
    /// The times measured before the report (`datasets_seconds`, `runs_seconds`).
    pub timing: serde_json::Value,
}

/// After the runs: evaluates them (unless no variant rendered) and writes `table/`,
/// `sweep.csv`, `charts/`, `sweep.html` and `sweep.json` (where it ran, the Slurm tasks
/// without result, `timing` plus the report's and the
/// total seconds since `t0`).
pub fn write_results(
    a: &SweepArgs,
    plan: &SweepPlan,
    variants: &[variants::Variant],
    pipes: &[String],
    out: &Path,
    started_unix: f64,
    execution: Execution,
) -> Result<()> {
    let Execution {
        executor,
        tasks_without_result: without_result,
        timing,
    } = execution;
    let (factor, values) = (plan.factor, &plan.values);
    let runs = out.join("runs");
    let table_dir = out.join("table");
    let t_rep = Instant::now();
    let rendered = variants.iter().any(|v| v.status != "failed");
    let rows: Vec<Row> = if !rendered {
        Vec::new()
    } else {
        report(&ReportArgs {
            runs: vec![runs.clone()],
            out: table_dir.clone(),
            datasets: Vec::new(),
            eval: a.eval.eval_options()?,
            align: a.eval.align_request()?,
            verbose: true,
        })?
    };
    let report_seconds = t_rep.elapsed().as_secs_f64();
    // cells
    let cells = cells::collect(&plan.planned, variants, pipes, &rows, &table_dir);
    let metrics = metrics::metrics(&a.metrics, &cells);
    write_atomic(
        &out.join("sweep.csv"),
        table::csv(factor, &cells, &metrics).as_bytes(),
    )?;
    let charts = charts::charts(factor, values, pipes, &cells, &metrics);
    let mut files = Vec::new();
    for (c, m) in charts.iter().zip(&metrics) {
        let f = format!("charts/{}.svg", metric_file(&m.path));
        write_atomic(&out.join(&f), line::svg(c).as_bytes())?;
        files.push(f);
    }
    let command = std::env::args()
        .map(|s| shell_quote(&s))
        .collect::<Vec<_>>()
        .join(" ");
    write_atomic(
        &out.join("sweep.html"),
        page::page(factor, &command, variants, pipes, &charts, &files).as_bytes(),
    )?;
    let total = unix_now() - started_unix;
    let mut timing = timing;
    if let Some(t) = timing.as_object_mut() {
        t.insert("report_seconds".into(), report_seconds.into());
        t.insert("total_seconds".into(), total.into());
    }
    let doc = serde_json::json!({
        "schema": "sfmeval.sweep/1",
        "factor": factor.name(),
        "definition": factor.description(),
        "values": values.iter().map(|v| v.0.clone()).collect::<Vec<_>>(),
        "base_generator_args": plan.base_args,
        "variants": variants,
        "pipelines": pipes,
        "executor": executor,
        "tasks_without_result": without_result,
        "metrics": metrics.iter().map(|m| serde_json::json!({"path": m.path, "label": m.label, "chart": metric_file(&m.path) + ".svg"})).collect::<Vec<_>>(),
        "command": command,
        "timing": timing,
    });
    let mut json = serde_json::to_string_pretty(&doc)?;
    json.push('\n');
    write_atomic(&out.join("sweep.json"), json.as_bytes())?;
    let ok = cells.iter().filter(|c| c.status == "ok").count();
    eprintln!(
        "sweep: {} value(s) × {} pipeline(s), {ok} ok; report {report_seconds:.0} s, total {total:.0} s → {}/{{sweep.csv,sweep.html,sweep.json,charts/}}",
        values.len(),
        pipes.len(),
        out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use serde_json::{Value as Json, json};

    use crate::chart::value::Value;
    use crate::sweep::cells::Cell;
    use crate::sweep::charts::charts;
    use crate::sweep::factor::Factor;
    use crate::sweep::metrics::Metric;
    use crate::sweep::table::csv;

    #[test]
    fn csv_and_charts_keep_failures() {
        let doc = json!({"report": {"accuracy": {"mean": 0.5}}, "run": {"wall_seconds": 3.0}});
        let mk = |v: &str, x: f64, p: &str, st: &str, d: Json| Cell {
            value: (v.into(), x),
            dataset: format!("noise-{v}"),
            pipeline: p.into(),
            status: st.into(),
            reason: (st != "ok").then(|| "exit 1, \"boom\"".to_string()),
            doc: d,
        };
        let cells = vec![
            mk("0", 0.0, "a", "ok", doc.clone()),
            mk("0", 0.0, "b", "failed", Json::Null),
            mk("4", 4.0, "a", "ok", doc),
        ];
        let metrics = vec![Metric {
            path: "report.accuracy.mean".into(),
            label: "mean".into(),
        }];
        let s = csv(Factor::Noise, &cells, &metrics);
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(
            lines[0],
            "factor,value,dataset,pipeline,status,reason,report.accuracy.mean"
        );
        assert_eq!(lines[1], "noise,0,noise-0,a,ok,,0.5");
        assert_eq!(
            lines[2],
            "noise,0,noise-0,b,failed,\"exit 1, \"\"boom\"\"\","
        );
        let values = vec![("0".to_string(), 0.0), ("4".to_string(), 4.0)];
        let ch = charts(
            Factor::Noise,
            &values,
            &["a".into(), "b".into()],
            &cells,
            &metrics,
        );
        assert_eq!(ch.len(), 1);
        let b = &ch[0].series[1].points;
        assert!(matches!(&b[0].1, Value::Failed(r) if r.starts_with("failed: exit 1")));
        assert!(matches!(&b[1].1, Value::Failed(r) if r == "not run"));
        assert_eq!(ch[0].series[0].points[1].1, Value::Ok(0.5));
    }
}
