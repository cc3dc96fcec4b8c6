//! The text of `report`'s tables: `table1.md`, `table1.csv`, `runs.csv`, `table.md` (both
//! tables) and `summary.json`, from the rows.

use serde::Serialize;

use crate::cells::{csv_num, table1_cell, wide_columns, wide_shape, wide_values};
use crate::csv::CsvWriter;
use crate::order::{dataset_order, find, pipeline_order};
use crate::row::Row;

/// The tables' files as text, each exactly what `sfmeval-runner report` writes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tables {
    /// `table1.md`: Table I (mean distance and points per dataset and pipeline).
    pub table1_md: String,
    /// `table1.csv`: Table I as CSV, numbers in full.
    pub table1_csv: String,
    /// `runs.csv`: the wide table of every run as CSV.
    pub runs_csv: String,
    /// `table.md`: Table I and the wide table.
    pub table_md: String,
}

/// Table I and the wide table of `rows` (datasets by name, pipelines built-ins first).
pub fn tables(rows: &[Row]) -> Tables {
    let datasets = dataset_order(rows);
    let pipes = pipeline_order(rows);
    // Table I.
    let mut t1 = String::from("| dataset |");
    for p in &pipes {
        t1.push_str(&format!(" {p} |"));
    }
    t1.push_str("\n|---|");
    t1.push_str(&"---:|".repeat(pipes.len()));
    t1.push('\n');
    for d in &datasets {
        t1.push_str(&format!("| {d} |"));
        for p in &pipes {
            t1.push_str(&format!(" {} |", table1_cell(find(rows, d, p))));
        }
        t1.push('\n');
    }
    let mut dtu_note = if rows.iter().any(|r| r.dtu.is_some()) {
        " On a DTU scan the cell is the DTU protocol's overall in mm (the mean of its accuracy and completeness)."
    } else {
        ""
    }
    .to_string();
    if rows.iter().any(|r| r.eth3d.is_some()) {
        dtu_note += &format!(
            " On an ETH3D scene the cell is ETH3D's F1 score at {} m (else at its first tolerance).",
            crate::cells::ETH3D_TABLE1_TOLERANCE
        );
    }
    let t1_md = format!(
        "# Table I: mean distance to the ground truth (m) and number of points\n\nEach cell: mean reconstruction → ground-truth distance in metres (after {}), and in parentheses the number of points; failed runs show why.{dtu_note}\n\n{t1}",
        alignment_caption(rows)
    );
    let mut csv = CsvWriter::new();
    let mut header = vec!["dataset".to_string()];
    for p in &pipes {
        header.extend([
            format!("{p}.mean_m"),
            format!("{p}.points"),
            format!("{p}.status"),
        ]);
    }
    csv.record(&header);
    for d in &datasets {
        let mut record = vec![d.clone()];
        for p in &pipes {
            match find(rows, d, p) {
                Some(r) => record.extend([
                    csv_num(r.mean),
                    if r.mean.is_some() {
                        r.points.to_string()
                    } else {
                        String::new()
                    },
                    r.status.clone(),
                ]),
                None => record.extend([String::new(), String::new(), String::new()]),
            }
        }
        csv.record(&record);
    }
    let table1_csv = csv.finish();
    // Wide table.
    let cols = wide_columns(rows);
    let shape = wide_shape(rows);
    let mut ordered: Vec<&Row> = Vec::new();
    for d in &datasets {
        for p in &pipes {
            if let Some(r) = find(rows, d, p) {
                ordered.push(r);
            }
        }
    }
    let mut wide = format!("| {} |\n|{}\n", cols.join(" | "), "---|".repeat(cols.len()));
    for r in &ordered {
        wide.push_str(&format!(
            "| {} |\n",
            wide_values(r, shape, false).join(" | ")
        ));
    }
    let mut wcsv = CsvWriter::new();
    wcsv.record(&cols);
    for r in &ordered {
        wcsv.record(wide_values(r, shape, true));
    }
    let table_md = format!(
        "{t1_md}\n# All runs\n\nP/R/F at thresholds in % of the ground-truth bounding-box diagonal; camera errors after the same alignment, centre errors also in % of the scene radius (mean distance of the ground-truth cameras from their centroid).\n\n{wide}"
    );
    Tables {
        table1_md: t1_md,
        table1_csv,
        runs_csv: wcsv.finish(),
        table_md,
    }
}

/// How Table I's caption names the alignment of its rows: the one mode they all used, or each
/// run's own when they differ (`auto` when no row was evaluated: the runner's default).
pub fn alignment_caption(rows: &[Row]) -> String {
    let modes: std::collections::BTreeSet<&str> =
        rows.iter().filter_map(|r| r.alignment.as_deref()).collect();
    let name = |m: &str| match m {
        crate::run::TNT_ALIGNMENT => "the Tanks and Temples protocol's registration".to_string(),
        m => format!("`{m}` alignment"),
    };
    match modes.iter().collect::<Vec<_>>().as_slice() {
        [] => name("auto"),
        [m] => name(m),
        more => format!(
            "each run's own alignment: {}",
            more.iter()
                .map(|m| name(m))
                .collect::<Vec<_>>()
                .join(" or ")
        ),
    }
}

