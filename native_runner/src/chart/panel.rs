//! The frame shared by the bar and cumulative charts of the tables' page: a fixed-size inline
//! SVG (no XML namespace) with a tooltip title and a heading centred on top.

use crate::html::esc;

/// Width (SVG pixels).
pub const WIDTH: f64 = 460.0;
/// Height (SVG pixels).
pub const HEIGHT: f64 = 260.0;
/// Space above the plot area, for the heading.
pub const TOP: f64 = 28.0;
/// Space below the plot area, for the x labels.
pub const BOTTOM: f64 = 40.0;

/// The opening `<svg>` of a panel of class `class`, with `title` as its tooltip and `heading`
/// written on top (both escaped here). Close it with `</svg>\n`.
pub fn open(class: &str, title: &str, heading: &str) -> String {
    format!(
        "<svg class=\"{class}\" width=\"{WIDTH}\" height=\"{HEIGHT}\" viewBox=\"0 0 {WIDTH} {HEIGHT}\" role=\"img\"><title>{}</title><text x=\"{}\" y=\"18\" font-size=\"13\" text-anchor=\"middle\">{}</text>",
        esc(title),
        WIDTH / 2.0,
        esc(heading)
    )
}
