//! `sfmeval table`: Table I and the wide comparison table of reports made anywhere (the Blender
//! panel, a script), in exactly the text `sfmeval-runner report` writes for its runs
//! (`sfmeval-table` builds both).

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use clap::{Args, ValueEnum};
use sfmeval::report::Report;
use sfmeval_fs::{Disk, named, path_str, pipeline_and_path, read, write_atomic};
use sfmeval_table::{Row, failed_row, read_row_poses, report_row, summary_json, tables};

/// `sfmeval table`'s flags.
#[derive(Args, Debug)]
pub struct TableArgs {
    /// Evaluation reports (`sfmeval eval --report`), each `PIPELINE=REPORT.json` or a path whose
    /// parent folder names the pipeline (`compare/colmap/report.json` → `colmap`). The pose
    /// protocols' reports beside one (`REPORT.poses-colmap.json`, `-imc`, `-co3d`: `sfmeval poses
    /// --protocol P --report ...`), when all three are there, add its pose columns.
    #[arg(value_name = "[PIPELINE=]REPORT", required = true)]
    reports: Vec<String>,
    /// The dataset's name in the tables (default: the ground truth's file name, without its
    /// extension, of the first report).
    #[arg(long, value_name = "NAME")]
    dataset: Option<String>,
    /// A pipeline without a report, shown as failed with this reason (repeatable).
    #[arg(long, value_name = "PIPELINE=REASON")]
    failed: Vec<String>,
    /// What to print: Table I as Markdown or CSV, both tables (`table.md`), the wide table as
    /// CSV (`runs.csv`), or the rows as JSON (`summary.json`).
    #[arg(long, value_enum, default_value_t = TableFormat::Md)]
    format: TableFormat,
    /// Also write every table file into this folder (`table1.md`, `table1.csv`, `table.md`,
    /// `runs.csv`, `summary.json`), as `sfmeval-runner report` names them.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// The printed table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum TableFormat {
    /// `table1.md`.
    Md,
    /// `table1.csv`.
    Csv,
    /// `table.md`: Table I and the wide table.
    Wide,
    /// `runs.csv`.
    WideCsv,
    /// `summary.json`.
    Json,
}

fn read_report(path: &Path) -> Result<Report> {
    let text = read(path)?;
    let text = std::str::from_utf8(&text)
        .with_context(|| format!("report '{}' is not UTF-8 text", path.display()))?;
    serde_json::from_str(text).with_context(|| {
        format!(
            "'{}' is not an sfmeval.report/3 (sfmeval eval --report) file",
            path.display()
        )
    })
}

/// The rows of the arguments, in argument order (the tables order them themselves).
fn rows(args: &TableArgs) -> Result<Vec<Row>> {
    let mut reports = Vec::new();
    for arg in &args.reports {
        let (pipeline, path) = pipeline_and_path(arg)?;
        let report = read_report(&path)?;
        reports.push((pipeline, path, report));
    }
    let dataset = match (&args.dataset, reports.first()) {
        (Some(d), _) => d.clone(),
        (None, Some((_, _, r))) => {
            let name = &r.inputs.ground_truth.name;
            Path::new(name)
                .file_stem()
                .map_or_else(|| name.clone(), |s| s.to_string_lossy().into_owned())
        }
        (None, None) => bail!("no report given"),
    };
    let mut rows = Vec::new();
    for (pipeline, path, report) in &reports {
        let file = path_str(path)?;
        let mut row = report_row(&dataset, pipeline, report, file);
        // the pose protocols' reports beside it (sfmeval poses --json), when there
        row.poses = read_row_poses(&Disk, file)?;
        rows.push(row);
    }
    for f in &args.failed {
        let Some((pipeline, reason)) = named(f) else {
            bail!("--failed '{f}': expected PIPELINE=REASON");
        };
        rows.push(failed_row(&dataset, pipeline, "failed", reason));
    }
    let mut seen = std::collections::BTreeSet::new();
    for r in &rows {
        if !seen.insert(r.pipeline.as_str()) {
            bail!(
                "pipeline '{}' is given twice: name each report PIPELINE=REPORT",
                r.pipeline
            );
        }
    }
    Ok(rows)
}

/// Runs `sfmeval table`.
pub fn table_cmd(args: &TableArgs) -> Result<()> {
    let rows = rows(args)?;
    let t = tables(&rows);
    let summary = summary_json(&rows)?;
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create '{}'", dir.display()))?;
        for (name, text) in [
            ("table1.md", &t.table1_md),
            ("table1.csv", &t.table1_csv),
            ("table.md", &t.table_md),
            ("runs.csv", &t.runs_csv),
            ("summary.json", &summary),
        ] {
            write_atomic(&dir.join(name), text.as_bytes())?;
        }
    }
    print!(
        "{}",
        match args.format {
            TableFormat::Md => &t.table1_md,
            TableFormat::Csv => &t.table1_csv,
            TableFormat::Wide => &t.table_md,
            TableFormat::WideCsv => &t.runs_csv,
            TableFormat::Json => &summary,
        }
    );
    Ok(())
}
