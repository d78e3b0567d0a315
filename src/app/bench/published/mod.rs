//! The published values the protocols set ours beside, typed in as data with the table or
//! figure each number belongs to: one file per source.

pub mod klee;
pub mod proximity_clouds;
pub mod thesis;
pub mod wagner;
