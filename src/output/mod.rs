//! What a run leaves behind: the CSV time history ([`history`]), particle frames for ParaView
//! ([`frames`]), checkpoints ([`checkpoint`], in parts on several ranks: [`checkpoint_parts`]),
//! what a file holds ([`info`]), files written atomically ([`atomic`]), progress
//! on the terminal ([`progress`]), the signals that end a run cleanly ([`signals`]), PNG
//! plots ([`plot`], [`curves`], the pictures of every run in [`pictures`]), LAMMPS data
//! files ([`lammps_data`]), and the tables and voxel labels of the voids and cracks analyses
//! ([`analysis`], [`voxels`]).

pub mod analysis;
pub mod atomic;
pub mod checkpoint;
pub mod checkpoint_parts;
pub mod curves;
pub mod frames;
pub mod history;
pub mod info;
pub mod lammps_data;
pub mod pictures;
pub mod plot;
pub mod progress;
pub mod signals;
pub mod views;
pub mod voxels;

pub use atomic::write_atomically;
pub use frames::{frame_name, Frames};
pub use history::History;
pub use progress::Progress;
