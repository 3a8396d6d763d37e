//! Micropolar bond-based peridynamics: six degrees of freedom per particle (displacement and
//! rotation), a bond force and two unequal bond moments (docs/theory.md §3, marked DERIVED there:
//! energy equivalence, not a published law; docs/models.md lists what was verified).
//!
//! Each particle carries an orientation Q (a unit quaternion, integrated, and its rotation
//! matrix, derived at every drift for the bond loop). For a bond of reference direction
//! n₀ = ξ/L, current vector y and d_i = Q_i n₀:
//!
//! * s = (|y| − L)/L, g = y/L − ½(d_i + d_j) (g = s n + γ for small motion, with γ the
//!   shear of docs/theory.md §3), and φ the rotation from Q_i to Q_j;
//! * micropotential w = ½L[(c_n − c_s) s² + c_s |g|²] + κ_φ (1 − cos|φ|)
//!   (= ½L(c_n s² + c_s|γ|²) + ½κ_φ|φ|² for small motion);
//! * force on i f = (c_n − c_s) s y/|y| + c_s g (j gets −f); moments
//!   M_i = ½L c_s d_i × g + κ_φ sin|φ| φ̂ and M_j = ½L c_s d_j × g − κ_φ sin|φ| φ̂.
//!
//! w is unchanged by a rigid rotation of everything, so M_i + M_j = y × f holds exactly (to
//! round-off, also for large rotations): angular momentum is conserved. Forces and moments are
//! the exact derivatives of w, so energy is conserved too. Calibration (3D):
//! c_n = 6E/(πδ⁴(1 − 2ν)), c_s = 6E(1 − 4ν)/(πδ⁴(1 + ν)(1 − 2ν)), so −1 < ν ≤ 1/4;
//! κ_φ = `kappa` · c_n δ² (default 0; its value is not calibrated). Rotational inertia
//! J = ρ V dx²/6 (a cube of side dx).
//!
//! Solids break at s0 = √(5G0(1 − 2ν)/(3Eδ)) (axial energy only) or a given critical stretch;
//! concrete (kind = "concrete") at its tensile and compressive stretches s_c < s < s_t.

use crate::model::attributes::Attributes;
use crate::model::lanes::{LaneForces, Real, F4, LANES};
use crate::model::rotation::{matrix, product, quaternion, relative, rotation_vector};
use crate::model::{
    check_options, stretch_line, BondGeom, Dimension, Material, MaterialKind, Model, ModelBuild,
    ModelError, Sample, SampleOf, Side,
};
use std::f64::consts::PI;

crate::attributes! {
    /// Position, rotation vector, their velocities, then the orientation quaternion (w, x, y, z)
    /// that the rotation vector summarizes, and the same orientation as a rotation matrix (row
    /// major). The quaternion is what is integrated; the matrix is derived from it at every
    /// drift because the bond loop turns a vector per bond, which costs a matrix 15 flops and a
    /// quaternion about 30.
    pub struct Motion6 {
        pub pos: [f64; 3],
        pub rotation: [f64; 3],
        pub vel: [f64; 3],
        pub angular_velocity: [f64; 3],
        pub orientation: [f64; 4],
        pub frame: [f64; 9],
    }
}

crate::attributes! {
    /// Force and moment.
    pub struct Force6 { pub force: [f64; 3], pub moment: [f64; 3] }
}

/// Constants of one pair of materials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    /// c_n − c_s.
    pub a: f64,
    pub cs: f64,
    pub kappa: f64,
    pub tensile: f64,
    pub compressive: f64,
    /// max(c_n, c_s), for the stable time step.
    pub c_max: f64,
}

/// c_n, c_s, tensile and compressive critical stretch of a material.
#[derive(Clone, Copy, Debug)]
struct Own {
    cn: f64,
    cs: f64,
    tensile: f64,
    compressive: f64,
}

#[derive(Clone, Debug)]
pub struct Micropolar {
    own: Vec<Own>,
    density: Vec<f64>,
    kappa: f64,
    delta: f64,
    spacing: f64,
}

/// A bond's strain measures, scaled by L to save divisions, for one bond (`T = f64`) or a lane
/// group of four (`T = F4`): y, |y|, 1/(L|y|), s, D_i = Q_i ξ, D_j = Q_j ξ and
/// G = y − ½(D_i + D_j) = L g.
struct Kinematics<T> {
    y: [T; 3],
    r: T,
    inv_lr: T,
    s: T,
    d_i: [T; 3],
    d_j: [T; 3],
    g: [T; 3],
}

