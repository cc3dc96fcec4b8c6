//! Self-contained SVG charts (no scripts, no fonts or files loaded): line charts over a numeric
//! axis (the sweep), grouped bar charts and cumulative distribution charts (the tables' page),
//! with their shared colours, scales and point values.

pub mod bar;
pub mod cdf;
pub mod line;
pub mod palette;
pub mod panel;
pub mod scale;
pub mod value;
