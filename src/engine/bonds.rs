//! Bond families, stored once each (half list, CSR, `u32` indices) with their history.
//!
//! Families are found once, in the reference configuration, with cells and the 13-cell half
//! shell, so each pair within the horizon is stored at exactly one of its ends (its owner) and
//! Newton's third law gives the other end its reaction. A bond's identity is the pair of global
//! ids of its ends, so its history can follow it to another layout.

use crate::engine::bond_geoms::BondGeoms;
use crate::engine::cells::{CellGrid, HALF_SHELL};
use crate::model::attributes::Attributes;
use crate::model::BondGeom;

pub struct BondList<H: Attributes> {
    /// Bonds of owner `i` are `offsets[i]..offsets[i + 1]`.
    pub(crate) offsets: Vec<u32>,
    /// Private so that the largest partner index stays known (the force loop relies on it).
    partner: Vec<u32>,
    max_partner: usize,
    /// Reference geometry, interned (`bond_geoms`): change a β with `scale_beta`.
    pub geom: BondGeoms,
    /// Once set, never cleared: a broken bond carries no force again, whatever happens later.
    pub broken: Vec<bool>,
    pub history: Vec<H>,
    /// Bonds each particle had in the reference configuration (counting both ends).
    pub initial: Vec<u32>,
}

/// Partial-volume factor β of a bond of length `l` (docs/theory.md §6, as LAMMPS's `vfrac_scale`):
/// 1 up to δ − dx/2, then falling linearly to (δ + dx/2 − l)/dx at the horizon.
pub fn partial_volume(l: f64, horizon: f64, dx: f64) -> f64 {
    if l <= horizon - 0.5 * dx {
        1.0
    } else {
        ((horizon + 0.5 * dx - l) / dx).clamp(0.0, 1.0)
    }
}

/// A bond list built one owner at a time, in owner order.
pub(crate) struct Families {
    offsets: Vec<u32>,
    partner: Vec<u32>,
    geom: BondGeoms,
    initial: Vec<u32>,
    horizon: f64,
    dx: f64,
    partial: bool,
}

impl Families {
    /// For a store of `n` particles (owned and ghosts).
    pub(crate) fn new(n: usize, horizon: f64, dx: f64, partial: bool) -> Families {
        Families {
            offsets: vec![0],
            partner: Vec::new(),
            geom: BondGeoms::new(),
            initial: vec![0; n],
            horizon,
            dx,
            partial,
        }
    }

    /// Stores the family of the next owner `i`: `found` holds (partner, length) pairs; they are
    /// stored in partner order, so the result does not depend on the search order.
    pub(crate) fn close(&mut self, i: usize, found: &mut [(u32, f64)]) {
        assert_eq!(
            i + 1,
            self.offsets.len(),
            "families must be closed in owner order"
        );
        found.sort_unstable_by_key(|&(j, _)| j);
        for &(j, l) in found.iter() {
            self.partner.push(j);
            let beta = if self.partial {
                partial_volume(l, self.horizon, self.dx)
            } else {
                1.0
            };
            self.geom.push(BondGeom { length: l, beta });
            self.initial[i] += 1;
            self.initial[j as usize] += 1;
        }
        assert!(
            self.partner.len() < u32::MAX as usize,
            "too many bonds for u32 offsets"
        );
        self.offsets.push(self.partner.len() as u32);
    }

    pub(crate) fn finish<H: Attributes>(self) -> BondList<H> {
        BondList::assemble(self.offsets, self.partner, self.geom, self.initial)
    }
}

impl<H: Attributes> BondList<H> {
    /// Every pair (i, j) with |x_j − x_i| ≤ `horizon` where i is owned (`i < n_owned`).
    /// Pairs of two ghosts are not bonds here. `dx` is the lattice spacing for partial volumes
    /// (`partial_volume = false` gives β = 1 everywhere).
    pub fn find(
        x0: &[[f64; 3]],
        n_owned: usize,
        horizon: f64,
        dx: f64,
        partial: bool,
    ) -> BondList<H> {
        assert!(
            x0.len() < u32::MAX as usize,
            "too many particles for u32 indices"
        );
        let grid = CellGrid::covering(x0, horizon);
        let (cell_of, start, order) = grid.bin(x0);
        // A pair at exactly the horizon (m = 3 on a lattice) is in the family whatever the
        // rounding of its coordinates: the test allows a relative 1e-10.
        let h2 = horizon * horizon * (1.0 + 2e-10);
        let mut families = Families::new(x0.len(), horizon, dx, partial);
        let mut found: Vec<(u32, f64)> = Vec::new();
        for i in 0..n_owned {
            let xi = x0[i];
            let c = cell_of[i] as usize;
            let cc = grid.coords(&xi);
            found.clear();
            let visit = |cell: usize, found: &mut Vec<(u32, f64)>, own_cell: bool| {
                for &j in &order[start[cell] as usize..start[cell + 1] as usize] {
                    let ju = j as usize;
                    if own_cell && ju <= i {
                        continue;
                    }
                    let xj = x0[ju];
                    let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    if r2 <= h2 {
                        found.push((j, r2.sqrt()));
                    }
                }
            };
            visit(c, &mut found, true);
            for o in HALF_SHELL {
                if let Some(n) = grid.neighbour(cc, o) {
                    visit(n, &mut found, false);
                }
            }
            // Ghost partners in the backward half shell: a ghost never owns a bond, so the
            // owned end takes it.
            for o in HALF_SHELL {
                if let Some(n) = grid.neighbour(cc, [-o[0], -o[1], -o[2]]) {
                    for &j in &order[start[n] as usize..start[n + 1] as usize] {
                        let ju = j as usize;
                        if ju < n_owned {
                            continue;
                        }
                        let xj = x0[ju];
                        let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                        if r2 <= h2 {
                            found.push((j, r2.sqrt()));
                        }
                    }
                }
            }
            // Ghost partners in the own cell with a lower index cannot exist (ghosts come after
            // owned particles), and forward cells were scanned in full above.
            families.close(i, &mut found);
        }
        families.finish()
    }

