//! Shared pieces of the example programs.

pub mod perf_args;
pub mod perf_stats;
pub mod shape_opts;
pub mod shape_output;
pub mod topic_types;
