//! The comparison tables of `sfmeval-runner report` as text, with no filesystem: a run's
//! record (`run.json`), its row built from the record and its `sfmeval.report/3`, and Table I
//! and the wide table as Markdown and CSV. The runner writes these strings to files; the page
//! (through the wasm bindings) builds the same strings from the same runs, so both say the same
//! thing byte for byte.

pub mod catalogue;
pub mod cells;
pub mod compare;
pub mod csv;
pub mod layout;
pub mod number;
pub mod order;
pub mod poses;
pub mod row;
pub mod run;
pub mod tables;
pub mod text;

pub use catalogue::{Best, CATALOGUE, Metric};
pub use compare::{CompareTable, Entry, compare_table};
pub use order::BUILTIN_PIPELINES;
pub use poses::{PoseReports, RowPoses, poses_file, read_row_poses};
pub use row::{Prf, Row};
pub use run::{RunFacts, Status, failed_row, report_row};
pub use tables::{Tables, summary_json, tables};
