//! Cropping in the ground-truth frame: a volume (axis-aligned box, oriented box, sphere) and the
//! cut-off that discards points farther than D from the ground truth.
//!
//! The crop file (`sfmeval.crop/1`, written by the browser page, read by the CLI):
//! ```json
//! {"schema": "sfmeval.crop/1",
//!  "volume": {"kind": "oriented_box", "center": [0, 0, 0], "half_extents": [1, 1, 1],
//!             "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]},
//!  "max_distance": 0.05}
//! ```
//! `volume` kinds: `box` (`min`, `max`), `oriented_box` (`center`, `half_extents`, `rotation` =
//! row-major `world_from_box`, whose columns are the box axes), `sphere` (`center`, `radius`),
//! `polygon_prism` (`polygon`, `axis`, `axis_min`, `axis_max`: Open3D's
//! `SelectionPolygonVolume`, the crop of the Tanks and Temples benchmark; see
//! [`Volume::PolygonPrism`]).
//! Both fields are optional. The volume crops the reconstruction and the ground-truth samples of
//! completeness alike; `max_distance` discards reconstructed points only.
//!
//! [`Crop::parse`] also reads Open3D's own `SelectionPolygonVolume` JSON (the `<scene>.json` of
//! a Tanks and Temples scene, `"class_name": "SelectionPolygonVolume"`) as a crop with that
//! volume.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::geometry::{Point3, sub};

/// A crop volume in the ground-truth frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
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
    /// A prism: a polygon drawn across `axis`, extruded from `axis_min` to `axis_max` along it
    /// (Open3D's `SelectionPolygonVolume`, with its exact inside test: the coordinate along
    /// `axis` within `[axis_min, axis_max]`, and an odd number of polygon edges crossing the
    /// point's row strictly before it; the polygon's own coordinate along `axis` is ignored).
    PolygonPrism {
        /// The polygon's vertices in order (closed implicitly).
        polygon: Vec<Point3>,
        /// The extrusion axis: `x`, `y` or `z`.
        axis: Axis,
        /// Lower bound along `axis`.
        axis_min: f64,
        /// Upper bound along `axis`.
        axis_max: f64,
    },
}

/// A coordinate axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

impl Axis {
    /// `(u, v, w)`: the two polygon coordinates and the axis itself, in Open3D's order.
    fn uvw(self) -> (usize, usize, usize) {
        match self {
            Axis::X => (1, 2, 0),
            Axis::Y => (0, 2, 1),
            Axis::Z => (0, 1, 2),
        }
    }
}

impl Volume {
    /// The report's name for the volume kind.
    pub fn kind(&self) -> &'static str {
        match self {
            Volume::Box { .. } => "box",
            Volume::OrientedBox { .. } => "oriented_box",
            Volume::Sphere { .. } => "sphere",
            Volume::PolygonPrism { .. } => "polygon_prism",
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
            Volume::PolygonPrism {
                polygon,
                axis,
                axis_min,
                axis_max,
            } => in_prism(polygon, *axis, *axis_min, *axis_max, p),
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
            Volume::PolygonPrism {
                polygon,
                axis_min,
                axis_max,
                ..
            } => {
                polygon.len() >= 3
                    && polygon.iter().all(|p| finite(p))
                    && axis_min.is_finite()
                    && axis_max.is_finite()
                    && axis_min <= axis_max
            }
        };
        if ok {
            Ok(())
        } else {
            Err(Error::InvalidContent(format!(
                "crop {} is invalid (non-finite values, min > max, negative size, a rotation that is not orthonormal, or a polygon of fewer than 3 vertices)",
                self.kind()
            )))
        }
    }
}

/// Open3D's `SelectionPolygonVolume::CropInPolygon` for one point: inside when the coordinate
/// along the axis lies in `[axis_min, axis_max]` and the number of polygon edges crossing the
/// point's row at a `u` strictly below the point's is odd (Open3D sorts the crossings and takes
/// `lower_bound`; counting them is the same without the allocation).
fn in_prism(polygon: &[Point3], axis: Axis, axis_min: f64, axis_max: f64, p: Point3) -> bool {
    let (u, v, w) = axis.uvw();
    if p[w] < axis_min || p[w] > axis_max {
        return false;
    }
    let mut below = 0usize;
    // Edge i runs from vertex i to the next (the last to the first), without a modulo a vertex.
    // Branch-free: the tests are combined with `&` and `|`, not `&&` and `||`, and the crossing
    // is computed for every edge (a division by zero on an edge the row does not cross gives
    // ±∞ or NaN, which its mask discards), so the same edges count as with the branches, and a
    // cloud's points, each crossing a few edges at random, cost no mispredictions.
    for (&a, &b) in polygon
        .iter()
        .zip(polygon.iter().skip(1).chain(polygon.first()))
    {
        let crosses = ((a[v] < p[v]) & (b[v] >= p[v])) | ((b[v] < p[v]) & (a[v] >= p[v]));
        let node = a[u] + (p[v] - a[v]) / (b[v] - a[v]) * (b[u] - a[u]);
        below += usize::from(crosses & (node < p[u]));
    }
    below % 2 == 1
}

/// Open3D's `SelectionPolygonVolume` JSON (`visualization.read_selection_polygon_volume`).
#[derive(Deserialize)]
struct Open3dPolygonVolume {
    class_name: String,
    #[serde(default = "one")]
    version_major: i64,
    #[serde(default)]
    version_minor: i64,
    bounding_polygon: Vec<Point3>,
    orthogonal_axis: String,
    axis_min: f64,
    axis_max: f64,
}

fn one() -> i64 {
    1
}

