//! What a run leaves behind: the CSV time history ([`history`]), particle frames for ParaView
//! ([`frames`]), checkpoints ([`checkpoint`]), files written atomically ([`atomic`]), progress
//! on the terminal ([`progress`]), the signals that end a run cleanly ([`signals`]) and PNG
//! plots ([`plot`]).

pub mod atomic;
pub mod checkpoint;
pub mod frames;
pub mod history;
pub mod plot;
pub mod progress;
pub mod signals;

pub use atomic::write_atomically;
pub use frames::{frame_name, Frames};
pub use history::History;
pub use progress::Progress;
