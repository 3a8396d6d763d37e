//! Progress of a run on the terminal.

use std::io::IsTerminal;
use std::time::Instant;

/// A progress bar with ETA on a terminal; a plain line every 10% otherwise.
pub struct Progress {
    /// The step the run started from (a restart's checkpoint step, else 0).
    first: u64,
    total: u64,
    start: Instant,
    last: Instant,
    tty: bool,
    enabled: bool,
    next_tenth: u64,
}

impl Progress {
    pub fn new(first: u64, total: u64, enabled: bool) -> Progress {
        Progress {
            first,
            total: total.max(1),
            start: Instant::now(),
            last: Instant::now(),
            tty: std::io::stderr().is_terminal(),
            enabled,
            next_tenth: 1 + first * 10 / total.max(1),
        }
    }

    pub fn update(&mut self, done: u64, broken: usize) {
        if !self.enabled {
            return;
        }
        let elapsed = self.start.elapsed().as_secs_f64();
        let frac = done as f64 / self.total as f64;
        // From the steps this run has made: a restart's earlier steps took no time here.
        let made = done.saturating_sub(self.first);
        let eta = if made > 0 {
            elapsed * self.total.saturating_sub(done) as f64 / made as f64
        } else {
            0.0
        };
        if self.tty {
            if self.last.elapsed().as_secs_f64() < 0.25 && done < self.total {
                return;
            }
            self.last = Instant::now();
            let width = 30;
            let filled = (frac * width as f64) as usize;
            eprint!(
                "\r[{}{}] {:5.1}% step {}/{} broken {} ETA {:.0} s   ",
                "#".repeat(filled),
                " ".repeat(width - filled),
                100.0 * frac,
                done,
                self.total,
                broken,
                eta
            );
            if done >= self.total {
                eprintln!();
            }
        } else if done * 10 >= self.next_tenth * self.total {
            while done * 10 >= self.next_tenth * self.total {
                self.next_tenth += 1;
            }
            eprintln!(
                "step {done}/{} ({:.0}%), broken bonds {broken}, elapsed {:.1} s, ETA {:.1} s",
                self.total,
                100.0 * frac,
                elapsed,
                eta
            );
        }
    }
}
