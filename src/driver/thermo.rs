//! Temperature and pressure of a history row (molecular dynamics): what turns its kinetic
//! energy and virial into them.

use super::record::Row;
use crate::input::setup::Setup;
use crate::model::Model;

/// What turns a row's kinetic energy and virial into temperature and pressure: Boltzmann's
/// constant in the deck's units, the translational degrees of freedom and the volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Thermo {
    pub boltzmann: f64,
    pub dof: f64,
    pub volume: f64,
}

impl Thermo {
    /// The run's constants. Degrees of freedom: the free translational DOFs, less 3 for the
    /// conserved momentum when no particle is held (LAMMPS's `compute temp`: 3N − 3). Volume:
    /// along a periodic axis its period, along any other the particles' extent plus one
    /// lattice spacing (the space their sites stand for).
    pub fn of_setup<M: Model>(setup: &Setup<M>, boltzmann: f64) -> Thermo {
        let free = setup.sim.free_dofs();
        let n2 = crate::model::second_order::<M>();
        let translational = free
            .chunks(n2.max(1))
            .map(|d| d.iter().take(3).filter(|&&f| f).count())
            .sum::<usize>();
        let held = translational < 3 * setup.sim.particles.n_owned;
        let dof = translational as f64 - if held { 0.0 } else { 3.0 };
        let p = &setup.sim.particles;
        let mut volume = 1.0;
        for a in 0..3 {
            volume *= if setup.domain.periodic[a] {
                setup.domain.period[a]
            } else {
                let along = (0..p.n_owned).map(|i| p.pos(i)[a]);
                let lo = along.clone().fold(f64::INFINITY, f64::min);
                let hi = along.fold(f64::NEG_INFINITY, f64::max);
                hi - lo + setup.spacing
            };
        }
        Thermo {
            boltzmann,
            dof: dof.max(1.0),
            volume,
        }
    }

    /// Temperature 2 KE/(dof k_B) and pressure (2 KE + W)/(3V), W = Σ x·F the virial of
    /// the internal forces (LAMMPS's `compute pressure`), V stretched by `[deform]`.
    pub fn of(&self, row: &Row, stretch: [f64; 3]) -> [f64; 2] {
        let (ke, volume) = (
            row.kinetic_energy,
            self.volume * stretch.iter().product::<f64>(),
        );
        [
            2.0 * ke / (self.dof * self.boltzmann),
            (2.0 * ke + row.virial) / (3.0 * volume),
        ]
    }
}
