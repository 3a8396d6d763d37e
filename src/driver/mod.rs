//! `pdq run` and `pdq check`: a deck's scene laid out on procCubes, stepped with its outputs
//! and stop criteria, summarised.

pub mod run;
