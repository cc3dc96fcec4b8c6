//! The variants of a sweep: the generator arguments of the base dataset and of each factor
//! value, and rendering them (a variant made by the same arguments is reused).

use std::path::Path;

use anyhow::{Context, Result};
use serde_json::Value as Json;

use sfmeval_fs::write_atomic;

use crate::dataset::Dataset;
use crate::generator::render_dataset;
use crate::sweep::factor::Factor;
use crate::sweep::overrides::factor_overrides;

/// One factor value to render: its text and number, its dataset name and the generator
/// overrides that make it.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The value as given.
    pub text: String,
    /// The value as a number.
    pub x: f64,
    /// Its dataset (folder) name, [`variant_name`].
    pub dataset: String,
    /// The factor's generator overrides.
    pub overrides: Vec<String>,
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

/// The base dataset's generator arguments: `--preset` and/or `--config` (default: the `small`
/// preset), then `outputs.depth` (true only with `visibility`), `outputs.masks=false` and the
/// user's `--set`s.
pub fn base_args(
    preset: Option<&str>,
    config: Option<&Path>,
    visibility: bool,
    sets: &[String],
) -> Result<Vec<String>> {
    let mut base_args: Vec<String> = Vec::new();
    match (preset, config) {
        (None, None) => base_args.extend(["--preset".into(), "small".into()]),
        (p, c) => {
            if let Some(p) = p {
                base_args.extend(["--preset".into(), p.to_string()]);
            }
            if let Some(c) = c {
                let c = std::path::absolute(c)?;
                base_args.extend(["--config".into(), c.to_string_lossy().to_string()]);
            }
        }
    }
    let depth = if visibility {
        "outputs.depth=true"
    } else {
        "outputs.depth=false"
    };
    for s in [depth, "outputs.masks=false"]
        .iter()
        .map(|s| s.to_string())
        .chain(sets.iter().cloned())
    {
        base_args.extend(["--set".into(), s]);
    }
    Ok(base_args)
}

/// Every value's overrides from the resolved base config, all checked before anything is
/// rendered (a bad value is an error).
pub fn plan(factor: Factor, values: &[(String, f64)], base: &Json) -> Result<Vec<Planned>> {
    let mut planned: Vec<Planned> = Vec::new();
    for (text, x) in values {
        let o = factor_overrides(factor, *x, base)?;
        planned.push(Planned {
            text: text.clone(),
            x: *x,
            dataset: variant_name(factor, text),
            overrides: o,
        });
    }
    Ok(planned)
}

/// Renders every planned variant into `ds_root/<dataset>/` with the generator (`python`,
/// `scripts`), or reuses it when it is complete and was made by the same arguments (unless
/// `fresh`). A variant that fails to render is recorded as `failed` and the others go on.
/// Returns every variant's facts and the datasets to run the pipelines on.
pub fn render(
    planned: &[Planned],
    base_args: &[String],
    ds_root: &Path,
    fresh: bool,
    python: &Path,
    scripts: &Path,
) -> Result<(Vec<Variant>, Vec<Dataset>)> {
    std::fs::create_dir_all(ds_root).with_context(|| format!("creating {}", ds_root.display()))?;
    let mut variants: Vec<Variant> = Vec::new();
    let mut datasets: Vec<Dataset> = Vec::new();
    for pl in planned {
        let (text, name, overrides) = (&pl.text, &pl.dataset, &pl.overrides);
        let dest = ds_root.join(name);
        let mut args = base_args.to_vec();
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
        if !complete || fresh {
            match render_dataset("sweep", python, scripts, &args, &dest) {
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
    Ok((variants, datasets))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variant_names_are_file_names() {
        assert_eq!(variant_name(Factor::Noise, "0.5"), "noise-0.5");
        assert_eq!(variant_name(Factor::Focal, "35/2"), "focal-35_2");
    }
}
