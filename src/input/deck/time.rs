//! `[time]` and `[solver]`: how long to run, the time step and integrator, and whether the
//! loads are followed by explicit steps or by quasi-static solves.

use super::convert::{Converter, R};
use super::sections::{SolverSection, TimeSection};
use super::spec::{CriticalStep, Equilibrium, Located, PeakStop, RunLength, SolverSpec, TimeSpec};
use crate::engine::simulation::Integrator;
use toml::Spanned;

/// Conjugate-gradient iterations per Newton iteration of the matrix-free solve, unless the deck
/// says: preconditioned CG on a slender beam takes a few times (length / spacing)² / (depth /
/// spacing) iterations (the suite's finest cantilever about 10,000); the cap is for a tangent
/// that is not positive definite, which CG would otherwise wander on.
pub const DEFAULT_KRYLOV_ITERATIONS: u64 = 50_000;

impl Converter {
    /// `[time]`; `bondless` names a model without bonds, which has no stable step to take a
    /// fraction of: its deck gives `dt`.
    pub(super) fn time(
        &self,
        section: Spanned<TimeSection>,
        bondless: Option<&str>,
    ) -> R<TimeSpec> {
        let line = self.line_of(&section);
        let t = section.into_inner();
        if let Some(name) = bondless {
            self.bondless_time(&t, line, name)?;
        }
        let length = self.run_length(&t, line)?;
        let dt = t.dt.map(|d| d.value(self.sys));
        if let Some(d) = dt {
            if !(d.is_finite() && d > 0.0) {
                return self.err(line, format!("[time] dt must be > 0 (got {d})"));
            }
        }
        let safety_factor = t.safety_factor.unwrap_or(0.8);
        if !(safety_factor > 0.0 && safety_factor <= 1.0) {
            return self.err(
                line,
                format!("[time] safety_factor must lie in (0, 1] (got {safety_factor})"),
            );
        }
        if dt.is_some() && t.safety_factor.is_some() {
            return self.err(line, "[time] give 'dt' or 'safety_factor', not both");
        }
        let critical_step = match t.critical_step.as_deref().unwrap_or("bound") {
            "bound" => CriticalStep::Bound,
            "measured" => CriticalStep::Measured,
            other => {
                return self.err(
                    line,
                    format!(
                        "[time] critical_step must be \"bound\" or \"measured\" (got \"{other}\")"
                    ),
                )
            }
        };
        let static_until = self.static_until(&t, line, length)?;
        let stop_at_broken_bonds = match t.stop_at_broken_bonds {
            None => 0,
            Some(n) if n >= 1 => n as u64,
            Some(n) => {
                return self.err(
                    line,
                    format!("[time] stop_at_broken_bonds must be a count >= 1 (got {n}); leave it out to run to the end"),
                )
            }
        };
        let stop_below_peak = match t.stop_below_peak {
            None => None,
            Some(p) if p.fraction > 0.0 && p.fraction < 1.0 && !p.column.is_empty() => {
                Some(PeakStop {
                    column: p.column,
                    fraction: p.fraction,
                })
            }
            Some(p) => {
                return self.err(
                    line,
                    format!(
                        "[time] stop_below_peak needs a history column and a fraction in (0, 1) (got column '{}', fraction {})",
                        p.column, p.fraction
                    ),
                )
            }
        };
        let name = t.integrator.as_deref().unwrap_or("verlet");
        let Some(integrator) = Integrator::from_name(name) else {
            return self.err(
                line,
                format!("[time] unknown integrator '{name}' (use \"verlet\" or \"leapfrog\")"),
            );
        };
        Ok(TimeSpec {
            line,
            length,
            dt,
            safety_factor,
            critical_step,
            static_until,
            force_dt: t.force_dt.unwrap_or(false),
            integrator,
            stop_at_broken_bonds,
            stop_below_peak,
        })
    }

    /// A bondless model's `[time]`: `dt` given, and nothing that derives a step from bonds.
    fn bondless_time(&self, t: &TimeSection, line: usize, name: &str) -> R<()> {
        if t.dt.is_none() {
            return self.err(
                line,
                format!("[time] model {name} has no bonds to bound the time step; give [time] dt"),
            );
        }
        let derived = [
            ("safety_factor", t.safety_factor.is_some()),
            ("critical_step", t.critical_step.is_some()),
            ("static_until", t.static_until.is_some()),
        ];
        if let Some((key, _)) = derived.iter().find(|(_, given)| *given) {
            return self.err(
                line,
                format!("[time] {key}: model {name} has no bonds, so no stable step or static solve to derive it from; leave it out (dt is the step)"),
            );
        }
        Ok(())
    }

