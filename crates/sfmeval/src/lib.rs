//! # sfmeval core
//!
//! Measures a Structure-from-Motion reconstruction against ground truth: read (PLY, glTF/GLB,
//! OBJ, SfM models) from bytes, align (a given similarity, camera centres, point pairs, a global
//! search, scaled ICP: [`align`]), crop, compute exact
//! point-to-triangle (or nearest-neighbour) accuracy and sampled completeness, statistics,
//! precision/recall/F-score, and the `sfmeval.report/3` report.
//!
//! No filesystem, no printing, no threads unless the `parallel` feature is on; compiles to
//! `wasm32-unknown-unknown`. Errors are typed ([`Error`]); input never causes a panic.
//!
//! Every front end makes the same request: a [`dataset::Dataset`] (the ground truth, read
//! through a [`files::FileSource`]: a folder on disk, dropped files, or a map of named bytes), a
//! reconstruction, and a [`pipeline::EvalRequest`] (alignment, measurement and pose options).
//!
//! ```
//! use std::collections::BTreeMap;
//! use sfmeval::align::AlignRequest;
//! use sfmeval::dataset::{Dataset, DatasetPaths};
//! use sfmeval::evaluate::EvalOptions;
//! use sfmeval::pipeline::{self, EvalRequest};
//! use sfmeval::progress::NoProgress;
//!
//! let files = BTreeMap::from([
//!     ("gt.obj".to_string(), b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec()),
//!     ("cloud.ply".to_string(),
//!      b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n0.2 0.2 0.1\n0.1 0.1 -0.3\n".to_vec()),
//! ]);
//! let mut dataset = Dataset::read(&files, &DatasetPaths::ground_truth("gt.obj")).unwrap();
//! let cloud = BTreeMap::from([("cloud.ply".to_string(), files["cloud.ply"].clone())]);
//! let recon = pipeline::read_reconstruction("cloud.ply", &cloud).unwrap();
//! let request = EvalRequest {
//!     align: AlignRequest::none(),
//!     eval: EvalOptions { samples: 1000, ..Default::default() },
//!     ..Default::default()
//! };
//! let eval = pipeline::run(&mut dataset, &recon, &request, &NoProgress).unwrap();
//! assert!((eval.report.accuracy.stats.mean - 0.2).abs() < 1e-7);
//! ```

pub mod align;
pub mod colormap;
pub mod crop;
pub mod dataset;
pub mod distance;
pub mod dropped;
mod error;
pub mod evaluate;
pub mod export;
pub mod files;
pub mod geometry;
pub mod gt_views;
pub mod io;
pub mod metrics;
pub mod model;
pub mod note;
pub mod parallel;
pub mod pipeline;
pub mod pose;
pub mod prepared;
pub mod progress;
pub mod report;
pub mod sampling;
mod spatial_order;
pub mod stats;
mod track_error;
pub mod transform;
#[cfg(feature = "ts")]
pub mod ts_declarations;
pub mod visibility;

pub use error::{AlignInputProblem, Error, Result};
