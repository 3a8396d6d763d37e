//! What the deck places on the particles: initial velocities and temperatures (`[[initial]]`,
//! then `[velocity]`'s Maxwell–Boltzmann start), boundary conditions, loads and probes, each on
//! the particles its region selects.

use crate::engine::boundary::{Constraint, Load, TEMPERATURE};
use crate::engine::particles::Particles;
use crate::input::deck::{DeckError, LoadKind, Region, Scene};
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};

/// Which particles the deck's regions see: the whole scene, or the owned particles of one
/// procCube (per-rank setup), with counts and sums taken over the whole scene by `sum`.
pub struct Scope<'a> {
    /// The local index of a global id held here, `None` when it is elsewhere.
    pub index: &'a dyn Fn(u32) -> Option<u32>,
    /// Particles in the whole scene (ids run below it).
    pub total: usize,
    /// The sum over every procCube of a value each holds (the identity for the whole scene).
    pub sum: &'a dyn Fn(f64) -> f64,
}

impl<'a> Scope<'a> {
    /// The whole scene, `index` giving the store index of each global id.
    pub fn whole(index: &'a dyn Fn(u32) -> Option<u32>, total: usize) -> Scope<'a> {
        Scope {
            index,
            total,
            sum: &|x| x,
        }
    }
}

/// Store indices of the (owned) particles of a region, in store order.
pub(crate) fn select<M: Model>(
    p: &Particles<M>,
    region: &Region,
    scope: &Scope,
) -> Result<Vec<u32>, String> {
    let n = p.n_owned;
    Ok(match region {
        Region::All => (0..n as u32).collect(),
        Region::Shape(s) => (0..n)
            .filter(|&i| s.contains(p.x0[i]))
            .map(|i| i as u32)
            .collect(),
        Region::Ids(ids) => {
            let mut v = Vec::with_capacity(ids.len());
            for &id in ids {
                if id as usize >= scope.total {
                    return Err(format!(
                        "particle id {id} does not exist (ids run from 0 to {})",
                        scope.total - 1
                    ));
                }
                v.extend((scope.index)(id).filter(|&i| (i as usize) < n));
            }
            v.sort_unstable();
            v.dedup();
            v
        }
    })
}

/// Whether a selection is empty on every procCube.
fn none_selected(sel: &[u32], scope: &Scope) -> bool {
    (scope.sum)(sel.len() as f64) == 0.0
}

/// Sets the deck's initial velocities, angular velocities and temperatures.
pub(crate) fn initial_state<M: Model>(
    particles: &mut Particles<M>,
    scene: &Scene,
    scope: &Scope,
) -> Result<(), DeckError> {
    let n2 = second_order::<M>();
    for init in &scene.initial {
        let at = |what: &str| scene.error(Some(init.line), format!("initial: {what}"));
        let sel = select(particles, &init.region, scope).map_err(|e| at(&e))?;
        if none_selected(&sel, scope) {
            return Err(at("the region selects no particle"));
        }
        if init.angular_velocity.is_some() && n2 < 6 {
            return Err(at(&format!(
                "model '{}' has no rotations for 'angular_velocity'",
                M::NAME
            )));
        }
        if init.temperature.is_some() && M::FIRST_ORDER == 0 {
            return Err(at(&format!("model '{}' has no temperature", M::NAME)));
        }
        for i in sel {
            let a = particles.alter[i as usize].as_mut_slice();
            if let Some(v) = init.velocity {
                a[n2..n2 + 3].copy_from_slice(&v);
            }
            if let Some(w) = init.angular_velocity {
                a[n2 + 3..n2 + 6].copy_from_slice(&w);
            }
            if let Some(t) = init.temperature {
                a[2 * n2] = t;
            }
        }
    }
    Ok(())
}

/// `[velocity]`: Maxwell–Boltzmann velocities at the deck's temperature on the particles of
/// its region (`maxwell.rs`), set after `[[initial]]`, so they replace the translational
/// velocities `[[initial]]` gave those particles. The mass of each component is the inertia
/// of its degree of freedom (density × volume).
pub(super) fn thermal_velocities<M: Model>(
    particles: &mut Particles<M>,
    scene: &Scene,
    scope: &Scope,
) -> Result<(), DeckError> {
    let Some(spec) = &scene.velocity else {
        return Ok(());
    };
    let at = |what: &str| scene.error(Some(spec.line), format!("[velocity]: {what}"));
    let sel = select(particles, &spec.region, scope).map_err(|e| at(&e))?;
    let gid: Vec<u32> = sel.iter().map(|&i| particles.gid[i as usize]).collect();
    let mass: Vec<[f64; 3]> = sel
        .iter()
        .map(|&i| {
            let inv = particles.inv_inertia[i as usize].as_slice();
            [1.0 / inv[0], 1.0 / inv[1], 1.0 / inv[2]]
        })
        .collect();
    let kb = scene.units.boltzmann();
    let v = super::maxwell::velocities(&gid, &mass, spec.temperature, spec.seed, kb)
        .map_err(|e| at(&e))?;
    let n2 = second_order::<M>();
    for (&i, v) in sel.iter().zip(v) {
        particles.alter[i as usize].as_mut_slice()[n2..n2 + 3].copy_from_slice(&v);
    }
    Ok(())
}

/// The deck's boundary conditions on the particles and degrees of freedom they hold.
pub(crate) fn constraints<M: Model>(
    particles: &Particles<M>,
    scene: &Scene,
    scope: &Scope,
) -> Result<Vec<Constraint>, DeckError> {
    let mut constraints = Vec::new();
    for b in &scene.boundaries {
        let at = |e: String| scene.error(Some(b.line), format!("boundary '{}': {e}", b.name));
        let sel = select(particles, &b.region, scope).map_err(at)?;
        if none_selected(&sel, scope) {
            return Err(at("the region selects no particle".into()));
        }
        let mut dofs = Vec::with_capacity(b.dofs.len());
        for &d in &b.dofs {
            dofs.push(dof_index::<M>(d).map_err(at)?);
        }
        constraints.push(Constraint::new(
            &b.name,
            sel,
            dofs,
            b.motion.clone(),
            b.history.clone(),
        ));
    }
    Ok(constraints)
}

/// The deck's loads, each spread over its particles by its kind's weights.
pub(crate) fn loads<M: Model>(
    particles: &Particles<M>,
    scene: &Scene,
    scope: &Scope,
) -> Result<Vec<Load>, DeckError> {
    let n2 = second_order::<M>();
    let mut loads = Vec::new();
    for l in &scene.loads {
        let at = |e: String| scene.error(Some(l.line), format!("load '{}': {e}", l.name));
        let sel = select(particles, &l.region, scope).map_err(at)?;
        if none_selected(&sel, scope) {
            return Err(at("the region selects no particle".into()));
        }
        if l.kind.is_heat() && M::FIRST_ORDER == 0 {
            return Err(at(format!(
                "model '{}' has no temperature to heat",
                M::NAME
            )));
        }
        let (vector, weight) = load_weights(particles, l.kind, &sel, scene.spacing, scope);
        loads.push(Load {
            name: l.name.clone(),
            particles: sel,
            weight,
            vector,
            dof: if l.kind.is_heat() { n2 } else { 0 },
            history: l.history.clone(),
        });
    }
    Ok(loads)
}

/// A load's vector and each selected particle's share of it.
fn load_weights<M: Model>(
    particles: &Particles<M>,
    kind: LoadKind,
    sel: &[u32],
    spacing: f64,
    scope: &Scope,
) -> ([f64; 3], Vec<f64>) {
    let volume_of = |i: &u32| particles.volume[*i as usize];
    match kind {
        LoadKind::PerParticle(v) => (v, vec![1.0; sel.len()]),
        LoadKind::Total(v) => {
            let total: f64 = (scope.sum)(sel.iter().map(volume_of).sum());
            (v, sel.iter().map(|i| volume_of(i) / total).collect())
        }
        LoadKind::BodyForce(v) => (v, sel.iter().map(volume_of).collect()),
        LoadKind::Gravity(g) => (
            g,
            sel.iter()
                .map(|&i| 1.0 / particles.inv_inertia[i as usize].as_slice()[0])
                .collect(),
        ),
        LoadKind::HeatFlux(q) => (
            [q, 0.0, 0.0],
            sel.iter().map(|i| volume_of(i) / spacing).collect(),
        ),
        LoadKind::HeatSource(q) => ([q, 0.0, 0.0], sel.iter().map(volume_of).collect()),
        LoadKind::TotalHeat(q) => {
            let total: f64 = (scope.sum)(sel.iter().map(volume_of).sum());
            (
                [q, 0.0, 0.0],
                sel.iter().map(|i| volume_of(i) / total).collect(),
            )
        }
    }
}

/// Each probe's name and the particle nearest to its point.
pub(crate) fn probes<M: Model>(particles: &Particles<M>, scene: &Scene) -> Vec<(String, usize)> {
    scene
        .probes
        .iter()
        .map(|pr| {
            (
                pr.name.clone(),
                nearest(particles, pr.at).map_or(0, |(_, i)| i),
            )
        })
        .collect()
}

/// The owned particle nearest to `at` (ties to the smaller global id, so that any layout picks
/// the same one) and its squared distance.
pub(crate) fn nearest<M: Model>(particles: &Particles<M>, at: [f64; 3]) -> Option<(f64, usize)> {
    let key = |i: usize| (dist2(particles.x0[i], at), particles.gid[i]);
    (0..particles.n_owned)
        .min_by(|&a, &b| {
            let (ka, kb) = (key(a), key(b));
            ka.0.total_cmp(&kb.0).then(ka.1.cmp(&kb.1))
        })
        .map(|i| (key(i).0, i))
}

/// The model's index of a DOF the deck names (x, y, z, rotations, temperature).
fn dof_index<M: Model>(d: usize) -> Result<usize, String> {
    let n2 = second_order::<M>();
    if d == TEMPERATURE {
        return if M::FIRST_ORDER > 0 {
            Ok(n2)
        } else {
            Err(format!("model '{}' has no temperature", M::NAME))
        };
    }
    if d >= n2 {
        return Err(format!(
            "model '{}' has no rotations (it has {n2} degrees of freedom per particle)",
            M::NAME
        ));
    }
    Ok(d)
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}
