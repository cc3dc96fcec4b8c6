//! `sfmeval-runner sweep`: where does each pipeline break? Varies one condition of a
//! generated dataset (number of views, baseline, focal length, texture strength, lighting,
//! image noise or blur), renders one variant per value with the Blender generator, runs the
//! pipelines on every variant (the `run` machinery: resumable, failures recorded), evaluates
//! them (the `report` machinery) and plots each metric against the factor, one line per
//! pipeline: `sweep.csv`, `sweep.html` and `charts/<metric>.svg`.
//!
//! Metrics are JSON paths into `{"report": <sfmeval.report/1>, "run": <the run's row>}`, so a
//! new report field is one more line in [`DEFAULT_METRICS`] (or `--metric PATH`).

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde_json::Value as Json;

use crate::args::SweepArgs;
use crate::chart::line::{self, Chart, Series};
use crate::chart::value::Value;
use crate::csv::CsvWriter;
use crate::dataset::Dataset;
use crate::exec::shell_quote;
use crate::files::write_atomic;
use crate::html::{self, esc};
use crate::row::Row;
use crate::text::one_line;

/// Metrics plotted by default: `(path, label)`. `[*]` expands to one metric per element
/// (the report's thresholds). Paths start at `report.` (the run's `sfmeval.report/1`) or `run.`
/// (its row in `runs.csv`, plus `registered_fraction`).
pub const DEFAULT_METRICS: &[(&str, &str)] = &[
    ("report.thresholds[*].recall", "completeness (recall)"),
    ("report.thresholds[*].precision", "precision"),
    ("report.thresholds[*].f_score", "F-score"),
    ("report.accuracy.mean", "accuracy: mean distance (m)"),
    ("report.accuracy.median", "accuracy: median distance (m)"),
    (
        "report.completeness.median",
        "completeness: median distance GT → reconstruction (m)",
    ),
    ("run.registered_fraction", "registered images (fraction)"),
    (
        "report.cameras.rotation_error_deg.median",
        "median rotation error (°)",
    ),
    ("report.cameras.ate_rmse", "ATE RMSE (m)"),
    ("run.points", "points"),
    ("run.wall_seconds", "run time (s, wall)"),
];

/// Metrics plotted when some run's report has them: with `--visibility` (depth maps rendered)
/// the core adds completeness over the visible surface and the track-based error.
pub const VISIBILITY_METRICS: &[(&str, &str)] = &[
    (
        "report.completeness_visible.thresholds[*].recall_visible",
        "completeness of the visible surface (recall)",
    ),
    (
        "report.completeness_visible.visible_fraction",
        "visible share of the surface (≥ k images)",
    ),
    (
        "report.track_error.median",
        "track-based true error: median (m)",
    ),
    (
        "report.track_error.thresholds[*].sliding_fraction",
        "sliding points (true error − surface distance > τ)",
    ),
];

/// The conditions a sweep can vary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factor {
    /// Total number of views.
    Views,
    /// Azimuth step between neighbouring cameras of a ring (degrees).
    Baseline,
    /// Focal length (mm).
    Focal,
    /// Texture contrast of the built-in objects.
    Texture,
    /// Light energy multiplier.
    Lighting,
    /// Additive image noise σ (8-bit grey levels).
    Noise,
    /// Gaussian blur σ (pixels).
    Blur,
}

/// Every factor: `(name, factor, what it changes)`.
pub const FACTORS: [(&str, Factor, &str); 7] = [
    (
        "views",
        Factor::Views,
        "total number of views N: the base config's rings (and sphere/shell views) keep their elevations and radii, their counts are scaled proportionally to sum to N (largest remainder; groups that get 0 are dropped)",
    ),
    (
        "baseline",
        Factor::Baseline,
        "angular baseline in degrees: the azimuth step between neighbouring cameras of every ring (views.orbits[].azimuth_step_deg), the number of views unchanged, so a ring covers an arc of count × step from its azimuth offset (more than 360° is an error)",
    ),
    (
        "focal",
        Factor::Focal,
        "focal length in mm (camera.focal_mm); with the default automatic orbit radius the object keeps filling the frame, so this varies perspective and distance",
    ),
    (
        "texture",
        Factor::Texture,
        "texture strength: contrast of the built-in objects' procedural textures (object.texture_contrast, 0 = uniform colour, 1 = full contrast)",
    ),
    (
        "lighting",
        Factor::Lighting,
        "light energy multiplier: every light's energy × value (1 = the base lighting; the uniform world background is unchanged)",
    ),
    (
        "noise",
        Factor::Noise,
        "additive Gaussian image noise σ in 8-bit grey levels (postprocess.noise_sigma), seeded, before EXIF",
    ),
    (
        "blur",
        Factor::Blur,
        "Gaussian image blur σ in pixels (postprocess.blur_sigma), before noise and EXIF",
    ),
];

