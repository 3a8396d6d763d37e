//! A membrane: particles on a square sheet joined by harmonic springs to their direct and
//! diagonal neighbours (the membrane of the TUM molecular-dynamics practical, worksheet 5),
//! f = k·(r − L) along the bond, L the bond's reference length: r0 for a direct neighbour and
//! √2·r0 for a diagonal one. Springs never break. Energy ½k(r − L)² per bond.
//!
//! In PDQ terms it is a bond-based model on a one-layer simple-cubic sheet (spacing r0) with a
//! horizon between √2·r0 and 2·r0 (m = 1.5 is the usual choice), so that a particle's family is
//! exactly its 4 direct and 4 diagonal neighbours. Unlike the peridynamic models, [`Model::pair`]
//! returns plain spring forces, **not** multiplied by the volumes, and the partial-volume
//! factor β plays no part: a spring is a spring. The mass is density × volume.
//!
//! The stable step: the engine bounds particle i by √(2m_i / (V_i Σ_j V_j C_ij)); the bond
//! stiffness C = k / V² (V = r0³, the volume of a lattice particle) makes that √(2m_i / Σ_j k),
//! the bound of central differences on a spring network (Gershgorin: the largest eigenvalue of
//! M⁻¹K is at most 2Σk/m), √(m/4k) for an inner particle with its eight springs.

use crate::model::{check_options, BondGeom, Dimension, Material, Model, ModelBuild, ModelError};
use crate::model::{PairTable, Side};

pub use super::pmb::{Force3, Motion};

/// The spring constant of a bond between two materials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    pub k: f64,
}

#[derive(Clone, Debug)]
pub struct Membrane {
    laws: PairTable<Law>,
    density: Vec<f64>,
    /// Volume of a lattice particle, spacing³: what turns k into the engine's bond stiffness
    /// per unit volume of both ends.
    volume: f64,
}

impl Membrane {
    fn own_law(m: &Material, _horizon: f64) -> Result<Law, ModelError> {
        m.only_uses(&["spring_constant"], Self::NAME)?;
        let k = m
            .positive("spring_constant", Dimension::new(1, 0, -2))?
            .ok_or_else(|| {
                m.error(format!(
                    "material '{}': model 'membrane' needs 'spring_constant' (force per length)",
                    m.name
                ))
            })?;
        Ok(Law { k })
    }
}

impl Model for Membrane {
    const NAME: &'static str = "membrane";
    const SUMMARY: &'static str =
        "square sheet of harmonic springs to direct and diagonal neighbours, k(r - L), unbreakable";

    type Alter = Motion;
    type Fixed = ();
    type Bond = ();
    type State = ();
    type Force = Force3;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let ratio = b.horizon / b.spacing;
        // Direct neighbours at r0, diagonal ones at √2·r0, the next ones in the sheet at 2·r0.
        if !(ratio > 2f64.sqrt() * (1.0 + 1e-9) && ratio < 2.0 * (1.0 - 1e-9)) {
            return Err(format!(
                "model 'membrane' joins direct and diagonal neighbours: its horizon must lie between √2 and 2 lattice spacings (m = 1.5), not {ratio} spacings"
            )
            .into());
        }
        let own = b.per_material(Self::own_law)?;
        // Two springs of different materials meet in series.
        let laws = PairTable::new(&own, |a, b| Law {
            k: 2.0 * a.k * b.k / (a.k + b.k),
        });
        Ok(Membrane {
            laws,
            density: b.materials.iter().map(|m| m.density).collect(),
            volume: b.spacing.powi(3),
        })
    }

    fn breaks(&self) -> bool {
        false
    }

    fn inertia(&self, material: u16, volume: f64, _fixed: &()) -> Force3 {
        let m = self.density[material as usize] * volume;
        Force3 { force: [m; 3] }
    }

    fn law(&self, mi: u16, mj: u16) -> Law {
        self.laws.get(mi, mj)
    }

    /// k per unit volume of both ends (see the module doc), so the engine's bound is √(2m/Σk).
    fn bond_stiffness(&self, law: &Law, _geom: &BondGeom) -> Force3 {
        Force3 {
            force: [law.k / (self.volume * self.volume); 3],
        }
    }

    /// A sheet of springs is no three-dimensional continuum: it has no Lamé constants, and (0, 0)
    /// says so to the surface correction and the bars, which have nothing to calibrate here.
    fn lame(&self, _material: u16) -> (f64, f64) {
        (0.0, 0.0)
    }

    /// The spring force k·(r − L) along the bond: on i towards j when stretched. Plain forces,
    /// no volumes.
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
        let f = law.k * (r - geom.length) / r;
        let fi = [f * y[0], f * y[1], f * y[2]];
        Some((
            Force3 { force: fi },
            Force3 {
                force: [-fi[0], -fi[1], -fi[2]],
            },
        ))
    }

    fn energy(&self, law: &Law, i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let (_, _, r) = crate::model::stretch(i, j, geom);
        0.5 * law.k * (r - geom.length) * (r - geom.length)
    }
}
