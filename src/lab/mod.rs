//! The lab: `pdq validate` (cases against engineering formulas), `pdq stress` (numerical
//! stability) and `pdq bench` (speed against LAMMPS and a hand-written loop).

pub mod bench;
pub mod stress;
pub mod validate;
