//! A factor's value as generator overrides (`section.key=value`, TOML values), computed from
//! the generator's resolved base config.

use anyhow::{Context, Result, bail};
use serde_json::Value as Json;

use crate::sweep::factor::Factor;

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

#[cfg(test)]
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
}
