//! Migration (thesis 3.11, as LAMMPS's `exchange` and `borders`): for a neighbour-list
//! rebuild, each particle that has left its procCube's cells goes to the neighbouring procCube
//! that owns its current cell, and every procCube sorts its particles into cells and receives
//! its ghosts again along the five messages. Nothing is gathered: the work and the messages
//! of a rebuild are each procCube's own, where a shuffle costs every worker the whole scene.
//!
//! The layout's cuts stay as they are (a shuffle, `[parallel] shuffle_every`, rebalances).
//! Migration handles particles without intact or dropped bonds, which is every particle of a
//! molecular-dynamics scene. Bonds change owners when their ends change cells (their history
//! travels with them), so a scene that has bonds, or a particle that has moved further than
//! the next procCube along an axis, rebuilds by a shuffle instead; every worker decides the
//! same.

use crate::engine::bonds::BondList;
use crate::engine::cells::Domain;
use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::comm::f64s;
use crate::parallel::decomposition::{particle_plan, CellPlan};
use crate::parallel::shuffle::wrap;
use crate::parallel::Cube;

/// Tags of the migration messages: upward then downward along x, y and z.
const MIGRATE_TAG: u32 = 16;

/// Fixed part of a migrating particle's record: gid, x0 (3), volume, material, initial bonds,
/// lost bonds, and the procCubes it still has to cross along each axis (3).
const HEAD: usize = 11;

impl<M: Model> Cube<M> {
    /// Puts every particle in the cell of its current position, its ghosts current, for a
    /// neighbour-list rebuild: by migration where every worker can, else by a shuffle. Every
    /// worker must call it at the same step.
    pub(crate) fn rebin(&mut self) -> Result<(), String> {
        let steps = if self.sim.bonds.is_empty() && self.dropped.is_empty() {
            self.steps_home()
        } else {
            None
        };
        let blocked = if steps.is_some() { 0.0 } else { 1.0 };
        let everyone_can = self.team().max(blocked) == 0.0;
        match steps {
            Some(steps) if everyone_can => {
                self.rebuilds[0] += 1;
                self.migrate(steps);
                self.count_particles()
            }
            _ => {
                self.rebuilds[1] += 1;
                self.shuffle_now()
            }
        }
    }

    /// Checks that migration kept every particle exactly once (one reduction).
    fn count_particles(&mut self) -> Result<(), String> {
        let owned = self.sim.particles.n_owned as f64;
        let total = self.team().sum(owned);
        if total as usize == self.global_particles {
            Ok(())
        } else {
            Err(format!(
                "migration at step {} left {total} particles where the scene has {}; this is a bug in PDQ, please report it with the deck",
                self.sim.step, self.global_particles
            ))
        }
    }

    /// Wraps owned positions into a periodic box and returns, for each owned particle, the
    /// procCubes to cross (-1, 0, 1 along each axis) to the owner of its cell; `None` if some
    /// particle is further than the next procCube along an axis.
    fn steps_home(&mut self) -> Option<Vec<[i8; 3]>> {
        let layout = &self.layout;
        let d = &layout.domain;
        let lo = self.plan.cells.lo;
        let p = &mut self.sim.particles;
        let mut steps = Vec::with_capacity(p.n_owned);
        for i in 0..p.n_owned {
            let (w, shift) = wrap(p.pos(i), d);
            p.alter[i].as_mut_slice()[..3].copy_from_slice(&w);
            for (x, s) in p.x0[i].iter_mut().zip(shift) {
                *x -= s;
            }
            let cell = d.grid.coords(&w);
            let mut step = [0i8; 3];
            for a in 0..3 {
                let cuts = &layout.cuts[a];
                let along = |c: usize| cuts.partition_point(|&x| x <= c) as i64 - 1;
                let k = along(cell[a]) - along(lo[a] as usize);
                let n = layout.procs[a] as i64;
                step[a] = match (k, d.periodic[a]) {
                    (0, _) => 0,
                    (-1 | 1, false) => k as i8,
                    (_, true) if k.rem_euclid(n) == 1 => 1,
                    (_, true) if k.rem_euclid(n) == n - 1 => -1,
                    _ => return None,
                };
            }
            steps.push(step);
        }
        Some(steps)
    }

