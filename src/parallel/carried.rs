//! What a migration carries besides the particles' own records: each bond goes, with its
//! history, to the procCube that evaluates it from its ends' new cells (the owner of the cell
//! it is found from through the half shell); a broken bond becomes an id pair with the owner
//! of its smaller id and a lost-bond count at each end; and each particle's places in the
//! boundary conditions, loads (with its weight) and probes go with it, so that no procCube
//! needs the whole scene's lists. The records are built before the particles move, while every
//! bond's ends are both held, and placed once the ghosts have arrived.

use crate::engine::bond_geoms::BondGeoms;
use crate::engine::bonds::BondList;
use crate::engine::cells::HALF_SHELL;
use crate::model::attributes::Attributes;
use crate::model::{BondGeom, Model};
use crate::parallel::decomposition::{CubePlan, Layout};
use crate::parallel::migrate::{cube_steps, Travellers};
use crate::parallel::Cube;
use std::collections::HashMap;

/// What a record says: an intact bond (with geometry and history), a broken bond's id pair,
/// one lost bond of a particle, or a particle's place in a boundary condition, a load (its
/// weight first after the ids) or a probe.
const INTACT: f64 = 0.0;
const DROPPED: f64 = 1.0;
const LOST: f64 = 2.0;
const CONSTRAINT: f64 = 3.0;
const LOAD: f64 = 4.0;
const PROBE: f64 = 5.0;

/// Fixed part of a record: faces to cross (3), kind, gid a (the bond's end it is evaluated
/// from, or the particle), gid b (or the condition, load or probe number), cell offset from
/// a's cell to b's (3), length, beta; then the history.
const BOND_HEAD: usize = 11;

/// Flat records of equal length, the faces still to cross first.
pub(crate) struct Letters {
    len: usize,
    data: Vec<f64>,
}

impl Letters {
    fn push(&mut self, steps: [i64; 3], kind: f64, a: u32, b: u32, rest: &[f64]) {
        self.data.extend(steps.map(|s| s as f64));
        self.data.extend_from_slice(&[kind, a as f64, b as f64]);
        self.data.extend_from_slice(rest);
        self.data
            .resize(self.data.len().next_multiple_of(self.len), 0.0);
    }
}

impl Travellers for Letters {
    fn furthest(&self, axis: usize) -> i64 {
        self.data
            .chunks_exact(self.len)
            .map(|r| r[axis].abs() as i64)
            .max()
            .unwrap_or(0)
    }

    fn leave(&mut self, axis: usize, dir: i8) -> Vec<f64> {
        let (len, dir) = (self.len, dir as f64);
        let mut out = Vec::new();
        let mut kept = 0;
        for r in 0..self.data.len() / len {
            let at = r * len;
            if self.data[at + axis].signum() == dir && self.data[at + axis] != 0.0 {
                self.data[at + axis] -= dir;
                out.extend_from_slice(&self.data[at..at + len]);
            } else {
                self.data.copy_within(at..at + len, kept * len);
                kept += 1;
            }
        }
        self.data.truncate(kept * len);
        out
    }

    fn arrive(&mut self, records: &[f64]) {
        self.data.extend_from_slice(records);
    }
}

/// A bond that stays on this procCube through a migration: by its ends' global ids and the
/// cell offset from a's cell to b's until the particles have settled, then by their new local
/// indices. Most bonds stay, and these records are a migration's peak memory: 16 bytes for a
/// bond without history, where a letter takes 88.
pub(crate) struct KeptBond<H> {
    a: u32,
    b: u32,
    /// Its geometry's position in the table of [`Kept::geoms`].
    geom: u32,
    /// The cell offset from a's cell to b's ([`pack_offset`]).
    offset: u8,
    history: H,
}

/// The bonds that stay, and the old list's geometry table their positions point into.
pub(crate) struct Kept<H> {
    bonds: Vec<KeptBond<H>>,
    geoms: BondGeoms,
}

/// A cell offset of −1..=1 along each axis as one number, 0..27.
fn pack_offset(d: [i64; 3]) -> u8 {
    ((d[0] + 1) * 9 + (d[1] + 1) * 3 + (d[2] + 1)) as u8
}

fn unpack_offset(v: u8) -> [i64; 3] {
    let v = v as i64;
    [v / 9 - 1, (v / 3) % 3 - 1, v % 3 - 1]
}

