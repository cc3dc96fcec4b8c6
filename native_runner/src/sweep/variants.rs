//! The variants of a sweep: the generator arguments of the base dataset and of each factor
//! value (rendered as the batch's datasets; a variant made by the same arguments is reused).

use std::path::Path;

use anyhow::Result;
use serde_json::Value as Json;

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variant_names_are_file_names() {
        assert_eq!(variant_name(Factor::Noise, "0.5"), "noise-0.5");
        assert_eq!(variant_name(Factor::Focal, "35/2"), "focal-35_2");
    }
}
