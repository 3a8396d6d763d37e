//! Particle shuffling (thesis 3.11): when particles have left their procCubes, ownership is
//! redrawn from current positions and every particle moves to its new owner with all its
//! attributes, its bonds' history attached.
//!
//! Bond families never change in peridynamics, so a scene whose particles stay near their
//! reference cells never needs this (ghost lists are drawn from reference cells and stay
//! correct under any motion); it pays off when matter travels far, where it keeps each
//! procCube's particles and their partners together and the load balanced. A shuffle is a
//! collective step: every worker sends its particles and bonds to all, and each rebuilds its
//! procCube from the whole set with the same code that built it at the start. That costs one
//! all-to-all exchange of the scene, so decks ask for it every N steps (`shuffle_every`).
//!
//! Intact bonds are then evaluated from the cells of their ends' current positions, which must
//! be neighbours: cells carry a skin over the horizon for this. Broken bonds carry no force
//! ever again, so a shuffle drops them from the bond lists and keeps them as counts (damage)
//! and as id pairs (the broken-bond output).

use crate::engine::bonds::BondList;
use crate::engine::cells::HALF_SHELL;
use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::{BondGeom, Model};
use crate::parallel::comm::f64s;
use crate::parallel::decomposition::{cell_plans, cube_plan, Layout};
use crate::parallel::{local_particles, Cube};
use std::collections::HashMap;

/// Fixed part of a particle record: gid, x0 (3), volume, material, initial bonds, lost bonds.
const PARTICLE_HEAD: usize = 8;
/// Fixed part of a bond record: gid i, gid j, length, beta, broken.
const BOND_HEAD: usize = 5;

