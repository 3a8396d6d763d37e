//! The wall method (thesis ch. 3): the scene cut into procCubes ([`decomposition`]), ghost
//! messages along the plan ([`wall`]) over a byte transport ([`comm`]: threads; [`comm_mpi`]:
//! MPI ranks), team reductions and gathers in rank order, particle shuffling ([`shuffle`]) and
//! the procCube itself ([`cube`]), which steps with its wall exchange.

pub mod balance;
mod carried;
pub mod comm;
#[cfg(feature = "mpi")]
pub mod comm_mpi;
pub mod cube;
pub mod decomposition;
pub mod deform;
mod migrate;
pub mod part;
pub mod shuffle;
pub mod snapshot;
pub mod wall;

pub use cube::*;
