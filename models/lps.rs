//! LPS: Silling's linear peridynamic solid, ordinary state-based (Silling et al. 2007;
//! docs/theory.md §2), any Poisson's ratio.
//!
//! * weighted volume m_i = Σ_j ω L² V_j β, summed once over the reference family (broken bonds
//!   keep counting, as in Peridigm);
//! * dilatation θ_i = (3/m_i) Σ_j ω L e V_j β over intact bonds (the state pass);
//! * force state t_i = ω[(3K − 5G) θ_i L / m_i + 15G e / m_i], i.e. 3Kθ_i ω L/m_i plus 15G/m_i
//!   times ω times the deviatoric extension e − θ_i L/3; the pair force on i is
//!   (t_i + t_j) V_i V_j β along the current bond, each end with its own material's K and G;
//! * energy (K/2) θ_i² V_i per particle plus (15G/(2m_i)) ω (e − θ_i L/3)² V_i V_j β per bond
//!   end;
//! * critical-stretch damage; from a fracture energy with PeriLab's
//!   s_c = √(G0 / ([3G + (3/4)⁴ (K − 5G/3)] δ)), which depends on ω and is approximate.
//!
//! Influence functions (`[model.options] influence`): "one" (ω = 1, Peridigm's default),
//! "inverse_length" (ω = δ/L, LAMMPS's and Peridynamics.jl's), "gaussian"
//! (ω = exp(−L²/(0.4δ)²)).

use crate::model::lanes::{LaneForces, Real, F4, LANES, MAX_COMPONENTS};
use crate::model::{
    check_options, stretch_line, BondGeom, Dimension, ElasticConstant, Isotropic, Material, Model,
    ModelBuild, ModelError, Sample, SampleOf, Side,
};

use super::pmb::lane_positions;
pub use super::pmb::{Force3, Motion};

crate::attributes! {
    /// m_i = Σ ω L² V_j β over the reference family.
    pub struct WeightedVolume { pub weighted_volume: f64 }
}

crate::attributes! {
    /// θ_i, the peridynamic volume strain, and 1/m_i: the pair force needs both ends' 1/m,
    /// and reading it next to θ saves a division and a second gathered record per bond.
    pub struct Dilatation { pub dilatation: f64, pub inverse_weighted_volume: f64 }
}

/// How bonds are weighted by their reference length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Influence {
    One,
    InverseLength,
    Gaussian,
}

impl Influence {
    fn parse(word: Option<&str>) -> Result<Influence, String> {
        match word.unwrap_or("one") {
            "one" | "1" => Ok(Influence::One),
            "inverse_length" | "1/r" => Ok(Influence::InverseLength),
            "gaussian" => Ok(Influence::Gaussian),
            other => Err(format!(
                "model 'lps': unknown influence '{other}' (use \"one\", \"inverse_length\" or \"gaussian\")"
            )),
        }
    }
}

/// Moduli of both ends of a bond and its critical stretch: `a = 3K − 5G`, `b = 15G`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    pub ai: f64,
    pub bi: f64,
    pub aj: f64,
    pub bj: f64,
    pub s0: f64,
    /// PMB micromodulus of the same P-wave modulus, for the stable time step.
    pub c_equivalent: f64,
}

#[derive(Clone, Debug)]
pub struct Lps {
    /// (K, G) of each material.
    moduli: Vec<(f64, f64)>,
    s0: Vec<f64>,
    density: Vec<f64>,
    delta: f64,
    influence: Influence,
}

impl Lps {
    /// ω(L)/d, with at most one division (the bond loops run this for every bond), on one
    /// bond or four.
    #[inline(always)]
    fn omega_over<T: Real>(&self, length: T, d: T) -> T {
        match self.influence {
            Influence::One => T::splat(1.0) / d,
            Influence::InverseLength => T::splat(self.delta) / (length * d),
            Influence::Gaussian => {
                let r = length / T::splat(0.4 * self.delta);
                (-r * r).lanewise(f64::exp) / d
            }
        }
    }

    /// ω(L)·L, without a division.
    #[inline(always)]
    fn omega_length<T: Real>(&self, length: T) -> T {
        match self.influence {
            Influence::One => length,
            Influence::InverseLength => T::splat(self.delta),
            Influence::Gaussian => {
                let r = length / T::splat(0.4 * self.delta);
                length * (-r * r).lanewise(f64::exp)
            }
        }
    }

