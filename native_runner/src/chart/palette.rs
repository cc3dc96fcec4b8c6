//! The charts' colours.

/// Series colours (matplotlib's tab10), by series index.
pub const COLORS: [&str; 10] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];

/// The failure marker's colour.
pub const FAIL_COLOR: &str = "#d62728";

/// The colour of series `i` (the list repeats after ten).
pub fn color(i: usize) -> &'static str {
    COLORS[i % COLORS.len()]
}
