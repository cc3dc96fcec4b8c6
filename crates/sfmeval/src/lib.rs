//! # sfmeval core
//!
//! Measures a Structure-from-Motion reconstruction against ground truth: read (PLY, glTF/GLB,
//! OBJ) from bytes, align (a given similarity, camera centres, point pairs, a global search,
//! scaled ICP: [`align`]), crop, compute exact
//! point-to-triangle (or nearest-neighbour) accuracy and sampled completeness, statistics,
//! precision/recall/F-score, and the `sfmeval.report/1` report.
//!
//! No filesystem, no printing, no threads unless the `parallel` feature is on; compiles to
//! `wasm32-unknown-unknown`. Errors are typed ([`Error`]); input never causes a panic.
//!
//! ```
//! use sfmeval::{evaluate::*, geometry::*, progress::NoProgress};
//! let gt = GroundTruth::Mesh(TriangleMesh {
//!     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
//!     triangles: vec![[0, 1, 2]],
//! });
//! let recon = PointCloud { points: vec![[0.2, 0.2, 0.1], [0.1, 0.1, -0.3]], colors: None };
//! let options = EvalOptions { samples: 1000, ..Default::default() };
//! let prepared = PreparedGroundTruth::new(&gt, options.samples, options.seed, &NoProgress).unwrap();
//! let eval = evaluate(&prepared, &recon, &AlignmentInput::none(), &options, &InputInfo::default(), &NoProgress).unwrap();
//! assert!((eval.report.accuracy.stats.mean - 0.2).abs() < 1e-12);
//! ```

pub mod align;
pub mod colormap;
pub mod crop;
pub mod distance;
pub mod error;
pub mod evaluate;
pub mod geometry;
pub mod gt_views;
pub mod io;
pub mod metrics;
pub mod model;
pub mod parallel;
pub mod pipeline;
pub mod pose;
pub mod progress;
pub mod report;
pub mod sampling;
pub mod spatial_order;
pub mod stats;
pub mod track_error;
pub mod transform;
pub mod visibility;

pub use error::{Error, Result};