impl Factor {
    /// By name.
    pub fn parse(name: &str) -> Result<Factor> {
        FACTORS
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|(_, f, _)| *f)
            .with_context(|| {
                format!(
                    "unknown factor '{name}' (known: {})",
                    FACTORS.iter().map(|f| f.0).collect::<Vec<_>>().join(", ")
                )
            })
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        FACTORS
            .iter()
            .find(|(_, f, _)| *f == self)
            .map(|f| f.0)
            .unwrap_or("?")
    }

    /// What it changes.
    pub fn description(self) -> &'static str {
        FACTORS
            .iter()
            .find(|(_, f, _)| *f == self)
            .map(|f| f.2)
            .unwrap_or("")
    }
}

/// `NAME=V1,V2,...` → the factor and its values `(text, number)`.
pub fn parse_factor(s: &str) -> Result<(Factor, Vec<(String, f64)>)> {
    let (name, values) = s
        .split_once('=')
        .with_context(|| format!("--factor expects NAME=V1,V2,..., got '{s}'"))?;
    let factor = Factor::parse(name.trim())?;
    let mut out: Vec<(String, f64)> = Vec::new();
    for v in values.split(',').map(str::trim).filter(|v| !v.is_empty()) {
        let x: f64 = v
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite())
            .with_context(|| format!("--factor {name}: '{v}' is not a number"))?;
        if out.iter().any(|(_, y)| *y == x) {
            bail!("--factor {name}: value {v} given twice");
        }
        out.push((v.to_string(), x));
    }
    if out.is_empty() {
        bail!("--factor {name}: no values");
    }
    Ok((factor, out))
}

/// A float in TOML syntax (always with a decimal point or exponent).
fn toml_float(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E']) {
        s
    } else {
        format!("{s}.0")
    }
}

