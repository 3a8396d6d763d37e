//! Counting the lattice sites a scene fills without storing them (the memory guard's first
//! figure): a site counts for the last `Add` that fills it, if no later entry (`Add` or
//! `Subtract`) fills it too, which is the overlap rule of [`super::build`]. Bars add their
//! particle counts (the few lattice sites they displace are not taken off: an upper bound).

use super::{all_finite, sites, Bar, Keys, Lattice, Op};

/// Particles of the scene `build` would make, counted site by site; `None` when an entry is
/// one `build` refuses (it reports the reason).
pub fn count_particles(lattice: &Lattice, ops: &[Op], bars: &[Bar]) -> Option<f64> {
    let (s, o) = (lattice.spacing, lattice.origin);
    if !(s.is_finite() && s > 0.0 && all_finite(&o)) {
        return None;
    }
    let keys = Keys::of(lattice);
    let (tol, half_open, kind) = (keys.tol, keys.half_open, lattice.kind);
    let mut total = 0.0;
    for (n, op) in ops.iter().enumerate() {
        let Op::Add { shape, .. } = op else {
            continue;
        };
        shape.validate().ok()?;
        let (lo, hi) = shape.bounds();
        if !all_finite(&[lo, hi].concat()) {
            return None;
        }
        let r = keys.around(lo, hi);
        if r.iter().map(|(a, b)| b - a + 1.0).product::<f64>() > u32::MAX as f64 {
            return None;
        }
        let later = &ops[n + 1..];
        total += sites(r)
            .filter(|key| kind.admits(key))
            .map(|key| keys.site(&key))
            .filter(|p| shape.fills(*p, tol, half_open))
            .filter(|p| {
                !later.iter().any(|l| {
                    let (Op::Add { shape, .. } | Op::Subtract { shape }) = l;
                    shape.fills(*p, tol, half_open)
                })
            })
            .count() as f64;
    }
    Some(total + bars.iter().map(|b| b.count()).sum::<f64>())
}

/// Lattice sites within `radius` of a site (itself not counted): an interior particle's
/// bonds for a horizon, or its neighbours for a pair reach.
pub fn neighbours_within(lattice: &Lattice, radius: f64) -> usize {
    let s = lattice.spacing;
    if !(radius > 0.0 && s > 0.0 && radius.is_finite()) {
        return 0;
    }
    let step = Keys::of(lattice).step;
    let n = (radius / step).ceil() + 1.0;
    sites([(-n, n); 3])
        .filter(|key| lattice.kind.admits(key) && *key != [0, 0, 0])
        .filter(|key| {
            let r2: f64 = key.iter().map(|&k| (k as f64 * step).powi(2)).sum();
            r2 <= radius * radius * (1.0 + 1e-12)
        })
        .count()
}
