//! Molecular dynamics and the non-bonded pass (issue 23), one test binary: the MD input
//! (`input`), the thermo against LAMMPS from the same start (`lammps_thermo`), layout
//! invariance on threads (`layouts`), the example scenes at a small size (`scenes`) and the
//! thermostats (`thermostat`), and the deforming box (`deform`).

#[path = "../common/mod.rs"]
mod common;

mod deform;
mod input;
mod lammps_thermo;
mod layouts;
mod scenes;
mod thermostat;