/// A JSON value as a TOML inline value (for `--set key=value`).
pub fn toml_inline(v: &Json) -> String {
    match v {
        Json::Null => "\"\"".into(),
        Json::Bool(b) => b.to_string(),
        Json::Number(n) => n.to_string(),
        Json::String(s) => Json::String(s.clone()).to_string(),
        Json::Array(a) => format!(
            "[{}]",
            a.iter().map(toml_inline).collect::<Vec<_>>().join(", ")
        ),
        Json::Object(o) => format!(
            "{{{}}}",
            o.iter()
                .map(|(k, v)| {
                    let key = if !k.is_empty()
                        && k.chars()
                            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
                    {
                        k.clone()
                    } else {
                        Json::String(k.clone()).to_string()
                    };
                    format!("{key} = {}", toml_inline(v))
                })
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

fn count_of(v: &Json) -> u64 {
    v.get("count").and_then(Json::as_u64).unwrap_or(0)
}

/// Splits `n` over `weights` proportionally (largest remainder, ties to the earlier group).
pub fn apportion(n: u64, weights: &[u64]) -> Vec<u64> {
    let total: u64 = weights.iter().sum();
    if total == 0 {
        return vec![0; weights.len()];
    }
    let mut out: Vec<u64> = weights.iter().map(|w| n * w / total).collect();
    let mut rem: Vec<(u64, usize)> = weights
        .iter()
        .enumerate()
        .map(|(i, w)| ((n * w) % total, i))
        .collect();
    rem.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let left = n - out.iter().sum::<u64>();
    for (_, i) in rem.into_iter().take(left as usize) {
        out[i] += 1;
    }
    out
}

/// The generator overrides (`section.key=value`) that set `factor` to `value`, given the
/// resolved base config (`generate.py --print-config`).
pub fn factor_overrides(factor: Factor, value: f64, base: &Json) -> Result<Vec<String>> {
    let name = factor.name();
    if !value.is_finite() {
        bail!("{name}: value must be finite");
    }
    let orbits = || -> Result<Vec<Json>> {
        base.pointer("/views/orbits")
            .and_then(Json::as_array)
            .cloned()
            .context("base config has no views.orbits")
    };
    Ok(match factor {
        Factor::Views => {
            if value < 1.0 || value.fract() != 0.0 {
                bail!("views={value}: the number of views must be a positive integer");
            }
            let n = value as u64;
            let rings: Vec<Json> = orbits()?.into_iter().filter(|r| count_of(r) > 0).collect();
            let sphere = base
                .pointer("/views/sphere/count")
                .and_then(Json::as_u64)
                .unwrap_or(0);
            let shell = base
                .pointer("/views/shell/count")
                .and_then(Json::as_u64)
                .unwrap_or(0);
            let mut weights: Vec<u64> = rings.iter().map(count_of).collect();
            weights.extend([sphere, shell]);
            if weights.iter().sum::<u64>() == 0 {
                bail!("views: the base config has no views to scale");
            }
            let counts = apportion(n, &weights);
            let new_rings: Vec<Json> = rings
                .iter()
                .zip(&counts)
                .filter(|(_, c)| **c > 0)
                .map(|(r, c)| {
                    let mut r = r.clone();
                    r["count"] = Json::from(*c);
                    r
                })
                .collect();
            let k = counts.len();
            vec![
                format!("views.orbits={}", toml_inline(&Json::Array(new_rings))),
                format!("views.sphere.count={}", counts[k - 2]),
                format!("views.shell.count={}", counts[k - 1]),
            ]
        }
        Factor::Baseline => {
            if value <= 0.0 {
                bail!("baseline={value}: the azimuth step must be > 0 degrees");
            }
            let mut rings = orbits()?;
            for (i, r) in rings.iter_mut().enumerate() {
                let c = count_of(r);
                if c as f64 * value > 360.0 + 1e-9 {
                    bail!(
                        "baseline={value}: ring {i} has {c} cameras, {c} × {value}° is more than a full circle; use fewer views (e.g. --set 'views.orbits=[...]') or a smaller step"
                    );
                }
                r["azimuth_step_deg"] = Json::from(value);
            }
            vec![format!("views.orbits={}", toml_inline(&Json::Array(rings)))]
        }
        Factor::Focal => {
            if value <= 0.0 {
                bail!("focal={value}: the focal length must be > 0 mm");
            }
            vec![format!("camera.focal_mm={}", toml_float(value))]
        }
        Factor::Texture => {
            if value < 0.0 {
                bail!("texture={value}: the texture contrast must be >= 0");
            }
            vec![format!("object.texture_contrast={}", toml_float(value))]
        }
        Factor::Lighting => {
            if value < 0.0 {
                bail!("lighting={value}: the energy multiplier must be >= 0");
            }
            let mut lights = base
                .get("lights")
                .and_then(Json::as_array)
                .cloned()
                .context("base config has no lights")?;
            for l in &mut lights {
                let e = l.get("energy").and_then(Json::as_f64).unwrap_or(0.0);
                l["energy"] = Json::from(e * value);
            }
            vec![format!("lights={}", toml_inline(&Json::Array(lights)))]
        }
        Factor::Noise | Factor::Blur => {
            if value < 0.0 {
                bail!("{name}={value}: σ must be >= 0");
            }
            let key = if factor == Factor::Noise {
                "noise_sigma"
            } else {
                "blur_sigma"
            };
            vec![format!("postprocess.{key}={}", toml_float(value))]
        }
    })
}

/// Dataset (folder) name of a variant: `<factor>-<value>`, file-name safe.
pub fn variant_name(factor: Factor, text: &str) -> String {
    let v: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{}-{v}", factor.name())
}

/// A metric to plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Metric {
    /// JSON path (CSV column), `[*]` expanded.
    pub path: String,
    /// Chart title.
    pub label: String,
}

/// The value at `path` (`a.b[2].c`) of `doc`, if a finite-or-not number.
pub fn lookup(doc: &Json, path: &str) -> Option<f64> {
    let mut cur = doc;
    for part in path.split('.') {
        let (key, rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            cur = cur.get(key)?;
        }
        let mut rest = rest;
        while let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']')?;
            let idx: usize = r[..end].parse().ok()?;
            cur = cur.get(idx)?;
            rest = &r[end + 1..];
        }
    }
    cur.as_f64()
}

