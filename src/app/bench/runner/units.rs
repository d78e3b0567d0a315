//! How a run's work divides: a protocol's units, and the shard of them a run takes
//! (`--shard K/N`); what a shard does with them is in [`super::shard`].

use serde::{Deserialize, Serialize};

/// How a protocol's work divides into units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// One unit per configuration it hands to [`super::Bench::measure`].
    Configs,
    /// The whole protocol is one unit.
    Whole,
}

/// `--shard K/N`: the K-th of N shards, 1 ≤ K ≤ N.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub k: u32,
    pub n: u32,
}

impl Shard {
    /// Does this shard measure the unit at (0-based) `index`?
    pub fn takes(&self, index: usize) -> bool {
        index % self.n as usize == (self.k - 1) as usize
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

/// "3/8" → the third of eight shards.
pub fn parse_shard(s: &str) -> Result<Shard, String> {
    let parsed = s.split_once('/').and_then(|(k, n)| {
        let (k, n) = (k.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?);
        (1..=n).contains(&k).then_some(Shard { k, n })
    });
    parsed.ok_or_else(|| format!("{s:?} is not a shard K/N with 1 ≤ K ≤ N, e.g. 3/8"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_units() {
        assert_eq!(parse_shard("2/3"), Ok(Shard { k: 2, n: 3 }));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
        for n in 1..5 {
            for i in 0..20 {
                let takers = (1..=n).filter(|&k| Shard { k, n }.takes(i)).count();
                assert_eq!(takers, 1, "unit {i} of {n} shards");
            }
        }
    }
}
