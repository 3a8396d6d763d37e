//! Where the time of a run goes, like PDQ's `timing.o`.

use std::fmt::Write as _;
use std::time::{Duration, Instant};

/// The phases a run reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Setup,
    State,
    Forces,
    /// The non-bonded pass.
    Pairs,
    /// Deciding when to rebuild the neighbour lists, moving particles to the procCubes of their
    /// current cells, and building the lists.
    Neighbours,
    Communication,
    Boundary,
    Integration,
    Output,
    /// In-situ analyses (`[[analysis]]`: voids and cracks on voxels).
    Analysis,
}

impl Phase {
    pub const ALL: [Phase; 10] = [
        Phase::Setup,
        Phase::State,
        Phase::Forces,
        Phase::Pairs,
        Phase::Neighbours,
        Phase::Communication,
        Phase::Boundary,
        Phase::Integration,
        Phase::Output,
        Phase::Analysis,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Phase::Setup => "setup",
            Phase::State => "state pass",
            Phase::Forces => "forces",
            Phase::Pairs => "pair forces",
            Phase::Neighbours => "neighbour lists",
            Phase::Communication => "communication",
            Phase::Boundary => "boundary/loads",
            Phase::Integration => "integration",
            Phase::Output => "output",
            Phase::Analysis => "analysis",
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Timing {
    spent: [Duration; 10],
}

impl Timing {
    pub fn add(&mut self, phase: Phase, d: Duration) {
        self.spent[phase as usize] += d;
    }

    /// Adds the time since `start` to `phase` and returns now.
    pub fn lap(&mut self, phase: Phase, start: Instant) -> Instant {
        let now = Instant::now();
        self.add(phase, now - start);
        now
    }

    pub fn get(&self, phase: Phase) -> Duration {
        self.spent[phase as usize]
    }

    pub fn total(&self) -> Duration {
        self.spent.iter().sum()
    }

    /// The table printed at the end of a run.
    pub fn table(&self, particle_steps: f64) -> String {
        let total = self.total().as_secs_f64().max(1e-12);
        let mut s = String::new();
        let _ = writeln!(s, "{:<16} {:>12} {:>7}", "phase", "seconds", "%");
        for p in Phase::ALL {
            let t = self.get(p).as_secs_f64();
            let _ = writeln!(
                s,
                "{:<16} {:>12.4} {:>6.1}%",
                p.name(),
                t,
                100.0 * t / total
            );
        }
        let _ = writeln!(s, "{:<16} {:>12.4} {:>6.1}%", "total", total, 100.0);
        if particle_steps > 0.0 {
            let stepping = total
                - self.get(Phase::Setup).as_secs_f64()
                - self.get(Phase::Output).as_secs_f64()
                - self.get(Phase::Analysis).as_secs_f64();
            let _ = writeln!(
                s,
                "step loop: {:.4} us per particle-step",
                1e6 * stepping / particle_steps
            );
        }
        s
    }
}
