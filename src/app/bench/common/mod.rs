//! What the protocols, their reports and the runner all read, below all three: the [`section`]
//! of `report.md` a protocol returns (the runner keeps and replays it, the report prints it),
//! the [`stats`] of a measured series, and the [`format`] of numbers and markdown tables.
//! Nothing here imports another part of the bench.

pub mod format;
pub mod section;
pub mod stats;
