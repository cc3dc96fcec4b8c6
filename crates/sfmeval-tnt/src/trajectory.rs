//! The benchmark's camera-trajectory files: the `.log` trajectory (one frame per input image:
//! a metadata line, then the 4×4 camera-to-world pose) and the `_mapping_reference.txt` that
//! picks a video's sampled frames. Read as the toolbox's `trajectory_io.read_trajectory` and
//! `registration.read_mapping` do, written as its `convert_to_logfile.py` writes them.

use std::fmt::Write as _;

use super::matrix::{IDENTITY, Matrix4};
use sfmeval::geometry::Point3;
use sfmeval::model::Reconstruction;
use sfmeval::{Error, Result};

const LOG: &str = ".log trajectory";
const MAPPING: &str = "mapping reference";

/// Trajectories longer than this are a video's: the mapping file picks the reference frames.
pub const MAPPING_ABOVE_FRAMES: usize = 1600;

/// One frame of a `.log` trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct LogFrame {
    /// The metadata line's integers (`k k 0` for a registered image, `k -1 0` for one the
    /// reconstruction lacks).
    pub metadata: Vec<i64>,
    /// Row-major camera-to-world pose (the identity for a missing image).
    pub world_from_cam: Matrix4,
}

impl LogFrame {
    /// The camera centre (the pose's translation column, which is all the protocol uses).
    pub fn center(&self) -> Point3 {
        [
            self.world_from_cam[0][3],
            self.world_from_cam[1][3],
            self.world_from_cam[2][3],
        ]
    }
}

