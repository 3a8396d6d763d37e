//! Thermomechanical PMB: the PMB bond (docs/theory.md §1) plus temperature as a first-order degree
//! of freedom with peridynamic heat conduction (thesis Table 2.1; Bobaru & Duangpanya 2010).
//!
//! * Heat into i through bond ij: q = κ_ij (T_j − T_i)/|ξ| · V_i V_j β; j receives −q. The
//!   microconductivity comes from energy equivalence with Fourier's law: κ = 6k/(πδ⁴) for the
//!   continuum family ∫|ξ| dV = πδ⁴. PDQ uses the particle's discrete family instead,
//!   κ_ij = 12k / (S_i + S_j) with S_i = Σ_j |ξ| V_j β (as LPS uses its discrete weighted
//!   volume): the conductivity of a cubic lattice is then exactly k in the bulk, and particles
//!   near a surface, with smaller S, conduct more (like the volume correction of docs/theory.md §6).
//! * ρ c_p V Ṫ = Σ q, integrated by forward Euler (the engine's first-order DOFs).
//! * Thermal expansion couples temperature into the mechanical stretch:
//!   s = (|y| − |ξ|)/|ξ| − α (½(T_i + T_j) − T_ref), with α = `thermal_expansion` (default 0)
//!   and T_ref the option `reference_temperature` (default 0).
//! * A broken bond carries neither force nor heat: a crack insulates.

use crate::model::{
    bond_based_lame, check_options, stretch_line, BondGeom, Dimension, ElasticConstant, Isotropic,
    Material, Model, ModelBuild, ModelError, Sample, SampleOf, Side,
};
use std::f64::consts::PI;

crate::attributes! {
    /// Position, velocity, temperature.
    pub struct MotionHeat { pub pos: [f64; 3], pub vel: [f64; 3], pub temperature: f64 }
}

crate::attributes! {
    /// Force and heat per unit time.
    pub struct ForceHeat { pub force: [f64; 3], pub heat: f64 }
}

crate::attributes! {
    /// S_i = Σ_j |ξ| V_j β over the reference family.
    pub struct ConductionSum { pub conduction_sum: f64 }
}

/// Constants of one pair of materials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    pub c: f64,
    pub s0: f64,
    /// 12k of the pair (series conductivity).
    pub twelve_k: f64,
    pub alpha: f64,
}

#[derive(Clone, Debug)]
struct Own {
    c: f64,
    s0: f64,
    k: f64,
    alpha: f64,
}

#[derive(Clone, Debug)]
pub struct Thermal {
    own: Vec<Own>,
    density: Vec<f64>,
    specific_heat: Vec<f64>,
    reference: f64,
    delta: f64,
}

