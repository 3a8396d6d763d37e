//! One procCube's physics: the particle store, the bond list, cells, the bond passes, boundary
//! conditions and loads, the integrators and the stable time step. Nothing here reads a deck,
//! writes a file or knows how many workers there are: where ghost data must move, the step
//! calls an [`simulation::Exchange`] it is handed.

pub mod analysis;
pub mod bond_geoms;
pub mod bond_sums;
pub mod bonds;
pub mod boundary;
pub mod cells;
pub mod correction;
pub mod forces;
pub mod pair_pass;
pub mod particles;
pub mod random;
pub mod simulation;
pub mod spectrum;
pub mod thermostat;
pub mod timing;
