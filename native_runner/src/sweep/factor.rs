//! The conditions a sweep varies (views, baseline, focal, texture, lighting, noise, blur), and
//! `--factor NAME=V1,V2,...`.

use anyhow::{Context, Result, bail};

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

#[cfg(test)]
mod tests {
    use super::*;

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
    }
}