/// Expands `[*]` (first occurrence) against the documents: one metric per index seen, the
/// label suffixed with the element's τ when it has one.
pub fn expand_metric(path: &str, label: &str, docs: &[&Json]) -> Vec<Metric> {
    let Some(i) = path.find("[*]") else {
        return vec![Metric {
            path: path.into(),
            label: label.into(),
        }];
    };
    let (prefix, suffix) = (&path[..i], &path[i + 3..]);
    let pointer = format!("/{}", prefix.replace('.', "/"));
    let mut n = 0;
    let mut first: Option<&Json> = None;
    for d in docs {
        if let Some(a) = d.pointer(&pointer).and_then(Json::as_array)
            && a.len() > n
        {
            n = a.len();
            first = Some(*d);
        }
    }
    (0..n)
        .map(|k| {
            let el = first.and_then(|d| d.pointer(&format!("{pointer}/{k}")));
            let tau = el.and_then(|e| e.get("tau")).and_then(Json::as_f64);
            let rel = el
                .and_then(|e| e.get("tau_relative_to_diagonal"))
                .and_then(Json::as_f64);
            let suffix_label = match (tau, rel) {
                (Some(t), Some(r)) if r > 0.0 => {
                    format!(
                        " at τ = {} m ({} % of the diagonal)",
                        sig(t),
                        sig(r * 100.0)
                    )
                }
                (Some(t), _) => format!(" at τ = {} m", sig(t)),
                _ => format!(" [{k}]"),
            };
            Metric {
                path: format!("{prefix}[{k}]{suffix}"),
                label: format!("{label}{suffix_label}"),
            }
        })
        .collect()
}

fn sig(x: f64) -> String {
    let s = format!("{x:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// One (value, pipeline) cell of the sweep.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Factor value text and number.
    pub value: (String, f64),
    /// Dataset name.
    pub dataset: String,
    /// Pipeline name.
    pub pipeline: String,
    /// `ok`, `failed`, `timeout`, `not installed`, `evaluation failed`, `generation failed`, `not run`.
    pub status: String,
    /// Why not ok.
    pub reason: Option<String>,
    /// `{"report": ..., "run": ...}`.
    pub doc: Json,
}

/// The metrics to plot: defaults then `--metric` ones, `[*]` expanded over the cells.
pub fn metrics(extra: &[String], cells: &[Cell]) -> Vec<Metric> {
    let docs: Vec<&Json> = cells.iter().map(|c| &c.doc).collect();
    let mut specs: Vec<(String, String)> = DEFAULT_METRICS
        .iter()
        .chain(VISIBILITY_METRICS.iter().filter(|(p, _)| {
            // only when a report has the section (runs with depth maps)
            let section = p.split('.').take(2).collect::<Vec<_>>().join("/");
            docs.iter()
                .any(|d| d.pointer(&format!("/{section}")).is_some())
        }))
        .map(|(p, l)| (p.to_string(), l.to_string()))
        .collect();
    for e in extra {
        let (p, l) = e.split_once('=').unwrap_or((e, e));
        specs.push((p.trim().to_string(), l.trim().to_string()));
    }
    let mut out: Vec<Metric> = Vec::new();
    for (p, l) in specs {
        for m in expand_metric(&p, &l, &docs) {
            if !out.iter().any(|o| o.path == m.path) {
                out.push(m);
            }
        }
    }
    out
}

/// The run's row as JSON, plus `registered_fraction`.
fn run_doc(row: &Row) -> Json {
    let mut v = serde_json::to_value(row).unwrap_or(Json::Null);
    if let Json::Object(o) = &mut v {
        o.remove("cdf");
        if row.images_total > 0 {
            o.insert(
                "registered_fraction".into(),
                Json::from(row.images_registered as f64 / row.images_total as f64),
            );
        }
    }
    v
}

/// `sweep.csv`: one row per (value, pipeline): factor, value, dataset, pipeline, status,
/// reason, then every metric (empty where there is none).
pub fn csv(factor: Factor, cells: &[Cell], metrics: &[Metric]) -> String {
    let mut w = CsvWriter::new();
    let mut header: Vec<String> = ["factor", "value", "dataset", "pipeline", "status", "reason"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    header.extend(metrics.iter().map(|m| m.path.clone()));
    w.record(&header);
    for c in cells {
        let mut record = vec![
            factor.name().to_string(),
            c.value.0.clone(),
            c.dataset.clone(),
            c.pipeline.clone(),
            c.status.clone(),
            c.reason.clone().unwrap_or_default().replace('\n', " "),
        ];
        record.extend(metrics.iter().map(|m| {
            lookup(&c.doc, &m.path)
                .map(|x| format!("{x}"))
                .unwrap_or_default()
        }));
        w.record(&record);
    }
    w.finish()
}

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

/// A file-name-safe stem for a metric path.
pub fn metric_file(path: &str) -> String {
    let s: String = path
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let mut out = String::new();
    for c in s.chars() {
        if !(c == '_' && out.ends_with('_')) {
            out.push(c);
        }
    }
    out.trim_matches('_').to_string()
}

/// Facts about one rendered variant.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Variant {
    /// Factor value as given.
    pub value: String,
    /// Dataset name.
    pub dataset: String,
    /// Generator overrides of the factor.
    pub overrides: Vec<String>,
    /// `rendered`, `reused` or `failed`.
    pub status: String,
    /// Why it failed.
    pub reason: Option<String>,
    /// Render seconds (null when reused).
    pub seconds: Option<f64>,
}

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
        "<h1>Where does each pipeline break? Sweep over <code>{}</code></h1>\n<p><b>{}</b>: {}.</p>\n<p>Command: <code>{}</code></p>\n<p>Pipelines: {}. Each chart plots one metric against the factor, one line per pipeline; a red × in the band under the axis is a run that failed or was not run (hover for the reason), a grey ○ a successful run without that metric. Metrics are read from each run's <code>sfmeval.report/1</code> (<code>report.…</code>) or its row in <code>table/runs.csv</code> (<code>run.…</code>); every value is in <code>sweep.csv</code>.</p>",
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
        let _ = writeln!(
            h,
            "<figure id=\"{}\">{}</figure>",
            esc(f),
            line::svg_inline(c)
        );
    }
    h.push_str("</div>\n");
    html::page("sfmeval sweep", STYLE, &h)
}