impl<M: Model> Cube<M> {
    /// Whether some owned particle now lies more than a quarter cell inside another procCube's
    /// cells. The quarter cell is hysteresis: ownership and ghost lists depend only on the
    /// cells, never on positions, so a particle may sit just across its procCube's face without
    /// harm, and one vibrating on a face would otherwise make every check shuffle the scene.
    fn someone_left(&mut self) -> bool {
        const MARGIN: f64 = 0.25;
        let p = &self.sim.particles;
        let d = &self.layout.domain;
        let g = &d.grid;
        let (lo, hi) = (self.plan.cells.lo, self.plan.cells.hi);
        let mut left = false;
        'particles: for i in 0..p.n_owned {
            let x = wrap(p.pos(i), d).0;
            for a in 0..3 {
                // Matter beyond the grid counts in the edge cells (as `CellGrid::coords`).
                let f = (x[a] - g.origin[a]) / g.size[a];
                let below = lo[a] > 0 && f < lo[a] as f64 - MARGIN;
                let above = (hi[a] as usize) < g.dims[a] && f >= hi[a] as f64 + MARGIN;
                if below || above {
                    left = true;
                    break 'particles;
                }
            }
        }
        self.team().max(if left { 1.0 } else { 0.0 }) > 0.0
    }

    /// Redraws ownership from current positions if any particle left its procCube. Every worker
    /// must call it at the same step; returns whether particles moved.
    pub fn shuffle(&mut self) -> Result<bool, String> {
        if !self.someone_left() {
            return Ok(false);
        }
        self.shuffle_now()?;
        Ok(true)
    }

    /// Redraws ownership and ghosts from current positions now, whether or not anyone left
    /// (a neighbour-list rebuild needs every particle in the cell of its current position).
    /// Every worker must call it at the same step.
    pub fn shuffle_now(&mut self) -> Result<(), String> {
        // Everyone gets everything: gather on the root, then the root's concatenation to all.
        let mine = self.pack();
        let mut team = self.team();
        let mut all: Vec<u8> = team
            .gather(bytemuck::cast_slice(&mine))
            .map(|parts| parts.concat())
            .unwrap_or_default();
        team.broadcast(&mut all);
        let mut whole = Whole::<M>::unpack(&f64s(&all), self.global_particles);

        // Positions back into a periodic box, then the new layout from where particles are now.
        let domain = self.layout.domain.clone();
        let pos = whole.wrap(&domain);
        let layout = Layout::new(self.layout.procs, &domain, &pos, self.layout.walls)?;
        let plans = cell_plans(&layout);
        let plan = cube_plan(&layout, &plans, self.plan.rank);

        // This procCube's particles, owned then ghosts (images shifted).
        let n = self.global_particles;
        let g = |l: usize| plan.global[l] as usize;
        let ids: Vec<u32> = (0..n as u32).collect();
        let mut part = local_particles(
            &self.sim.model,
            &plan,
            &ids,
            &whole.x0,
            &whole.volume,
            &whole.material,
            &whole.alter,
        );
        for l in 0..plan.n_owned {
            part.force[l] = whole.force[g(l)];
        }
        for l in 0..plan.global.len() {
            part.fixed[l] = whole.fixed[g(l)];
        }
        let mut local_of_owned = HashMap::with_capacity(plan.n_owned);
        for l in 0..plan.n_owned {
            local_of_owned.insert(plan.global[l] as u32, l as u32);
        }
        let list = whole.local_bonds(&pos, &layout, &plan, &local_of_owned)?;

        // Dropped bonds live with the owner of their smaller id.
        let mut dropped = std::mem::take(&mut whole.dropped);
        dropped.sort_unstable();
        self.dropped = dropped
            .into_iter()
            .filter(|(a, _)| local_of_owned.contains_key(a))
            .collect();
        self.lost = (0..plan.n_owned).map(|l| whole.lost[g(l)]).collect();

        self.install(part, list, plan);
        self.layout = layout;
        // Ghosts came current from the whole scene, forces with their particles. The neighbour
        // lists held the old local indices: they are built again here.
        if self.sim.pairs.is_some() {
            self.build_pair_list();
        }
        Ok(())
    }

    /// Puts new particles, bonds and plan in place of the old, with this procCube's share of
    /// the boundary conditions, loads and probes found again by global id.
    pub(crate) fn install(
        &mut self,
        part: Particles<M>,
        list: BondList<M::Bond>,
        plan: crate::parallel::decomposition::CubePlan,
    ) {
        let (mut constraints, loads, probes) = if self.everywhere.is_empty() {
            (Vec::new(), Vec::new(), Vec::new())
        } else {
            let mut local = vec![u32::MAX; self.global_particles];
            for l in 0..plan.n_owned {
                local[plan.global[l] as usize] = l as u32;
            }
            self.everywhere.share(&local)
        };
        // Reactions are reported before the next force evaluation: each procCube keeps its
        // share (the sum over procCubes is what the history shows).
        for (new, old) in constraints.iter_mut().zip(&self.sim.constraints) {
            new.reaction.clone_from(&old.reaction);
        }
        self.sim.particles = part;
        self.sim.bonds = list;
        self.sim.constraints = constraints;
        self.sim.loads = loads;
        self.probes = probes;
        self.wall.set_stages(plan.stages.clone());
        self.plan = plan;
    }

    /// This procCube's owned particles and bonds as f64 records: counts (particles, bonds,
    /// dropped bonds), then a particle record each (`PARTICLE_HEAD` and the attributes), a bond
    /// record each (`BOND_HEAD` and the history), and the dropped bonds' id pairs.
    fn pack(&self) -> Vec<f64> {
        let p = &self.sim.particles;
        let b = &self.sim.bonds;
        let mut mine: Vec<f64> = vec![p.n_owned as f64, b.len() as f64, self.dropped.len() as f64];
        for i in 0..p.n_owned {
            mine.push(p.gid[i] as f64);
            mine.extend_from_slice(&p.x0[i]);
            mine.push(p.volume[i]);
            mine.push(p.material[i] as f64);
            mine.push(b.initial[i] as f64);
            mine.push(self.lost[i] as f64);
            mine.extend_from_slice(p.alter[i].as_slice());
            mine.extend_from_slice(p.force[i].as_slice());
            mine.extend_from_slice(p.fixed[i].as_slice());
        }
        for (i, j, k) in b.iter() {
            mine.extend_from_slice(&[
                p.gid[i] as f64,
                p.gid[j] as f64,
                b.geom[k].length,
                b.geom[k].beta,
                if b.broken[k] { 1.0 } else { 0.0 },
            ]);
            mine.extend_from_slice(b.history[k].as_slice());
        }
        for &(a, c) in &self.dropped {
            mine.extend_from_slice(&[a as f64, c as f64]);
        }
        mine
    }
}

