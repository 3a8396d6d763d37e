//! `[velocity]`: velocities drawn from the Maxwell–Boltzmann distribution at a temperature, as
//! LAMMPS's `velocity all create T seed mom yes dist gaussian` draws them: each component
//! Gaussian with variance k_B·T/m, then the centre-of-mass velocity removed and every velocity
//! scaled so that the temperature 2·KE / (k_B·(3N − 3)) is exactly T.
//!
//! The draws are keyed by (seed, global id, component), never by the order of the store, and the
//! sums run in global-id order: a particle gets the same velocity bit for bit whatever the
//! layout or the order the particles are stored in.

use crate::engine::random::normal as gaussian;

/// The velocities of particles `gid` of translational masses `mass` (one per component) at
/// temperature `t`, with Boltzmann's constant `kb` in the deck's units: zero total momentum and
/// 2·KE / (kb·(3N − 3)) = t. At least two particles: one alone has no degree of freedom left
/// once its momentum is removed.
pub(super) fn velocities(
    gid: &[u32],
    mass: &[[f64; 3]],
    t: f64,
    seed: u64,
    kb: f64,
) -> Result<Vec<[f64; 3]>, String> {
    let n = gid.len();
    if n < 2 {
        return Err(format!(
            "the region selects {n} particle{}: a temperature needs at least two (3N − 3 degrees of freedom once the momentum is removed)",
            if n == 1 { "" } else { "s" }
        ));
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by_key(|&i| gid[i]);
    let mut v: Vec<[f64; 3]> = (0..n)
        .map(|i| [0, 1, 2].map(|k| (kb * t / mass[i][k]).sqrt() * gaussian(seed, gid[i], k)))
        .collect();
    for k in 0..3 {
        let (mut p, mut m) = (0.0, 0.0);
        for &i in &order {
            p += mass[i][k] * v[i][k];
            m += mass[i][k];
        }
        let centre = p / m;
        for vi in v.iter_mut() {
            vi[k] -= centre;
        }
    }
    let mut twice_ke = 0.0;
    for &i in &order {
        for k in 0..3 {
            twice_ke += mass[i][k] * v[i][k] * v[i][k];
        }
    }
    let dof = 3.0 * n as f64 - 3.0;
    let now = twice_ke / (kb * dof);
    // t = 0 stops every particle; `now` is 0 only if every draw vanished.
    let scale = if now > 0.0 { (t / now).sqrt() } else { 0.0 };
    for vi in v.iter_mut() {
        for c in vi.iter_mut() {
            *c *= scale;
        }
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn momentum_and_temperature(
        mass: &[[f64; 3]],
        v: &[[f64; 3]],
        kb: f64,
    ) -> ([f64; 3], f64, f64) {
        let mut p = [0.0; 3];
        let (mut scale, mut twice_ke) = (0.0, 0.0);
        for (m, v) in mass.iter().zip(v) {
            for k in 0..3 {
                p[k] += m[k] * v[k];
                scale += m[k] * v[k].abs();
                twice_ke += m[k] * v[k] * v[k];
            }
        }
        let t = twice_ke / (kb * (3.0 * v.len() as f64 - 3.0));
        (p, scale, t)
    }

    #[test]
    fn zero_momentum_and_the_exact_temperature() {
        let n = 500;
        let gid: Vec<u32> = (0..n).map(|g| 3 * g + 7).collect();
        // Two species, one twice as heavy.
        let mass: Vec<[f64; 3]> = (0..n).map(|g| [1.0 + (g % 2) as f64; 3]).collect();
        for (t, kb) in [(1.44, 1.0), (300.0, 1.380649e-23 / 1e-3)] {
            let v = velocities(&gid, &mass, t, 87287, kb).unwrap();
            let (p, scale, got) = momentum_and_temperature(&mass, &v, kb);
            assert!(p.iter().all(|c| c.abs() <= 1e-12 * scale), "{p:?}");
            assert!((got - t).abs() <= 1e-12 * t, "{got} vs {t}");
        }
        // Each component has variance k_B·T/m: the heavy species moves 1/√2 as fast.
        let v = velocities(&gid, &mass, 2.0, 1, 1.0).unwrap();
        let mean_sq = |parity: usize| {
            let s: Vec<f64> = (parity..n as usize).step_by(2).flat_map(|i| v[i]).collect();
            s.iter().map(|x| x * x).sum::<f64>() / s.len() as f64
        };
        assert!(
            (mean_sq(0) / mean_sq(1) - 2.0).abs() < 0.3,
            "{} {}",
            mean_sq(0),
            mean_sq(1)
        );
        assert!((mean_sq(0) - 2.0).abs() < 0.3, "{}", mean_sq(0));
    }

    #[test]
    fn a_particle_gets_its_velocity_whatever_the_order_and_the_seed_matters() {
        let gid: Vec<u32> = (0..64).collect();
        let mass = vec![[1.0; 3]; 64];
        let v = velocities(&gid, &mass, 1.0, 5, 1.0).unwrap();
        // The same particles stored in another order.
        let perm: Vec<usize> = (0..64).map(|i| (i * 37 + 11) % 64).collect();
        let gid2: Vec<u32> = perm.iter().map(|&i| gid[i]).collect();
        let w = velocities(&gid2, &mass, 1.0, 5, 1.0).unwrap();
        for (k, &i) in perm.iter().enumerate() {
            assert_eq!(w[k], v[i], "particle {i}");
        }
        let other = velocities(&gid, &mass, 1.0, 6, 1.0).unwrap();
        assert!(v.iter().zip(&other).all(|(a, b)| a != b));
        assert_eq!(
            velocities(&gid, &mass, 0.0, 5, 1.0).unwrap(),
            vec![[0.0; 3]; 64]
        );
        assert!(velocities(&gid[..1], &mass[..1], 1.0, 5, 1.0).is_err());
    }
}
