//! Particle shuffling (thesis 3.11): when particles have left their procCubes, the cuts are
//! drawn again from where the particles are now (bond work per layer of cells, summed over the
//! procCubes) and every particle migrates to its new owner with its attributes, its bonds and
//! their history ([`crate::parallel::migrate`]).
//!
//! Bond families never change in peridynamics, so a scene whose particles stay near their
//! reference cells never needs this (ghost lists are drawn from reference cells and stay
//! correct under any motion); it pays off when matter travels far, where it keeps each
//! procCube's particles and their partners together and the load balanced. A shuffle is a
//! collective step, but its messages go to neighbouring procCubes only: the cells' counts are
//! one reduction, the particles and bonds cross one face at a time. Where the balanced cuts
//! would send some particle further than the next procCube, the shuffle keeps the cuts it has
//! (every worker decides the same), and only a particle further than that is an error. Decks
//! ask for it every N steps (`shuffle_every`).
//!
//! Intact bonds are then evaluated from the cells of their ends' current positions, which must
//! be neighbours: cells carry a skin over the horizon for this. Broken bonds carry no force
//! ever again, so a shuffle drops them from the bond lists and keeps them as counts (damage)
//! and as id pairs (the broken-bond output).

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::model::Model;
use crate::parallel::comm::Reduce;
use crate::parallel::decomposition::Layout;
use crate::parallel::Cube;

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

    /// Draws the cuts again and migrates if any particle left its procCube. Every worker must
    /// call it at the same step; returns whether particles moved.
    pub fn shuffle(&mut self) -> Result<bool, String> {
        if !self.someone_left() {
            return Ok(false);
        }
        self.wrap_owned();
        let balanced = self.balanced_layout()?;
        let (layout, steps) = match self.particle_steps(&balanced) {
            Ok(steps) => (balanced, steps),
            Err(_) => {
                let kept = self.layout.clone();
                match self.particle_steps(&kept) {
                    Ok(steps) => (kept, steps),
                    Err(far) => return Err(self.too_far(far)),
                }
            }
        };
        self.migrate_to(layout, steps)?;
        Ok(true)
    }

    /// The layout with the same procCubes cut by the bond work of the particles where they are
    /// now (their cell counts summed over the procCubes). Positions must be wrapped.
    fn balanced_layout(&mut self) -> Result<Layout, String> {
        let domain = self.layout.domain.for_procs(self.layout.procs);
        let grid = &domain.grid;
        let p = &self.sim.particles;
        let mut count = vec![0.0f64; grid.len()];
        for i in 0..p.n_owned {
            count[grid.index(grid.coords(&p.pos(i)))] += 1.0;
        }
        self.team().reduce(&mut count, Reduce::Sum);
        let mut start = Vec::with_capacity(count.len() + 1);
        start.push(0u32);
        for c in &count {
            start.push(start[start.len() - 1] + *c as u32);
        }
        let cells = |_: &crate::engine::cells::Domain| (start.clone(), Vec::new());
        Layout::with_cells(self.layout.procs, &domain, self.layout.walls, &cells)
    }

    /// Puts new particles, bonds and plan in place of the old (the boundary conditions, loads
    /// and probes already point at the new local indices).
    pub(crate) fn install(
        &mut self,
        part: Particles<M>,
        list: BondList<M::Bond>,
        plan: crate::parallel::decomposition::CubePlan,
    ) {
        self.sim.particles = part;
        self.sim.bonds = list;
        self.wall.set_stages(plan.stages.clone());
        self.plan = plan;
    }
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