/// The two ends of a bond as the law reads them: current and reference positions, frames.
struct Ends<T> {
    pos: [[T; 3]; 2],
    x0: [[T; 3]; 2],
    frame: [[T; 9]; 2],
}

#[inline(always)]
fn kinematics<T: Real>(e: &Ends<T>, l: T) -> Kinematics<T> {
    let ([a, b], [a0, b0]) = (e.pos, e.x0);
    let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
    // One division per bond: 1/L = r/(L r).
    let inv_lr = T::splat(1.0) / (l * r);
    let xi = [b0[0] - a0[0], b0[1] - a0[1], b0[2] - a0[2]];
    // Written out, not `[0, 1, 2].map`: `map` goes through a call the inliner may keep out of
    // line in a long bond loop.
    let turn = |m: &[T; 9]| {
        [
            m[0] * xi[0] + m[1] * xi[1] + m[2] * xi[2],
            m[3] * xi[0] + m[4] * xi[1] + m[5] * xi[2],
            m[6] * xi[0] + m[7] * xi[1] + m[8] * xi[2],
        ]
    };
    let (d_i, d_j) = (turn(&e.frame[0]), turn(&e.frame[1]));
    let half = T::splat(0.5);
    let g = [
        y[0] - half * (d_i[0] + d_j[0]),
        y[1] - half * (d_i[1] + d_j[1]),
        y[2] - half * (d_i[2] + d_j[2]),
    ];
    Kinematics {
        y,
        r,
        inv_lr,
        s: (r - l) * r * inv_lr,
        d_i,
        d_j,
        g,
    }
}

/// Force on i and the two moments without the relative-rotation term, from c_n − c_s (`a`),
/// c_s, L and v = β V_i V_j. With G = L g and D = L d: f = v[(c_n − c_s) s y/|y| + c_s G/L]
/// and M_i = ½L c_s v d_i × g = (c_s v/(2L)) D_i × G; y/|y| = L y/(L|y|), 1/L = |y|/(L|y|).
#[inline(always)]
fn forces<T: Real>(k: &Kinematics<T>, a: T, cs: T, l: T, v: T) -> [[T; 3]; 3] {
    let (y, g) = (k.y, k.g);
    let axial = v * a * k.s * l * k.inv_lr;
    let shear = v * cs * k.r * k.inv_lr;
    let f = [
        axial * y[0] + shear * g[0],
        axial * y[1] + shear * g[1],
        axial * y[2] + shear * g[2],
    ];
    let half = T::splat(0.5) * shear;
    let hg = [half * g[0], half * g[1], half * g[2]];
    let cross = |d: &[T; 3]| {
        [
            d[1] * hg[2] - d[2] * hg[1],
            d[2] * hg[0] - d[0] * hg[2],
            d[0] * hg[1] - d[1] * hg[0],
        ]
    };
    [f, cross(&k.d_i), cross(&k.d_j)]
}

/// Adds the relative-rotation moments ±κ_φ v sin|φ| φ̂ to `[f, M_i, M_j]` (κ_φ ≠ 0 only).
#[inline(always)]
fn add_relative<T: Real>(kappa: T, v: T, qi: &[T; 4], qj: &[T; 4], fm: &mut [[T; 3]; 3]) {
    let (sin_phi, _) = relative(qi, qj);
    let k = kappa * v;
    for c in 0..3 {
        fm[1][c] = fm[1][c] + k * sin_phi[c];
        fm[2][c] = fm[2][c] - k * sin_phi[c];
    }
}

/// Offsets (in values) of fields of the particle record, for loading them four particles at a
/// time.
const POS: usize = std::mem::offset_of!(Motion6, pos) / 8;
const ORIENTATION: usize = std::mem::offset_of!(Motion6, orientation) / 8;
const FRAME: usize = std::mem::offset_of!(Motion6, frame) / 8;

