//! Point particles: a position and a velocity, a mass, and no bonds. The particles of a
//! molecular-dynamics scene, which feel each other through a non-bonded pair law (`[pair]`), or
//! nothing at all and move in straight lines.
//!
//! The mass is density × volume: on an fcc lattice given by its number density n, a material
//! of density n·m gives every particle the mass m (volume a³/4 = 1/n). A deck names no horizon
//! ([`Model::BONDED`] is false): the engine searches for no bonds, and with no bond to bound
//! the time step the deck gives `[time] dt`.

use crate::model::{check_options, BondGeom, Material, Model, ModelBuild, ModelError, Side};

pub use super::pmb::{Force3, Motion};

#[derive(Clone, Debug)]
pub struct Point {
    density: Vec<f64>,
}

impl Point {
    /// A point material has a density and nothing else.
    fn own(m: &Material, _horizon: f64) -> Result<f64, ModelError> {
        m.only_uses(&[], Self::NAME)?;
        Ok(m.density)
    }
}

impl Model for Point {
    const NAME: &'static str = "point";
    const SUMMARY: &'static str =
        "bondless point particles (molecular dynamics): position, velocity, mass = density x volume";
    const BONDED: bool = false;

    type Alter = Motion;
    type Fixed = ();
    type Bond = ();
    type State = ();
    type Force = Force3;
    /// There are no bonds, so no bond law.
    type Law = ();

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        Ok(Point {
            density: b.per_material(Self::own)?,
        })
    }

    fn breaks(&self) -> bool {
        false
    }

    fn inertia(&self, material: u16, volume: f64, _fixed: &()) -> Force3 {
        let m = self.density[material as usize] * volume;
        Force3 { force: [m; 3] }
    }

    fn law(&self, _mi: u16, _mj: u16) {}

    /// No bond, no stiffness (the stable step is infinite; the deck's dt is the step).
    fn bond_stiffness(&self, _law: &(), _geom: &BondGeom) -> Force3 {
        Force3::default()
    }

    /// Point particles are no continuum: no elastic constants. Nothing reads these (0, 0): a
    /// bondless model's deck has no surface correction, and its bars are lines of particles
    /// with no bonds to calibrate.
    fn lame(&self, _material: u16) -> (f64, f64) {
        (0.0, 0.0)
    }

    /// The engine hands a bondless model no bonds; were it to, a point pair carries no force.
    fn pair(
        &self,
        _law: &(),
        _i: &Side<Self>,
        _j: &Side<Self>,
        _geom: &BondGeom,
        _bond: &mut (),
    ) -> Option<(Force3, Force3)> {
        Some((Force3::default(), Force3::default()))
    }

    fn energy(&self, _law: &(), _i: &Side<Self>, _j: &Side<Self>, _geom: &BondGeom, _: &()) -> f64 {
        0.0
    }
}
