//! PDQ: a peridynamics engine for cracking of plain, reinforced and prestressed concrete.
//!
//! Data flows one way: [`deck`] (TOML) → [`geometry`] → [`particles`] and [`bonds`] →
//! [`simulation`] (the step loop) → [`output`]. Models live in `models/`, one file each, and
//! see nothing but the [`model::Model`] interface.

pub mod analysis;
pub mod attributes;
pub mod bars;
pub mod bench;
pub mod bonds;
pub mod boundary;
pub mod cells;
pub mod checkpoint;
pub mod comm;
#[cfg(feature = "mpi")]
pub mod comm_mpi;
pub mod correction;
pub mod deck;
pub mod decomposition;
pub mod forces;
pub mod geometry;
pub mod implicit;
pub mod lanes;
pub mod model;
#[path = "../models/mod.rs"]
pub mod models;
pub mod output;
pub mod parallel;
pub mod particles;
pub mod plot;
pub mod relaxation;
pub mod run;
pub mod setup;
pub mod shuffle;
pub mod signals;
pub mod simulation;
pub mod spectrum;
pub mod static_start;
pub mod stress;
pub mod timing;
pub mod units;
pub mod validate;
pub mod wall;
