//! `pdq run` and `pdq check`: a deck's scene laid out on procCubes ([`run`]), stepped by its
//! solver with its outputs and stop criteria observing (`step_loop`), recorded (`record`:
//! the typed history row, frames and the final state gathered by global id), summarised;
//! `check` describes a deck without running it; `post` runs the voids analysis on a run's
//! saved frames (`pdq voids`).

mod check;
pub mod export;
mod observers;
mod picture;
pub mod post;
mod record;
pub mod run;
pub mod run_part;
mod step_loop;
mod thermo;