impl Model for Thermal {
    const NAME: &'static str = "thermal";
    const SUMMARY: &'static str =
        "PMB bonds with temperature: peridynamic heat conduction, thermal expansion, critical stretch";
    const OPTIONS: &'static [(&'static str, &'static str)] = &[(
        "reference_temperature",
        "temperature at which bonds have no thermal stretch (default 0)",
    )];
    const FIRST_ORDER: usize = 1;
    const FIXED_FROM_BONDS: bool = true;

    type Alter = MotionHeat;
    type Fixed = ConductionSum;
    type Bond = ();
    type State = ();
    type Force = ForceHeat;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let reference = b.option("reference_temperature")?.unwrap_or(0.0);
        let delta = b.horizon;
        let mut own = Vec::new();
        let mut specific_heat = Vec::new();
        for m in b.materials {
            let (o, heat) = own_constants(m, delta)?;
            own.push(o);
            specific_heat.push(heat);
        }
        Ok(Thermal {
            own,
            density: b.materials.iter().map(|m| m.density).collect(),
            specific_heat,
            reference,
            delta,
        })
    }

    fn sample(of: &SampleOf) -> Option<Sample> {
        // Concrete-like conduction: k = 2 W/m/K, c_p = 900 J/kg/K.
        let heat = "thermal_conductivity = 2.0\nspecific_heat = 900.0\n";
        Some(match *of {
            SampleOf::Benchmark {
                micromodulus,
                horizon,
                critical_stretch,
                density,
            } => {
                let k = micromodulus * PI * horizon.powf(4.0) / 18.0;
                Sample::new(format!(
                    "density = {density}\nbulk_modulus = {k:e}\ncritical_stretch = {critical_stretch}\n{heat}thermal_expansion = 1e-5\n"
                ))
            }
            // Without expansion (not `full`) the mechanics are PMB's and the mechanical energy
            // is conserved on its own.
            SampleOf::Solid {
                youngs_modulus,
                density,
                critical_stretch,
                full,
                ..
            } => {
                let expansion = if full {
                    "thermal_expansion = 1e-5\n"
                } else {
                    ""
                };
                let sample = Sample::new(format!(
                    "density = {density}\nyoungs_modulus = {youngs_modulus:e}\n{heat}{expansion}{}",
                    stretch_line("critical_stretch", critical_stretch)
                ));
                if full {
                    sample
                } else {
                    sample.mechanics_of(super::pmb::Pmb::NAME)
                }
            }
        })
    }

    fn breaks(&self) -> bool {
        self.own.iter().any(|o| o.s0.is_finite())
    }

    fn inertia(&self, material: u16, volume: f64, _: &ConductionSum) -> ForceHeat {
        let m = self.density[material as usize] * volume;
        ForceHeat {
            force: [m; 3],
            heat: m * self.specific_heat[material as usize],
        }
    }

    fn law(&self, mi: u16, mj: u16) -> Law {
        let (a, b) = (&self.own[mi as usize], &self.own[mj as usize]);
        let series = |x: f64, y: f64| 2.0 * x * y / (x + y);
        Law {
            c: series(a.c, b.c),
            s0: a.s0.min(b.s0),
            twelve_k: 12.0 * series(a.k, b.k),
            alpha: 0.5 * (a.alpha + b.alpha),
        }
    }

    fn bond_stiffness(&self, law: &Law, geom: &BondGeom) -> ForceHeat {
        ForceHeat {
            force: [law.c / geom.length; 3],
            // 12k / (2 S) with the continuum S = πδ⁴.
            heat: law.twelve_k / (2.0 * PI * self.delta.powi(4) * geom.length),
        }
    }

    fn lame(&self, material: u16) -> (f64, f64) {
        bond_based_lame(self.own[material as usize].c, self.delta)
    }

    fn bond_fixed(
        &self,
        _: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
    ) -> (ConductionSum, ConductionSum) {
        let w = geom.length * geom.beta;
        (
            ConductionSum {
                conduction_sum: w * j.volume,
            },
            ConductionSum {
                conduction_sum: w * i.volume,
            },
        )
    }

    #[inline(always)]
    fn pair(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _: &mut (),
    ) -> Option<(ForceHeat, ForceHeat)> {
        let (a, b) = (i.pos(), j.pos());
        let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
        let l = geom.length;
        let (ti, tj) = (i.alter.temperature, j.alter.temperature);
        let s = (r - l) / l - law.alpha * (0.5 * (ti + tj) - self.reference);
        if s > law.s0 {
            return None;
        }
        let v = geom.beta * i.volume * j.volume;
        let f = law.c * v * s / r;
        let kappa = law.twelve_k / (i.fixed.conduction_sum + j.fixed.conduction_sum);
        let q = kappa * v * (tj - ti) / l;
        Some((
            ForceHeat {
                force: [f * y[0], f * y[1], f * y[2]],
                heat: q,
            },
            ForceHeat {
                force: [-f * y[0], -f * y[1], -f * y[2]],
                heat: -q,
            },
        ))
    }

    fn energy(&self, law: &Law, i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let (a, b) = (i.pos(), j.pos());
        let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let l = geom.length;
        let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
        let t = 0.5 * (i.alter.temperature + j.alter.temperature) - self.reference;
        let s = (r - l) / l - law.alpha * t;
        0.5 * law.c * s * s * l * geom.beta * i.volume * j.volume
    }
}

/// The bond constants and the specific heat of one material.
fn own_constants(m: &Material, delta: f64) -> Result<(Own, f64), ModelError> {
    let name = Thermal::NAME;
    m.only_uses(
        &[
            "bulk_modulus",
            "youngs_modulus",
            "critical_stretch",
            "fracture_energy",
            "thermal_conductivity",
            "specific_heat",
            "thermal_expansion",
        ],
        name,
    )?;
    let (which, value) = m.one_of(
        &[
            ("bulk_modulus", Dimension::STRESS),
            ("youngs_modulus", Dimension::STRESS),
        ],
        name,
        "one of 'bulk_modulus' or 'youngs_modulus'",
    )?;
    // ν = 1/4 is built into the bond-based solid: K = E/(3(1 − 2ν)) = 2E/3.
    let k_bulk = if which == 0 {
        value
    } else {
        let given = ElasticConstant::YoungsModulus(value);
        let elastic = Isotropic::from_any_two(given, ElasticConstant::PoissonRatio(0.25));
        elastic.expect("E with ν").bulk_modulus
    };
    let c = 18.0 * k_bulk / (PI * delta.powi(4));
    let s0 = m.critical_stretch_or(|g0| (10.0 * g0 / (PI * c * delta.powi(5))).sqrt())?;
    let conductivity = m.positive("thermal_conductivity", Dimension::NUMBER)?;
    let expansion = m.checked(
        "thermal_expansion",
        Dimension::NUMBER,
        |a| a.is_finite(),
        "be finite",
    )?;
    let own = Own {
        c,
        s0,
        k: m.require(conductivity, "thermal_conductivity", name)?,
        alpha: expansion.unwrap_or(0.0),
    };
    let heat = m.positive("specific_heat", Dimension::NUMBER)?;
    Ok((own, m.require(heat, "specific_heat", name)?))
}