/// The whole sweep.
pub fn sweep(a: &SweepArgs) -> Result<()> {
    let t0 = Instant::now();
    let (factor, values) = parse_factor(&a.factor)?;
    a.exec.check()?;
    // absolute paths: the generator runs in the datasets folder
    let python = crate::env::find_python(a.tools.python.as_deref())?;
    let scripts = std::path::absolute(crate::generator::find_blender_scripts(
        a.blender_scripts.as_deref(),
    )?)?;
    let customs = crate::pipelines::parse_customs(&a.tools.customs)?;
    let specs = crate::pipelines::parse_list(&a.pipelines, &customs)?;
    let eval = a.eval.eval_options()?;
    // base: preset/config, no masks, depth maps only with --visibility, the user's --set
    let mut base_args: Vec<String> = Vec::new();
    match (&a.dataset_preset, &a.dataset_config) {
        (None, None) => base_args.extend(["--preset".into(), "small".into()]),
        (p, c) => {
            if let Some(p) = p {
                base_args.extend(["--preset".into(), p.clone()]);
            }
            if let Some(c) = c {
                let c = std::path::absolute(c)?;
                base_args.extend(["--config".into(), c.to_string_lossy().to_string()]);
            }
        }
    }
    let depth = if a.visibility {
        "outputs.depth=true"
    } else {
        "outputs.depth=false"
    };
    for s in [depth, "outputs.masks=false"]
        .iter()
        .map(|s| s.to_string())
        .chain(a.sets.iter().cloned())
    {
        base_args.extend(["--set".into(), s]);
    }
    let base = crate::generator::resolved_config(&python, &scripts, &base_args)?;
    // every value's overrides first: a bad value stops the sweep before anything is rendered
    let mut planned: Vec<(String, f64, String, Vec<String>)> = Vec::new();
    for (text, x) in &values {
        let o = factor_overrides(factor, *x, &base)?;
        planned.push((text.clone(), *x, variant_name(factor, text), o));
    }
    let out = std::path::absolute(&a.out)
        .with_context(|| format!("output folder {}", a.out.display()))?;
    let ds_root = out.join("datasets");
    std::fs::create_dir_all(&ds_root).with_context(|| format!("creating {}", ds_root.display()))?;
    let mut variants: Vec<Variant> = Vec::new();
    let mut datasets: Vec<Dataset> = Vec::new();
    for (text, _, name, overrides) in &planned {
        let dest = ds_root.join(name);
        let mut args = base_args.clone();
        for o in overrides
            .iter()
            .cloned()
            .chain([format!("dataset.name=\"{name}\"")])
        {
            args.extend(["--set".into(), o]);
        }
        // reuse only a complete variant made by the same generator arguments
        let stamp = ds_root.join(format!("{name}.args.json"));
        let stamp_json = serde_json::to_string_pretty(&args)? + "\n";
        let complete = dest.join("dataset.json").is_file()
            && dest.join("cameras.json").is_file()
            && std::fs::read_to_string(&stamp).ok().as_deref() == Some(stamp_json.as_str());
        let mut v = Variant {
            value: text.clone(),
            dataset: name.clone(),
            overrides: overrides.clone(),
            status: "reused".into(),
            reason: None,
            seconds: None,
        };
        if !complete || a.fresh {
            match crate::generator::render_dataset("sweep", &python, &scripts, &args, &dest) {
                Ok(secs) => {
                    write_atomic(&stamp, stamp_json.as_bytes())?;
                    v.status = "rendered".into();
                    v.seconds = Some(secs);
                }
                Err(e) => {
                    eprintln!("sweep: {name}: generation failed: {e:#}");
                    let _ = std::fs::remove_file(&stamp);
                    v.status = "failed".into();
                    v.reason = Some(format!("{e:#}"));
                }
            }
        } else {
            eprintln!("sweep: reusing {}", dest.display());
        }
        if v.status != "failed" {
            match Dataset::open(&dest) {
                Ok(d) => datasets.push(d),
                Err(e) => {
                    v.status = "failed".into();
                    v.reason = Some(format!("{e:#}"));
                }
            }
        }
        variants.push(v);
    }
    let render_seconds = t0.elapsed().as_secs_f64();
    // runs
    let runs = out.join("runs");
    let table = out.join("table");
    let t_runs = Instant::now();
    if !datasets.is_empty() {
        let env = crate::env::make_env(&a.tools, &runs)?;
        let opts = a.exec.batch_options(&runs, !a.fresh, a.retry_failed)?;
        let sum = crate::run::run_batch(&datasets, &specs, &customs, &env, &opts)?;
        eprintln!(
            "sweep: runs: {} executed, {} reused",
            sum.ran.values().sum::<usize>(),
            sum.skipped
        );
    }
    let runs_seconds = t_runs.elapsed().as_secs_f64();
    // report
    let t_rep = Instant::now();
    let rows: Vec<Row> = if datasets.is_empty() {
        Vec::new()
    } else {
        crate::report::report(&crate::report::ReportArgs {
            runs: vec![runs.clone()],
            out: table.clone(),
            datasets: Vec::new(),
            eval,
            align: a.eval.align.clone(),
            verbose: true,
        })?
    };
    let report_seconds = t_rep.elapsed().as_secs_f64();
    // cells
    let pipes: Vec<String> = specs.iter().map(|s| s.name.clone()).collect();
    let mut cells: Vec<Cell> = Vec::new();
    for ((text, x, name, _), v) in planned.iter().zip(&variants) {
        for p in &pipes {
            let row = rows.iter().find(|r| &r.dataset == name && &r.pipeline == p);
            let (status, reason, doc) = match (v.status.as_str(), row) {
                ("failed", _) => (
                    "generation failed".to_string(),
                    v.reason.clone(),
                    Json::Null,
                ),
                (_, None) => ("not run".to_string(), None, Json::Null),
                (_, Some(r)) => {
                    let report = r
                        .report
                        .as_ref()
                        .and_then(|rel| std::fs::read(table.join(rel)).ok())
                        .and_then(|b| serde_json::from_slice::<Json>(&b).ok())
                        .unwrap_or(Json::Null);
                    (
                        r.status.clone(),
                        r.reason.clone(),
                        serde_json::json!({"report": report, "run": run_doc(r)}),
                    )
                }
            };
            cells.push(Cell {
                value: (text.clone(), *x),
                dataset: name.clone(),
                pipeline: p.clone(),
                status,
                reason,
                doc,
            });
        }
    }
    let metrics = metrics(&a.metrics, &cells);
    write_atomic(
        &out.join("sweep.csv"),
        csv(factor, &cells, &metrics).as_bytes(),
    )?;
    let charts = charts(factor, &values, &pipes, &cells, &metrics);
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
        page(factor, &command, &variants, &pipes, &charts, &files).as_bytes(),
    )?;
    let total = t0.elapsed().as_secs_f64();
    let doc = serde_json::json!({
        "schema": "sfmeval.sweep/1",
        "factor": factor.name(),
        "definition": factor.description(),
        "values": values.iter().map(|v| v.0.clone()).collect::<Vec<_>>(),
        "base_generator_args": base_args,
        "variants": variants,
        "pipelines": pipes,
        "metrics": metrics.iter().map(|m| serde_json::json!({"path": m.path, "label": m.label, "chart": metric_file(&m.path) + ".svg"})).collect::<Vec<_>>(),
        "command": command,
        "timing": {"datasets_seconds": render_seconds, "runs_seconds": runs_seconds,
                   "report_seconds": report_seconds, "total_seconds": total},
    });
    let mut json = serde_json::to_string_pretty(&doc)?;
    json.push('\n');
    write_atomic(&out.join("sweep.json"), json.as_bytes())?;
    let ok = cells.iter().filter(|c| c.status == "ok").count();
    eprintln!(
        "sweep: {} value(s) × {} pipeline(s), {ok} ok; datasets {render_seconds:.0} s, runs {runs_seconds:.0} s, report {report_seconds:.0} s, total {total:.0} s → {}/{{sweep.csv,sweep.html,sweep.json,charts/}}",
        values.len(),
        pipes.len(),
        a.out.display()
    );
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::float_cmp)]
mod tests {
    use super::*;
    use serde_json::json;

