//! The tangential-history table: one value per contact (the spring ξ of paper 000 eq. 4
//! or δ_F of paper 001 eq. 6), keyed by a hash of the two particle ids (SPEC 3).
//!
//! Open addressing with linear probing, a power-of-two capacity and at most half full.
//! Each step builds a fresh table from the current contact list: `gather_history` looks
//! every contact up in the previous table (a missing key is a contact that just opened:
//! a fresh spring, 0), the force stage updates the values, and `store_history` inserts
//! them into the new table. A contact that closed is simply not carried over, so no
//! deletion (and no tombstone) is needed, and a contact that opens and closes within one
//! step can neither be lost nor duplicated. Keys depend only on ids, never on the sorted
//! order, so springs survive every re-sort.

use crate::cpu::contacts::Pair;

const EMPTY: u64 = u64::MAX;
const MIN_CAPACITY: usize = 64;

/// The key of a pair: both ids in one u64 (i < j, so it is unique and order-free).
pub fn pair_key(p: Pair) -> u64 {
    ((p.i as u64) << 32) | p.j as u64
}

/// Slot hash: the SplitMix64 finaliser, which spreads neighbouring ids over the table.
pub fn hash(key: u64) -> u64 {
    let mut z = key;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[derive(Clone, Debug, PartialEq)]
pub struct SpringTable {
    pub keys: Vec<u64>,
    pub values: Vec<f64>,
    /// Spheropolygon pairs (law hertz_cohesive): each pair's sub-contact springs, keyed
    /// by the pair (the sub-contacts inside by their own keys, `SubSprings`).
    pub sub: std::collections::BTreeMap<u64, crate::cpu::springs::SubSprings>,
}

impl Default for SpringTable {
    fn default() -> Self {
        Self::with_capacity_for(0)
    }
}

impl SpringTable {
    /// An empty table able to hold `n` entries at load ≤ 1/2.
    pub fn with_capacity_for(n: usize) -> Self {
        let cap = (2 * n).next_power_of_two().max(MIN_CAPACITY);
        Self {
            keys: vec![EMPTY; cap],
            values: vec![0.0; cap],
            sub: Default::default(),
        }
    }

    pub fn capacity(&self) -> usize {
        self.keys.len()
    }

    pub fn len(&self) -> usize {
        self.keys.iter().filter(|&&k| k != EMPTY).count()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn lookup(&self, key: u64) -> Option<f64> {
        let mask = self.capacity() - 1;
        let mut slot = hash(key) as usize & mask;
        loop {
            match self.keys[slot] {
                k if k == key => return Some(self.values[slot]),
                EMPTY => return None,
                _ => slot = (slot + 1) & mask,
            }
        }
    }

    /// Inserts or overwrites. The caller sized the table, so a free slot exists.
    pub fn insert(&mut self, key: u64, value: f64) {
        let mask = self.capacity() - 1;
        let mut slot = hash(key) as usize & mask;
        while self.keys[slot] != EMPTY && self.keys[slot] != key {
            slot = (slot + 1) & mask;
        }
        self.keys[slot] = key;
        self.values[slot] = value;
    }

    /// All (key, value) entries in slot order.
    pub fn entries(&self) -> impl Iterator<Item = (u64, f64)> + '_ {
        self.keys
            .iter()
            .zip(&self.values)
            .filter(|(k, _)| **k != EMPTY)
            .map(|(k, v)| (*k, *v))
    }
}

/// Stage: the previous history of each current contact (0 for a new contact).
pub fn gather_history(table: &SpringTable, pairs: &[Pair], out: &mut Vec<f64>) {
    out.clear();
    out.extend(
        pairs
            .iter()
            .map(|&p| table.lookup(pair_key(p)).unwrap_or(0.0)),
    );
}

/// Stage: a fresh table holding the updated history of the current contacts.
pub fn store_history(pairs: &[Pair], values: &[f64], table: &mut SpringTable) {
    *table = SpringTable::with_capacity_for(pairs.len());
    for (&p, &v) in pairs.iter().zip(values) {
        table.insert(pair_key(p), v);
    }
}

/// Sub-contact springs a pair keeps at most from one step to the next: a rod pair has
/// at most four sub-contacts (two vertices on each side). Beyond that (polygon cores
/// touching at many points) the shallowest sub-contacts' springs restart every step.
pub const MAX_SUB: usize = 4;

/// One pair's springs beyond its tangential one, each keyed: a spheropolygon pair's
/// sub-contacts' tangential springs (by `SubContact::key`; SPEC 3: "keyed by the pair
/// and the sub-contact"), or a disk pair's rolling spring (`ROLLING_KEY`,
/// src/law/rolling.rs; rods take no rolling resistance, so the two never meet). What
/// the neighbour list's slot holds between steps, and the spring table and checkpoints
/// beside the tangential spring.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SubSprings {
    pub count: usize,
    pub key: [u32; MAX_SUB],
    pub xi: [f64; MAX_SUB],
}

