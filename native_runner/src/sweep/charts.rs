//! The sweep's charts: one line chart per metric, one line per pipeline, a failure marker
//! where a run failed or was not run.

use crate::chart::line::{Chart, Series};
use crate::chart::value::Value;
use crate::sweep::cells::Cell;
use crate::sweep::factor::Factor;
use crate::sweep::metrics::{Metric, lookup};
use sfmeval_table::text::one_line;

/// One chart per metric, one series per pipeline (in `pipes` order).
pub fn charts(
    factor: Factor,
    values: &[(String, f64)],
    pipes: &[String],
    cells: &[Cell],
    metrics: &[Metric],
) -> Vec<Chart> {
    metrics
        .iter()
        .map(|m| Chart {
            title: m.label.clone(),
            subtitle: m.path.clone(),
            x_label: factor.name().to_string(),
            x_ticks: values.iter().map(|(t, x)| (*x, t.clone())).collect(),
            series: pipes
                .iter()
                .map(|p| Series {
                    name: p.clone(),
                    points: values
                        .iter()
                        .map(|(t, x)| {
                            let c = cells.iter().find(|c| &c.pipeline == p && &c.value.0 == t);
                            let v = match c {
                                None => Value::Failed("not run".into()),
                                Some(c) if c.status != "ok" => Value::Failed(format!(
                                    "{}{}",
                                    c.status,
                                    c.reason
                                        .as_deref()
                                        .map(|r| format!(": {}", one_line(r, 160)))
                                        .unwrap_or_default()
                                )),
                                Some(c) => {
                                    Value::from_opt(lookup(&c.doc, &m.path), "not in the report")
                                }
                            };
                            (*x, v)
                        })
                        .collect(),
                })
                .collect(),
        })
        .collect()
}
