//! What a deck or the command line asks of the decomposition into procCubes
//! (`[parallel]`, `--procs`, `--walls`); `parallel::decomposition` carries it out.

/// The procCube counts a deck or the command line asks for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Procs {
    /// Chosen from the particle distribution and the box shape for a number of workers.
    Auto,
    Given([usize; 3]),
}

/// What a ghost message carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Walls {
    /// Every cell the sender holds in its face layer (received ones included), as the thesis sends.
    #[default]
    Whole,
    /// Only the cells the receiver uses or passes on (the thesis's beams, columns and cornices).
    Trimmed,
}

impl Walls {
    pub fn name(self) -> &'static str {
        match self {
            Walls::Whole => "whole",
            Walls::Trimmed => "trimmed",
        }
    }
}
