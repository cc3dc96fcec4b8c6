//! The sweep's HTML page: what varied and how, the variants table and every chart inline.

use std::fmt::Write as _;

use crate::chart::line::{Chart, svg_inline};
use crate::html::{self, esc};
use crate::sweep::factor::Factor;
use crate::sweep::variants::Variant;
use sfmeval_table::text::one_line;

/// The page's own style, after the shell's.
const STYLE: &str = "th,td{border:1px solid #ccc;padding:3px 7px;text-align:left}th{background:#f3f3f3}td.failed{color:#a00;background:#fff3f3}\n.charts{display:flex;flex-wrap:wrap;gap:1em}.charts figure{margin:0}svg{border:1px solid #ddd}code{background:#f5f5f5;padding:1px 3px}";

/// `sweep.html` (self-contained: inline SVG, no scripts, nothing loaded): the factor, the
/// command, the variants table and every chart (`files`: their ids, the chart files' names).
pub fn page(
    factor: Factor,
    command: &str,
    variants: &[Variant],
    pipes: &[String],
    charts: &[Chart],
    files: &[String],
) -> String {
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<h1>Where does each pipeline break? Sweep over <code>{}</code></h1>\n<p><b>{}</b>: {}.</p>\n<p>Command: <code>{}</code></p>\n<p>Pipelines: {}. Each chart plots one metric against the factor, one line per pipeline; a red × in the band under the axis is a run that failed or was not run (hover for the reason), a grey ○ a successful run without that metric. Metrics are read from each run's <code>sfmeval.report/3</code> (<code>report.…</code>) or its row in <code>table/runs.csv</code> (<code>run.…</code>); every value is in <code>sweep.csv</code>.</p>",
        esc(factor.name()),
        esc(factor.name()),
        esc(factor.description()),
        esc(command),
        esc(&pipes.join(", "))
    );
    h.push_str("<h2>Variants</h2>\n<table><tr><th>value</th><th>dataset</th><th>generator overrides</th><th>render</th></tr>\n");
    for v in variants {
        let failed = v.status == "failed";
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td><code>{}</code></td><td{}>{}</td></tr>",
            esc(&v.value),
            esc(&v.dataset),
            esc(&v.overrides.join(" ")),
            if failed { " class=\"failed\"" } else { "" },
            esc(&match (&v.status[..], v.seconds, &v.reason) {
                ("failed", _, Some(r)) => format!("failed: {}", one_line(r, 160)),
                (s, Some(t), _) => format!("{s} in {t:.0} s"),
                (s, _, _) => s.to_string(),
            })
        );
    }
    h.push_str("</table>\n<h2>Charts</h2>\n<div class=\"charts\">\n");
    for (c, f) in charts.iter().zip(files) {
        let _ = writeln!(h, "<figure id=\"{}\">{}</figure>", esc(f), svg_inline(c));
    }
    h.push_str("</div>\n");
    html::page("sfmeval sweep", STYLE, &h)
}
