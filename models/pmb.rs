//! PMB: Silling's prototype microelastic brittle model (Silling 2000; Silling & Askari 2005).
//!
//! f_ij = c·s·β·V_i·V_j along the current bond, c = 18K/(πδ⁴) (ν = ¼ is implied), and the bond
//! breaks for good once s > s0, with s0 given or from the fracture energy: s0 = √(5G0/(9Kδ)).
//! docs/theory.md §1. A bond between two materials takes the series stiffness 2c_a c_b/(c_a + c_b)
//! and the smaller critical stretch.

use crate::model::{bond_based_lame, check_options, stretch, BondGeom, Model, ModelBuild, Side};
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
    /// `laws[a * n + b]` for materials a, b.
    laws: Vec<Law>,
    n: usize,
    density: Vec<f64>,
    delta: f64,
}

impl Pmb {
    pub fn laws(&self) -> &[Law] {
        &self.laws
    }
}

impl Model for Pmb {
    const NAME: &'static str = "pmb";
    const SUMMARY: &'static str =
        "bond-based prototype microelastic brittle solid (Silling), nu = 1/4, critical stretch";

    type Alter = Motion;
    type Fixed = ();
    type Bond = ();
    type State = ();
    type Force = Force3;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, String> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let delta = b.horizon;
        let mut own = Vec::new();
        for m in b.materials {
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
            let stiffnesses = [m.micromodulus, m.bulk_modulus, m.youngs_modulus]
                .iter()
                .filter(|v| v.is_some())
                .count();
            if stiffnesses > 1 {
                return Err(format!(
                    "material '{}': give one of 'bulk_modulus', 'youngs_modulus' or 'micromodulus' for model 'pmb', not several",
                    m.name
                ));
            }
            let c = match (m.micromodulus, m.bulk_modulus, m.youngs_modulus) {
                (Some(c), _, _) => c,
                (None, Some(k), _) => 18.0 * k / (PI * delta.powi(4)),
                // ν = 1/4 is built into bond-based PMB: K = 2E/3.
                (None, None, Some(e)) => 12.0 * e / (PI * delta.powi(4)),
                _ => {
                    return Err(format!(
                        "material '{}' needs 'bulk_modulus', 'youngs_modulus' or 'micromodulus' for model 'pmb'",
                        m.name
                    ))
                }
            };
            if let Some(nu) = m.poisson_ratio {
                if (nu - 0.25).abs() > 1e-9 {
                    return Err(format!(
                        "material '{}': bond-based PMB has Poisson's ratio 1/4, the deck gives {nu}; remove 'poisson_ratio' (other values need a state-based model)",
                        m.name
                    ));
                }
            }
            if !(c.is_finite() && c > 0.0) {
                return Err(format!("material '{}': micromodulus must be > 0", m.name));
            }
            // s0 = sqrt(10 G0 / (π c δ⁵)), equal to sqrt(5G0/(9Kδ)) with c = 18K/(πδ⁴).
            let s0 = m.critical_stretch_or(|g0| (10.0 * g0 / (PI * c * delta.powi(5))).sqrt())?;
            if s0.is_nan() || s0 <= 0.0 {
                return Err(format!(
                    "material '{}': critical stretch must be > 0",
                    m.name
                ));
            }
            own.push(Law { c, s0 });
        }
        let n = own.len();
        let mut laws = Vec::with_capacity(n * n);
        for a in &own {
            for b in &own {
                laws.push(Law {
                    c: 2.0 * a.c * b.c / (a.c + b.c),
                    s0: a.s0.min(b.s0),
                });
            }
        }
        Ok(Pmb {
            laws,
            n,
            delta: b.horizon,
            density: b.materials.iter().map(|m| m.density).collect(),
        })
    }

    fn breaks(&self) -> bool {
        self.laws.iter().any(|l| l.s0.is_finite())
    }

    fn inertia(&self, material: u16, volume: f64, _fixed: &()) -> Force3 {
        let m = self.density[material as usize] * volume;
        Force3 { force: [m; 3] }
    }

    fn law(&self, mi: u16, mj: u16) -> Law {
        self.laws[mi as usize * self.n + mj as usize]
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
