//! `[thermostat]` on the built scene: its group by global id, the group's degrees of freedom,
//! and the checks that need the particles and the time step.

use super::place::select;
use crate::engine::simulation::Simulation;
use crate::engine::thermostat::{Kind, Thermostat};
use crate::input::deck::{DeckError, Scene, ThermostatKind};
use crate::model::Model;

/// The deck's thermostat, if any, for `sim` (particles, boundary conditions and Δt set).
pub(super) fn thermostat<M: Model>(
    sim: &Simulation<M>,
    scene: &Scene,
    scope: &super::place::Scope,
) -> Result<Option<Thermostat>, DeckError> {
    let Some(spec) = &scene.thermostat else {
        return Ok(None);
    };
    let at = |what: String| scene.error(Some(spec.line), format!("[thermostat] {what}"));
    let p = &sim.particles;
    let mut group = select(p, &spec.region, scope).map_err(&at)?;
    if !spec.materials.is_empty() {
        group.retain(|&i| spec.materials.contains(&p.material[i as usize]));
    }
    if group.is_empty() {
        return Err(at(
            "the group (region and materials) selects no particle".into()
        ));
    }
    let mut member = vec![false; p.len()];
    for &i in &group {
        member[p.gid[i as usize] as usize] = true;
    }
    // A held velocity is the boundary's, not the thermostat's: scaling it would be undone at
    // once, and its kinetic energy is no temperature.
    for c in &sim.constraints {
        if !c.dofs.iter().any(|&d| d < 3) {
            continue;
        }
        if let Some(&i) = c
            .particles
            .iter()
            .find(|&&i| member[p.gid[i as usize] as usize])
        {
            return Err(at(format!(
                "the group includes particle {} held by boundary '{}'; select the free particles (region, or materials = [...] without the wall's)",
                p.gid[i as usize], c.name
            )));
        }
    }
    let all = group.len() == p.len();
    let n = group.len() as f64;
    // The momentum of a group that is every particle stays what it is (its forces sum to zero),
    // taking three DOFs from the temperature; Langevin's random forces move it, and every
    // other group exchanges momentum with the rest.
    let langevin = matches!(spec.kind, ThermostatKind::Langevin { .. });
    let dof = if all && !langevin {
        3.0 * n - 3.0
    } else {
        3.0 * n
    };
    if dof < 1.0 {
        return Err(at(
            "the group is one particle, which has no temperature once its momentum is fixed: select at least two".into(),
        ));
    }
    let kind = match spec.kind {
        ThermostatKind::Rescale { every } => Kind::Rescale { every },
        ThermostatKind::Berendsen { damping } => Kind::Berendsen { tau: damping },
        ThermostatKind::Langevin { damping, seed } => Kind::Langevin { tau: damping, seed },
        ThermostatKind::NoseHoover { damping } => Kind::NoseHoover {
            tau: damping,
            xi: 0.0,
            eta: 0.0,
        },
    };
    if let Kind::Berendsen { tau } | Kind::NoseHoover { tau, .. } = kind {
        if tau < sim.dt {
            return Err(at(format!(
                "damping = {tau:e} is shorter than the time step {:e}: {} relaxes over many steps; give damping ≥ dt (typically 100 dt)",
                sim.dt,
                kind.name()
            )));
        }
    }
    Ok(Some(Thermostat {
        kind,
        temperature: spec.temperature,
        kb: scene.units.boltzmann(),
        member: (!all).then_some(member),
        dof,
        removed: 0.0,
    }))
}
