//! Pipeline specs on the command line: `KIND[:key=value,...]`, e.g. `colmap:matcher=sequential`,
//! `theia:max_features=2000,name=theia-2k`. `all` expands to every built-in pipeline, and
//! every `--custom NAME=COMMAND` defines a pipeline `NAME`.

use std::collections::BTreeMap;

use anyhow::{Result, bail};

use crate::adapters::{self, Adapter, BUILTIN, RUNNER_OPTIONS};

/// One pipeline of a batch.
#[derive(Debug, Clone, PartialEq)]
pub struct PipelineSpec {
    /// Run-folder name (`name=` option, else the kind).
    pub name: String,
    /// Adapter kind (`colmap`, `pycolmap-global`, a custom name, ...).
    pub kind: String,
    /// `key=value` options.
    pub options: BTreeMap<String, String>,
}

/// Parses a comma-separated list of pipeline specs. Commas inside a spec's options are
/// options separators, so specs are separated by `;` or given as separate arguments; a plain
/// `a,b,c` of bare names also works.
pub fn parse_list(
    args: &[String],
    customs: &BTreeMap<String, String>,
) -> Result<Vec<PipelineSpec>> {
    let mut out: Vec<PipelineSpec> = Vec::new();
    for arg in args {
        for item in split_specs(arg) {
            if item == "all" {
                for b in BUILTIN {
                    out.push(parse_one(b, customs)?);
                }
                for c in customs.keys() {
                    out.push(parse_one(c, customs)?);
                }
            } else {
                out.push(parse_one(&item, customs)?);
            }
        }
    }
    let mut seen = std::collections::BTreeSet::new();
    out.retain(|p| seen.insert(p.name.clone()));
    if out.is_empty() {
        bail!("no pipelines given");
    }
    Ok(out)
}

fn split_specs(arg: &str) -> Vec<String> {
    // `a,b:x=1,y=2;c` → ["a", "b:x=1,y=2", "c"]: a comma starts a new spec unless the part
    // after it is `key=value` of the current spec.
    let mut specs: Vec<String> = Vec::new();
    for group in arg.split(';') {
        for part in group.split(',') {
            let part = part.trim();
            if part.is_empty() {
                continue;
            }
            match specs.last_mut() {
                Some(last) if part.contains('=') && !part.contains(':') && last.contains(':') => {
                    last.push(',');
                    last.push_str(part);
                }
                _ => specs.push(part.to_string()),
            }
        }
        specs.push(String::new());
    }
    specs.retain(|s| !s.is_empty());
    specs
}

fn parse_one(spec: &str, customs: &BTreeMap<String, String>) -> Result<PipelineSpec> {
    let (kind, rest) = spec.split_once(':').unwrap_or((spec, ""));
    let kind = kind.trim().to_string();
    let mut options = BTreeMap::new();
    for kv in rest.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let Some((k, v)) = kv.split_once('=') else {
            bail!("pipeline '{spec}': option '{kv}' is not key=value");
        };
        options.insert(k.trim().to_string(), v.trim().to_string());
    }
    let name = options.get("name").cloned().unwrap_or_else(|| kind.clone());
    if name.is_empty()
        || name.starts_with('.')
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.+".contains(c))
    {
        bail!("pipeline name '{name}' must be letters, digits, - _ . + (it names a folder)");
    }
    let spec = PipelineSpec {
        name,
        kind,
        options,
    };
    let a = spec.adapter(customs)?;
    for k in spec.options.keys() {
        if !RUNNER_OPTIONS.contains(&k.as_str()) && !a.options().contains(&k.as_str()) {
            bail!(
                "pipeline '{}': unknown option '{k}' (known: {})",
                spec.name,
                RUNNER_OPTIONS
                    .iter()
                    .chain(a.options())
                    .copied()
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    if let Some(t) = spec.options.get("timeout")
        && !t.parse::<f64>().is_ok_and(|t| t > 0.0)
    {
        bail!(
            "pipeline '{}': timeout must be seconds > 0, got '{t}'",
            spec.name
        );
    }
    if let Some(i) = spec.options.get("intrinsics")
        && i != "exif"
        && i != "known"
    {
        bail!("pipeline '{}': intrinsics must be exif or known", spec.name);
    }
    Ok(spec)
}

impl PipelineSpec {
    /// The adapter of this pipeline.
    pub fn adapter(&self, customs: &BTreeMap<String, String>) -> Result<Box<dyn Adapter>> {
        adapters::adapter(&self.kind, &self.name, customs)
    }
}

/// Parses `--custom NAME=COMMAND` definitions.
pub fn parse_customs(defs: &[String]) -> Result<BTreeMap<String, String>> {
    let mut out = BTreeMap::new();
    for d in defs {
        let Some((name, cmd)) = d.split_once('=') else {
            bail!("--custom needs NAME=COMMAND, got '{d}'");
        };
        let name = name.trim();
        if BUILTIN.contains(&name) || name == "all" {
            bail!("--custom name '{name}' is a built-in pipeline");
        }
        if !cmd.contains("{out}") {
            bail!("--custom {name}: the command must write its model into {{out}}");
        }
        out.insert(name.to_string(), cmd.to_string());
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn specs() {
        let customs = parse_customs(&["mine=tool {images} {out}".into()]).unwrap();
        let l = parse_list(
            &[
                "colmap:matcher=sequential,overlap=5,pycolmap;theia:max_features=100,name=t1"
                    .into(),
                "mine".into(),
            ],
            &customs,
        )
        .unwrap();
        let names: Vec<_> = l.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["colmap", "pycolmap", "t1", "mine"]);
        assert_eq!(l[0].options.get("overlap").map(String::as_str), Some("5"));
        assert_eq!(l[2].kind, "theia");
        let all = parse_list(&["all".into()], &customs).unwrap();
        assert_eq!(all.len(), BUILTIN.len() + 1);
        assert!(parse_list(&["nope".into()], &customs).is_err());
        assert!(parse_list(&["colmap:bogus=1".into()], &customs).is_err());
        assert!(parse_list(&["colmap:timeout=-1".into()], &customs).is_err());
        assert!(parse_customs(&["colmap=x {out}".into()]).is_err());
        assert!(parse_customs(&["x=no placeholder".into()]).is_err());
    }
}
