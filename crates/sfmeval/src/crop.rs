//! Cropping in the ground-truth frame: a volume (axis-aligned box, oriented box, sphere) and the
//! seed paper's "discard points farther than D from the ground truth".
//!
//! The crop file (`sfmeval.crop/1`, written by the browser page, read by the CLI):
//! ```json
//! {"schema": "sfmeval.crop/1",
//!  "volume": {"kind": "oriented_box", "center": [0, 0, 0], "half_extents": [1, 1, 1],
//!             "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]},
//!  "max_distance": 0.05}
//! ```
//! `volume` kinds: `box` (`min`, `max`), `oriented_box` (`center`, `half_extents`, `rotation` =
//! row-major `world_from_box`, whose columns are the box axes), `sphere` (`center`, `radius`).
//! Both fields are optional. The volume crops the reconstruction and the ground-truth samples of
//! completeness alike; `max_distance` discards reconstructed points only.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::geometry::{Point3, sub};

/// A crop volume in the ground-truth frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Volume {
    /// Axis-aligned box.
    Box {
        /// Minimum corner.
        min: Point3,
        /// Maximum corner.
        max: Point3,
    },
    /// Box with its own axes.
    OrientedBox {
        /// Centre.
        center: Point3,
        /// Half sizes along the box axes.
        half_extents: Point3,
        /// Row-major `world_from_box` rotation (columns are the box axes in the world).
        rotation: [[f64; 3]; 3],
    },
    /// Ball.
    Sphere {
        /// Centre.
        center: Point3,
        /// Radius.
        radius: f64,
    },
}

impl Volume {
    /// The report's name for the volume kind.
    pub fn kind(&self) -> &'static str {
        match self {
            Volume::Box { .. } => "box",
            Volume::OrientedBox { .. } => "oriented_box",
            Volume::Sphere { .. } => "sphere",
        }
    }

    /// Whether `p` lies inside (boundary included).
    #[inline]
    pub fn contains(&self, p: Point3) -> bool {
        match self {
            Volume::Box { min, max } => (0..3).all(|k| p[k] >= min[k] && p[k] <= max[k]),
            Volume::OrientedBox {
                center,
                half_extents,
                rotation,
            } => {
                let d = sub(p, *center);
                (0..3).all(|k| {
                    let local =
                        rotation[0][k] * d[0] + rotation[1][k] * d[1] + rotation[2][k] * d[2];
                    local.abs() <= half_extents[k]
                })
            }
            Volume::Sphere { center, radius } => {
                let d = sub(p, *center);
                d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= radius * radius
            }
        }
    }

    fn validate(&self) -> Result<()> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let ok = match self {
            Volume::Box { min, max } => {
                finite(min) && finite(max) && (0..3).all(|k| min[k] <= max[k])
            }
            Volume::OrientedBox {
                center,
                half_extents,
                rotation,
            } => {
                finite(center)
                    && finite(half_extents)
                    && half_extents.iter().all(|h| *h >= 0.0)
                    && rotation.iter().all(|r| finite(r))
                    && is_rotation(rotation)
            }
            Volume::Sphere { center, radius } => {
                finite(center) && radius.is_finite() && *radius >= 0.0
            }
        };
        if ok {
            Ok(())
        } else {
            Err(Error::InvalidOption(format!(
                "crop {} is invalid (non-finite values, min > max, negative size, or a rotation that is not orthonormal)",
                self.kind()
            )))
        }
    }
}

fn is_rotation(r: &[[f64; 3]; 3]) -> bool {
    (0..3).all(|i| {
        (0..3).all(|j| {
            let d: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            (d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-6
        })
    })
}

/// A crop: an optional volume and an optional maximum distance to the ground truth.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Crop {
    /// `"sfmeval.crop/1"` in files (optional when given inline).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    /// Keep only points inside this volume.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume: Option<Volume>,
    /// Discard reconstructed points farther than this from the ground truth.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_distance: Option<f64>,
}

/// Schema id of crop files.
pub(crate) const CROP_SCHEMA: &str = "sfmeval.crop/1";

impl Crop {
    /// Parses a crop file.
    pub fn parse(bytes: &[u8]) -> Result<Crop> {
        let crop: Crop = serde_json::from_slice(bytes)
            .map_err(|e| Error::InvalidOption(format!("crop file: {e}")))?;
        if let Some(s) = crop.schema.as_ref().filter(|s| *s != CROP_SCHEMA) {
            return Err(Error::InvalidOption(format!(
                "crop file schema is '{s}', expected '{CROP_SCHEMA}'"
            )));
        }
        crop.validate()?;
        Ok(crop)
    }

    /// Checks every value.
    pub fn validate(&self) -> Result<()> {
        if let Some(v) = &self.volume {
            v.validate()?;
        }
        if let Some(d) = self.max_distance.filter(|d| !(d.is_finite() && *d >= 0.0)) {
            return Err(Error::InvalidOption(format!(
                "max distance must be ≥ 0, got {d}"
            )));
        }
        Ok(())
    }

    /// The report's crop kind: `none`, the volume kind, `max_distance`, or `<volume>+max_distance`.
    pub fn kind(&self) -> String {
        match (&self.volume, self.max_distance) {
            (None, None) => "none".into(),
            (Some(v), None) => v.kind().into(),
            (None, Some(_)) => "max_distance".into(),
            (Some(v), Some(_)) => format!("{}+max_distance", v.kind()),
        }
    }

    /// Whether `p` is inside the volume (true without a volume).
    #[inline]
    pub(crate) fn in_volume(&self, p: Point3) -> bool {
        self.volume.as_ref().is_none_or(|v| v.contains(p))
    }

    /// The file form of this crop (with the schema id).
    pub fn to_file_json(&self) -> String {
        let mut c = self.clone();
        c.schema = Some(CROP_SCHEMA.into());
        serde_json::to_string_pretty(&c).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn volumes() {
        let b = Volume::Box {
            min: [0.0; 3],
            max: [1.0; 3],
        };
        assert!(b.contains([0.5, 1.0, 0.0]) && !b.contains([0.5, 1.01, 0.0]));
        let s = 0.5f64.sqrt();
        // A box rotated 45° about z: its local x axis is (s, s, 0).
        let ob = Volume::OrientedBox {
            center: [0.0; 3],
            half_extents: [2.0, 0.1, 0.1],
            rotation: [[s, -s, 0.0], [s, s, 0.0], [0.0, 0.0, 1.0]],
        };
        assert!(ob.contains([1.0, 1.0, 0.0]));
        assert!(!ob.contains([1.0, -1.0, 0.0]));
        let sp = Volume::Sphere {
            center: [1.0, 0.0, 0.0],
            radius: 1.0,
        };
        assert!(sp.contains([2.0, 0.0, 0.0]) && !sp.contains([2.0, 0.1, 0.0]));
    }

    #[test]
    fn parse_file_and_errors() {
        let c = Crop::parse(br#"{"schema":"sfmeval.crop/1","volume":{"kind":"sphere","center":[0,0,0],"radius":2},"max_distance":0.1}"#).unwrap();
        assert_eq!(c.kind(), "sphere+max_distance");
        assert_eq!(Crop::parse(c.to_file_json().as_bytes()).unwrap(), c);
        assert!(Crop::parse(br#"{"volume":{"kind":"box","min":[1,0,0],"max":[0,1,1]}}"#).is_err());
        assert!(Crop::parse(br#"{"volume":{"kind":"cone"}}"#).is_err());
        assert!(Crop::parse(br#"{"max_distance":-1}"#).is_err());
        assert!(Crop::parse(br#"{"max_dist":1}"#).is_err());
    }
}