impl Open3dPolygonVolume {
    fn into_volume(self) -> Result<Volume> {
        if self.class_name != "SelectionPolygonVolume"
            || self.version_major != 1
            || self.version_minor != 0
        {
            return Err(Error::InvalidContent(format!(
                "crop file: class '{}' version {}.{} is not Open3D's SelectionPolygonVolume 1.0",
                self.class_name, self.version_major, self.version_minor
            )));
        }
        let axis = match self.orthogonal_axis.as_str() {
            "x" | "X" => Axis::X,
            "y" | "Y" => Axis::Y,
            "z" | "Z" => Axis::Z,
            other => {
                return Err(Error::InvalidContent(format!(
                    "crop file: orthogonal_axis is '{other}', expected x, y or z"
                )));
            }
        };
        Ok(Volume::PolygonPrism {
            polygon: self.bounding_polygon,
            axis,
            axis_min: self.axis_min,
            axis_max: self.axis_max,
        })
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
    /// Parses a crop file: `sfmeval.crop/1`, or Open3D's `SelectionPolygonVolume` JSON (a
    /// Tanks and Temples `<scene>.json`), which becomes a [`Volume::PolygonPrism`] crop.
    pub fn parse(bytes: &[u8]) -> Result<Crop> {
        let value: serde_json::Value = serde_json::from_slice(bytes)
            .map_err(|e| Error::InvalidContent(format!("crop file: {e}")))?;
        if value.get("class_name").is_some() {
            let o3d: Open3dPolygonVolume = serde_json::from_value(value).map_err(|e| {
                Error::InvalidContent(format!("crop file (Open3D SelectionPolygonVolume): {e}"))
            })?;
            let crop = Crop {
                schema: None,
                volume: Some(o3d.into_volume()?),
                max_distance: None,
            };
            crop.validate()?;
            return Ok(crop);
        }
        let crop: Crop = serde_json::from_value(value)
            .map_err(|e| Error::InvalidContent(format!("crop file: {e}")))?;
        if let Some(s) = crop.schema.as_ref().filter(|s| *s != CROP_SCHEMA) {
            return Err(Error::InvalidContent(format!(
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

    /// An L-shaped prism across y (the polygon in x–z), as Open3D's crop test reads it.
    fn l_prism() -> Volume {
        Volume::PolygonPrism {
            polygon: vec![
                [0.0, 9.0, 0.0],
                [2.0, 9.0, 0.0],
                [2.0, 9.0, 1.0],
                [1.0, 9.0, 1.0],
                [1.0, 9.0, 2.0],
                [0.0, 9.0, 2.0],
            ],
            axis: Axis::Y,
            axis_min: -1.0,
            axis_max: 1.0,
        }
    }

    #[test]
    fn polygon_prism_follows_open3d() {
        let l = l_prism();
        // Inside both arms, the polygon's own y (9) ignored.
        assert!(l.contains([0.5, 0.0, 0.5]) && l.contains([1.5, 1.0, 0.5]));
        assert!(l.contains([0.5, -1.0, 1.5]));
        // The notch of the L, beyond the axis range, outside the polygon.
        assert!(!l.contains([1.5, 0.0, 1.5]));
        assert!(!l.contains([0.5, 1.0001, 0.5]) && !l.contains([0.5, -1.5, 0.5]));
        assert!(!l.contains([-0.1, 0.0, 0.5]) && !l.contains([0.5, 0.0, 2.5]));
        // Open3D's edge rules: a crossing counts when the edge spans (v_i < p_v <= v_j) and the
        // crossing's u is strictly below p_u: the left edge (u = 0) is outside, the right edge
        // (u = 2) is inside, the bottom row (v = 0) is outside, the row v = 1 is inside.
        assert!(!l.contains([0.0, 0.0, 0.5]));
        assert!(l.contains([2.0, 0.0, 0.5]));
        assert!(!l.contains([0.5, 0.0, 0.0]));
        assert!(l.contains([1.5, 0.0, 1.0]));
    }

    #[test]
    fn open3d_selection_polygon_volume_file() {
        let json = br#"{
            "axis_max" : 1.0, "axis_min" : -1.0,
            "bounding_polygon" : [[0,9,0],[2,9,0],[2,9,1],[1,9,1],[1,9,2],[0,9,2]],
            "class_name" : "SelectionPolygonVolume",
            "orthogonal_axis" : "Y", "version_major" : 1, "version_minor" : 0}"#;
        let c = Crop::parse(json).unwrap();
        assert_eq!(c.volume, Some(l_prism()));
        assert_eq!(c.kind(), "polygon_prism");
        // The sfmeval form round-trips.
        assert_eq!(
            Crop::parse(c.to_file_json().as_bytes()).unwrap().volume,
            c.volume
        );
        let bad_axis = String::from_utf8_lossy(json).replace("\"Y\"", "\"w\"");
        let e = Crop::parse(bad_axis.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("orthogonal_axis is 'w'"), "{e}");
        let other = String::from_utf8_lossy(json).replace("SelectionPolygonVolume", "PointCloud");
        let e = Crop::parse(other.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("class 'PointCloud'"), "{e}");
        let two = br#"{"class_name":"SelectionPolygonVolume","bounding_polygon":[[0,0,0],[1,0,0]],"orthogonal_axis":"z","axis_min":0,"axis_max":1}"#;
        assert!(Crop::parse(two).is_err());
        let missing = br#"{"class_name":"SelectionPolygonVolume","orthogonal_axis":"z","axis_min":0,"axis_max":1}"#;
        let e = Crop::parse(missing).unwrap_err().to_string();
        assert!(e.contains("bounding_polygon"), "{e}");
    }
}