/// The key of a disk pair's rolling spring among its `SubSprings`: no sub-contact's key
/// (those are below 2¹⁸, `overlap::spheropolygon::VERTICES` and two 8-bit indices), nor
/// the GPU's empty key (u32::MAX).
pub const ROLLING_KEY: u32 = u32::MAX - 1;

impl SubSprings {
    /// A disk pair's rolling spring alone.
    pub fn rolling(m_k: f64) -> Self {
        let mut s = Self::default();
        s.push(ROLLING_KEY, m_k);
        s
    }

    /// The spring of a sub-contact, 0 for one that was not there at the last step.
    pub fn get(&self, key: u32) -> f64 {
        (0..self.count)
            .find(|&k| self.key[k] == key)
            .map_or(0.0, |k| self.xi[k])
    }

    /// Keeps a sub-contact's spring for the next step (the first `MAX_SUB` only).
    pub fn push(&mut self, key: u32, xi: f64) {
        if self.count < MAX_SUB {
            self.key[self.count] = key;
            self.xi[self.count] = xi;
            self.count += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::Rng;
    use std::collections::BTreeMap;

    #[test]
    fn table_matches_a_map_under_contact_churn() {
        let mut rng = Rng::new(3);
        let mut table = SpringTable::default();
        let mut reference: BTreeMap<u64, f64> = BTreeMap::new();
        for step in 0..200 {
            // A random contact set overlapping the previous one: some persist, some open,
            // some close in this very step.
            let mut pairs: Vec<Pair> = reference
                .keys()
                .filter(|_| rng.uniform() < 0.8)
                .map(|&k| Pair {
                    i: (k >> 32) as u32,
                    j: k as u32,
                })
                .collect();
            for _ in 0..(rng.uniform() * 40.0) as usize {
                let i = (rng.uniform() * 500.0) as u32;
                pairs.push(Pair {
                    i,
                    j: i + 1 + (rng.uniform() * 20.0) as u32,
                });
            }
            pairs.sort();
            pairs.dedup();
            let mut hist = Vec::new();
            gather_history(&table, &pairs, &mut hist);
            for (p, h) in pairs.iter().zip(&hist) {
                assert_eq!(
                    *h,
                    reference.get(&pair_key(*p)).copied().unwrap_or(0.0),
                    "step {step}"
                );
            }
            let updated: Vec<f64> = hist.iter().map(|h| h + 1.0 + step as f64).collect();
            store_history(&pairs, &updated, &mut table);
            reference = pairs
                .iter()
                .zip(&updated)
                .map(|(p, v)| (pair_key(*p), *v))
                .collect();
            assert_eq!(
                table.len(),
                reference.len(),
                "no lost or duplicated springs"
            );
            assert!(table.len() * 2 <= table.capacity());
        }
    }
}
