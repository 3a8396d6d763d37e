//! Migration (thesis 3.11, as LAMMPS's `exchange` and `borders`): each particle that has left
//! its procCube's cells goes to the neighbouring procCube that owns its current cell, with its
//! attributes; every bond goes, with its history, to the procCube that evaluates it from the
//! ends' new cells; then every procCube sorts its particles into cells and receives its ghosts
//! again along the five messages. Nothing is gathered and nothing goes further than the next
//! procCubes: the work and the messages are each procCube's own.
//!
//! A particle may cross one procCube face per axis (26 neighbours), never more: one that has
//! gone further since particles last changed procCube is an error naming it. A bond may have
//! to cross two, when its evaluating end changes to the partner and the partner moved on: bond
//! records take as many hops as the furthest needs, one face at a time. Broken bonds carry no
//! force again, so migration drops them from the bond lists and keeps them as counts (damage)
//! and as id pairs (the broken-bond output), with the owner of the smaller id.

use crate::engine::cells::Domain;
use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::comm::f64s;
use crate::parallel::decomposition::{cell_plans, particle_plan, CellPlan, CubePlan, Layout};
use crate::parallel::shuffle::wrap;
use crate::parallel::Cube;

/// Tags of the particle messages (upward then downward along x, y and z), then the other
/// records'.
const MIGRATE_TAG: u32 = 16;
const LETTER_TAG: u32 = 24;

/// Fixed part of a migrating particle's record: gid, x0 (3), volume, material, initial bonds,
/// lost bonds, and the procCubes it still has to cross along each axis (3).
const HEAD: usize = 11;

impl<M: Model> Cube<M> {
    /// Puts every particle in the cell of its current position, its ghosts current, for a
    /// neighbour-list rebuild; the layout's cuts stay. Every worker must call it at the same
    /// step.
    pub(crate) fn rebin(&mut self) -> Result<(), String> {
        self.wrap_owned();
        let layout = self.layout.clone();
        match self.particle_steps(&layout) {
            Ok(steps) => {
                self.rebuilds += 1;
                self.migrate_to(layout, steps)
            }
            Err(far) => Err(self.too_far(far)),
        }
    }

    /// Moves every owned position into the periodic box; reference positions move with them,
    /// so displacements are unchanged.
    pub(crate) fn wrap_owned(&mut self) {
        let d = &self.layout.domain;
        let p = &mut self.sim.particles;
        for i in 0..p.n_owned {
            let (w, shift) = wrap(p.pos(i), d);
            p.alter[i].as_mut_slice()[..3].copy_from_slice(&w);
            for (x, s) in p.x0[i].iter_mut().zip(shift) {
                *x -= s;
            }
        }
    }

    /// For each owned particle, the procCubes to cross (-1, 0, 1 along each axis) to the owner
    /// of its cell in `layout`; on every worker alike, `Err` with the largest global id of a
    /// particle further than that (a reduction).
    pub(crate) fn particle_steps(&mut self, layout: &Layout) -> Result<Vec<[i8; 3]>, u32> {
        let here = layout.coords(self.plan.rank);
        let p = &self.sim.particles;
        let mut steps = Vec::with_capacity(p.n_owned);
        let mut far = -1.0f64;
        for i in 0..p.n_owned {
            let s = cube_steps(layout, here, layout.domain.grid.coords(&p.pos(i)));
            if s.iter().any(|v| v.abs() > 1) {
                far = far.max(p.gid[i] as f64);
            }
            steps.push(s.map(|v| v.clamp(-1, 1) as i8));
        }
        match self.team().max(far) {
            f if f >= 0.0 => Err(f as u32),
            _ => Ok(steps),
        }
    }

    /// The error for particle `gid`, too far from its procCube to migrate (every worker
    /// returns it; the owner adds where the particle is).
    pub(crate) fn too_far(&self, gid: u32) -> String {
        let p = &self.sim.particles;
        let at = (0..p.n_owned)
            .find(|&i| p.gid[i] == gid)
            .map(|i| {
                let x = p.pos(i);
                format!(" (now at ({:.6e}, {:.6e}, {:.6e}))", x[0], x[1], x[2])
            })
            .unwrap_or_default();
        format!(
            "particle {gid}{at} moved further than the next procCube since particles last changed procCube (step {}): migration moves particles to neighbouring procCubes only. A particle this fast usually means the run is unstable (reduce the time step); otherwise let particles change procCube more often ([parallel] shuffle_every)",
            self.sim.step
        )
    }

    /// Moves the particles by `steps` and the bonds to their evaluating procCubes in `layout`
    /// (this one's cuts, or new ones as close), sorts them into cells, brings the ghosts and
    /// rebuilds the neighbour lists.
    pub(crate) fn migrate_to(&mut self, layout: Layout, steps: Vec<[i8; 3]>) -> Result<(), String> {
        let rank = self.plan.rank;
        let cells = cell_plans(&layout).swap_remove(rank);
        let before = self.sim.bonds.len() + self.dropped.len();
        // The particles first: `letters` frees the bond list, their initial counts with it.
        let mut owned = Owned::<M>::take(self, steps);
        let (mut letters, kept) = self.letters(&layout)?;
        self.route(MIGRATE_TAG, &mut owned);
        self.route(LETTER_TAG, &mut letters);
        let counts = owned.sort_into_cells(&cells, &layout.domain);
        self.layout = layout;
        let (part, plan, initial) = self.settle(owned, cells, counts);
        let list = self.place(letters, kept, &plan, initial);
        let list = self.agree(list)?;
        self.install(part, list, plan);
        self.build_pair_list();
        self.count_kept(before)
    }