/// Reads a `.log` trajectory: groups of five lines, the first of integers, the other four of
/// four numbers each. Reading stops at the first empty line, as the toolbox's does; anything
/// else that is not a full frame is an error naming the line.
pub fn read_log(bytes: &[u8]) -> Result<Vec<LogFrame>> {
    let text = std::str::from_utf8(bytes).map_err(|_| Error::Malformed {
        format: LOG,
        detail: "not UTF-8 text".into(),
    })?;
    let mut lines = text.lines().enumerate();
    let mut frames = Vec::new();
    while let Some((meta_no, meta)) = lines.next() {
        if meta.trim().is_empty() {
            break;
        }
        let metadata = meta
            .split_whitespace()
            .map(|t| {
                t.parse::<i64>().map_err(|_| Error::Malformed {
                    format: LOG,
                    detail: format!(
                        "line {}: '{t}' in a frame's metadata line is not an integer",
                        meta_no + 1
                    ),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut pose = [[0.0; 4]; 4];
        for row in pose.iter_mut() {
            let (no, line) = lines.next().ok_or_else(|| Error::Truncated {
                format: LOG,
                detail: format!(
                    "the frame that starts on line {} has fewer than 4 matrix rows",
                    meta_no + 1
                ),
            })?;
            let values: Vec<f64> = line
                .split_whitespace()
                .map(|t| t.parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| Error::Malformed {
                    format: LOG,
                    detail: format!("line {}: a matrix row that is not 4 numbers", no + 1),
                })?;
            if values.len() != 4 || values.iter().any(|v| !v.is_finite()) {
                return Err(Error::Malformed {
                    format: LOG,
                    detail: format!(
                        "line {}: a matrix row needs 4 finite numbers, found '{}'",
                        no + 1,
                        line.trim()
                    ),
                });
            }
            row.copy_from_slice(&values);
        }
        frames.push(LogFrame {
            metadata,
            world_from_cam: pose,
        });
    }
    if frames.is_empty() {
        return Err(Error::Empty {
            what: "the .log trajectory (no frame)".into(),
        });
    }
    Ok(frames)
}

/// Writes frames as the toolbox's converters do: the metadata integers joined by spaces, then
/// the four rows with 12 decimals.
pub fn write_log(frames: &[LogFrame]) -> String {
    let mut s = String::with_capacity(frames.len() * 240);
    for f in frames {
        let meta: Vec<String> = f.metadata.iter().map(i64::to_string).collect();
        let _ = writeln!(s, "{}", meta.join(" "));
        for row in &f.world_from_cam {
            let _ = writeln!(
                s,
                "{:.12} {:.12} {:.12} {:.12}",
                row[0], row[1], row[2], row[3]
            );
        }
    }
    s
}

/// The trajectory of a reconstruction over a list of input images (the benchmark's order: the
/// image files sorted by name), as `convert_to_logfile.py` makes it: frame `k` is `k k 0` with
/// the image's camera-to-world pose when the reconstruction registered image `k`, else `k -1 0`
/// with the identity. Images are matched by file name (the model's name or its last path
/// component). Returns the frames and how many images were registered.
pub fn log_from_model(model: &Reconstruction, image_names: &[String]) -> (Vec<LogFrame>, usize) {
    let base = |n: &str| n.rsplit(['/', '\\']).next().unwrap_or(n).to_string();
    let by_name: std::collections::HashMap<String, usize> = model
        .images
        .iter()
        .enumerate()
        .map(|(i, im)| (base(&im.name), i))
        .collect();
    let mut registered = 0;
    let frames = image_names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let k = k as i64;
            match by_name.get(&base(name)) {
                Some(&i) => {
                    registered += 1;
                    let pose = &model.images[i].cam_from_world;
                    let c = pose.center();
                    let r = &pose.rotation;
                    // world_from_cam = [Rᵀ | C].
                    let mut m = IDENTITY;
                    for (a, row) in m.iter_mut().take(3).enumerate() {
                        for (b, v) in row.iter_mut().take(3).enumerate() {
                            *v = r[b][a];
                        }
                        row[3] = c[a];
                    }
                    LogFrame {
                        metadata: vec![k, k, 0],
                        world_from_cam: m,
                    }
                }
                None => LogFrame {
                    metadata: vec![k, -1, 0],
                    world_from_cam: IDENTITY,
                },
            }
        })
        .collect();
    (frames, registered)
}

/// `_mapping_reference.txt`: which frame of a full video trajectory each reference frame is.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapping {
    /// Frames in the video.
    pub total_frames: u64,
    /// For each reference frame, its 1-based index in the video trajectory (the second column).
    pub video_frames: Vec<u64>,
}

/// Reads a mapping file: the sampled-frame count, the total, then one `a b` line per sampled
/// frame.
pub fn read_mapping(bytes: &[u8]) -> Result<Mapping> {
    let text = std::str::from_utf8(bytes).map_err(|_| Error::Malformed {
        format: MAPPING,
        detail: "not UTF-8 text".into(),
    })?;
    let mut lines = text.lines().enumerate();
    let mut count = |what: &str| -> Result<u64> {
        let (no, line) = lines.next().ok_or_else(|| Error::Truncated {
            format: MAPPING,
            detail: format!("no {what} line"),
        })?;
        line.trim().parse().map_err(|_| Error::Malformed {
            format: MAPPING,
            detail: format!(
                "line {}: the {what} '{}' is not a count",
                no + 1,
                line.trim()
            ),
        })
    };
    let sampled = count("sampled-frame count")?;
    let total_frames = count("total-frame count")?;
    let mut video_frames = Vec::new();
    for (no, line) in lines.take(sampled as usize) {
        let cols: Vec<i64> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| Error::Malformed {
                format: MAPPING,
                detail: format!("line {}: '{}' is not two integers", no + 1, line.trim()),
            })?;
        match cols.as_slice() {
            [_, b] if *b >= 1 && (*b as u64) <= total_frames => video_frames.push(*b as u64),
            _ => {
                return Err(Error::Malformed {
                    format: MAPPING,
                    detail: format!(
                        "line {}: expected two integers, the second in 1..={total_frames}, found '{}'",
                        no + 1,
                        line.trim()
                    ),
                });
            }
        }
    }
    if video_frames.len() as u64 != sampled {
        return Err(Error::Truncated {
            format: MAPPING,
            detail: format!(
                "{sampled} sampled frames declared, {} present",
                video_frames.len()
            ),
        });
    }
    Ok(Mapping {
        total_frames,
        video_frames,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO: &str = "0 0 0\n1.000000000000 0.000000000000 0.000000000000 0.500000000000\n0.000000000000 1.000000000000 0.000000000000 -1.000000000000\n0.000000000000 0.000000000000 1.000000000000 2.000000000000\n0.000000000000 0.000000000000 0.000000000000 1.000000000000\n1 -1 0\n1.000000000000 0.000000000000 0.000000000000 0.000000000000\n0.000000000000 1.000000000000 0.000000000000 0.000000000000\n0.000000000000 0.000000000000 1.000000000000 0.000000000000\n0.000000000000 0.000000000000 0.000000000000 1.000000000000\n";

    #[test]
    fn log_round_trip_and_errors() {
        let frames = read_log(TWO.as_bytes()).unwrap();
        assert_eq!(frames.len(), 2);
        assert_eq!(frames[0].metadata, vec![0, 0, 0]);
        assert_eq!(frames[0].center(), [0.5, -1.0, 2.0]);
        assert_eq!(frames[1].world_from_cam, IDENTITY);
        assert_eq!(write_log(&frames), TWO);
        // A trailing empty line ends the file; tabs separate too.
        let tabs = TWO.replace(' ', "\t") + "\n\n";
        assert_eq!(read_log(tabs.as_bytes()).unwrap(), frames);
        let e = read_log(
            TWO.lines()
                .take(3)
                .collect::<Vec<_>>()
                .join("\n")
                .as_bytes(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("fewer than 4 matrix rows") && e.contains("line 1"),
            "{e}"
        );
        let e = read_log(TWO.replacen("0.500000000000", "x", 1).as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = read_log(TWO.replacen(" 0.500000000000", "", 1).as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.contains("4 finite numbers"), "{e}");
        assert!(read_log(TWO.replacen("1 -1 0", "1 a 0", 1).as_bytes()).is_err());
        assert!(read_log(b"").is_err());
        assert!(read_log(TWO.replacen("0.500000000000", "inf", 1).as_bytes()).is_err());
    }

    #[test]
    fn mapping_file() {
        let m = read_mapping(b"3\n10\n1 1\n2 5\n3 10\n").unwrap();
        assert_eq!(m.total_frames, 10);
        assert_eq!(m.video_frames, vec![1, 5, 10]);
        assert!(read_mapping(b"3\n10\n1 1\n2 5\n").is_err());
        assert!(read_mapping(b"1\n10\n1 11\n").is_err());
        assert!(read_mapping(b"1\n10\n1 0\n").is_err());
        assert!(read_mapping(b"x\n").is_err());
    }
}