/// Normal and shear bond constants and critical stretches of one material, from E and ν.
fn own_constants(m: &Material, delta: f64) -> Result<Own, ModelError> {
    let name = Micropolar::NAME;
    let concrete = m.kind == MaterialKind::Concrete;
    let breaking: &[&str] = if concrete {
        &["tensile_stretch", "compressive_stretch"]
    } else {
        &["critical_stretch", "fracture_energy"]
    };
    let mut used = vec!["youngs_modulus", "poisson_ratio"];
    used.extend_from_slice(breaking);
    m.only_uses(&used, name)?;
    let e = m.required("youngs_modulus", Dimension::STRESS, name)?;
    let nu = m.require(m.poisson_ratio()?, "poisson_ratio", name)?;
    if nu > 0.25 + 1e-12 {
        return Err(m.error(format!(
            "material '{}': micropolar bonds need poisson_ratio <= 1/4 (c_s >= 0), the deck gives {nu}; use model 'lps' for larger values",
            m.name
        )));
    }
    let d4 = PI * delta.powi(4);
    let cn = 6.0 * e / (d4 * (1.0 - 2.0 * nu));
    let cs = 6.0 * e * (1.0 - 4.0 * nu) / (d4 * (1.0 + nu) * (1.0 - 2.0 * nu));
    let (tensile, compressive) = if concrete {
        let tensile = m.positive("tensile_stretch", Dimension::NUMBER)?;
        let compressive = m.checked(
            "compressive_stretch",
            Dimension::NUMBER,
            |c| c < 0.0,
            "be < 0",
        )?;
        (
            m.require(tensile, "tensile_stretch", name)?,
            m.require(compressive, "compressive_stretch", name)?,
        )
    } else {
        let s0 =
            m.critical_stretch_or(|g0| (5.0 * g0 * (1.0 - 2.0 * nu) / (3.0 * e * delta)).sqrt())?;
        (s0, f64::NEG_INFINITY)
    };
    Ok(Own {
        cn,
        cs,
        tensile,
        compressive,
    })
}