    /// `r` where every worker succeeded; an error on every worker where any failed (a
    /// reduction), so that none waits for a message that will not come.
    pub(crate) fn agree<T>(&mut self, r: Result<T, String>) -> Result<T, String> {
        let failed = self.team().max(if r.is_err() { 1.0 } else { 0.0 }) > 0.0;
        match r {
            Ok(_) if failed => Err(format!(
                "migration at step {} failed on another procCube (its worker says why)",
                self.sim.step
            )),
            r => r,
        }
    }

    /// Checks that migration kept every particle and every bond exactly once (a reduction).
    fn count_kept(&mut self, bonds_before: usize) -> Result<(), String> {
        let after = self.sim.bonds.len() + self.dropped.len();
        let mut v = [
            self.sim.particles.n_owned as f64,
            bonds_before as f64,
            after as f64,
        ];
        self.team()
            .reduce(&mut v, crate::parallel::comm::Reduce::Sum);
        if v[0] as usize == self.global_particles && v[1] == v[2] {
            Ok(())
        } else {
            Err(format!(
                "migration at step {} left {} particles where the scene has {}, and {} bonds of {}; this is a bug in PDQ, please report it with the deck",
                self.sim.step, v[0], self.global_particles, v[2], v[1]
            ))
        }
    }

    /// Carries `travellers` to their procCubes: along x, then y, then z, one face at a time,
    /// as many hops as the furthest needs. Every worker must call it.
    fn route(&mut self, tag: u32, travellers: &mut impl Travellers) {
        let rank = self.plan.rank;
        let mut inp = Vec::new();
        for a in 0..3 {
            let periodic = self.layout.domain.periodic[a];
            let hops = self.team().max(travellers.furthest(a) as f64) as usize;
            for _ in 0..hops {
                for (k, dir) in [1i8, -1].into_iter().enumerate() {
                    let next = |d: i8| {
                        self.layout
                            .neighbour(rank, a, d as i64, periodic)
                            .map(|(r, _)| r)
                    };
                    let (to, from) = (next(dir), next(-dir));
                    let out = travellers.leave(a, dir);
                    assert!(
                        to.is_some() || out.is_empty(),
                        "migration: records leave procCube {rank} where it has no neighbour"
                    );
                    let tag = tag + 2 * a as u32 + k as u32;
                    self.wall.transport().exchange(
                        tag,
                        to,
                        bytemuck::cast_slice(&out),
                        from,
                        &mut inp,
                    );
                    // Without a sender (a non-periodic face) nothing arrives: `inp` still
                    // holds the last message.
                    if from.is_some() {
                        travellers.arrive(&f64s(&inp));
                    }
                }
            }
        }
    }

    /// The migrated particles as the owned ones, cell by cell, with their ghosts brought along
    /// the five messages (first each held cell's count, then the particles); the new plan and
    /// every local particle's initial bond count.
    fn settle(
        &mut self,
        owned: Owned<M>,
        cells: CellPlan,
        mut counts: Vec<u32>,
    ) -> (Particles<M>, CubePlan, Vec<u32>) {
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
        self.lost = owned.lost;
        (part, plan, with_slots(owned.initial, total))
    }
}

/// Records on their way through the procCubes, each knowing how many faces it still has to
/// cross along each axis.
pub(crate) trait Travellers {
    /// The most faces any record here still has to cross along `axis`.
    fn furthest(&self, axis: usize) -> i64;
    /// Takes out, as f64 records, those that cross along `axis` in direction `dir` (one face
    /// fewer to go); the ones that stay keep their order.
    fn leave(&mut self, axis: usize, dir: i8) -> Vec<f64>;
    /// Appends the records of a message made by [`Travellers::leave`].
    fn arrive(&mut self, records: &[f64]);
}

/// The procCube of `cell` (grid coordinates) in `layout`.
pub(crate) fn cube_of(layout: &Layout, cell: [usize; 3]) -> [usize; 3] {
    [0, 1, 2].map(|a| layout.cuts[a].partition_point(|&x| x <= cell[a]) - 1)
}

/// The faces to cross along each axis from procCube `here` to the owner of `cell`, the short
/// way round a periodic axis.
pub(crate) fn cube_steps(layout: &Layout, here: [usize; 3], cell: [usize; 3]) -> [i64; 3] {
    let there = cube_of(layout, cell);
    [0, 1, 2].map(|a| {
        let k = there[a] as i64 - here[a] as i64;
        let n = layout.procs[a] as i64;
        if layout.domain.periodic[a] {
            let up = k.rem_euclid(n);
            if up <= n / 2 {
                up
            } else {
                up - n
            }
        } else {
            k
        }
    })
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

impl<M: Model> Travellers for Owned<M> {
    fn furthest(&self, axis: usize) -> i64 {
        self.steps
            .iter()
            .map(|s| s[axis].unsigned_abs() as i64)
            .max()
            .unwrap_or(0)
    }

    fn leave(&mut self, axis: usize, dir: i8) -> Vec<f64> {
        let mut out = Vec::new();
        let mut kept = 0;
        for i in 0..self.gid.len() {
            if self.steps[i][axis].signum() == dir {
                let mut steps = self.steps[i];
                steps[axis] -= dir;
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
