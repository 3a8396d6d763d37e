//! How a run gets from one step to the next, behind one interface ([`Solver`]): explicit time
//! stepping ([`Explicit`]), adaptive dynamic relaxation to equilibrium at each load step
//! ([`Adr`], in [`adr`]), and Newton's method ([`Newton`], in [`newton`]) with the factored
//! tangent ([`implicit`]) or matrix-free conjugate gradients ([`krylov`]). Each solver type owns
//! its load step and the state it keeps between steps (ADR's mass scale, Newton's factored
//! tangent); the procCube it is handed is only data. The
//! static start of an explicit run ([`static_start`]) is one Newton load step on the whole
//! scene.

pub mod adr;
pub mod coarse;
pub mod implicit;
pub mod krylov;
pub mod newton;
pub mod static_start;

use crate::model::Model;
use crate::parallel::Cube;
pub use adr::{Adr, Relaxed};
pub use newton::{MatrixFree, Newton};

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

/// Velocity Verlet or leapfrog time steps (the scene's integrator), one force
/// evaluation each.
pub struct Explicit;

impl<M: Model> Solver<M> for Explicit {
    fn advance(&mut self, cube: &mut Cube<M>, _step: u64) -> Result<Option<Relaxed>, String> {
        cube.advance()?;
        Ok(None)
    }
    fn quasi_static(&self) -> bool {
        false
    }
}