    /// Moves the particles along x, then y, then z, to their cells' owners, sorts them into
    /// cells, brings the ghosts and rebuilds the neighbour lists.
    fn migrate(&mut self, steps: Vec<[i8; 3]>) {
        let mut owned = Owned::<M>::take(self, steps);
        let rank = self.plan.rank;
        let mut inp = Vec::new();
        for a in 0..3 {
            let periodic = self.layout.domain.periodic[a];
            for (k, dir) in [1i8, -1].into_iter().enumerate() {
                let next = |d: i8| {
                    self.layout
                        .neighbour(rank, a, d as i64, periodic)
                        .map(|(r, _)| r)
                };
                let (to, from) = (next(dir), next(-dir));
                let out = owned.leave(a, dir);
                assert!(
                    to.is_some() || out.is_empty(),
                    "migration: particles leave procCube {rank} where it has no neighbour"
                );
                let tag = MIGRATE_TAG + 2 * a as u32 + k as u32;
                self.wall
                    .transport()
                    .exchange(tag, to, bytemuck::cast_slice(&out), from, &mut inp);
                // Without a sender (a non-periodic face) nothing arrives: `inp` still holds
                // the last message.
                if from.is_some() {
                    owned.arrive(&f64s(&inp));
                }
            }
        }
        let counts = owned.sort_into_cells(&self.plan.cells, &self.layout.domain);
        self.settle(owned, counts);
        self.build_pair_list();
    }

    /// Installs the migrated particles as the owned ones, cell by cell, and brings the ghosts
    /// along the five messages: first each held cell's count, then the particles.
    fn settle(&mut self, owned: Owned<M>, mut counts: Vec<u32>) {
        let cells = self.plan.cells.clone();
        self.wall.set_stages(cells.cell_stages());
        self.wall.forward(&mut counts, false);
        let total = counts.iter().map(|&c| c as usize).sum::<usize>();
        let n_owned = owned.gid.len();
        let mut gid = owned.gid;
        gid.resize(total, 0);
        let period = self.layout.domain.period;
        let mut plan = particle_plan(self.plan.rank, &cells, &counts, gid, period);
        self.wall.set_stages(plan.stages.clone());
        self.wall.forward(&mut plan.global, false);

        let mut x0 = with_slots(owned.x0, total);
        let mut volume = with_slots(owned.volume, total);
        let mut material = with_slots(owned.material, total);
        self.wall.forward(&mut x0, true);
        self.wall.forward(&mut volume, false);
        self.wall.forward(&mut material, false);
        let mut part = Particles::new(&self.sim.model, plan.global.clone(), x0, volume, material);
        part.n_owned = n_owned;
        part.alter[..n_owned].copy_from_slice(&owned.alter);
        part.force[..n_owned].copy_from_slice(&owned.force);
        part.fixed[..n_owned].copy_from_slice(&owned.fixed);
        self.wall.forward(&mut part.alter, true);
        self.wall.forward(&mut part.fixed, false);

        let mut initial = owned.initial;
        initial.resize(total, 0);
        let list = BondList::assemble(
            vec![0; n_owned + 1],
            Vec::new(),
            Default::default(),
            initial,
        );
        self.lost = owned.lost;
        self.install(part, list, plan);
    }
}

/// Owned particles in the middle of a migration, one array per attribute.
struct Owned<M: Model> {
    gid: Vec<u32>,
    x0: Vec<[f64; 3]>,
    volume: Vec<f64>,
    material: Vec<u16>,
    initial: Vec<u32>,
    lost: Vec<u32>,
    /// The procCubes still to cross along each axis: -1, 0 or 1.
    steps: Vec<[i8; 3]>,
    alter: Vec<M::Alter>,
    force: Vec<M::Force>,
    fixed: Vec<M::Fixed>,
}

impl<M: Model> Owned<M> {
    fn take(cube: &Cube<M>, steps: Vec<[i8; 3]>) -> Self {
        let p = &cube.sim.particles;
        let n = p.n_owned;
        Owned {
            gid: p.gid[..n].to_vec(),
            x0: p.x0[..n].to_vec(),
            volume: p.volume[..n].to_vec(),
            material: p.material[..n].to_vec(),
            initial: cube.sim.bonds.initial[..n].to_vec(),
            lost: cube.lost.clone(),
            steps,
            alter: p.alter[..n].to_vec(),
            force: p.force[..n].to_vec(),
            fixed: p.fixed[..n].to_vec(),
        }
    }

    fn record_len() -> usize {
        HEAD + <M::Alter as Attributes>::LEN
            + <M::Force as Attributes>::LEN
            + <M::Fixed as Attributes>::LEN
    }