impl Model for Micropolar {
    const NAME: &'static str = "micropolar";
    const SUMMARY: &'static str =
        "bond-based micropolar solid: displacements and rotations, bond force and two moments, nu <= 1/4 (DERIVED)";
    const OPTIONS: &'static [(&'static str, &'static str)] = &[(
        "kappa",
        "relative-rotation stiffness as a multiple of c_n*delta^2 (default 0; uncalibrated)",
    )];

    // About 115 flops per bond: four bonds side by side fill the vector lanes
    // (docs/performance.md).
    const BOND_LANES: usize = LANES;

    type Alter = Motion6;
    type Fixed = ();
    type Bond = ();
    type State = ();
    type Force = Force6;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let kappa = b.option("kappa")?.unwrap_or(0.0);
        if !(kappa.is_finite() && kappa >= 0.0) {
            return Err(format!("model 'micropolar': kappa must be >= 0 (got {kappa})").into());
        }
        let delta = b.horizon;
        let own = b.per_material(own_constants)?;
        Ok(Micropolar {
            own,
            density: b.materials.iter().map(|m| m.density).collect(),
            kappa,
            delta,
            spacing: b.spacing,
        })
    }

    fn sample(of: &SampleOf) -> Option<Sample> {
        Some(match *of {
            // The benchmark's bulk modulus at ν = 0.2, so that the shear part (c_s > 0) and its
            // moments are computed; rotations bound the step below the other models' 1e-7 s
            // (docs/theory.md §4).
            SampleOf::Benchmark {
                micromodulus,
                horizon,
                critical_stretch,
                density,
            } => {
                let k = micromodulus * PI * horizon.powf(4.0) / 18.0;
                Sample::new(format!(
                    "density = {density}\nyoungs_modulus = {:e}\npoisson_ratio = 0.2\ncritical_stretch = {critical_stretch}\n",
                    3.0 * k * (1.0 - 0.4)
                ))
                .with_dt(5e-8)
            }
            SampleOf::Solid {
                youngs_modulus,
                density,
                critical_stretch,
                full,
                ..
            } => {
                let sample = Sample::new(format!(
                    "density = {density}\nyoungs_modulus = {youngs_modulus:e}\npoisson_ratio = 0.2\n{}",
                    stretch_line("critical_stretch", critical_stretch)
                ));
                if full {
                    sample.with_options("kappa = 0.05\n")
                } else {
                    sample
                }
            }
        })
    }

    fn breaks(&self) -> bool {
        self.own
            .iter()
            .any(|o| o.tensile.is_finite() || o.compressive.is_finite())
    }

    fn inertia(&self, material: u16, volume: f64, _: &()) -> Force6 {
        let m = self.density[material as usize] * volume;
        let j = m * self.spacing * self.spacing / 6.0;
        Force6 {
            force: [m; 3],
            moment: [j; 3],
        }
    }

    fn law(&self, mi: u16, mj: u16) -> Law {
        let (a, b) = (self.own[mi as usize], self.own[mj as usize]);
        let series = |x: f64, y: f64| {
            if x + y > 0.0 {
                2.0 * x * y / (x + y)
            } else {
                0.0
            }
        };
        let (cn, cs) = (series(a.cn, b.cn), series(a.cs, b.cs));
        Law {
            a: cn - cs,
            cs,
            kappa: self.kappa * cn * self.delta * self.delta,
            tensile: a.tensile.min(b.tensile),
            compressive: a.compressive.max(b.compressive),
            c_max: cn.max(cs),
        }
    }

    fn bond_stiffness(&self, law: &Law, geom: &BondGeom) -> Force6 {
        let t = law.c_max / geom.length;
        // docs/theory.md §4: rotations bound the step through c_s L/4 + κ_φ.
        let r = law.cs * geom.length / 4.0 + law.kappa;
        Force6 {
            force: [t; 3],
            moment: [r; 3],
        }
    }

    fn lame(&self, material: u16) -> (f64, f64) {
        let o = self.own[material as usize];
        let d4 = PI * self.delta.powi(4);
        (
            d4 * (o.cn - o.cs) / 30.0,
            d4 * (2.0 * o.cn + 3.0 * o.cs) / 60.0,
        )
    }

    fn drift(&self, a: &mut Motion6, h: f64) {
        for k in 0..3 {
            a.pos[k] += h * a.vel[k];
        }
        let w = a.angular_velocity;
        let q = product(&quaternion([h * w[0], h * w[1], h * w[2]]), &a.orientation);
        let n = 1.0 / (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        a.orientation = [q[0] * n, q[1] * n, q[2] * n, q[3] * n];
        a.frame = matrix(&a.orientation);
        a.rotation = rotation_vector(&a.orientation);
    }

    #[inline(always)]
    fn pair(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _: &mut (),
    ) -> Option<(Force6, Force6)> {
        let ends = Ends {
            pos: [i.pos(), j.pos()],
            x0: [*i.x0, *j.x0],
            frame: [i.alter.frame, j.alter.frame],
        };
        let k = kinematics(&ends, geom.length);
        if k.s > law.tensile || k.s < law.compressive {
            return None;
        }
        let v = geom.beta * i.volume * j.volume;
        let mut fm = forces(&k, law.a, law.cs, geom.length, v);
        // κ_φ = 0 (the default) skips the relative rotation; one law per pass keeps the branch
        // predictable.
        if law.kappa != 0.0 {
            let (qi, qj) = (&i.alter.orientation, &j.alter.orientation);
            add_relative(law.kappa, v, qi, qj, &mut fm);
        }
        let [f, moment_i, moment_j] = fm;
        Some((
            Force6 {
                force: f,
                moment: moment_i,
            },
            Force6 {
                force: [-f[0], -f[1], -f[2]],
                moment: moment_j,
            },
        ))
    }

    /// Four bonds as the four lanes of `F4` values, through the same `kinematics`, `forces`
    /// and `add_relative` as `pair`: the same bits, every operation on four bonds at once.
    #[inline(always)]
    fn pair_lanes(
        &self,
        law: [&Law; LANES],
        i: &Side<Self>,
        j: [&Side<Self>; LANES],
        geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        let rows = [
            j[0].alter.as_slice(),
            j[1].alter.as_slice(),
            j[2].alter.as_slice(),
            j[3].alter.as_slice(),
        ];
        let own = |v: &[f64]| [F4::splat(v[0]), F4::splat(v[1]), F4::splat(v[2])];
        let [p0, p1, p2, _] = F4::columns::<POS>(rows);
        let [r0, r1, r2, r3] = F4::columns::<FRAME>(rows);
        let [r4, r5, r6, r7] = F4::columns::<{ FRAME + 4 }>(rows);
        let r8 = F4::gather(|l| rows[l][FRAME + 8]);
        let fi = &i.alter.frame;
        let ends = Ends {
            pos: [own(&i.alter.pos), [p0, p1, p2]],
            x0: [
                own(i.x0),
                [
                    F4::gather(|l| j[l].x0[0]),
                    F4::gather(|l| j[l].x0[1]),
                    F4::gather(|l| j[l].x0[2]),
                ],
            ],
            frame: [
                [
                    F4::splat(fi[0]),
                    F4::splat(fi[1]),
                    F4::splat(fi[2]),
                    F4::splat(fi[3]),
                    F4::splat(fi[4]),
                    F4::splat(fi[5]),
                    F4::splat(fi[6]),
                    F4::splat(fi[7]),
                    F4::splat(fi[8]),
                ],
                [r0, r1, r2, r3, r4, r5, r6, r7, r8],
            ],
        };
        let length = F4::gather(|l| geom[l].length);
        let k = kinematics(&ends, length);
        let tensile = F4::gather(|l| law[l].tensile);
        if k.s.any_outside(F4::gather(|l| law[l].compressive), tensile) {
            return None;
        }
        let v = F4::gather(|l| geom[l].beta * i.volume * j[l].volume);
        let (a, cs) = (F4::gather(|l| law[l].a), F4::gather(|l| law[l].cs));
        let mut fm = forces(&k, a, cs, length, v);
        // κ_φ of every law is the option times c_n δ², so this is the same test as `pair`'s.
        if self.kappa != 0.0 {
            let q = &i.alter.orientation;
            let qi = [
                F4::splat(q[0]),
                F4::splat(q[1]),
                F4::splat(q[2]),
                F4::splat(q[3]),
            ];
            let qj = F4::columns::<ORIENTATION>(rows);
            add_relative(F4::gather(|l| law[l].kappa), v, &qi, &qj, &mut fm);
        }
        let [f, m_i, m_j] = fm;
        let zero = F4::splat(0.0);
        Some(LaneForces {
            i: [f[0], f[1], f[2], m_i[0], m_i[1], m_i[2], zero, zero],
            j: [-f[0], -f[1], -f[2], m_j[0], m_j[1], m_j[2], zero, zero],
            opposite: false,
        })
    }

    fn energy(&self, law: &Law, i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let ends = Ends {
            pos: [i.pos(), j.pos()],
            x0: [*i.x0, *j.x0],
            frame: [i.alter.frame, j.alter.frame],
        };
        let k = kinematics(&ends, geom.length);
        let (s, big_g) = (k.s, k.g);
        let (_, one_minus_cos) = relative(&i.alter.orientation, &j.alter.orientation);
        let l2 = geom.length * geom.length;
        let g2 = (big_g[0] * big_g[0] + big_g[1] * big_g[1] + big_g[2] * big_g[2]) / l2;
        geom.beta
            * i.volume
            * j.volume
            * (0.5 * geom.length * (law.a * s * s + law.cs * g2) + law.kappa * one_minus_cos)
    }

    fn at_rest(&self, a: &mut Motion6) {
        a.orientation = [1.0, 0.0, 0.0, 0.0];
        a.frame = matrix(&a.orientation);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::material::PlainNumbers;
    use crate::model::{Material, OptionValue, Written};

    fn model(kappa: f64, materials: &[Material]) -> Micropolar {
        let options = [("kappa".to_string(), OptionValue::Number(kappa))];
        Micropolar::build(&ModelBuild {
            materials,
            horizon: 3.015e-3,
            spacing: 1e-3,
            options: &options,
        })
        .unwrap()
    }

    fn solid(name: &str, e: f64, nu: f64, s0: f64) -> Material {
        let keys = [
            ("youngs_modulus", e),
            ("poisson_ratio", nu),
            ("critical_stretch", s0),
        ];
        let keys = keys
            .iter()
            .map(|&(k, v)| (k.to_string(), Written::Number(v)))
            .collect();
        Material::new(name, 0, MaterialKind::Solid, 2400.0, keys, &PlainNumbers).unwrap()
    }

    /// A particle moved and turned by a deterministic pseudo-random amount.
    fn particle(seed: u64, x0: [f64; 3], scale: f64) -> Motion6 {
        let mut x = seed.wrapping_mul(0x9e3779b97f4a7c15) | 1;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut a = Motion6::default();
        for (p, x) in a.pos.iter_mut().zip(x0) {
            *p = x + scale * 1e-4 * next();
        }
        let r = [scale * next(), scale * next(), scale * next()];
        a.orientation = quaternion(r);
        a.frame = matrix(&a.orientation);
        a
    }

    /// `pair_lanes` gives `pair`'s forces bit for bit, with and without κ_φ, for two materials,
    /// and `None` when one lane breaks.
    #[test]
    fn lanes_give_the_single_bond_forces_bit_for_bit() {
        let materials = [solid("a", 30e9, 0.2, 0.01), solid("b", 200e9, 0.1, 0.02)];
        for kappa in [0.0, 0.3] {
            let m = model(kappa, &materials);
            let x0 = [
                [0.0, 0.0, 0.0],
                [1e-3, 0.0, 0.0],
                [0.0, 2e-3, 1e-3],
                [1e-3, 1e-3, 1e-3],
                [-2e-3, 1e-3, 0.0],
            ];
            let alter: Vec<Motion6> = (0..5).map(|p| particle(p as u64 + 7, x0[p], 0.2)).collect();
            let material = [0u16, 1, 0, 1, 1];
            let side = |p: usize| Side::<Micropolar> {
                x0: &x0[p],
                volume: 1e-9 * (1.0 + p as f64 / 10.0),
                material: material[p],
                alter: &alter[p],
                fixed: &(),
                state: &(),
            };
            let i = side(0);
            let js = [side(1), side(2), side(3), side(4)];
            let geoms: Vec<BondGeom> = (1..5)
                .map(|p| {
                    let d = [
                        x0[p][0] - x0[0][0],
                        x0[p][1] - x0[0][1],
                        x0[p][2] - x0[0][2],
                    ];
                    BondGeom {
                        length: (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(),
                        beta: 1.0 - p as f64 / 20.0,
                    }
                })
                .collect();
            let laws: Vec<Law> = js.iter().map(|j| m.law(0, j.material)).collect();
            let lanes = m
                .pair_lanes(
                    [&laws[0], &laws[1], &laws[2], &laws[3]],
                    &i,
                    [&js[0], &js[1], &js[2], &js[3]],
                    [&geoms[0], &geoms[1], &geoms[2], &geoms[3]],
                )
                .expect("no lane breaks");
            for l in 0..LANES {
                let (a, b) = m.pair(&laws[l], &i, &js[l], &geoms[l], &mut ()).unwrap();
                for (c, (x, y)) in a.as_slice().iter().zip(b.as_slice()).enumerate() {
                    assert_eq!(
                        lanes.i[c].lane(l).to_bits(),
                        x.to_bits(),
                        "kappa {kappa} lane {l} i {c}"
                    );
                    assert_eq!(
                        lanes.j[c].lane(l).to_bits(),
                        y.to_bits(),
                        "kappa {kappa} lane {l} j {c}"
                    );
                }
                assert!(a.moment.iter().any(|&v| v != 0.0));
            }
            // Lane 2 stretched past its critical stretch: the group is refused.
            let mut far = alter[3];
            far.pos[0] += 1e-4;
            let j2 = Side::<Micropolar> {
                alter: &far,
                ..side(3)
            };
            assert!(m.pair(&laws[2], &i, &j2, &geoms[2], &mut ()).is_none());
            assert!(m
                .pair_lanes(
                    [&laws[0], &laws[1], &laws[2], &laws[3]],
                    &i,
                    [&js[0], &js[1], &j2, &js[3]],
                    [&geoms[0], &geoms[1], &geoms[2], &geoms[3]],
                )
                .is_none());
        }
    }

    #[test]
    fn quaternions_round_trip() {
        let r = [0.3, -1.2, 0.7];
        let back = rotation_vector(&quaternion(r));
        for k in 0..3 {
            assert!((back[k] - r[k]).abs() < 1e-14);
        }
        // A quarter turn about z takes x to y.
        let q = quaternion([0.0, 0.0, PI / 2.0]);
        let m = matrix(&q);
        let v = [m[0], m[3], m[6]];
        assert!((v[0]).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15);
        // Relative rotation of identity to q: sin|φ| φ̂ = (0, 0, 1), 1 − cos|φ| = 1.
        let (s, c) = relative(&[1.0, 0.0, 0.0, 0.0], &q);
        assert!((s[2] - 1.0).abs() < 1e-15 && (c - 1.0).abs() < 1e-15);
    }

    #[test]
    fn small_angle_series_match_the_trigonometric_forms() {
        // Both sides of each series' threshold, against the closed forms.
        for a in [1e-9_f64, 1e-4, 0.01, 0.0624, 0.0626, 0.3] {
            let r = [0.48 * a, -0.6 * a, 0.64 * a];
            let angle = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
            let q = quaternion(r);
            let k = (0.5 * angle).sin() / angle;
            let exact = [(0.5 * angle).cos(), k * r[0], k * r[1], k * r[2]];
            for c in 0..4 {
                assert!(
                    (q[c] - exact[c]).abs() <= 2e-16 * (1.0 + exact[c].abs()),
                    "a={a}"
                );
            }
            let back = rotation_vector(&exact);
            for c in 0..3 {
                assert!(
                    (back[c] - r[c]).abs() <= 4e-16 * angle,
                    "a={a}: {back:?} vs {r:?}"
                );
            }
        }
    }
}