    fn omega(&self, length: f64) -> f64 {
        self.omega_over(length, 1.0)
    }

    /// A bond's share of its ends' dilatation sums before the volume of the other end:
    /// ω L e β.
    #[inline(always)]
    fn dilatation_weight<T: Real>(&self, e: T, length: T, beta: T) -> T {
        self.omega_length(length) * e * beta
    }

    /// The pair force on end i per unit bond vector: ω/r (t_i + t_j) β V_i V_j, with both
    /// ends' dilatations `theta`, inverse weighted volumes `inv_m` and volumes `v`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn force_factor<T: Real>(
        &self,
        law: &LawLanes<T>,
        length: T,
        e: T,
        r: T,
        theta: [T; 2],
        inv_m: [T; 2],
        beta: T,
        v: [T; 2],
    ) -> T {
        let t = length * (law.ai * theta[0] * inv_m[0] + law.aj * theta[1] * inv_m[1])
            + e * (law.bi * inv_m[0] + law.bj * inv_m[1]);
        self.omega_over(length, r) * t * beta * v[0] * v[1]
    }
}

/// The moduli of a [`Law`] on one bond (`f64`) or four (`F4`).
struct LawLanes<T> {
    ai: T,
    bi: T,
    aj: T,
    bj: T,
}

/// The bond vector and its length r, and the elongation r − L.
#[inline(always)]
fn bond_vector<T: Real>(a: [T; 3], b: [T; 3], length: T) -> ([T; 3], T, T) {
    let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
    (y, r, r - length)
}

