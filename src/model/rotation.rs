//! Finite rotations as unit quaternions (w, x, y, z), for models whose particles turn
//! (`models/micropolar.rs`): composition, the rotation between two orientations, and the
//! conversions to and from rotation vectors and matrices, written for one value (`f64`) or
//! four lanes (`F4`) where the bond loop needs them.

use crate::model::lanes::Real;

/// The rotation matrix (row major) of the unit quaternion q.
pub fn matrix(q: &[f64; 4]) -> [f64; 9] {
    let [w, x, y, z] = *q;
    [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    ]
}

/// a ⊗ b.
#[inline(always)]
pub fn product<T: Real>(a: &[T; 4], b: &[T; 4]) -> [T; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// sin|φ| φ̂ and 1 − cos|φ| of the rotation φ taking orientation `qi` to `qj` (spatial frame):
/// from q = q_j ⊗ q_i*, sin|φ| φ̂ = 2 q_w q_v and 1 − cos|φ| = 2|q_v|².
#[inline(always)]
pub fn relative<T: Real>(qi: &[T; 4], qj: &[T; 4]) -> ([T; 3], T) {
    let q = product(qj, &[qi[0], -qi[1], -qi[2], -qi[3]]);
    let two = T::splat(2.0);
    (
        [two * q[0] * q[1], two * q[0] * q[2], two * q[0] * q[3]],
        two * (q[1] * q[1] + q[2] * q[2] + q[3] * q[3]),
    )
}

/// The rotation vector of a unit quaternion.
pub fn rotation_vector(q: &[f64; 4]) -> [f64; 3] {
    let (w, v) = if q[0] < 0.0 {
        (-q[0], [-q[1], -q[2], -q[3]])
    } else {
        (q[0], [q[1], q[2], q[3]])
    };
    let s2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    // 2 atan2(s, w)/s = (2/w) atan(t)/t with t = s/w. Below t = 1/64 the series to t⁸ is exact
    // to round-off (next term t¹⁰/11 < 1e-19) and avoids atan2 and a square root on every
    // particle at every step; most rotations in a structure are that small.
    let k = if s2 < (w * w) * (1.0 / 4096.0) {
        let t2 = s2 / (w * w);
        2.0 / w * (1.0 - t2 * (1.0 / 3.0 - t2 * (1.0 / 5.0 - t2 * (1.0 / 7.0 - t2 / 9.0))))
    } else {
        let s = s2.sqrt();
        2.0 * s.atan2(w) / s
    };
    [k * v[0], k * v[1], k * v[2]]
}

/// The unit quaternion of rotation vector `r`.
pub fn quaternion(r: [f64; 3]) -> [f64; 4] {
    let a2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    // cos(a/2) and sin(a/2)/a. A step turns a particle by far less than 1/16 rad, where the
    // series to a⁸ are exact to round-off (next terms below 1e-20 relative): no sin and cos on
    // every particle at every step.
    let (c, k) = if a2 < 1.0 / 256.0 {
        let x = 0.25 * a2; // (a/2)²
        (
            1.0 - x * (0.5 - x * (1.0 / 24.0 - x * (1.0 / 720.0 - x / 40320.0))),
            0.5 * (1.0 - x * (1.0 / 6.0 - x * (1.0 / 120.0 - x * (1.0 / 5040.0 - x / 362880.0)))),
        )
    } else {
        let angle = a2.sqrt();
        let half = 0.5 * angle;
        (half.cos(), half.sin() / angle)
    };
    [c, k * r[0], k * r[1], k * r[2]]
}
