//! Solvers beyond explicit stepping: adaptive dynamic relaxation ([`adr`]), the implicit static
//! solve by Newton's method ([`implicit`]), and the static start of an explicit run
//! ([`static_start`]).

pub mod adr;
pub mod implicit;
pub mod static_start;
