//! `[parallel]`: the procCube layout, worker threads, what the walls carry, shuffling and the
//! cell skin.

use super::convert::{Converter, R};
use super::sections::{ParallelSection, ProcsSpec};
use super::spec::ParallelSpec;
use crate::input::procs::{Procs, Walls};
use toml::Spanned;

/// The most workers (threads, procCubes) a deck may ask for: far beyond any machine, and low
/// enough that the layout search over nx·ny·nz = workers stays quick (`threads = 10¹¹` kept
/// `pdq check` searching for hours) and counts multiply without overflow.
const MAX_WORKERS: i64 = 1 << 20;

impl Converter {
    pub(super) fn parallel(&self, section: Option<&Spanned<ParallelSection>>) -> R<ParallelSpec> {
        let (p, line) = match section {
            Some(p) => (p.get_ref(), self.line_of(p)),
            None => (&ParallelSection::default(), 0),
        };
        let procs = match &p.procs {
            None => Procs::Auto,
            Some(ProcsSpec::Word(w)) if w == "auto" => Procs::Auto,
            Some(ProcsSpec::Word(w)) => {
                return self.err(
                    line,
                    format!("[parallel] procs = \"{w}\": give [nx, ny, nz] or \"auto\""),
                )
            }
            Some(ProcsSpec::Given(v)) => {
                if v.iter().any(|&n| n < 1) {
                    return self.err(
                        line,
                        format!("[parallel] procs = {v:?}: every count must be at least 1"),
                    );
                }
                let cubes = v.iter().try_fold(1i64, |p, &n| p.checked_mul(n));
                if cubes.is_none_or(|c| c > MAX_WORKERS) {
                    return self.err(
                        line,
                        format!("[parallel] procs = {v:?} makes more than {MAX_WORKERS} procCubes; give at most {MAX_WORKERS} (one per worker)"),
                    );
                }
                Procs::Given(v.map(|n| n as usize))
            }
        };
        let threads = match (p.threads, &procs) {
            (Some(t), _) if t < 1 => {
                return self.err(line, format!("[parallel] threads = {t}: must be at least 1"))
            }
            (Some(t), _) if t > MAX_WORKERS => {
                return self.err(
                    line,
                    format!("[parallel] threads = {t}: give at most {MAX_WORKERS} (one procCube per thread)"),
                )
            }
            (Some(t), Procs::Given(v)) if t as usize != v.iter().product::<usize>() => {
                return self.err(
                    line,
                    format!(
                        "[parallel] threads = {t} but procs = {v:?} makes {} procCubes; give one procCube per thread",
                        v.iter().product::<usize>()
                    ),
                )
            }
            (Some(t), _) => t as usize,
            (None, Procs::Given(v)) => v.iter().product(),
            (None, Procs::Auto) => 1,
        };
        let walls = match p.walls.as_deref() {
            None | Some("whole") => Walls::Whole,
            Some("trimmed") => Walls::Trimmed,
            Some(other) => {
                return self.err(
                    line,
                    format!("[parallel] walls = \"{other}\": use \"whole\" or \"trimmed\""),
                )
            }
        };
        let shuffle_every = match p.shuffle_every {
            None => 0,
            Some(n) if n >= 0 => n as u64,
            Some(n) => {
                return self.err(
                    line,
                    format!("[parallel] shuffle_every = {n}: give a number of steps (0 = never)"),
                )
            }
        };
        let skin = match (p.skin, p.cell_factor) {
            (Some(_), Some(_)) => {
                return self.err(
                    line,
                    "[parallel] give 'skin' or 'cell_factor' (= 1 + skin), not both",
                )
            }
            (None, Some(f)) if f.is_finite() && (1.0..=11.0).contains(&f) => Some(f - 1.0),
            (None, Some(f)) => {
                return self.err(
                    line,
                    format!("[parallel] cell_factor = {f}: cells are cell_factor horizons wide; give a number from 1 to 11 (below 1 a cell would be thinner than the horizon)"),
                )
            }
            (s, None) => s,
        };
        let skin = match skin {
            None if shuffle_every > 0 => 0.25,
            None => 0.0,
            Some(s) if s.is_finite() && (0.0..=10.0).contains(&s) => s,
            Some(s) => {
                return self.err(
                    line,
                    format!(
                        "[parallel] skin = {s}: give a fraction of the horizon between 0 and 10"
                    ),
                )
            }
        };
        Ok(ParallelSpec {
            line,
            procs,
            threads,
            walls,
            shuffle_every,
            skin,
        })
    }
}
