//! Deterministic pseudo-random numbers keyed by integers (a site's lattice indices, a DOF's
//! global id): the same value on every layout and every run.

/// SplitMix64's finalizer (Steele, Lea & Flood 2014): a well-mixed 64-bit hash of `z`.
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