impl<M: Model> Cube<M> {
    /// Every bond, dropped pair and membership of this procCube as a record addressed to where
    /// it lives in `layout` after the particles have moved to the cells of their current
    /// (wrapped) positions; the bonds that stay here as compact records. The bond list and the
    /// dropped pairs leave `self`. Collective (one ghost message, a reduction).
    pub(crate) fn letters(&mut self, layout: &Layout) -> Result<(Letters, Kept<M::Bond>), String> {
        // Each held particle's new cell, from its owner: ghosts never recompute it, so both
        // ends of a bond see the cell their owner sorts them into.
        let p = &self.sim.particles;
        let mut cell = vec![[0u32; 3]; p.len()];
        for (i, c) in cell.iter_mut().enumerate().take(p.n_owned) {
            *c = layout.domain.grid.coords(&p.pos(i)).map(|v| v as u32);
        }
        self.wall.forward(&mut cell, false);

        let here = layout.coords(self.plan.rank);
        let to = |c: [u32; 3]| cube_steps(layout, here, c.map(|v| v as usize));
        let lh = <M::Bond as Attributes>::LEN;
        let mut out = Letters {
            len: BOND_HEAD + lh,
            data: Vec::new(),
        };
        let (b, gid) = (&self.sim.bonds, &self.sim.particles.gid);
        let mut kept = Vec::with_capacity(b.len());
        let mut error = None;
        for (i, j, k) in b.iter() {
            let (gi, gj) = (gid[i], gid[j]);
            if b.broken[k] {
                let first = if gi < gj { i } else { j };
                out.push(to(cell[first]), DROPPED, gi.min(gj), gi.max(gj), &[]);
                out.push(to(cell[i]), LOST, gi, 0, &[]);
                out.push(to(cell[j]), LOST, gj, 0, &[]);
                continue;
            }
            let d = cell_offset(layout, cell[i], cell[j]);
            if d.iter().any(|v| v.abs() > 1) {
                let (x, y) = (self.sim.particles.pos(i), self.sim.particles.pos(j));
                error.get_or_insert(format!(
                    "an intact bond between particles {gi} and {gj} now spans more than one cell (from {x:?} to {y:?}) at step {}: moving particles between procCubes needs every intact bond shorter than a cell; raise [parallel] skin (cells are the horizon times 1 + skin)",
                    self.sim.step
                ));
                continue;
            }
            let half = HALF_SHELL.contains(&d.map(|v| v as i32));
            let (a, c, off) = if d == [0; 3] {
                let (a, c) = if gi < gj { (i, j) } else { (j, i) };
                (a, c, d)
            } else if half {
                (i, j, d)
            } else {
                (j, i, d.map(|v| -v))
            };
            let steps = to(cell[a]);
            if steps == [0; 3] {
                kept.push(KeptBond {
                    a: gid[a],
                    b: gid[c],
                    geom: b.geom.position(k),
                    offset: pack_offset(off),
                    history: b.history[k],
                });
                continue;
            }
            let g = b.geom[k];
            let mut rest = vec![off[0] as f64, off[1] as f64, off[2] as f64];
            rest.extend_from_slice(&[g.length, g.beta]);
            rest.extend_from_slice(b.history[k].as_slice());
            out.push(steps, INTACT, gid[a], gid[c], &rest);
        }
        let dropped = std::mem::take(&mut self.dropped);
        if !dropped.is_empty() {
            let p = &self.sim.particles;
            let local: HashMap<u32, usize> = (0..p.n_owned).map(|i| (p.gid[i], i)).collect();
            for (a, c) in dropped {
                out.push(to(cell[local[&a]]), DROPPED, a, c, &[]);
            }
        }
        self.memberships(&mut out, |l| to(cell[l]));
        let mine = match error {
            Some(e) => Err(e),
            None => Ok(out),
        };
        let out = self.agree(mine)?;
        // Everything of the old list that stays here is in `kept`: free the list before the
        // particles move.
        let old = std::mem::replace(&mut self.sim.bonds, BondList::empty());
        let geoms = old.into_geom_table();
        Ok((out, Kept { bonds: kept, geoms }))
    }

    /// Each owned particle's places in the boundary conditions, loads and probes, as records
    /// going where the particle goes (`to` its local index).
    fn memberships(&self, out: &mut Letters, to: impl Fn(usize) -> [i64; 3]) {
        let gid = &self.sim.particles.gid;
        for (k, c) in self.sim.constraints.iter().enumerate() {
            for &l in &c.particles {
                let l = l as usize;
                out.push(to(l), CONSTRAINT, gid[l], k as u32, &[]);
            }
        }
        for (k, load) in self.sim.loads.iter().enumerate() {
            for (&l, &w) in load.particles.iter().zip(&load.weight) {
                let l = l as usize;
                out.push(to(l), LOAD, gid[l], k as u32, &[w]);
            }
        }
        for &(k, l) in &self.probes {
            out.push(to(l), PROBE, gid[l], k as u32, &[]);
        }
    }

