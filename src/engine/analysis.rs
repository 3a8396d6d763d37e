//! Measurements on a built simulation that compare it with continuum mechanics: the stress
//! at a particle under an imposed deformation, and the elastic constants it implies.

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::engine::simulation::Simulation;
use crate::model::attributes::Attributes;
use crate::model::Model;

/// Moves every particle to x = x0 + H·(x0 − centre): a homogeneous deformation with
/// displacement gradient `h`. Rotations, velocities and other values are left alone.
pub fn deform_affinely<M: Model>(p: &mut Particles<M>, h: [[f64; 3]; 3], centre: [f64; 3]) {
    for i in 0..p.len() {
        let x = p.x0[i];
        let d = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
        let a = p.alter[i].as_mut_slice();
        for r in 0..3 {
            a[r] = x[r] + h[r][0] * d[0] + h[r][1] * d[1] + h[r][2] * d[2];
        }
    }
}

/// The virial stress at particle `i`: σ = (1 / 2V_i) Σ_j F_ij ⊗ ξ_ij over i's intact bonds,
/// with F_ij the force its bond with j puts on i and ξ_ij = x0_j − x0_i. For a particle whose
/// family (and, for state-based models, whose neighbours' families) lies wholly inside a
/// homogeneously deformed body, this is the model's Cauchy stress (small strain). Bond
/// history is read, never changed; the model's state must be current (after a force pass).
pub fn virial_stress<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
    i: usize,
) -> [[f64; 3]; 3] {
    let mut s = [[0.0; 3]; 3];
    for (a, b, k) in bonds.iter() {
        if bonds.broken[k] || (a != i && b != i) {
            continue;
        }
        let law = model.law(p.material[a], p.material[b]);
        let mut history = bonds.history[k];
        let Some((fa, fb)) = model.pair(&law, &p.side(a), &p.side(b), &bonds.geom[k], &mut history)
        else {
            continue;
        };
        let (f, other) = if a == i { (fa, b) } else { (fb, a) };
        let f = f.as_slice();
        let (xi, xj) = (p.x0[i], p.x0[other]);
        let xi_ij = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
        for r in 0..3 {
            for c in 0..3 {
                s[r][c] += 0.5 * f[r] * xi_ij[c] / p.volume[i];
            }
        }
    }
    s
}

/// The cubic constants at the particle nearest the centre of a block whose centre particle's
/// family (and its neighbours' families) is whole: the virial stress there under uniaxial
/// strain 10⁻⁴ along x and under engineering shear 10⁻⁴ in xy, each imposed affinely.
/// `None` for a simulation without particles.
pub fn cubic_constants_at_centre<M: Model>(sim: &mut Simulation<M>) -> Option<CubicConstants> {
    let p = &sim.particles;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in &p.x0 {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    }
    let mid = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let distance = |i: usize| (0..3).map(|k| (p.x0[i][k] - mid[k]).powi(2)).sum::<f64>();
    let centre = (0..p.len()).min_by(|&a, &b| distance(a).total_cmp(&distance(b)))?;
    let mut stress = |h: [[f64; 3]; 3]| {
        deform_affinely(&mut sim.particles, h, mid);
        sim.compute_forces();
        virial_stress(&sim.model, &sim.particles, &sim.bonds, centre)
    };
    let (eps, gamma) = (1e-4, 1e-4);
    let uniaxial = stress([[eps, 0.0, 0.0], [0.0; 3], [0.0; 3]]);
    let shear = stress([[0.0, 0.5 * gamma, 0.0], [0.5 * gamma, 0.0, 0.0], [0.0; 3]]);
    Some(CubicConstants::from_tests(&uniaxial, eps, &shear, gamma))
}

/// The three elastic constants of a solid with the lattice's cubic symmetry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicConstants {
    pub c11: f64,
    pub c12: f64,
    pub c44: f64,
}

impl CubicConstants {
    /// From the stress under uniaxial strain ε along x (σ_xx = C11 ε, σ_yy = σ_zz = C12 ε)
    /// and under engineering shear strain γ in xy (σ_xy = C44 γ).
    pub fn from_tests(
        uniaxial: &[[f64; 3]; 3],
        strain: f64,
        shear: &[[f64; 3]; 3],
        gamma: f64,
    ) -> Self {
        CubicConstants {
            c11: uniaxial[0][0] / strain,
            c12: 0.5 * (uniaxial[1][1] + uniaxial[2][2]) / strain,
            c44: 0.5 * (shear[0][1] + shear[1][0]) / gamma,
        }
    }

    /// Lamé constants of the orientation average (Voigt): λ = (C11 + 4C12 − 2C44)/5,
    /// μ = (C11 − C12 + 3C44)/5. A lattice is cubic, not isotropic; this is the isotropic solid
    /// it stands for, and what "recovered E and ν" means in the validation tables.
    pub fn isotropic_lame(&self) -> (f64, f64) {
        (
            (self.c11 + 4.0 * self.c12 - 2.0 * self.c44) / 5.0,
            (self.c11 - self.c12 + 3.0 * self.c44) / 5.0,
        )
    }

    /// Young's modulus along a cube axis ([100]): 1/S11 = (C11 − C12)(C11 + 2C12)/(C11 + C12),
    /// what a beam along a lattice axis bends with.
    pub fn youngs_modulus_100(&self) -> f64 {
        (self.c11 - self.c12) * (self.c11 + 2.0 * self.c12) / (self.c11 + self.c12)
    }

    /// Zener's anisotropy ratio 2C44/(C11 − C12): 1 for an isotropic solid.
    pub fn anisotropy(&self) -> f64 {
        2.0 * self.c44 / (self.c11 - self.c12)
    }
}

/// Young's modulus and Poisson's ratio from Lamé constants.
pub fn young_poisson(lambda: f64, mu: f64) -> (f64, f64) {
    (
        mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu),
        lambda / (2.0 * (lambda + mu)),
    )
}
