//! Deterministic pseudo-random numbers keyed by integers (a site's lattice indices, a DOF's
//! global id): the same value on every layout and every run.

use std::f64::consts::PI;

/// SplitMix64's finalizer (Steele, Lea & Flood 2014): a well-mixed 64-bit hash of `z`.
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A standard normal number for component `k` of particle `gid` under `seed` (Box–Muller on
/// two keyed uniforms): the Maxwell–Boltzmann start's draws.
pub fn normal(seed: u64, gid: u32, k: usize) -> f64 {
    let mut h = splitmix64(seed ^ 0x6A09_E667_F3BC_C909);
    h = splitmix64(h ^ u64::from(gid));
    h = splitmix64(h ^ k as u64);
    box_muller(h)
}

/// A standard normal number for component `k` of particle `gid` at `step` under `seed`: the
/// Langevin thermostat's noise, the same for a particle whatever procCube or thread steps it.
/// The step is hashed in after the particle, so every (particle, step) pair has its own stream
/// and no step repeats another's numbers.
pub fn normal_at_step(seed: u64, gid: u32, step: u64, k: usize) -> f64 {
    let mut h = splitmix64(seed ^ 0xBB67_AE85_84CA_A73B);
    h = splitmix64(h ^ u64::from(gid));
    h = splitmix64(h ^ step);
    h = splitmix64(h ^ k as u64);
    box_muller(h)
}

/// Box–Muller's cosine branch on the uniforms of `h` and `h + 1`.
fn box_muller(h: u64) -> f64 {
    let uniform = |x: u64| (splitmix64(x) >> 11) as f64 / (1u64 << 53) as f64;
    // u1 in (0, 1], so its logarithm is finite.
    let (u1, u2) = (1.0 - uniform(h), uniform(h.wrapping_add(1)));
    (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_noise_is_standard_normal_and_uncorrelated_between_steps() {
        let n = 200_000;
        let x: Vec<f64> = (0..n)
            .map(|s| normal_at_step(7, (s % 97) as u32, s / 97, (s % 3) as usize))
            .collect();
        let mean = x.iter().sum::<f64>() / n as f64;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        // Standard errors: 1/√n = 0.0022 for the mean, √(2/n) = 0.0032 for the variance.
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((var - 1.0).abs() < 0.015, "{var}");
        // One particle's draws at consecutive steps: correlation within 5 standard errors.
        let a: Vec<f64> = (0..n).map(|s| normal_at_step(7, 3, s, 0)).collect();
        let c = a.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / n as f64;
        assert!(c.abs() < 5.0 / (n as f64).sqrt(), "{c}");
        assert_ne!(normal_at_step(7, 3, 0, 0), normal_at_step(8, 3, 0, 0));
    }
}