/// The whole scene by global id, as every worker holds it during a shuffle.
struct Whole<M: Model> {
    x0: Vec<[f64; 3]>,
    volume: Vec<f64>,
    material: Vec<u16>,
    initial: Vec<u32>,
    lost: Vec<u32>,
    alter: Vec<M::Alter>,
    force: Vec<M::Force>,
    fixed: Vec<M::Fixed>,
    /// Intact bonds by global ids.
    bonds: Vec<(u32, u32, BondGeom, M::Bond)>,
    dropped: Vec<(u32, u32)>,
}

impl<M: Model> Whole<M> {
    /// The scene from every worker's [`Cube::pack`] records, concatenated.
    fn unpack(all: &[f64], n: usize) -> Self {
        let la = <M::Alter as Attributes>::LEN;
        let lf = <M::Force as Attributes>::LEN;
        let lx = <M::Fixed as Attributes>::LEN;
        let lh = <M::Bond as Attributes>::LEN;
        let mut w = Whole::<M> {
            x0: vec![[0.0; 3]; n],
            volume: vec![0.0; n],
            material: vec![0u16; n],
            initial: vec![0u32; n],
            lost: vec![0u32; n],
            alter: vec![M::Alter::default(); n],
            force: vec![M::Force::default(); n],
            fixed: vec![M::Fixed::default(); n],
            bonds: Vec::new(),
            dropped: Vec::new(),
        };
        let mut at = 0;
        while at < all.len() {
            let (np, nb, nd) = (all[at] as usize, all[at + 1] as usize, all[at + 2] as usize);
            at += 3;
            for _ in 0..np {
                let r = &all[at..at + PARTICLE_HEAD + la + lf + lx];
                let g = r[0] as usize;
                w.x0[g] = [r[1], r[2], r[3]];
                w.volume[g] = r[4];
                w.material[g] = r[5] as u16;
                w.initial[g] = r[6] as u32;
                // Broken bonds from records read earlier may already have counted here.
                w.lost[g] += r[7] as u32;
                let (alter, rest) = r[PARTICLE_HEAD..].split_at(la);
                let (force, fixed) = rest.split_at(lf);
                w.alter[g].as_mut_slice().copy_from_slice(alter);
                w.force[g].as_mut_slice().copy_from_slice(force);
                // Fixed data travels whole: bond sums (LPS weighted volume) are not redone.
                w.fixed[g].as_mut_slice().copy_from_slice(fixed);
                at += PARTICLE_HEAD + la + lf + lx;
            }
            for _ in 0..nb {
                let r = &all[at..at + BOND_HEAD + lh];
                let (gi, gj) = (r[0] as u32, r[1] as u32);
                if r[4] != 0.0 {
                    w.dropped.push((gi.min(gj), gi.max(gj)));
                    w.lost[gi as usize] += 1;
                    w.lost[gj as usize] += 1;
                } else {
                    let mut h = M::Bond::default();
                    h.as_mut_slice().copy_from_slice(&r[BOND_HEAD..]);
                    let geom = BondGeom {
                        length: r[2],
                        beta: r[3],
                    };
                    w.bonds.push((gi, gj, geom, h));
                }
                at += BOND_HEAD + lh;
            }
            for _ in 0..nd {
                w.dropped.push((all[at] as u32, all[at + 1] as u32));
                at += 2;
            }
        }
        w
    }

    /// Moves every position into the periodic box (reference positions move with them, so
    /// displacements are unchanged) and returns the positions.
    fn wrap(&mut self, domain: &crate::parallel::decomposition::Domain) -> Vec<[f64; 3]> {
        let mut pos = vec![[0.0; 3]; self.alter.len()];
        for ((p, alter), x0) in pos.iter_mut().zip(&mut self.alter).zip(&mut self.x0) {
            let (w, shift) = wrap(pos_of::<M>(alter), domain);
            *p = w;
            alter.as_mut_slice()[..3].copy_from_slice(&w);
            for (x, s) in x0.iter_mut().zip(shift) {
                *x -= s;
            }
        }
        pos
    }

