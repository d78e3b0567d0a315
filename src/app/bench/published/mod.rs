//! The published values the protocols set ours beside, typed in as data with the table or
//! figure each number belongs to: one file per source. Klee 2016's tables are few and used by
//! one protocol, so they stay beside it ([`crate::bench::protocols::klee`]).

pub mod proximity_clouds;
pub mod thesis;
pub mod wagner;
