//! PMB: Silling's prototype microelastic brittle model (Silling 2000; Silling & Askari 2005).
//!
//! f_ij = c·s·β·V_i·V_j along the current bond, c = 18K/(πδ⁴) (ν = ¼ is implied), and the bond
//! breaks for good once s > s0, with s0 given or from the fracture energy: s0 = √(5G0/(9Kδ)).
//! docs/theory.md §1. A bond between two materials takes the series stiffness 2c_a c_b/(c_a + c_b)
//! and the smaller critical stretch.

use crate::model::attributes::Attributes;
use crate::model::lanes::{LaneForces, Real, F4, LANES};
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

/// The owner's position in every lane and four partners' positions, for the lane laws of
/// models that move particles by `Motion` (the rows start with the positions: loaded whole
/// and transposed).
#[inline(always)]
pub(crate) fn lane_positions<M: Model<Alter = Motion>>(
    i: &Side<M>,
    j: [&Side<M>; LANES],
) -> ([F4; 3], [F4; 3]) {
    let [bx, by, bz, _] = F4::columns::<0>(j.map(|j| j.alter.as_slice()));
    let a = i.alter.pos;
    (
        [F4::splat(a[0]), F4::splat(a[1]), F4::splat(a[2])],
        [bx, by, bz],
    )
}

/// The bond's elongation e = r − L and its length r (bond vector `y`), on one bond or four.
/// Comparing e with s0·L and folding 1/L into 1/r leaves one division per bond.
#[inline(always)]
pub(crate) fn elongation<T: Real>(y: &[T; 3], length: T) -> (T, T) {
    let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
    (r - length, r)
}

/// The force on end i per unit bond vector: c·β·V_i·V_j·s/r with s = e/L.
#[inline(always)]
fn factor<T: Real>(c: T, beta: T, vi: T, vj: T, e: T, length: T, r: T) -> T {
    c * beta * vi * vj * e / (length * r)
}

impl Model for Pmb {
    const NAME: &'static str = "pmb";
    const SUMMARY: &'static str =
        "bond-based prototype microelastic brittle solid (Silling), nu = 1/4, critical stretch";
    const LAMMPS_PEER: Option<&'static str> = Some("peri/pmb");
    const BOND_LANES: usize = LANES;

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
        let (e, r) = elongation(&y, geom.length);
        if e > law.s0 * geom.length {
            return None;
        }
        let f = factor(law.c, geom.beta, i.volume, j.volume, e, geom.length, r);
        let fi = [f * y[0], f * y[1], f * y[2]];
        Some((
            Force3 { force: fi },
            Force3 {
                force: [-fi[0], -fi[1], -fi[2]],
            },
        ))
    }

    /// Four bonds through the same `elongation` and `factor` as `pair`, one per lane: the
    /// partners' positions are loaded as rows (a `Motion` starts with them) and transposed.
    #[inline(always)]
    fn pair_lanes(
        &self,
        law: [&Law; LANES],
        i: &Side<Self>,
        j: [&Side<Self>; LANES],
        geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        let (a, b) = lane_positions(i, j);
        let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let length = F4::gather(|l| geom[l].length);
        let (e, r) = elongation(&y, length);
        let s0_length = F4::gather(|l| law[l].s0) * length;
        if e.any_outside(F4::splat(f64::NEG_INFINITY), s0_length) {
            return None;
        }
        let f = factor(
            F4::gather(|l| law[l].c),
            F4::gather(|l| geom[l].beta),
            F4::splat(i.volume),
            F4::gather(|l| j[l].volume),
            e,
            length,
            r,
        );
        Some(LaneForces::central(f, &y))
    }

    fn energy(&self, law: &Law, i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let (s, _, _) = stretch(i, j, geom);
        0.5 * law.c * s * s * geom.length * geom.beta * i.volume * j.volume
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::lanes::fixture::{assert_same_bits, geom, moved, volume, X0};
    use crate::model::material::{MaterialKind, PlainNumbers};
    use crate::model::Written;

    fn solid(name: &str, e: f64, s0: f64) -> Material {
        let keys = [("youngs_modulus", e), ("critical_stretch", s0)]
            .iter()
            .map(|&(k, v)| (k.to_string(), Written::Number(v)))
            .collect();
        Material::new(name, 0, MaterialKind::Solid, 2400.0, keys, &PlainNumbers).unwrap()
    }

    /// `pair_lanes` gives `pair`'s forces bit for bit for two materials (stretched and
    /// shortened bonds), and `None` when one lane breaks.
    #[test]
    fn lanes_give_the_single_bond_forces_bit_for_bit() {
        let materials = [solid("a", 30e9, 0.01), solid("b", 200e9, 0.02)];
        let m = Pmb::build(&ModelBuild {
            materials: &materials,
            horizon: 3.015e-3,
            spacing: 1e-3,
            options: &[],
        })
        .unwrap();
        let alter: Vec<Motion> = (0..5)
            .map(|p| Motion {
                pos: moved(p),
                vel: [0.0; 3],
            })
            .collect();
        let material = [0u16, 1, 0, 1, 1];
        let side = |p: usize| Side::<Pmb> {
            x0: &X0[p],
            volume: volume(p),
            material: material[p],
            alter: &alter[p],
            fixed: &(),
            state: &(),
        };
        let i = side(0);
        let js = [side(1), side(2), side(3), side(4)];
        let geoms = [geom(1), geom(2), geom(3), geom(4)];
        let laws = js.each_ref().map(|j| m.law(0, j.material));
        let (law_refs, geom_refs) = (laws.each_ref(), geoms.each_ref());
        let lanes = m
            .pair_lanes(law_refs, &i, js.each_ref(), geom_refs)
            .expect("no lane breaks");
        let single: [(Force3, Force3); LANES] =
            std::array::from_fn(|l| m.pair(&laws[l], &i, &js[l], &geoms[l], &mut ()).unwrap());
        assert_same_bits(
            &lanes,
            single.each_ref().map(|(a, b)| (a.as_slice(), b.as_slice())),
            "pmb",
        );
        // Force on i along the bond: positive when stretched; both kinds are tested.
        let along = |l: usize| -> f64 {
            (0..3)
                .map(|k| single[l].0.force[k] * (js[l].pos()[k] - i.pos()[k]))
                .sum()
        };
        let signs: Vec<f64> = (0..LANES).map(along).collect();
        assert!(signs.iter().any(|&s| s > 0.0) && signs.iter().any(|&s| s < 0.0));
        // Lane 2 stretched past its critical stretch: the group is refused.
        let mut far = alter[3];
        far.pos[0] += 1e-4;
        let j2 = Side::<Pmb> {
            alter: &far,
            ..side(3)
        };
        assert!(m.pair(&laws[2], &i, &j2, &geoms[2], &mut ()).is_none());
        assert!(m
            .pair_lanes(law_refs, &i, [&js[0], &js[1], &j2, &js[3]], geom_refs)
            .is_none());
    }
}