    /// The bonds this procCube evaluates: from the cell of one end to the same cell or a
    /// half-shell neighbour holding the other.
    fn local_bonds(
        &self,
        pos: &[[f64; 3]],
        layout: &Layout,
        plan: &crate::parallel::decomposition::CubePlan,
        local_of_owned: &HashMap<u32, u32>,
    ) -> Result<BondList<M::Bond>, String> {
        let domain = &layout.domain;
        let grid = &domain.grid;
        let cell_at = |gid: u32| -> [i64; 3] {
            let c = grid.coords(&pos[gid as usize]);
            [c[0] as i64, c[1] as i64, c[2] as i64]
        };
        let held: HashMap<[i64; 3], usize> = plan
            .cells
            .held
            .iter()
            .enumerate()
            .map(|(k, h)| (h.at, k))
            .collect();
        let (lo, hi) = (plan.cells.lo, plan.cells.hi);
        let mut mine: Vec<(u32, u32, BondGeom, M::Bond)> = Vec::new();
        for &(a, b, geom, h) in &self.bonds {
            let (ca, cb) = (cell_at(a), cell_at(b));
            let mut d = [0i64; 3];
            for k in 0..3 {
                d[k] = cb[k] - ca[k];
                if domain.periodic[k] {
                    let nk = grid.dims[k] as i64;
                    d[k] = (d[k] + nk + 1).rem_euclid(nk) - 1;
                }
            }
            if d.iter().any(|v| v.abs() > 1) {
                return Err(format!(
                    "an intact bond between particles {a} and {b} now spans more than one cell (from {:?} to {:?}): shuffling needs every intact bond shorter than a cell; raise [parallel] skin (cells are the horizon times 1 + skin)",
                    pos[a as usize], pos[b as usize]
                ));
            }
            let h32 = [d[0] as i32, d[1] as i32, d[2] as i32];
            let (i, j, off) = if d == [0; 3] {
                (a.min(b), a.max(b), [0i64; 3])
            } else if HALF_SHELL.contains(&h32) {
                (a, b, d)
            } else {
                (b, a, [-d[0], -d[1], -d[2]])
            };
            let ci = cell_at(i);
            if (0..3).any(|k| ci[k] < lo[k] || ci[k] >= hi[k]) {
                continue;
            }
            let li = local_of_owned[&i];
            let target = [ci[0] + off[0], ci[1] + off[1], ci[2] + off[2]];
            let cell = held
                .get(&target)
                .map(|&k| plan.cell_range[k].clone())
                .unwrap_or_else(|| panic!("shuffle: no held cell at {target:?} for particle {j}"));
            let lj = plan.global[cell.clone()]
                .binary_search(&j)
                .map(|p| (cell.start + p) as u32)
                .unwrap_or_else(|_| panic!("shuffle: particle {j} is not in its cell"));
            mine.push((li, lj, geom, h));
        }
        Ok(self.assemble(mine, plan))
    }

    /// A bond list from (local i, local j, geometry, history) records.
    fn assemble(
        &self,
        mut mine: Vec<(u32, u32, BondGeom, M::Bond)>,
        plan: &crate::parallel::decomposition::CubePlan,
    ) -> BondList<M::Bond> {
        mine.sort_unstable_by_key(|&(i, j, _, _)| (i, j));
        let mut offsets = vec![0u32; plan.n_owned + 1];
        for &(i, ..) in &mine {
            offsets[i as usize + 1] += 1;
        }
        for i in 0..plan.n_owned {
            offsets[i + 1] += offsets[i];
        }
        let mut init_local = vec![0u32; plan.global.len()];
        for (init, &g) in init_local.iter_mut().zip(&plan.global[..plan.n_owned]) {
            *init = self.initial[g as usize];
        }
        let mut list: BondList<M::Bond> = BondList::assemble(
            offsets,
            mine.iter().map(|b| b.1).collect(),
            mine.iter().map(|b| b.2).collect(),
            init_local,
        );
        list.history = mine.iter().map(|b| b.3).collect();
        list
    }
}

fn pos_of<M: Model>(a: &M::Alter) -> [f64; 3] {
    let s = a.as_slice();
    [s[0], s[1], s[2]]
}

/// A position moved into the periodic box, and the shift taken off.
pub(crate) fn wrap(
    p: [f64; 3],
    d: &crate::parallel::decomposition::Domain,
) -> ([f64; 3], [f64; 3]) {
    let mut w = p;
    let mut shift = [0.0; 3];
    for a in 0..3 {
        if d.periodic[a] {
            let k = ((p[a] - d.grid.origin[a]) / d.period[a]).floor();
            if k != 0.0 {
                shift[a] = k * d.period[a];
                w[a] = p[a] - shift[a];
            }
        }
    }
    (w, shift)
}