    /// A bond list from bonds already found elsewhere (the wall method's per-procCube search):
    /// owner `i` holds `partner[offsets[i]..offsets[i + 1]]`; `initial` counts both ends.
    pub fn assemble(
        offsets: Vec<u32>,
        partner: Vec<u32>,
        geom: BondGeoms,
        initial: Vec<u32>,
    ) -> BondList<H> {
        assert!(
            offsets.last().map(|&o| o as usize) == Some(partner.len())
                && geom.len() == partner.len()
                && offsets.windows(2).all(|w| w[0] <= w[1]),
            "inconsistent bond list"
        );
        let n = partner.len();
        let max_partner = partner.iter().map(|&j| j as usize).max().unwrap_or(0);
        assert!(
            max_partner < initial.len().max(1),
            "bond partner out of range"
        );
        BondList {
            offsets,
            partner,
            max_partner,
            geom,
            broken: vec![false; n],
            history: vec![H::default(); n],
            initial,
        }
    }

    /// A list of no bonds and no particles.
    pub(crate) fn empty() -> BondList<H> {
        BondList::assemble(vec![0], Vec::new(), BondGeoms::new(), Vec::new())
    }

    /// The geometry table alone, the rest of the list freed (a migration keeps the bonds
    /// that stay as compact records and builds a new list from them).
    pub(crate) fn into_geom_table(self) -> BondGeoms {
        self.geom.table_only()
    }

    pub fn len(&self) -> usize {
        self.partner.len()
    }

    /// Bonds of owner `i` are `offsets()[i]..offsets()[i + 1]`.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// Owners (the families stored).
    pub fn owners(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Bonds of owner `i`, as a range that holds no borrow (a loop over the bonds can change
    /// them; collecting `iter()` first would cost 24 bytes per bond).
    pub fn family(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Partner (store index) of every bond.
    pub fn partners(&self) -> &[u32] {
        &self.partner
    }

    /// Split borrows for the bond loops: (offsets, partners, geometry, broken, history).
    #[allow(clippy::type_complexity)]
    pub fn parts_mut(&mut self) -> (&[u32], &[u32], &BondGeoms, &mut [bool], &mut [H]) {
        (
            &self.offsets,
            &self.partner,
            &self.geom,
            &mut self.broken,
            &mut self.history,
        )
    }

    pub fn max_partner(&self) -> usize {
        self.max_partner
    }

    pub fn is_empty(&self) -> bool {
        self.partner.is_empty()
    }

    pub fn broken_count(&self) -> usize {
        self.broken.iter().filter(|&&b| b).count()
    }

    /// Damage of every particle: broken / initial bonds (0 for a particle with no bonds).
    pub fn damage(&self, n_particles: usize) -> Vec<f64> {
        let mut broken = vec![0u32; n_particles];
        for i in 0..self.offsets.len() - 1 {
            for b in self.offsets[i] as usize..self.offsets[i + 1] as usize {
                if self.broken[b] {
                    broken[i] += 1;
                    broken[self.partner[b] as usize] += 1;
                }
            }
        }
        (0..n_particles)
            .map(|i| {
                if self.initial[i] == 0 {
                    0.0
                } else {
                    broken[i] as f64 / self.initial[i] as f64
                }
            })
            .collect()
    }

    /// The bonds as (owner, partner, bond index) triples.
    pub fn iter(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        (0..self.offsets.len() - 1).flat_map(move |i| {
            (self.offsets[i] as usize..self.offsets[i + 1] as usize)
                .map(move |b| (i, self.partner[b] as usize, b))
        })
    }

    /// Bytes held per bond.
    pub fn bytes_per_bond() -> usize {
        4 + BondGeoms::BYTES_PER_BOND + 1 + std::mem::size_of::<H>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_volume_matches_the_formula() {
        assert_eq!(partial_volume(2.0, 3.0, 1.0), 1.0);
        assert_eq!(partial_volume(2.5, 3.0, 1.0), 1.0);
        assert!((partial_volume(3.0, 3.015, 1.0) - 0.515).abs() < 1e-12);
    }

    #[test]
    fn cubic_lattice_has_the_expected_family() {
        let mut x = Vec::new();
        for k in 0..9 {
            for j in 0..9 {
                for i in 0..9 {
                    x.push([i as f64, j as f64, k as f64]);
                }
            }
        }
        let b = BondList::<()>::find(&x, x.len(), 3.015, 1.0, true);
        // The centre particle has 122 neighbours within 3.015 spacings.
        let centre = 4 * 81 + 4 * 9 + 4;
        assert_eq!(b.initial[centre], 122);
    }
}
