//! The run's time step and step count: Δt below the stable step (the Silling–Askari bound or
//! the measured critical step), and the static start's checks.

use crate::engine::simulation::Simulation;
use crate::input::deck::{CriticalStep, DeckError, RunLength, Scene, SolverSpec};
use crate::model::Model;

/// The time step, how it was limited and the steps of the run.
pub(super) struct Stepping {
    pub(super) dt: f64,
    pub(super) steps: u64,
    /// With `critical_step = "measured"`: the measured step and the evaluations it took.
    pub(super) dt_measured: Option<(f64, u64)>,
}

/// Δt and the steps: explicit runs step below the limit (measured on the stiffest mode, or
/// the bound `dt_critical` set by store index `critical_particle`); relaxation's pseudo time
/// has its own limit, and its steps are its load steps.
pub(super) fn stepping<M: Model>(
    sim: &mut Simulation<M>,
    scene: &Scene,
    dt_critical: f64,
    critical_particle: usize,
) -> Result<Stepping, DeckError> {
    let time_line = Some(scene.time.line);
    if let Some(until) = scene.time.static_until {
        static_start_allowed::<M>(scene, until)?;
    }
    let explicit = matches!(scene.solver.item, SolverSpec::Explicit);
    let measured = scene.time.critical_step == CriticalStep::Measured;
    if measured && !explicit {
        return Err(scene.error(
            time_line,
            "[time] critical_step = \"measured\" is for explicit runs: a quasi-static [solver] has no time step to limit",
        ));
    }
    let dt_measured = if measured {
        Some(crate::engine::spectrum::critical_time_step(sim).ok_or_else(|| {
            scene.error(
                time_line,
                "[time] critical_step = \"measured\": no free degree of freedom has a bond, so there is no stiffest mode to measure; use the bound",
            )
        })?)
    } else {
        None
    };
    let (limit, limit_name) = match dt_measured {
        Some((dt, _)) => (dt, "measured on the stiffest mode".to_string()),
        None => (
            dt_critical,
            format!(
                "Silling–Askari bound, set by particle {} at {:?}",
                sim.particles.gid[critical_particle], sim.particles.x0[critical_particle]
            ),
        ),
    };
    let (dt, steps) = below_limit(scene, limit, &limit_name)?;
    Ok(Stepping {
        dt,
        steps,
        dt_measured,
    })
}

/// Δt below the stable step `limit` (named for the message), or the deck's own if it is below,
/// and the steps of the run.
pub(crate) fn below_limit(
    scene: &Scene,
    limit: f64,
    limit_name: &str,
) -> Result<(f64, u64), DeckError> {
    let time_line = Some(scene.time.line);
    let dt = match scene.time.dt {
        Some(dt) => {
            if dt > limit && !scene.time.force_dt {
                return Err(scene.error(
                    time_line,
                    format!(
                        "[time] dt = {dt:.4e} is above the stable time step {limit:.4e} ({limit_name}); lower dt, use safety_factor, or set force_dt = true to run anyway"
                    ),
                ));
            }
            dt
        }
        None => scene.time.safety_factor * limit,
    };
    let (dt, steps) = load_steps(scene, dt);
    if steps > 1_000_000_000_000 {
        return Err(scene.error(
            time_line,
            format!("[time] the run would take {steps} steps of {dt:.4e}: shorten the duration"),
        ));
    }
    Ok((dt, steps))
}

/// The steps at time step `dt`. A static start reaches `static_until` without steps; the steps
/// follow it. Relaxation follows the loads through the same time span in `load_steps` equal
/// steps; a "step" is then a load step and Δt its length in the loads' time.
fn load_steps(scene: &Scene, dt: f64) -> (f64, u64) {
    let steps = match scene.time.length {
        RunLength::Steps(n) => n,
        RunLength::Duration(d) => ((d - scene.time.static_until.unwrap_or(0.0)) / dt).ceil() as u64,
    };
    match scene.solver.item {
        SolverSpec::Relaxation { load_steps, .. } => {
            let span = match scene.time.length {
                RunLength::Steps(n) => n as f64 * dt,
                RunLength::Duration(d) => d,
            };
            (span / load_steps as f64, load_steps)
        }
        SolverSpec::Explicit => (dt, steps),
    }
}

/// Refuses a static start (`[time] static_until`) that cannot be made: under a quasi-static
/// solver (which has no explicit steps to start), with initial velocities (it starts at
/// rest), with periodic axes or temperature (which the implicit solve does not take).
fn static_start_allowed<M: Model>(scene: &Scene, until: f64) -> Result<(), DeckError> {
    let line = Some(scene.time.line);
    if !matches!(scene.solver.item, SolverSpec::Explicit) {
        return Err(scene.error(
            line,
            "[time] static_until starts an explicit run from a static solve; with a quasi-static [solver] every load step is static already: leave it out",
        ));
    }
    if let Some(i) = scene
        .initial
        .iter()
        .find(|i| i.velocity.is_some() || i.angular_velocity.is_some())
    {
        return Err(scene.error(
            Some(i.line),
            format!("[[initial]] velocities cannot be combined with [time] static_until = {until:e}: the static start begins the run at rest"),
        ));
    }
    if let Some(v) = &scene.velocity {
        return Err(scene.error(
            Some(v.line),
            format!("[velocity] cannot be combined with [time] static_until = {until:e}: the static start begins the run at rest"),
        ));
    }
    if scene.periodic.iter().any(|&p| p) {
        return Err(scene.error(
            line,
            "[time] static_until: the static start's implicit solve does not handle periodic axes (it finds who feels whom from reference positions); leave static_until out",
        ));
    }
    if M::FIRST_ORDER > 0 {
        return Err(scene.error(
            line,
            format!(
                "[time] static_until: the static start solves for mechanical equilibrium, and model '{}' has temperature (first-order degrees of freedom); leave it out",
                M::NAME
            ),
        ));
    }
    Ok(())
}