/// `summary.json`: schema, datasets and pipelines in table order, and every row.
pub fn summary_json(rows: &[Row]) -> Result<String, serde_json::Error> {
    let mut json = serde_json::to_string_pretty(&serde_json::json!({
        "schema": "sfmeval.runner-table/1",
        "datasets": dataset_order(rows),
        "pipelines": pipeline_order(rows),
        "rows": rows,
    }))?;
    json.push('\n');
    Ok(json)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::row::Prf;
    use crate::run::{RunFacts, Status, base_row};

    fn row(d: &str, p: &str, mean: Option<f64>) -> Row {
        let mut r = base_row(&RunFacts {
            dataset: d.into(),
            pipeline: p.into(),
            tool: "t".into(),
            version: Some("1".into()),
            status: if mean.is_some() {
                Status::Ok
            } else {
                Status::Failed
            },
            reason: mean.is_none().then(|| "boom | bad\nline".to_string()),
            wall_seconds: 1.25,
            cpu_seconds: 2.0,
            peak_memory_bytes: 3_000_000,
            images_total: 36,
            images_registered: 30,
            points: 100,
        });
        r.mean = mean;
        if mean.is_some() {
            r.thresholds = vec![Prf {
                tau: 0.01,
                tau_percent_of_diagonal: 0.5,
                precision: 0.25,
                recall: 0.5,
                f_score: 1.0 / 3.0,
            }];
        }
        r
    }

    #[test]
    fn builtins_come_first_then_names_and_failures_say_why() {
        let rows = vec![
            row("b", "zz", Some(0.5)),
            row("a", "colmap", None),
            row("a", "openmvg", Some(0.125)),
        ];
        let t = tables(&rows);
        assert!(
            t.table1_md
                .contains("| dataset | colmap | openmvg | zz |\n|---|---:|---:|---:|\n")
        );
        assert!(
            t.table1_md
                .contains("| a | failed: boom   bad line | 0.125000 (100) | — |\n")
        );
        assert_eq!(
            t.table1_csv,
            "dataset,colmap.mean_m,colmap.points,colmap.status,openmvg.mean_m,openmvg.points,openmvg.status,zz.mean_m,zz.points,zz.status\na,,,failed,0.125,100,ok,,,\nb,,,,,,,0.5,100,ok\n"
        );
        let lines: Vec<&str> = t.runs_csv.lines().collect();
        assert!(lines[0].starts_with("dataset,pipeline,status,points,registered,mean (m),median (m),RMS (m),P@0.5%,R@0.5%,F@0.5%,"));
        assert!(lines[1].starts_with("a,colmap,failed,,30/36,,,,,,,"));
        // a reason with a line break is one quoted CSV field, in full
        assert!(t.runs_csv.contains(
            ",t 1,\"boom | bad\nline\"\na,openmvg,ok,100,30/36,0.125,,,0.25,0.5,0.3333333333333333,"
        ));
        assert!(t.table_md.starts_with(&t.table1_md));
        assert!(
            t.table_md
                .contains("| b | zz | ok | 100 | 30/36 | 0.500000 |")
        );
    }

    #[test]
    fn the_caption_names_the_alignment_used() {
        let mut rows = vec![row("a", "zz", Some(0.5)), row("a", "colmap", None)];
        assert!(tables(&rows).table1_md.contains("(after `auto` alignment)"));
        rows[0].alignment = Some("given".into());
        assert!(
            tables(&rows)
                .table1_md
                .contains("(after `given` alignment)")
        );
        rows[1].alignment = Some(crate::run::TNT_ALIGNMENT.into());
        assert!(tables(&rows).table1_md.contains(
            "(after each run's own alignment: `given` alignment or the Tanks and Temples protocol's registration)"
        ));
    }

    #[test]
    fn dtu_rows_add_the_dtu_columns_and_their_overall_in_table_one() {
        let plain = vec![row("a", "colmap", Some(0.25))];
        assert!(!tables(&plain).runs_csv.contains("DTU"));
        let mut dtu = row("scan1", "zz", None);
        dtu.status = "ok".into();
        dtu.reason = None;
        dtu.dtu = Some(crate::row::DtuNumbers {
            scan: 1,
            mean_accuracy: Some(0.5),
            mean_completeness: Some(1.25),
            overall: Some(0.875),
        });
        let rows = vec![row("a", "colmap", Some(0.25)), dtu];
        let t = tables(&rows);
        let lines: Vec<&str> = t.runs_csv.lines().collect();
        assert!(
            lines[0].contains(",F@0.5%,DTU accuracy (mm),DTU completeness (mm),DTU overall (mm),"),
            "{}",
            lines[0]
        );
        assert!(lines[1].contains(",0.3333333333333333,,,,"), "{}", lines[1]);
        assert!(lines[2].contains(",,,,0.5,1.25,0.875,"), "{}", lines[2]);
        assert!(
            t.table1_md
                .contains("| scan1 | — | 0.875 mm DTU overall (100) |")
        );
        assert!(t.table1_md.contains("DTU protocol's overall in mm"));
        assert!(t.table_md.contains("| 0.500 | 1.250 | 0.875 |"));
        // the summary keeps the numbers; rows without them have no `dtu` key
        let s = summary_json(&rows).unwrap();
        assert_eq!(s.matches("\"dtu\"").count(), 1);
    }

    #[test]
    fn summary_lists_the_order_and_rows() {
        let rows = vec![row("a", "zz", Some(0.5)), row("a", "colmap", Some(0.25))];
        let s = summary_json(&rows).unwrap();
        let v: serde_json::Value = serde_json::from_str(&s).unwrap();
        assert_eq!(v["pipelines"], serde_json::json!(["colmap", "zz"]));
        assert_eq!(v["rows"].as_array().unwrap().len(), 2);
        assert!(s.ends_with("}\n"));
    }
}
