//! A batch — `table1`, `sweep` or `run` — as one typed plan and the work of its tasks, which
//! either executor runs: the local one ([`crate::local`]) stage by stage in this process, the
//! Slurm one ([`crate::slurm`]) as job arrays. The modules: [`plan`] (one function per command
//! makes the plan: datasets, cells, stages, where each task reads and writes), [`state`] (which
//! tasks left their result), [`task`] (rendering a dataset, running cells) and [`collect`] (the
//! command's outputs from what the executor did, one function for both).

pub mod collect;
pub mod plan;
pub mod state;
pub mod task;
