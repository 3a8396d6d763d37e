//! The energy surface correction of bond-based models (Madenci & Oterkus 2014; Le & Bobaru
//! 2018; docs/theory.md §6).
//!
//! A particle near a surface misses part of its family and is too soft; on a lattice even an
//! interior particle's discrete family differs from the continuum integral the micromodulus
//! was calibrated to. For each axis k the body is stretched by u = ε₀ x_k e_k; the factor
//! gᵢᵏ = W_CCM / W_PD,iᵏ compares the continuum energy density ½(λ + 2μ)ε₀² with the particle's
//! peridynamic one; a bond takes G_ij = [Σ_k (n_k / ḡᵏ)²]^(−½) with ḡᵏ = (gᵢᵏ + gⱼᵏ)/2 and n
//! its reference direction. G multiplies the bond's volume factor β, so force, energy and
//! bond history see one corrected bond; it is computed once, on the whole scene.

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::Model;

/// The stretch of the three probing deformations.
const PROBE_STRAIN: f64 = 1e-3;

/// gᵢᵏ for every particle of a store that holds whole families (positions are restored).
pub fn energy_factors<M: Model>(
    model: &M,
    p: &mut Particles<M>,
    bonds: &BondList<M::Bond>,
) -> Vec<[f64; 3]> {
    let n = p.len();
    let saved = p.alter.clone();
    let mut g = vec![[1.0; 3]; n];
    for k in 0..3 {
        for (a, x) in p.alter.iter_mut().zip(&p.x0) {
            a.as_mut_slice()[k] = x[k] * (1.0 + PROBE_STRAIN);
        }
        let w = particle_energies(model, p, bonds, |_, _| true);
        for (i, gi) in g.iter_mut().enumerate() {
            let (lambda, mu) = model.lame(p.material[i]);
            let continuum = 0.5 * (lambda + 2.0 * mu) * PROBE_STRAIN * PROBE_STRAIN;
            let discrete = w[i] / p.volume[i];
            if discrete > 0.0 {
                gi[k] = continuum / discrete;
            }
        }
        p.alter.clone_from(&saved);
    }
    g
}

/// Half the energy of each bond between particles `i` and `j` that `keep(i, j)` accepts, summed
/// at each of its two ends.
pub fn particle_energies<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
    keep: impl Fn(usize, usize) -> bool,
) -> Vec<f64> {
    let mut w = vec![0.0; p.len()];
    for (i, j, b) in bonds.iter() {
        if !keep(i, j) {
            continue;
        }
        let law = model.law(p.material[i], p.material[j]);
        let e = model.energy(
            &law,
            &p.side(i),
            &p.side(j),
            &bonds.geom[b],
            &bonds.history[b],
        );
        w[i] += 0.5 * e;
        w[j] += 0.5 * e;
    }
    w
}

/// G_ij of a bond with reference vector `xi` between particles with factors `gi` and `gj`.
pub fn bond_factor(xi: [f64; 3], gi: &[f64; 3], gj: &[f64; 3]) -> f64 {
    let l = (xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]).sqrt();
    let mut s = 0.0;
    for k in 0..3 {
        let n = xi[k] / l;
        let g = 0.5 * (gi[k] + gj[k]);
        s += (n / g) * (n / g);
    }
    1.0 / s.sqrt()
}

/// Multiplies every bond's β by its G_ij; `g(i)` gives the factors of store particle i. Bonds
/// for which `skip(i, j)` holds are left alone: a bar's own bonds, which `input/bars.rs` scales as a
/// whole (the factors of a bar particle come from the body around it, not from the bar).
pub fn correct_bonds<H: Attributes>(
    bonds: &mut BondList<H>,
    x0: &[[f64; 3]],
    g: impl Fn(usize) -> [f64; 3],
    skip: impl Fn(usize, usize) -> bool,
) {
    for i in 0..bonds.owners() {
        for b in bonds.family(i) {
            let j = bonds.partners()[b] as usize;
            if skip(i, j) {
                continue;
            }
            let (a, c) = (x0[i], x0[j]);
            let xi = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            bonds.geom.scale_beta(b, bond_factor(xi, &g(i), &g(j)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bond_factor_of_equal_factors_is_that_factor() {
        let g = [0.9, 0.9, 0.9];
        assert!((bond_factor([1.0, 2.0, -2.0], &g, &g) - 0.9).abs() < 1e-15);
        // Along an axis only that axis's factor counts.
        let h = [2.0, 0.5, 0.7];
        assert!((bond_factor([0.0, 3.0, 0.0], &h, &h) - 0.5).abs() < 1e-15);
    }
}