    fn base() -> Json {
        json!({
            "views": {
                "orbits": [
                    {"elevation_deg": 10.0, "count": 40, "radius": "auto", "azimuth_offset_deg": 0.0, "azimuth_step_deg": 0.0},
                    {"elevation_deg": 30.0, "count": 40, "radius": "auto", "azimuth_offset_deg": 4.5, "azimuth_step_deg": 0.0},
                    {"elevation_deg": 50.0, "count": 40, "radius": "auto", "azimuth_offset_deg": 9.0, "azimuth_step_deg": 0.0},
                    {"elevation_deg": 89.0, "count": 1, "radius": "auto", "azimuth_offset_deg": 0.0, "azimuth_step_deg": 0.0}
                ],
                "sphere": {"count": 0}, "shell": {"count": 0}
            },
            "lights": [{"type": "area", "energy": 250.0, "color": [1.0, 1.0, 1.0]},
                       {"type": "area", "energy": 120.0}]
        })
    }

    #[test]
    fn factor_parsing() {
        let (f, v) = parse_factor("views=12,24, 36").unwrap();
        assert_eq!(f, Factor::Views);
        assert_eq!(
            v,
            vec![
                ("12".into(), 12.0),
                ("24".into(), 24.0),
                ("36".into(), 36.0)
            ]
        );
        assert!(parse_factor("colour=1,2").is_err());
        assert!(parse_factor("views").is_err());
        assert!(parse_factor("views=").is_err());
        assert!(parse_factor("noise=1,x").is_err());
        assert!(parse_factor("noise=1,1.0").is_err());
        assert!(parse_factor("noise=nan").is_err());
        assert_eq!(variant_name(Factor::Noise, "0.5"), "noise-0.5");
        assert_eq!(variant_name(Factor::Focal, "35/2"), "focal-35_2");
    }

