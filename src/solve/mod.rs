//! How a run gets from one step to the next, behind one interface ([`Solver`]): explicit time
//! stepping ([`Explicit`]), adaptive dynamic relaxation to equilibrium at each load step
//! ([`adr`]), and Newton's method with the assembled tangent ([`implicit`]). The static start
//! of an explicit run ([`static_start`]) is one implicit load step on the whole scene.

pub mod adr;
pub mod implicit;
pub mod static_start;

use crate::model::Model;
use crate::parallel::Cube;
pub use adr::Relaxed;

/// Advances a procCube by one step of the run: a time step, or a load step solved to
/// equilibrium. Every worker calls it at the same step (the solvers reduce over procCubes).
pub trait Solver<M: Model>: Send {
    /// Advances `cube` to `step`; a quasi-static solver reports how its solve went.
    fn advance(&mut self, cube: &mut Cube<M>, step: u64) -> Result<Option<Relaxed>, String>;
    /// Whether steps are load steps (no inertia between them), not time steps.
    fn quasi_static(&self) -> bool {
        true
    }
}

/// Velocity Verlet or semi-implicit Euler time steps (the scene's integrator), one force
/// evaluation each.
pub struct Explicit;

impl<M: Model> Solver<M> for Explicit {
    fn advance(&mut self, cube: &mut Cube<M>, _step: u64) -> Result<Option<Relaxed>, String> {
        cube.advance();
        Ok(None)
    }
    fn quasi_static(&self) -> bool {
        false
    }
}

/// Adaptive dynamic relaxation (Kilic & Madenci 2010, docs/theory.md §5) with these
/// fictitious masses; they double, for this and every later load step, when a step diverges.
pub struct Adr {
    pub mass: adr::FictitiousMass,
    pub tolerance: f64,
    pub max_iterations: u64,
    /// Whether this worker reports a divergence (the root only).
    pub report: bool,
    mass_scale: f64,
}

impl Adr {
    pub fn new(
        mass: adr::FictitiousMass,
        tolerance: f64,
        max_iterations: u64,
        report: bool,
    ) -> Self {
        Adr {
            mass,
            tolerance,
            max_iterations,
            report,
            mass_scale: 1.0,
        }
    }
}

impl<M: Model> Solver<M> for Adr {
    fn advance(&mut self, cube: &mut Cube<M>, step: u64) -> Result<Option<Relaxed>, String> {
        let before = self.mass_scale;
        let r = cube.relax_step(
            &self.mass.by_gid,
            &mut self.mass_scale,
            self.tolerance,
            self.max_iterations,
        );
        if self.mass_scale != before && self.report {
            eprintln!(
                "warning    relaxation diverged at step {step}: repeated with the fictitious masses ×{}{}",
                self.mass_scale,
                if r.diverged { ", and diverged again" } else { "" }
            );
        }
        Ok(Some(r))
    }
}

/// Newton's method with the assembled tangent stiffness, on one procCube; the tangent is kept
/// between load steps while no bond breaks.
pub struct Newton {
    pub tolerance: f64,
    pub max_iterations: u64,
    /// `[time] stop_at_broken_bonds` (0 = off): the iterations end there.
    pub stop_at_broken: u64,
    tangent: Option<implicit::Tangent>,
}

impl Newton {
    pub fn new(tolerance: f64, max_iterations: u64, stop_at_broken: u64) -> Self {
        Newton {
            tolerance,
            max_iterations,
            stop_at_broken,
            tangent: None,
        }
    }
}

impl<M: Model> Solver<M> for Newton {
    fn advance(&mut self, cube: &mut Cube<M>, _step: u64) -> Result<Option<Relaxed>, String> {
        cube.implicit_step(
            &mut self.tangent,
            self.tolerance,
            self.max_iterations,
            self.stop_at_broken,
        )
        .map(Some)
        .map_err(|e| format!("{e} (or use [solver] kind = \"adr\", which assembles no tangent)"))
    }
}