impl Model for Lps {
    const NAME: &'static str = "lps";
    const SUMMARY: &'static str =
        "state-based linear peridynamic solid (Silling 2007): any nu, dilatation pass, critical stretch";
    const OPTIONS: &'static [(&'static str, &'static str)] = &[(
        "influence",
        "influence function: \"one\" (default), \"inverse_length\" (delta/L) or \"gaussian\"",
    )];
    const FIXED_FROM_BONDS: bool = true;
    const LAMMPS_PEER: Option<&'static str> = Some("peri/lps");
    const BOND_LANES: usize = LANES;

    type Alter = Motion;
    type Fixed = WeightedVolume;
    type Bond = ();
    type State = Dilatation;
    type Force = Force3;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let influence = Influence::parse(b.word("influence")?)?;
        let delta = b.horizon;
        let (mut moduli, mut s0) = (Vec::new(), Vec::new());
        for m in b.materials {
            let (k, g, s) = own_constants(m, delta)?;
            moduli.push((k, g));
            s0.push(s);
        }
        Ok(Lps {
            moduli,
            s0,
            density: b.materials.iter().map(|m| m.density).collect(),
            delta,
            influence,
        })
    }

    fn sample(of: &SampleOf) -> Option<Sample> {
        Some(match *of {
            // LAMMPS `peri/lps`'s own constants (K = G = 14.9 GPa, so ν = 1/8) and influence
            // function ω = δ/L, so that the peer runs the same scene.
            SampleOf::Benchmark {
                critical_stretch,
                density,
                ..
            } => Sample::new(format!(
                "density = {density}\nbulk_modulus = 14.9e9\npoisson_ratio = 0.125\ncritical_stretch = {critical_stretch}\n"
            ))
            .with_options("influence = \"inverse_length\"\n"),
            // Plain: ν = ¼, where the dilatation term vanishes (3K − 5G = 0) and LPS is the
            // bond-based solid (what `pdq stress` compares). Full: ν = 0.3, so that the state
            // pass and the dilatation term carry force (the tests' decks).
            SampleOf::Solid {
                youngs_modulus,
                density,
                critical_stretch,
                full,
                ..
            } => Sample::new(format!(
                "density = {density}\nyoungs_modulus = {youngs_modulus:e}\npoisson_ratio = {}\n{}",
                if full { 0.3 } else { 0.25 },
                stretch_line("critical_stretch", critical_stretch)
            )),
        })
    }

    fn breaks(&self) -> bool {
        self.s0.iter().any(|s| s.is_finite())
    }

    fn inertia(&self, material: u16, volume: f64, _: &WeightedVolume) -> Force3 {
        let m = self.density[material as usize] * volume;
        Force3 { force: [m; 3] }
    }

    fn law(&self, mi: u16, mj: u16) -> Law {
        let ((ki, gi), (kj, gj)) = (self.moduli[mi as usize], self.moduli[mj as usize]);
        // A PMB solid has P-wave modulus πδ⁴c/10; the stiffer end sets the time step.
        let p_wave = (ki + 4.0 * gi / 3.0).max(kj + 4.0 * gj / 3.0);
        Law {
            ai: 3.0 * ki - 5.0 * gi,
            bi: 15.0 * gi,
            aj: 3.0 * kj - 5.0 * gj,
            bj: 15.0 * gj,
            s0: self.s0[mi as usize].min(self.s0[mj as usize]),
            c_equivalent: 10.0 * p_wave / (std::f64::consts::PI * self.delta.powi(4)),
        }
    }

    fn bond_stiffness(&self, law: &Law, geom: &BondGeom) -> Force3 {
        Force3 {
            force: [law.c_equivalent / geom.length; 3],
        }
    }

    fn relaxation_stiffness(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
    ) -> Force3 {
        // The force's derivative along the bond, ω (bᵢ/mᵢ + bⱼ/mⱼ), plus the dilatation's
        // coupling to the other bonds of each end, 3|aᵢ|ω/mᵢ per bond (Cauchy–Schwarz:
        // (Σ ω L V)² ≤ Σ ω V · mᵢ). Near a free face mᵢ is small and the bonds stiffer, which
        // the continuum micromodulus of `bond_stiffness` does not see.
        let w = self.omega(geom.length);
        let end = |a: f64, b: f64, m: f64| (b + 3.0 * a.abs()) / m;
        let c = w
            * (end(law.ai, law.bi, i.fixed.weighted_volume)
                + end(law.aj, law.bj, j.fixed.weighted_volume));
        Force3 { force: [c; 3] }
    }

    fn lame(&self, material: u16) -> (f64, f64) {
        let (k, g) = self.moduli[material as usize];
        (k - 2.0 * g / 3.0, g)
    }

    fn bond_fixed(
        &self,
        _: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
    ) -> (WeightedVolume, WeightedVolume) {
        let w = self.omega(geom.length) * geom.length * geom.length * geom.beta;
        (
            WeightedVolume {
                weighted_volume: w * j.volume,
            },
            WeightedVolume {
                weighted_volume: w * i.volume,
            },
        )
    }

    #[inline(always)]
    fn state(
        &self,
        _: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _: &(),
    ) -> (Dilatation, Dilatation) {
        let (_, _, e) = bond_vector(i.pos(), j.pos(), geom.length);
        let w = self.dilatation_weight(e, geom.length, geom.beta);
        (
            Dilatation {
                dilatation: w * j.volume,
                inverse_weighted_volume: 0.0,
            },
            Dilatation {
                dilatation: w * i.volume,
                inverse_weighted_volume: 0.0,
            },
        )
    }

    /// `state` on four bonds, one per lane.
    #[inline(always)]
    fn state_lanes(
        &self,
        _: [&Law; LANES],
        i: &Side<Self>,
        j: [&Side<Self>; LANES],
        geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        let (a, b) = lane_positions(i, j);
        let length = F4::gather(|l| geom[l].length);
        let (_, _, e) = bond_vector(a, b, length);
        let w = self.dilatation_weight(e, length, F4::gather(|l| geom[l].beta));
        let zero = F4::splat(0.0);
        let mut out = LaneForces {
            i: [zero; MAX_COMPONENTS],
            j: [zero; MAX_COMPONENTS],
            opposite: false,
        };
        out.i[0] = w * F4::gather(|l| j[l].volume);
        out.j[0] = w * F4::splat(i.volume);
        Some(out)
    }

    fn finish_state(&self, state: &mut Dilatation, fixed: &WeightedVolume) {
        let inv = 1.0 / fixed.weighted_volume;
        state.dilatation *= 3.0 * inv;
        state.inverse_weighted_volume = inv;
    }

    #[inline(always)]
    fn pair(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _: &mut (),
    ) -> Option<(Force3, Force3)> {
        let l = geom.length;
        let (y, r, e) = bond_vector(i.pos(), j.pos(), l);
        if e > law.s0 * l {
            return None;
        }
        let moduli = LawLanes {
            ai: law.ai,
            bi: law.bi,
            aj: law.aj,
            bj: law.bj,
        };
        let (si, sj) = (i.state, j.state);
        let f = self.force_factor(
            &moduli,
            l,
            e,
            r,
            [si.dilatation, sj.dilatation],
            [si.inverse_weighted_volume, sj.inverse_weighted_volume],
            geom.beta,
            [i.volume, j.volume],
        );
        let fi = [f * y[0], f * y[1], f * y[2]];
        Some((
            Force3 { force: fi },
            Force3 {
                force: [-fi[0], -fi[1], -fi[2]],
            },
        ))
    }

    /// `pair` on four bonds, one per lane, through the same `bond_vector` and `force_factor`.
    #[inline(always)]
    fn pair_lanes(
        &self,
        law: [&Law; LANES],
        i: &Side<Self>,
        j: [&Side<Self>; LANES],
        geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        let (a, b) = lane_positions(i, j);
        let l = F4::gather(|k| geom[k].length);
        let (y, r, e) = bond_vector(a, b, l);
        let s0_l = F4::gather(|k| law[k].s0) * l;
        if e.any_outside(F4::splat(f64::NEG_INFINITY), s0_l) {
            return None;
        }
        let moduli = LawLanes {
            ai: F4::gather(|k| law[k].ai),
            bi: F4::gather(|k| law[k].bi),
            aj: F4::gather(|k| law[k].aj),
            bj: F4::gather(|k| law[k].bj),
        };
        let si = i.state;
        let f = self.force_factor(
            &moduli,
            l,
            e,
            r,
            [
                F4::splat(si.dilatation),
                F4::gather(|k| j[k].state.dilatation),
            ],
            [
                F4::splat(si.inverse_weighted_volume),
                F4::gather(|k| j[k].state.inverse_weighted_volume),
            ],
            F4::gather(|k| geom[k].beta),
            [F4::splat(i.volume), F4::gather(|k| j[k].volume)],
        );
        Some(LaneForces::central(f, &y))
    }

    fn energy(&self, law: &Law, i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let (a, b) = (i.pos(), j.pos());
        let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let l = geom.length;
        let e = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt() - l;
        let (ei, ej) = (
            e - i.state.dilatation * l / 3.0,
            e - j.state.dilatation * l / 3.0,
        );
        // b = 15G, so 15G/(2m) = b/(2m).
        0.5 * self.omega(l)
            * geom.beta
            * i.volume
            * j.volume
            * (law.bi * ei * ei / i.fixed.weighted_volume
                + law.bj * ej * ej / j.fixed.weighted_volume)
    }

    fn particle_energy(
        &self,
        material: u16,
        volume: f64,
        _: &WeightedVolume,
        state: &Dilatation,
    ) -> f64 {
        let k = self.moduli[material as usize].0;
        0.5 * k * state.dilatation * state.dilatation * volume
    }
}