    #[test]
    fn apportion_is_proportional_and_exact() {
        assert_eq!(
            apportion(12, &[40, 40, 40, 1, 0, 0]),
            vec![4, 4, 4, 0, 0, 0]
        );
        assert_eq!(apportion(121, &[40, 40, 40, 1]), vec![40, 40, 40, 1]);
        assert_eq!(apportion(8, &[18, 18, 0, 0]), vec![4, 4, 0, 0]);
        assert_eq!(apportion(7, &[18, 18]), vec![4, 3]);
        for n in 1..200 {
            assert_eq!(apportion(n, &[40, 40, 40, 1, 5, 0]).iter().sum::<u64>(), n);
        }
    }

    #[test]
    fn views_scales_the_rings() {
        let o = factor_overrides(Factor::Views, 24.0, &base()).unwrap();
        assert_eq!(o.len(), 3);
        assert!(o[0].starts_with("views.orbits=[{"), "{}", o[0]);
        assert_eq!(o[0].matches("count = 8").count(), 3, "{}", o[0]);
        assert!(
            !o[0].contains("89.0"),
            "the 1-view ring gets no view: {}",
            o[0]
        );
        assert!(o[0].contains("radius = \"auto\""));
        assert_eq!(o[1], "views.sphere.count=0");
        assert!(factor_overrides(Factor::Views, 0.0, &base()).is_err());
        assert!(factor_overrides(Factor::Views, 2.5, &base()).is_err());
    }

