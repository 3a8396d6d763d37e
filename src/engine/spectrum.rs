//! The stiffest mode of a scene: the largest eigenvalue of W⁻¹K (K the stiffness about the
//! current state, W a diagonal weight per degree of freedom) by a Lanczos run with K applied as
//! force differences, so that it works for every model without assembling K.
//!
//! Two users: adaptive dynamic relaxation scales its fictitious masses by λ_max of K against
//! the Gershgorin masses (`relaxation::fictitious_mass`), and an explicit run with `[time]
//! critical_step = "measured"` takes its critical step 2/√λ_max of K against the real masses
//! ([`critical_time_step`]), the limit of central differences, instead of the Silling–Askari
//! bound, which is 1.4–2.4× below it (docs/stability.md).
//!
//! The top Ritz value approaches λ_max from below; on the suite's scenes 30 steps give the same
//! four digits as 60 and 120. The estimate is made on the whole scene in one store (the
//! setup's, before the procCubes are cut), serially and from a start that is a function of
//! global ids, so every layout and a restart get the same value.

use crate::engine::simulation::{stable_time_steps, Simulation};
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};

/// Krylov steps of the estimate (one force evaluation each, plus one at the start).
pub const LANCZOS_STEPS: usize = 30;

/// A perturbation's largest displacement, relative to the shortest bond: small enough that no
/// bond breaks and the force difference is linear, large enough against rounding (10⁻¹⁰ of the
/// coordinates' size at most).
const PROBE_DISPLACEMENT: f64 = 1e-6;

/// The critical time step of central differences (velocity Verlet and the leapfrog
/// alike), 2/√λ_max(M⁻¹K) over the second-order DOFs that no boundary condition holds, with M
/// the particles' masses (and rotational inertias), measured about the scene's current state;
/// first-order DOFs (temperature) keep their forward-Euler bound. And the force evaluations
/// it took. `None` when no free DOF has a bond.
pub fn critical_time_step<M: Model>(sim: &mut Simulation<M>) -> Option<(f64, u64)> {
    let first_order = stable_time_steps(&sim.model, &sim.particles, &sim.bonds)[1].0;
    let n2 = second_order::<M>();
    let p = &sim.particles;
    let mass: Vec<f64> = p.inv_inertia[..p.n_owned]
        .iter()
        .flat_map(|inv| inv.as_slice()[..n2].iter().map(|v| 1.0 / v))
        .collect();
    let free = sim.free_dofs();
    match stiffest_mode(sim, &mass, &free) {
        Some((l, e)) if l.is_finite() && l > 0.0 => Some(((2.0 / l.sqrt()).min(first_order), e)),
        _ => None,
    }
}