    /// `steps` or `duration`, exactly one.
    fn run_length(&self, t: &TimeSection, line: usize) -> R<RunLength> {
        match (t.steps, t.duration) {
            (Some(0), None) => self.err(line, "[time] steps must be ≥ 1"),
            (Some(n), None) => Ok(RunLength::Steps(n)),
            (None, Some(d)) => {
                let d = d.value(self.sys);
                if !(d.is_finite() && d > 0.0) {
                    return self.err(line, format!("[time] duration must be > 0 (got {d})"));
                }
                Ok(RunLength::Duration(d))
            }
            (None, None) => self.err(line, "[time] needs 'steps' or 'duration'"),
            (Some(_), Some(_)) => self.err(line, "[time] give 'steps' or 'duration', not both"),
        }
    }

    /// `static_until`: a time > 0 before the end of the run.
    fn static_until(&self, t: &TimeSection, line: usize, length: RunLength) -> R<Option<f64>> {
        match t.static_until.map(|d| d.value(self.sys)) {
            None => Ok(None),
            Some(s) if !(s.is_finite() && s > 0.0) => self.err(
                line,
                format!("[time] static_until must be a time > 0 (got {s})"),
            ),
            Some(s) => match length {
                RunLength::Duration(d) if s >= d => self.err(
                    line,
                    format!("[time] static_until = {s:e} is not before the end of the run (duration {d:e}): nothing would be left to step"),
                ),
                _ => Ok(Some(s)),
            },
        }
    }

    /// `[solver]`, at line 0 (explicit) when the deck leaves it out.
    pub(super) fn solver(
        &self,
        section: Option<&Spanned<SolverSection>>,
        bondless: Option<&str>,
    ) -> R<Located<SolverSpec>> {
        let Some(sec) = section else {
            return Ok(Located {
                item: SolverSpec::Explicit,
                line: 0,
            });
        };
        let line = self.line_of(sec);
        let s = sec.get_ref();
        if let (Some(name), false) = (bondless, s.kind == "explicit") {
            return self.err(
                line,
                format!("[solver] model {name} has no bonds, so no equilibrium to relax to: only kind = \"explicit\""),
            );
        }
        let item = match s.kind.as_str() {
            "explicit" => {
                if s.load_steps.is_some()
                    || s.tolerance.is_some()
                    || s.max_iterations.is_some()
                    || s.krylov_iterations.is_some()
                    || s.preconditioner.is_some()
                {
                    return self.err(line, "[solver] load_steps, tolerance, max_iterations, krylov_iterations and preconditioner belong to kind = \"adr\", \"implicit\" or \"newton_krylov\"");
                }
                SolverSpec::Explicit
            }
            kind @ ("adr" | "implicit" | "newton_krylov") => {
                let method = match kind {
                    "adr" => Equilibrium::Relaxation,
                    "implicit" => Equilibrium::Newton,
                    _ => Equilibrium::NewtonKrylov,
                };
                let newton = method != Equilibrium::Relaxation;
                if !newton && s.krylov_iterations.is_some() {
                    return self.err(line, "[solver] krylov_iterations belongs to kind = \"implicit\" or \"newton_krylov\" (the conjugate-gradient iterations of the matrix-free solve)");
                }
                if !newton && s.preconditioner.is_some() {
                    return self.err(line, "[solver] preconditioner belongs to kind = \"implicit\" or \"newton_krylov\" (the matrix-free solve's conjugate gradients)");
                }
                let coarse = match s.preconditioner.as_deref() {
                    None | Some("two_level") => true,
                    Some("diagonal") => false,
                    Some(other) => {
                        return self.err(line, format!("[solver] preconditioner '{other}' is not one (use \"two_level\", the diagonal with a coarse level of rigid group motions, or \"diagonal\")"));
                    }
                };
                let load_steps = s.load_steps.unwrap_or(10);
                let tolerance = s.tolerance.unwrap_or(if newton { 1e-8 } else { 1e-4 });
                let max_iterations = s
                    .max_iterations
                    .unwrap_or(if newton { 20 } else { 100_000 });
                let krylov_iterations = s.krylov_iterations.unwrap_or(DEFAULT_KRYLOV_ITERATIONS);
                if load_steps == 0 || max_iterations == 0 || krylov_iterations == 0 {
                    return self.err(
                        line,
                        "[solver] load_steps, max_iterations and krylov_iterations must be ≥ 1",
                    );
                }
                if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
                    return self.err(
                        line,
                        format!(
                            "[solver] tolerance must lie in (0, 1), the deck gives {tolerance}"
                        ),
                    );
                }
                SolverSpec::Relaxation {
                    load_steps,
                    tolerance,
                    max_iterations,
                    method,
                    krylov_iterations,
                    coarse,
                }
            }
            other => {
                return self.err(
                    line,
                    format!(
                    "[solver] unknown kind '{other}' (use \"explicit\", \"adr\", \"implicit\" or \"newton_krylov\")"
                ),
                )
            }
        };
        Ok(Located { item, line })
    }
}