    #[test]
    fn other_factors_map_to_their_keys() {
        let b = base();
        let o = factor_overrides(Factor::Baseline, 5.0, &b).unwrap();
        assert_eq!(o.len(), 1);
        assert_eq!(
            o[0].matches("azimuth_step_deg = 5.0").count(),
            4,
            "{}",
            o[0]
        );
        assert!(
            factor_overrides(Factor::Baseline, 10.0, &b).is_err(),
            "40 × 10° > 360°"
        );
        assert!(factor_overrides(Factor::Baseline, 0.0, &b).is_err());
        assert_eq!(
            factor_overrides(Factor::Focal, 50.0, &b).unwrap(),
            vec!["camera.focal_mm=50.0"]
        );
        assert!(factor_overrides(Factor::Focal, -1.0, &b).is_err());
        assert_eq!(
            factor_overrides(Factor::Texture, 0.25, &b).unwrap(),
            vec!["object.texture_contrast=0.25"]
        );
        let l = factor_overrides(Factor::Lighting, 0.5, &b).unwrap();
        assert!(l[0].starts_with("lights=[{"), "{}", l[0]);
        assert!(l[0].contains("energy = 125.0") && l[0].contains("energy = 60.0"));
        assert!(l[0].contains("color = [1.0, 1.0, 1.0]") && l[0].contains("type = \"area\""));
        assert_eq!(
            factor_overrides(Factor::Noise, 4.0, &b).unwrap(),
            vec!["postprocess.noise_sigma=4.0"]
        );
        assert_eq!(
            factor_overrides(Factor::Blur, 1.5, &b).unwrap(),
            vec!["postprocess.blur_sigma=1.5"]
        );
        assert!(factor_overrides(Factor::Blur, -1.0, &b).is_err());
    }

    #[test]
    fn metric_paths() {
        let doc = json!({"report": {"accuracy": {"mean": 0.5},
            "thresholds": [{"tau": 0.006, "tau_relative_to_diagonal": 0.005, "recall": 0.1},
                           {"tau": 0.012, "tau_relative_to_diagonal": 0.01, "recall": 0.3}]},
            "run": {"wall_seconds": 3.0}});
        assert_eq!(lookup(&doc, "report.accuracy.mean"), Some(0.5));
        assert_eq!(lookup(&doc, "report.thresholds[1].recall"), Some(0.3));
        assert_eq!(lookup(&doc, "report.thresholds[2].recall"), None);
        assert_eq!(lookup(&doc, "report.cameras.ate_rmse"), None);
        assert_eq!(lookup(&Json::Null, "run.wall_seconds"), None);
        let m = expand_metric(
            "report.thresholds[*].recall",
            "recall",
            &[&Json::Null, &doc],
        );
        assert_eq!(m.len(), 2);
        assert_eq!(m[1].path, "report.thresholds[1].recall");
        assert_eq!(m[0].label, "recall at τ = 0.006 m (0.5 % of the diagonal)");
        assert!(expand_metric("report.thresholds[*].recall", "r", &[&Json::Null]).is_empty());
        assert_eq!(
            metric_file("report.thresholds[1].f_score"),
            "report_thresholds_1_f_score"
        );
    }

    #[test]
    fn visibility_metrics_only_when_a_report_has_them() {
        let cell = |doc: Json| Cell {
            value: ("1".into(), 1.0),
            dataset: "d".into(),
            pipeline: "p".into(),
            status: "ok".into(),
            reason: None,
            doc,
        };
        let plain = json!({"report": {"thresholds": [{"tau": 0.01, "recall": 0.3}]}});
        let without = metrics(&[], &[cell(plain.clone())]);
        assert!(
            !without
                .iter()
                .any(|m| m.path.contains("visible") || m.path.contains("track"))
        );
        let with = json!({"report": {
            "thresholds": [{"tau": 0.01, "recall": 0.3}],
            "completeness_visible": {"visible_fraction": 0.8,
                "thresholds": [{"tau": 0.01, "recall_visible": 0.4}]},
            "track_error": {"median": 0.001, "thresholds": [{"tau": 0.01, "sliding_fraction": 0.02}]}}});
        let m = metrics(&[], &[cell(plain), cell(with.clone())]);
        let paths: Vec<&str> = m.iter().map(|m| m.path.as_str()).collect();
        for p in [
            "report.completeness_visible.thresholds[0].recall_visible",
            "report.completeness_visible.visible_fraction",
            "report.track_error.median",
            "report.track_error.thresholds[0].sliding_fraction",
        ] {
            assert!(paths.contains(&p), "{p} missing from {paths:?}");
            assert!(lookup(&with, p).is_some(), "{p}");
        }
    }

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
