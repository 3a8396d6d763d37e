//! PMB: Silling's prototype microelastic brittle model (Silling 2000; Silling & Askari 2005).
//!
//! f_ij = c·s·β·V_i·V_j along the current bond, c = 18K/(πδ⁴) (ν = ¼ is implied), and the bond
//! breaks for good once s > s0, with s0 given or from the fracture energy: s0 = √(5G0/(9Kδ)).
//! docs/theory.md §1. A bond between two materials takes the series stiffness 2c_a c_b/(c_a + c_b)
//! and the smaller critical stretch.

use crate::model::{
    bond_based_lame, check_options, stretch, stretch_line, BondGeom, Dimension, Material, Model,
    ModelBuild, ModelError, PairTable, Sample, SampleOf, Side,
};
use std::f64::consts::PI;

crate::attributes! {
    /// Current position and velocity.
    pub struct Motion { pub pos: [f64; 3], pub vel: [f64; 3] }
}

crate::attributes! {
    /// Force on the three translational degrees of freedom.
    pub struct Force3 { pub force: [f64; 3] }
}

/// Micromodulus and critical stretch of one pair of materials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    pub c: f64,
    pub s0: f64,
}

#[derive(Clone, Debug)]
pub struct Pmb {
    laws: PairTable<Law>,
    density: Vec<f64>,
    delta: f64,
}

impl Pmb {
    pub fn laws(&self) -> &[Law] {
        self.laws.all()
    }

    /// The law of one material: c from one stiffness (ν = ¼ is built into bond-based PMB:
    /// K = 2E/3), s0 given or from the fracture energy.
    fn own_law(m: &Material, delta: f64) -> Result<Law, ModelError> {
        m.only_uses(
            &[
                "bulk_modulus",
                "youngs_modulus",
                "micromodulus",
                "poisson_ratio",
                "critical_stretch",
                "fracture_energy",
            ],
            Self::NAME,
        )?;
        let (which, value) = m.one_of(
            &[
                ("bulk_modulus", Dimension::STRESS),
                ("youngs_modulus", Dimension::STRESS),
                ("micromodulus", Dimension::MICROMODULUS),
            ],
            Self::NAME,
            "'bulk_modulus', 'youngs_modulus' or 'micromodulus'",
        )?;
        let c = match which {
            0 => 18.0 * value / (PI * delta.powi(4)),
            1 => 12.0 * value / (PI * delta.powi(4)),
            _ => value,
        };
        if let Some(nu) = m.poisson_ratio()? {
            if (nu - 0.25).abs() > 1e-9 {
                return Err(m.error(format!(
                    "material '{}': bond-based PMB has Poisson's ratio 1/4, the deck gives {nu}; remove 'poisson_ratio' (other values need a state-based model)",
                    m.name
                )));
            }
        }
        if !(c.is_finite() && c > 0.0) {
            return Err(m.error(format!("material '{}': micromodulus must be > 0", m.name)));
        }
        // s0 = sqrt(10 G0 / (π c δ⁵)), equal to sqrt(5G0/(9Kδ)) with c = 18K/(πδ⁴).
        let s0 = m.critical_stretch_or(|g0| (10.0 * g0 / (PI * c * delta.powi(5))).sqrt())?;
        if s0.is_nan() || s0 <= 0.0 {
            return Err(m.error(format!(
                "material '{}': critical stretch must be > 0",
                m.name
            )));
        }
        Ok(Law { c, s0 })
    }
}

impl Model for Pmb {
    const NAME: &'static str = "pmb";
    const SUMMARY: &'static str =
        "bond-based prototype microelastic brittle solid (Silling), nu = 1/4, critical stretch";
    const LAMMPS_PEER: Option<&'static str> = Some("peri/pmb");

    type Alter = Motion;
    type Fixed = ();
    type Bond = ();
    type State = ();
    type Force = Force3;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let own = b.per_material(Self::own_law)?;
        // A bond between two materials: the series stiffness and the smaller critical stretch.
        let laws = PairTable::new(&own, |a, b| Law {
            c: 2.0 * a.c * b.c / (a.c + b.c),
            s0: a.s0.min(b.s0),
        });
        Ok(Pmb {
            laws,
            delta: b.horizon,
            density: b.materials.iter().map(|m| m.density).collect(),
        })
    }

    fn sample(of: &SampleOf) -> Option<Sample> {
        Some(Sample::new(match *of {
            SampleOf::Benchmark {
                micromodulus,
                critical_stretch,
                density,
                ..
            } => format!(
                "density = {density}\nmicromodulus = {micromodulus:e}\ncritical_stretch = {critical_stretch}\n"
            ),
            SampleOf::Solid {
                youngs_modulus,
                density,
                critical_stretch,
                ..
            } => format!(
                "density = {density}\nyoungs_modulus = {youngs_modulus:e}\n{}",
                stretch_line("critical_stretch", critical_stretch)
            ),
        }))
    }

    fn breaks(&self) -> bool {
        self.laws.all().iter().any(|l| l.s0.is_finite())
    }

    fn inertia(&self, material: u16, volume: f64, _fixed: &()) -> Force3 {
        let m = self.density[material as usize] * volume;
        Force3 { force: [m; 3] }
    }

    fn law(&self, mi: u16, mj: u16) -> Law {
        self.laws.get(mi, mj)
    }

    fn bond_stiffness(&self, law: &Law, geom: &BondGeom) -> Force3 {
        Force3 {
            force: [law.c / geom.length; 3],
        }
    }

    fn lame(&self, material: u16) -> (f64, f64) {
        let own = self.law(material, material);
        bond_based_lame(own.c, self.delta)
    }

    #[inline(always)]
    fn pair(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _bond: &mut (),
    ) -> Option<(Force3, Force3)> {
        let (a, b) = (i.pos(), j.pos());
        let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
        // s = e/L; comparing e with s0·L and folding 1/L into 1/r leaves one division per bond.
        let e = r - geom.length;
        if e > law.s0 * geom.length {
            return None;
        }
        let f = law.c * geom.beta * i.volume * j.volume * e / (geom.length * r);
        let fi = [f * y[0], f * y[1], f * y[2]];
        Some((
            Force3 { force: fi },
            Force3 {
                force: [-fi[0], -fi[1], -fi[2]],
            },
        ))
    }

    fn energy(&self, law: &Law, i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let (s, _, _) = stretch(i, j, geom);
        0.5 * law.c * s * s * geom.length * geom.beta * i.volume * j.volume
    }
}
