//! From a deck to a built scene: TOML read into typed sections ([`deck`], the only module that
//! knows TOML), quantities with units ([`units`]), lattice-filled shapes ([`geometry`]), bars
//! ([`bars`]), and the whole scene built from the checked deck ([`setup`]).

pub mod bars;
pub mod deck;
pub mod geometry;
pub mod materials;
pub mod procs;
pub mod setup;
pub mod units;
