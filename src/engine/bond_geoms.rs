//! The reference geometry (length, partial volume) of every bond, stored as a 4-byte index into
//! a table of the distinct values.
//!
//! Bond storage is most of a peridynamic run's memory (about 58 bonds per particle at m = 3):
//! a 16-byte record per bond made 1.4 kB per PMB particle. On a lattice only a few hundred
//! distinct (length, β) pairs occur, told apart by their exact bits, so each bond keeps the
//! index of its pair: a bond reads back exactly the bits it was given, and the table is small
//! enough to stay in cache while the sweep streams the indices. Where β is scaled bond by bond
//! (a surface correction) the table grows towards one entry per bond; the store is then 4 bytes
//! per bond worse than a plain record, never wrong.

use crate::model::BondGeom;
use std::collections::HashMap;

#[derive(Clone, Debug, Default)]
pub struct BondGeoms {
    /// The distinct pairs, in the order first met.
    table: Vec<BondGeom>,
    /// Private so that every index stays below `table.len()` (the sweep relies on it).
    index: Vec<u32>,
    /// Table position of each pair, by its bits.
    lookup: HashMap<[u64; 2], u32>,
}

impl BondGeoms {
    pub fn new() -> BondGeoms {
        BondGeoms::default()
    }

    /// The table position of `g`, added if new.
    pub(crate) fn intern(&mut self, g: BondGeom) -> u32 {
        let key = [g.length.to_bits(), g.beta.to_bits()];
        if let Some(&at) = self.lookup.get(&key) {
            return at;
        }
        assert!(
            self.table.len() < u32::MAX as usize,
            "too many distinct bond geometries for u32 indices"
        );
        let at = self.table.len() as u32;
        self.table.push(g);
        self.lookup.insert(key, at);
        at
    }

    /// Appends the next bond's geometry.
    pub fn push(&mut self, g: BondGeom) {
        let at = self.intern(g);
        self.index.push(at);
    }

    /// Appends a bond by its table position, as [`BondGeoms::position`] or
    /// [`BondGeoms::intern`] gave it.
    pub(crate) fn push_position(&mut self, at: u32) {
        assert!(
            (at as usize) < self.table.len(),
            "bond geometry position out of the table"
        );
        self.index.push(at);
    }

    /// The table position of bond `k`'s geometry.
    pub(crate) fn position(&self, k: usize) -> u32 {
        self.index[k]
    }

    /// The table alone, with no bonds: a migration keeps each staying bond's position in it
    /// and interns the arriving ones.
    pub(crate) fn table_only(mut self) -> BondGeoms {
        self.index = Vec::new();
        self
    }

    pub fn len(&self) -> usize {
        self.index.len()
    }

    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
    }

    /// Geometry of bond `k`.
    #[inline(always)]
    pub fn get(&self, k: usize) -> &BondGeom {
        let at = self.index[k] as usize;
        // SAFETY: every index was returned by `intern`, so it is below the table's length, and
        // the table never shrinks.
        unsafe { self.table.get_unchecked(at) }
    }

    /// Bonds `range` as a slice for the sweep.
    #[inline(always)]
    pub fn slice(&self, range: std::ops::Range<usize>) -> GeomSlice<'_> {
        GeomSlice {
            table: &self.table,
            index: &self.index[range],
        }
    }

    /// Multiplies bond `k`'s β by `factor` (a correction of its partial volume).
    pub fn scale_beta(&mut self, k: usize, factor: f64) {
        let mut g = *self.get(k);
        g.beta *= factor;
        self.index[k] = self.intern(g);
    }

    /// Every bond's geometry, in bond order.
    pub fn iter(&self) -> impl Iterator<Item = &BondGeom> + '_ {
        self.index.iter().map(|&at| &self.table[at as usize])
    }

    /// Distinct (length, β) pairs held.
    pub fn distinct(&self) -> usize {
        self.table.len()
    }

    /// Bytes held per bond, not counting the table.
    pub const BYTES_PER_BOND: usize = std::mem::size_of::<u32>();
}

/// The geometry of a run of bonds (one owner's family).
#[derive(Clone, Copy)]
pub struct GeomSlice<'a> {
    table: &'a [BondGeom],
    index: &'a [u32],
}

impl<'a> GeomSlice<'a> {
    #[inline(always)]
    pub fn get(&self, k: usize) -> &'a BondGeom {
        let at = self.index[k] as usize;
        // SAFETY: as in `BondGeoms::get`.
        unsafe { self.table.get_unchecked(at) }
    }
}

impl std::ops::Index<usize> for BondGeoms {
    type Output = BondGeom;
    fn index(&self, k: usize) -> &BondGeom {
        self.get(k)
    }
}

impl FromIterator<BondGeom> for BondGeoms {
    fn from_iter<I: IntoIterator<Item = BondGeom>>(it: I) -> BondGeoms {
        let mut g = BondGeoms::new();
        for x in it {
            g.push(x);
        }
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bonds_read_back_the_bits_they_were_given() {
        let values = [
            BondGeom {
                length: 1.0,
                beta: 1.0,
            },
            BondGeom {
                length: 1.0 + f64::EPSILON,
                beta: 1.0,
            },
            BondGeom {
                length: 1.0,
                beta: 0.5,
            },
        ];
        let mut g = BondGeoms::new();
        for k in 0..30 {
            g.push(values[k % 3]);
        }
        assert_eq!(g.len(), 30);
        assert_eq!(g.distinct(), 3);
        for k in 0..30 {
            assert_eq!(g[k].length.to_bits(), values[k % 3].length.to_bits());
            assert_eq!(g[k].beta.to_bits(), values[k % 3].beta.to_bits());
        }
        // Scaling one bond leaves the others that shared its entry alone.
        g.scale_beta(0, 0.25);
        assert_eq!(g[0].beta, 0.25);
        assert_eq!(g[3].beta, 1.0);
        assert_eq!(g.distinct(), 4);
        assert_eq!(g.iter().count(), 30);
    }
}