    /// The bond list of the new `plan` from the bonds that stayed and the records that
    /// arrived; dropped pairs, lost counts and memberships into `self` (by the new local
    /// indices, in global id order as setup made them). `initial` is every local particle's
    /// initial bond count.
    pub(crate) fn place(
        &mut self,
        letters: Letters,
        kept: Kept<M::Bond>,
        plan: &CubePlan,
        initial: Vec<u32>,
    ) -> Result<BondList<M::Bond>, String> {
        let n_owned = plan.n_owned;
        let local: HashMap<u32, u32> = (0..n_owned).map(|l| (plan.global[l], l as u32)).collect();
        let mut cell_of = vec![0usize; n_owned];
        for k in 0..plan.cells.owned_cells {
            for l in plan.cell_range[k].clone() {
                cell_of[l] = k;
            }
        }
        let held: HashMap<[i64; 3], usize> = (plan.cells.held.iter().enumerate())
            .map(|(k, h)| (h.at, k))
            .collect();
        let owned = |ga: u32| {
            local.get(&ga).copied().ok_or_else(|| {
                format!(
                    "migration: a bond record for particle {ga} reached procCube {}, which does not own it; this is a bug in PDQ, please report it with the deck",
                    plan.rank
                )
            })
        };
        // The new local indices of a bond's ends: b is found in the cell at a's plus the offset.
        let ends = |ga: u32, gb: u32, off: [i64; 3]| -> Result<(u32, u32), String> {
            let la = owned(ga)?;
            let at = plan.cells.held[cell_of[la as usize]].at;
            let target = [0, 1, 2].map(|a| at[a] + off[a]);
            let lb = held.get(&target).and_then(|&k| {
                let cell = plan.cell_range[k].clone();
                let found = plan.global[cell.clone()].binary_search(&gb).ok();
                found.map(|p| (cell.start + p) as u32)
            });
            match lb {
                Some(lb) => Ok((la, lb)),
                None => Err(format!(
                    "migration: particle {gb}, bonded to {ga}, is not in the cell at {target:?} on procCube {}; this is a bug in PDQ, please report it with the deck",
                    plan.rank
                )),
            }
        };
        let Kept {
            mut bonds,
            mut geoms,
        } = kept;
        for k in bonds.iter_mut() {
            (k.a, k.b) = ends(k.a, k.b, unpack_offset(k.offset))?;
        }
        let lh = <M::Bond as Attributes>::LEN;
        let mut constraints = vec![Vec::new(); self.sim.constraints.len()];
        let mut loads = vec![Vec::new(); self.sim.loads.len()];
        self.probes.clear();
        for r in letters.data.chunks_exact(letters.len) {
            let (ga, gb) = (r[4] as u32, r[5] as u32);
            let la = owned(ga)?;
            match r[3] {
                DROPPED => self.dropped.push((ga, gb)),
                LOST => self.lost[la as usize] += 1,
                CONSTRAINT => constraints[gb as usize].push((ga, la)),
                LOAD => loads[gb as usize].push((ga, la, r[6])),
                PROBE => self.probes.push((gb as usize, la as usize)),
                _ => {
                    let (la, lb) = ends(ga, gb, [r[6], r[7], r[8]].map(|v| v as i64))?;
                    let geom = geoms.intern(BondGeom {
                        length: r[9],
                        beta: r[10],
                    });
                    let mut history = M::Bond::default();
                    history
                        .as_mut_slice()
                        .copy_from_slice(&r[BOND_HEAD..BOND_HEAD + lh]);
                    bonds.push(KeptBond {
                        a: la,
                        b: lb,
                        geom,
                        offset: 0,
                        history,
                    });
                }
            }
        }
        self.dropped.sort_unstable();
        self.probes.sort_unstable();
        for (c, mut m) in self.sim.constraints.iter_mut().zip(constraints) {
            m.sort_unstable();
            c.particles = m.into_iter().map(|(_, l)| l).collect();
        }
        for (load, mut m) in self.sim.loads.iter_mut().zip(loads) {
            m.sort_unstable_by_key(|&(g, ..)| g);
            load.particles = m.iter().map(|&(_, l, _)| l).collect();
            load.weight = m.iter().map(|&(.., w)| w).collect();
        }
        Ok(assemble(bonds, geoms, n_owned, initial))
    }
}

/// From cell `a` to cell `b` (grid coordinates), the short way round a periodic axis.
fn cell_offset(layout: &Layout, a: [u32; 3], b: [u32; 3]) -> [i64; 3] {
    let d = &layout.domain;
    [0, 1, 2].map(|k| {
        let v = b[k] as i64 - a[k] as i64;
        if d.periodic[k] {
            let n = d.grid.dims[k] as i64;
            (v + n + 1).rem_euclid(n) - 1
        } else {
            v
        }
    })
}

/// A bond list from bonds by local indices, ordered by (i, j); `geoms` is the table their
/// geometry positions point into.
fn assemble<H: Attributes>(
    mut bonds: Vec<KeptBond<H>>,
    mut geoms: BondGeoms,
    n_owned: usize,
    initial: Vec<u32>,
) -> BondList<H> {
    bonds.sort_unstable_by_key(|b| (b.a, b.b));
    let mut offsets = vec![0u32; n_owned + 1];
    for b in &bonds {
        offsets[b.a as usize + 1] += 1;
    }
    for i in 0..n_owned {
        offsets[i + 1] += offsets[i];
    }
    let partner = bonds.iter().map(|b| b.b).collect();
    for b in &bonds {
        geoms.push_position(b.geom);
    }
    let history = bonds.iter().map(|b| b.history).collect();
    drop(bonds);
    let mut list = BondList::assemble(offsets, partner, geoms, initial);
    list.history = history;
    list
}
