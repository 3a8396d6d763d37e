//! A periodic box that changes with time (`[deform]`, as LAMMPS's `fix deform … erate …
//! remap x`): each axis's length is L(t) = L0 (1 + rate·t) about the box's fixed centre, and
//! the particles are mapped with it (affinely, velocities unchanged). At the end of every
//! `every`-th step (after the second half-kick, where LAMMPS's fix changes the box, so that the
//! two codes agree to round-off) the procCubes stretch their cells and the owned positions alike, and their ghost messages add
//! the new periods to the images they bring. The neighbour lists stay until the particles
//! have moved half the skin *relative to the box* (the list's reference positions are mapped
//! too), as in LAMMPS; a shrinking box spends part of the skin, which the list accounts for.

use crate::engine::cells::Domain;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::Cube;

/// The box's change with time, and what it was at t = 0.
#[derive(Clone, Debug)]
pub struct Deform {
    /// Engineering strain rate of each axis, per unit time.
    pub rate: [f64; 3],
    /// Steps between changes of the box.
    pub every: u64,
    /// The layout's cells at t = 0.
    start: Domain,
    /// The box now, as a multiple of the one at t = 0, per axis.
    stretch: [f64; 3],
}

impl Deform {
    /// The box changing from `start` (a layout's domain at t = 0).
    pub fn new(rate: [f64; 3], every: u64, start: Domain) -> Self {
        Deform {
            rate,
            every: every.max(1),
            start,
            stretch: [1.0; 3],
        }
    }

    /// L(t)/L0 along each axis.
    pub fn stretch_at(&self, t: f64) -> [f64; 3] {
        self.rate.map(|r| 1.0 + r * t)
    }

    /// The box now as a multiple of the one at t = 0, per axis.
    pub fn stretch(&self) -> [f64; 3] {
        self.stretch
    }

    /// The centre of the box (it stays where it was).
    pub fn centre(&self) -> [f64; 3] {
        let g = &self.start.grid;
        [0, 1, 2].map(|a| g.origin[a] + 0.5 * g.dims[a] as f64 * g.size[a])
    }

    /// Where the point `x` of the box at t = 0 is in the box now.
    pub fn map(&self, x: [f64; 3]) -> [f64; 3] {
        let c = self.centre();
        [0, 1, 2].map(|a| c[a] + (x[a] - c[a]) * self.stretch[a])
    }

    /// The cells stretched by `stretch` about the centre; an error when a cell would be
    /// narrower than `reach` (the pair law's cutoff + skin), or the box not positive.
    fn domain_at(&self, stretch: [f64; 3], reach: f64, t: f64) -> Result<Domain, String> {
        let c = self.centre();
        let mut d = self.start.clone();
        for a in 0..3 {
            let s = stretch[a];
            let size = self.start.grid.size[a] * s;
            if !(s > 0.0 && size >= reach) {
                return Err(format!(
                    "[deform] at t = {t:.6e} the box along {} is {s:.4} times its length at t = 0: its cells ({size:.6e}) would be narrower than the pair law's reach (cutoff + skin = {reach:.6e}); end the run earlier or compress less",
                    ["x", "y", "z"][a]
                ));
            }
            d.grid.size[a] = size;
            d.grid.origin[a] = c[a] + (self.start.grid.origin[a] - c[a]) * s;
            d.period[a] = self.start.period[a] * s;
        }
        Ok(d)
    }
}

impl<M: Model> Cube<M> {
    /// The box at time `t` without moving the particles (a restart: the checkpoint holds
    /// positions in the box of its time). The next neighbour-list build must rebin.
    pub(crate) fn set_box(&mut self, t: f64) -> Result<(), String> {
        let reach = self.reach();
        if let Some(d) = &mut self.deform {
            let stretch = d.stretch_at(t);
            self.layout.domain = d.domain_at(stretch, reach, t)?;
            d.stretch = stretch;
        }
        Ok(())
    }

    /// Changes the box to the one at the current time when due (every worker decides the
    /// same, from the step count): the cells, the owned particles, the neighbour list's
    /// reference positions and the ghost messages' periodic offsets. Ghosts get their new
    /// places at the next force evaluation's exchange.
    pub(crate) fn deform_box(&mut self) -> Result<(), String> {
        let reach = self.reach();
        let (t, step) = (self.sim.time, self.sim.step);
        let Some(d) = &mut self.deform else {
            return Ok(());
        };
        if !step.is_multiple_of(d.every) {
            return Ok(());
        }
        let stretch = d.stretch_at(t);
        self.layout.domain = d.domain_at(stretch, reach, t)?;
        let c = d.centre();
        let by = [0, 1, 2].map(|a| stretch[a] / d.stretch[a]);
        d.stretch = stretch;
        let p = &mut self.sim.particles;
        for i in 0..p.n_owned {
            let x = &mut p.alter[i].as_mut_slice()[..3];
            for a in 0..3 {
                x[a] = c[a] + (x[a] - c[a]) * by[a];
            }
        }
        if let Some(pairs) = &mut self.sim.pairs {
            pairs.deformed(c, by);
        }
        // Each message's offset is a whole number of periods (the reference positions' offsets,
        // `plan.shift`, are left: only bonds read them, and a deforming scene has none).
        let period = self.layout.domain.period;
        let shifts = self
            .plan
            .cells
            .stages
            .iter()
            .map(|st| [0, 1, 2].map(|a| st.wraps[a] as f64 * period[a]));
        for (st, s) in self.plan.stages.iter_mut().zip(shifts.clone()) {
            st.shift = s;
        }
        self.wall.set_shifts(shifts);
        Ok(())
    }

    /// The pair law's cutoff + skin (0 without one): the narrowest a cell may be.
    fn reach(&self) -> f64 {
        self.sim.pairs.as_ref().map_or(0.0, |p| p.reach())
    }
}
