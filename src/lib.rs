//! PDQ: a peridynamics engine for cracking of plain, reinforced and prestressed concrete.
//!
//! The folders are the layers; each uses only the ones listed before it (`docs/architecture.md`
//! draws the picture):
//!
//! - [`model`] — the interface a model file implements: declared attribute records, the
//!   [`model::Model`] trait, vector lanes; [`models`] — one file per model (`models/`).
//! - [`engine`] — one procCube's particles, bonds, cells, bond passes, boundary conditions,
//!   integrators and the stable time step; it knows nothing of decks, files or other workers.
//! - [`input`] — the deck (TOML → typed [`input::deck::Scene`]), units, geometry, bars, and
//!   the built whole scene ([`input::setup`]).
//! - [`parallel`] — the wall method: decomposition into procCubes, ghost messages on a
//!   transport (threads or MPI), team reductions, shuffling, the procCube.
//! - [`voids`] — voids on voxels: occupancy from positions, connected empty voxels labelled.
//! - [`output`] — history, frames, checkpoints, progress, signals, plots.
//! - [`solve`] — quasi-static and static solvers (ADR, the implicit Newton solve, the static
//!   start).
//! - [`driver`] — `pdq run` and `pdq check`: the step loop with its outputs.
//! - [`lab`] — `pdq validate`, `pdq stress`, `pdq bench`.

pub mod model;
#[path = "../models/mod.rs"]
pub mod models;
#[path = "../pairs/mod.rs"]
pub mod pairs;

pub mod engine;
pub mod input;
pub mod parallel;
pub mod voids;

pub mod output;
pub mod solve;

pub mod driver;
pub mod lab;