    /// Takes out the particles that cross along `axis` in direction `dir`, as records; the
    /// ones that stay keep their order.
    fn leave(&mut self, axis: usize, dir: i8) -> Vec<f64> {
        let mut out = Vec::new();
        let mut kept = 0;
        for i in 0..self.gid.len() {
            if self.steps[i][axis] == dir {
                let mut steps = self.steps[i];
                steps[axis] = 0;
                out.push(self.gid[i] as f64);
                out.extend_from_slice(&self.x0[i]);
                out.extend_from_slice(&[
                    self.volume[i],
                    self.material[i] as f64,
                    self.initial[i] as f64,
                    self.lost[i] as f64,
                ]);
                out.extend(steps.map(|s| s as f64));
                out.extend_from_slice(self.alter[i].as_slice());
                out.extend_from_slice(self.force[i].as_slice());
                out.extend_from_slice(self.fixed[i].as_slice());
            } else {
                self.gid[kept] = self.gid[i];
                self.x0[kept] = self.x0[i];
                self.volume[kept] = self.volume[i];
                self.material[kept] = self.material[i];
                self.initial[kept] = self.initial[i];
                self.lost[kept] = self.lost[i];
                self.steps[kept] = self.steps[i];
                self.alter[kept] = self.alter[i];
                self.force[kept] = self.force[i];
                self.fixed[kept] = self.fixed[i];
                kept += 1;
            }
        }
        self.truncate(kept);
        out
    }

    fn truncate(&mut self, n: usize) {
        self.gid.truncate(n);
        self.x0.truncate(n);
        self.volume.truncate(n);
        self.material.truncate(n);
        self.initial.truncate(n);
        self.lost.truncate(n);
        self.steps.truncate(n);
        self.alter.truncate(n);
        self.force.truncate(n);
        self.fixed.truncate(n);
    }

    /// Appends the particles of `records` (made by [`Owned::leave`]).
    fn arrive(&mut self, records: &[f64]) {
        let (la, lf) = (<M::Alter as Attributes>::LEN, <M::Force as Attributes>::LEN);
        for r in records.chunks_exact(Self::record_len()) {
            self.gid.push(r[0] as u32);
            self.x0.push([r[1], r[2], r[3]]);
            self.volume.push(r[4]);
            self.material.push(r[5] as u16);
            self.initial.push(r[6] as u32);
            self.lost.push(r[7] as u32);
            self.steps.push([r[8] as i8, r[9] as i8, r[10] as i8]);
            let (alter, rest) = r[HEAD..].split_at(la);
            let (force, fixed) = rest.split_at(lf);
            let mut a = M::Alter::default();
            a.as_mut_slice().copy_from_slice(alter);
            self.alter.push(a);
            let mut f = M::Force::default();
            f.as_mut_slice().copy_from_slice(force);
            self.force.push(f);
            let mut x = M::Fixed::default();
            x.as_mut_slice().copy_from_slice(fixed);
            self.fixed.push(x);
        }
    }

    /// Orders the particles by owned cell, by global id within a cell (as the layout's binning
    /// does), and returns each held cell's count (ghost cells zero).
    fn sort_into_cells(&mut self, cells: &CellPlan, domain: &Domain) -> Vec<u32> {
        let cell: Vec<usize> = self
            .alter
            .iter()
            .map(|a| {
                let s = a.as_slice();
                cells.owned_index(domain.grid.coords(&[s[0], s[1], s[2]]))
            })
            .collect();
        let mut order: Vec<usize> = (0..self.gid.len()).collect();
        order.sort_unstable_by_key(|&i| (cell[i], self.gid[i]));
        let mut counts = vec![0u32; cells.held.len()];
        for &c in &cell {
            counts[c] += 1;
        }
        *self = Owned {
            gid: pick(&order, &self.gid),
            x0: pick(&order, &self.x0),
            volume: pick(&order, &self.volume),
            material: pick(&order, &self.material),
            initial: pick(&order, &self.initial),
            lost: pick(&order, &self.lost),
            steps: pick(&order, &self.steps),
            alter: pick(&order, &self.alter),
            force: pick(&order, &self.force),
            fixed: pick(&order, &self.fixed),
        };
        counts
    }
}

/// `v` with default slots up to `total` (the ghosts, filled by the messages).
fn with_slots<T: Clone + Default>(mut v: Vec<T>, total: usize) -> Vec<T> {
    v.resize(total, T::default());
    v
}

/// `v` in the order of `order`.
fn pick<T: Copy>(order: &[usize], v: &[T]) -> Vec<T> {
    order.iter().map(|&i| v[i]).collect()
}