/// K, G and the critical stretch of one material: ν with E or K, s0 given or from G0.
fn own_constants(m: &Material, delta: f64) -> Result<(f64, f64, f64), ModelError> {
    m.only_uses(
        &[
            "youngs_modulus",
            "bulk_modulus",
            "poisson_ratio",
            "critical_stretch",
            "fracture_energy",
        ],
        Lps::NAME,
    )?;
    let nu = m.require(m.poisson_ratio()?, "poisson_ratio", Lps::NAME)?;
    let (which, value) = m.one_of(
        &[
            ("youngs_modulus", Dimension::STRESS),
            ("bulk_modulus", Dimension::STRESS),
        ],
        Lps::NAME,
        "one of 'youngs_modulus' or 'bulk_modulus' (with 'poisson_ratio')",
    )?;
    let given = if which == 0 {
        ElasticConstant::YoungsModulus(value)
    } else {
        ElasticConstant::BulkModulus(value)
    };
    let elastic =
        Isotropic::from_any_two(given, ElasticConstant::PoissonRatio(nu)).expect("E or K, with ν");
    let (k, g) = (elastic.bulk_modulus, elastic.shear_modulus);
    let s = m.critical_stretch_or(|g0| {
        (g0 / ((3.0 * g + 0.75f64.powi(4) * (k - 5.0 * g / 3.0)) * delta)).sqrt()
    })?;
    if !(k.is_finite() && k > 0.0 && g > 0.0) {
        return Err(m.error(format!(
            "material '{}': the moduli must be > 0 (K = {k:e}, G = {g:e})",
            m.name
        )));
    }
    if s.is_nan() || s <= 0.0 {
        return Err(m.error(format!(
            "material '{}': critical stretch must be > 0",
            m.name
        )));
    }
    Ok((k, g, s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::attributes::Attributes;
    use crate::model::lanes::fixture::{assert_same_bits, geom, moved, volume, X0};
    use crate::model::material::{MaterialKind, PlainNumbers};
    use crate::model::{OptionValue, Written};

    fn solid(name: &str, e: f64, nu: f64, s0: f64) -> Material {
        let keys = [
            ("youngs_modulus", e),
            ("poisson_ratio", nu),
            ("critical_stretch", s0),
        ]
        .iter()
        .map(|&(k, v)| (k.to_string(), Written::Number(v)))
        .collect();
        Material::new(name, 0, MaterialKind::Solid, 2400.0, keys, &PlainNumbers).unwrap()
    }

    /// `state_lanes` and `pair_lanes` give `state`'s and `pair`'s values bit for bit, for each
    /// influence function and two materials, and `pair_lanes` refuses a group with a breaking
    /// bond.
    #[test]
    fn lanes_give_the_single_bond_values_bit_for_bit() {
        let materials = [solid("a", 30e9, 0.3, 0.01), solid("b", 200e9, 0.1, 0.02)];
        for influence in ["one", "inverse_length", "gaussian"] {
            let options = [(
                "influence".to_string(),
                OptionValue::Word(influence.to_string()),
            )];
            let m = Lps::build(&ModelBuild {
                materials: &materials,
                horizon: 3.015e-3,
                spacing: 1e-3,
                options: &options,
            })
            .unwrap();
            // Particles 0-4, and particle 3 moved past its bond's critical stretch (5).
            let mut alter: Vec<Motion> = (0..5)
                .map(|p| Motion {
                    pos: moved(p),
                    vel: [0.0; 3],
                })
                .collect();
            let mut far = alter[3];
            far.pos[0] += 1e-4;
            alter.push(far);
            let material = [0u16, 1, 0, 1, 1];
            // Dilatations of both signs and distinct 1/m, as after `finish_state`.
            let fixed: Vec<WeightedVolume> = (0..5)
                .map(|p| WeightedVolume {
                    weighted_volume: 1e-12 * (2.0 + p as f64),
                })
                .collect();
            let state: Vec<Dilatation> = (0..5)
                .map(|p| Dilatation {
                    dilatation: 1e-4 * (p as f64 - 2.5),
                    inverse_weighted_volume: 1.0 / fixed[p].weighted_volume,
                })
                .collect();
            let side = |p: usize, a: usize| Side::<Lps> {
                x0: &X0[p],
                volume: volume(p),
                material: material[p],
                alter: &alter[a],
                fixed: &fixed[p],
                state: &state[p],
            };
            let i = side(0, 0);
            let js = [1, 2, 3, 4].map(|p| side(p, p));
            let geoms = [geom(1), geom(2), geom(3), geom(4)];
            let laws = js.each_ref().map(|j| m.law(0, j.material));
            let (law_refs, geom_refs) = (laws.each_ref(), geoms.each_ref());

            let states = m
                .state_lanes(law_refs, &i, js.each_ref(), geom_refs)
                .unwrap();
            let single: [(Dilatation, Dilatation); LANES] =
                std::array::from_fn(|l| m.state(&laws[l], &i, &js[l], &geoms[l], &()));
            let slices = single.each_ref().map(|(a, b)| (a.as_slice(), b.as_slice()));
            assert_same_bits(&states, slices, &format!("{influence} state"));

            let forces = m
                .pair_lanes(law_refs, &i, js.each_ref(), geom_refs)
                .expect("no lane breaks");
            let single: [(Force3, Force3); LANES] =
                std::array::from_fn(|l| m.pair(&laws[l], &i, &js[l], &geoms[l], &mut ()).unwrap());
            let slices = single.each_ref().map(|(a, b)| (a.as_slice(), b.as_slice()));
            assert_same_bits(&forces, slices, &format!("{influence} pair"));
            assert!(single
                .iter()
                .all(|(a, _)| a.force.iter().any(|&f| f != 0.0)));

            let j2 = side(3, 5);
            assert!(m.pair(&laws[2], &i, &j2, &geoms[2], &mut ()).is_none());
            assert!(m
                .pair_lanes(law_refs, &i, [&js[0], &js[1], &j2, &js[3]], geom_refs)
                .is_none());
        }
    }
}