/// λ_max of W⁻¹K over the DOFs marked `free` (second-order DOFs of owned particles, particle-
/// major; W diagonal, `weight` > 0 where free) by Lanczos on W^-½ K W^-½, with K·y from the
/// force change under a small displacement along y; and the force evaluations it took
/// ([`LANCZOS_STEPS`] + 1). `None` when no DOF is free or the scene has no bond. The scene is
/// left as it was found.
pub fn stiffest_mode<M: Model>(
    sim: &mut Simulation<M>,
    weight: &[f64],
    free: &[bool],
) -> Option<(f64, u64)> {
    let n2 = second_order::<M>();
    let dofs: Vec<usize> = (0..free.len()).filter(|&d| free[d]).collect();
    let shortest = sim
        .bonds
        .geom
        .iter()
        .map(|g| g.length)
        .fold(f64::INFINITY, f64::min);
    if dofs.is_empty() || !shortest.is_finite() {
        return None;
    }
    let scale: Vec<f64> = dofs.iter().map(|&d| 1.0 / weight[d].sqrt()).collect();
    let saved = (
        sim.particles.alter.clone(),
        sim.particles.state.clone(),
        sim.particles.force.clone(),
        sim.bonds.history.clone(),
        sim.bonds.broken.clone(),
        sim.constraints
            .iter()
            .map(|c| c.reaction.clone())
            .collect::<Vec<_>>(),
    );
    let forces = |sim: &Simulation<M>| -> Vec<f64> {
        dofs.iter()
            .map(|&d| sim.particles.force[d / n2].as_slice()[d % n2])
            .collect()
    };
    sim.compute_forces();
    let f0 = forces(sim);
    let mut evaluations = 1u64;
    let mut moved: Vec<usize> = dofs.iter().map(|&d| d / n2).collect();
    moved.dedup();
    // q ↦ W^-½ K W^-½ q.
    let mut apply = |sim: &mut Simulation<M>, q: &[f64]| -> Vec<f64> {
        let y: Vec<f64> = q.iter().zip(&scale).map(|(q, s)| q * s).collect();
        // No translation beyond PROBE_DISPLACEMENT × the shortest bond, no rotation beyond
        // PROBE_DISPLACEMENT radians: both stay linear whichever dominates the vector.
        let largest = |translations: bool| {
            dofs.iter()
                .zip(&y)
                .filter(|(&d, _)| (d % n2 < 3) == translations)
                .fold(0.0f64, |m, (_, y)| m.max(y.abs()))
        };
        // q is a unit vector, so at least one of the two is non-zero and h is finite.
        let h = PROBE_DISPLACEMENT * (shortest / largest(true)).min(1.0 / largest(false));
        // Through the model's drift with velocities h·y over a unit time, as the integrator
        // moves particles: rotations compose into the orientation the bond loop reads.
        let mut velocity = vec![0.0; sim.particles.n_owned * n2];
        for (&d, y) in dofs.iter().zip(&y) {
            velocity[d] = h * y;
        }
        for &i in &moved {
            let mut a = saved.0[i];
            a.as_mut_slice()[n2..2 * n2].copy_from_slice(&velocity[i * n2..(i + 1) * n2]);
            sim.model.drift(&mut a, 1.0);
            a.as_mut_slice()[n2..2 * n2].copy_from_slice(&saved.0[i].as_slice()[n2..2 * n2]);
            sim.particles.alter[i] = a;
        }
        sim.compute_forces();
        evaluations += 1;
        forces(sim)
            .iter()
            .zip(&f0)
            .zip(&scale)
            .map(|((f, f0), s)| -(f - f0) / h * s)
            .collect()
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
    // A start with every mode in it, the same on every layout (a function of global ids).
    let mut q: Vec<f64> = dofs
        .iter()
        .map(|&d| {
            let key = (sim.particles.gid[d / n2] as u64) * n2 as u64 + (d % n2) as u64;
            (crate::engine::random::splitmix64(key) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    let norm = dot(&q, &q).sqrt();
    q.iter_mut().for_each(|v| *v /= norm);
    let mut previous = vec![0.0; q.len()];
    let (mut alpha, mut beta) = (Vec::new(), Vec::new());
    for _ in 0..LANCZOS_STEPS {
        let mut w = apply(sim, &q);
        let a = dot(&q, &w);
        let b_prev = beta.last().copied().unwrap_or(0.0);
        for ((w, q), p) in w.iter_mut().zip(&q).zip(&previous) {
            *w -= a * q + b_prev * p;
        }
        alpha.push(a);
        let b = dot(&w, &w).sqrt();
        if b.is_nan() || b <= 1e-12 * a.abs() {
            break;
        }
        beta.push(b);
        previous = std::mem::replace(&mut q, w.iter().map(|w| w / b).collect());
    }
    beta.truncate(alpha.len() - 1);
    let p = &mut sim.particles;
    (p.alter, p.state, p.force) = (saved.0, saved.1, saved.2);
    (sim.bonds.history, sim.bonds.broken) = (saved.3, saved.4);
    for (c, r) in sim.constraints.iter_mut().zip(saved.5) {
        c.reaction = r;
    }
    Some((largest_eigenvalue(&alpha, &beta), evaluations))
}

/// The largest eigenvalue of the symmetric tridiagonal matrix with diagonal `a` and
/// off-diagonal `b`, by bisection on the Sturm count.
fn largest_eigenvalue(a: &[f64], b: &[f64]) -> f64 {
    let below = |x: f64| {
        let mut count = 0;
        let mut d = 1.0;
        for (i, &ai) in a.iter().enumerate() {
            let off = if i > 0 { b[i - 1] * b[i - 1] } else { 0.0 };
            d = ai - x - if i > 0 { off / d } else { 0.0 };
            if d == 0.0 {
                d = -f64::EPSILON * (ai.abs() + x.abs()).max(f64::MIN_POSITIVE);
            }
            count += (d < 0.0) as usize;
        }
        count
    };
    let radius =
        |i: usize| (if i > 0 { b[i - 1].abs() } else { 0.0 }) + b.get(i).map_or(0.0, |v| v.abs());
    let mut lo = (0..a.len())
        .map(|i| a[i] - radius(i))
        .fold(f64::INFINITY, f64::min);
    let mut hi = (0..a.len())
        .map(|i| a[i] + radius(i))
        .fold(f64::NEG_INFINITY, f64::max);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if below(mid) == a.len() {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::largest_eigenvalue;

    #[test]
    fn tridiagonal_top_eigenvalue() {
        // The path graph's Laplacian 2, −1: eigenvalues 2 − 2cos(kπ/(n+1)).
        let n = 12;
        let top = largest_eigenvalue(&vec![2.0; n], &vec![-1.0; n - 1]);
        let exact = 2.0 - 2.0 * (n as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos();
        assert!((top - exact).abs() < 1e-12, "{top} against {exact}");
        assert_eq!(largest_eigenvalue(&[3.5], &[]), 3.5);
    }
}
