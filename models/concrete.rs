//! The thesis's reinforced-concrete model (Sakhavand 2011, appendix A `ConcConc`; docs/theory.md §8).
//!
//! * concrete–concrete: f = E′·s between the compressive and tensile critical stretches
//!   s_c < s < s_t, E′ = 6E/(πδ⁴(1−2ν)) (thesis eq. 4.1); outside that range the bond breaks for
//!   good (the thesis code re-formed it when the stretch came back, the defect not repeated here);
//! * steel–steel: elastic to the yield stretch, then perfectly plastic in stretch, with the
//!   plastic stretch kept as bond history, until |s| exceeds the failure stretch;
//! * concrete–steel: the concrete law with its force and both critical stretches multiplied by
//!   `interface_factor` (default 3, the EMU manual's advice).
//!
//! Two different concrete (or steel) materials bond with the series stiffness and the tighter
//! limits.

use super::pmb::{elongation, lane_positions};
use crate::model::lanes::{LaneForces, Real, F4, LANES};
use crate::model::{
    bond_based_lame, check_options, stretch, BondGeom, Dimension, Material, MaterialKind, Model,
    ModelBuild, ModelError, PairTable, Sample, SampleOf, Side,
};
use std::f64::consts::PI;

pub use super::pmb::{Force3, Motion};

crate::attributes! {
    /// Plastic part of the bond stretch (steel bonds only; zero elsewhere).
    pub struct PlasticStretch { pub plastic_stretch: f64 }
}

/// The law of one pair of materials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Law {
    /// Linear between `compressive` (< 0) and `tensile` (> 0) stretch, broken outside.
    Brittle {
        c: f64,
        tensile: f64,
        compressive: f64,
    },
    /// Elastic–perfectly plastic in stretch, failing beyond `failure`.
    Plastic { c: f64, yield_: f64, failure: f64 },
}

impl Law {
    fn stiffness(&self) -> f64 {
        match *self {
            Law::Brittle { c, .. } | Law::Plastic { c, .. } => c,
        }
    }
}

#[derive(Clone, Debug)]
pub struct Concrete {
    laws: PairTable<Law>,
    density: Vec<f64>,
    delta: f64,
}

impl Concrete {
    /// c × elastic elongation of a bond of elongation `e = r − L` and length `l`, or `None`
    /// if it breaks now. Working with e (not s = e/L) saves a division on concrete bonds.
    #[inline(always)]
    fn coefficient(law: Law, e: f64, l: f64, plastic: &mut f64) -> Option<f64> {
        match law {
            Law::Brittle {
                c,
                tensile,
                compressive,
            } => {
                if e > tensile * l || e < compressive * l {
                    None
                } else {
                    Some(c * e)
                }
            }
            Law::Plastic { c, yield_, failure } => {
                let s = e / l;
                if s.abs() > failure {
                    return None;
                }
                let elastic = s - *plastic;
                if elastic > yield_ {
                    *plastic = s - yield_;
                } else if elastic < -yield_ {
                    *plastic = s + yield_;
                }
                Some(c * (s - *plastic) * l)
            }
        }
    }

    /// The brittle laws' (c, tensile, compressive) of four lanes, or `None` if any lane's law
    /// is plastic: a steel bond's plastic stretch is bond history, which only `pair` keeps.
    #[inline(always)]
    fn brittle_lanes(law: [&Law; LANES]) -> Option<[(f64, f64, f64); LANES]> {
        let brittle = law.map(|l| match *l {
            Law::Brittle {
                c,
                tensile,
                compressive,
            } => Some((c, tensile, compressive)),
            Law::Plastic { .. } => None,
        });
        let [Some(a), Some(b), Some(c), Some(d)] = brittle else {
            return None;
        };
        Some([a, b, c, d])
    }
}

/// The force on end i per unit bond vector, from c × the elastic elongation `ce`:
/// ce·β·V_i·V_j/(L·r) (the 1/L of the stretch folded into the one division).
#[inline(always)]
fn factor<T: Real>(ce: T, beta: T, vi: T, vj: T, length: T, r: T) -> T {
    ce * beta * vi * vj / (length * r)
}

/// The bond micromodulus of the thesis (eq. 4.1).
pub fn thesis_micromodulus(e: f64, nu: f64, delta: f64) -> f64 {
    6.0 * e / (PI * delta.powi(4) * (1.0 - 2.0 * nu))
}

impl Model for Concrete {
    const NAME: &'static str = "concrete";
    // Concrete bonds (and concrete–steel ones) go four at a time; a group with a steel bond,
    // whose plastic stretch is history, is refused and goes one by one.
    const BOND_LANES: usize = LANES;
    const SUMMARY: &'static str =
        "thesis reinforced-concrete bonds: brittle concrete (s_c < s < s_t), elastic-plastic steel, x3 interface";
    const OPTIONS: &'static [(&'static str, &'static str)] = &[(
        "interface_factor",
        "concrete-steel bonds: multiplier on force and critical stretches (default 3)",
    )];

    type Alter = Motion;
    type Fixed = ();
    type Bond = PlasticStretch;
    type State = ();
    type Force = Force3;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let factor = b.option("interface_factor")?.unwrap_or(3.0);
        if !(factor.is_finite() && factor > 0.0) {
            return Err("model option 'interface_factor' must be > 0".into());
        }
        let own = b.per_material(own_law)?;
        Ok(Concrete {
            laws: PairTable::new(&own, |a, b| combine(*a, *b, factor)),
            delta: b.horizon,
            density: b.materials.iter().map(|m| m.density).collect(),
        })
    }

    fn sample(of: &SampleOf) -> Option<Sample> {
        Some(Sample::new(match *of {
            // The benchmark's stiffness through the thesis's E′ = 6E/(πδ⁴(1−2ν)) at ν = 0.25,
            // its critical stretch in tension and 10x in compression.
            SampleOf::Benchmark {
                micromodulus,
                horizon,
                critical_stretch: s0,
                density,
            } => {
                let e = micromodulus * PI * horizon.powf(4.0) * 0.5 / 6.0;
                format!("kind = \"concrete\"\ndensity = {density}\nyoungs_modulus = {e:e}\npoisson_ratio = 0.25\ntensile_stretch = {s0}\ncompressive_stretch = {}\n", -10.0 * s0)
            }
            // Steel that never yields: the stiffness contrast of a reinforced section.
            SampleOf::Solid {
                youngs_modulus: e,
                density,
                steel: true,
                ..
            } => format!("kind = \"steel\"\ndensity = {density}\nyoungs_modulus = {e:e}\npoisson_ratio = 0.25\nyield_stretch = 1e6\n"),
            SampleOf::Solid {
                youngs_modulus: e,
                density,
                critical_stretch: s0,
                ..
            } => {
                let (t, c) = if s0.is_finite() { (s0, -10.0 * s0) } else { (1e6, -1e6) };
                format!("kind = \"concrete\"\ndensity = {density}\nyoungs_modulus = {e:e}\npoisson_ratio = 0.25\ntensile_stretch = {t:e}\ncompressive_stretch = {c:e}\n")
            }
        }))
    }

    fn breaks(&self) -> bool {
        self.laws.all().iter().any(|l| match *l {
            Law::Brittle {
                tensile,
                compressive,
                ..
            } => tensile.is_finite() || compressive.is_finite(),
            Law::Plastic { failure, .. } => failure.is_finite(),
        })
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
            force: [law.stiffness() / geom.length; 3],
        }
    }

    fn lame(&self, material: u16) -> (f64, f64) {
        let own = self.law(material, material);
        bond_based_lame(own.stiffness(), self.delta)
    }

    fn prestrained(&self, law: &Law, strain: f64) -> Result<PlasticStretch, String> {
        match *law {
            // Elastic stretch = s − plastic, so a plastic stretch of −ε holds the bond at +ε.
            Law::Plastic { yield_, .. } if strain.abs() < yield_ => Ok(PlasticStretch {
                plastic_stretch: -strain,
            }),
            Law::Plastic { yield_, .. } => Err(format!(
                "prestrain {strain} is not below the bar's yield stretch {yield_}: it would yield at once"
            )),
            Law::Brittle { .. } => {
                Err("only a bar of kind \"steel\" can be prestrained (its bonds keep a plastic stretch)".into())
            }
        }
    }

    #[inline(always)]
    fn pair(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        bond: &mut PlasticStretch,
    ) -> Option<(Force3, Force3)> {
        let (a, b) = (i.pos(), j.pos());
        let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let l = geom.length;
        let (e, r) = elongation(&y, l);
        let ce = Self::coefficient(*law, e, l, &mut bond.plastic_stretch)?;
        let f = factor(ce, geom.beta, i.volume, j.volume, l, r);
        let fi = [f * y[0], f * y[1], f * y[2]];
        Some((
            Force3 { force: fi },
            Force3 {
                force: [-fi[0], -fi[1], -fi[2]],
            },
        ))
    }

    /// Four brittle bonds through the same `elongation`, limits and `factor` as `pair`, one per
    /// lane; `None` if any of them is a steel bond or breaks now.
    #[inline(always)]
    fn pair_lanes(
        &self,
        law: [&Law; LANES],
        i: &Side<Self>,
        j: [&Side<Self>; LANES],
        geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        let law = Self::brittle_lanes(law)?;
        let (a, b) = lane_positions(i, j);
        let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let length = F4::gather(|l| geom[l].length);
        let (e, r) = elongation(&y, length);
        let tensile = F4::gather(|l| law[l].1) * length;
        let compressive = F4::gather(|l| law[l].2) * length;
        if e.any_outside(compressive, tensile) {
            return None;
        }
        let f = factor(
            F4::gather(|l| law[l].0) * e,
            F4::gather(|l| geom[l].beta),
            F4::splat(i.volume),
            F4::gather(|l| j[l].volume),
            length,
            r,
        );
        Some(LaneForces::central(f, &y))
    }

    fn energy(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        bond: &PlasticStretch,
    ) -> f64 {
        let (s, _, _) = stretch(i, j, geom);
        let elastic = s - bond.plastic_stretch;
        let c = law.stiffness();
        0.5 * c * elastic * elastic * geom.length * geom.beta * i.volume * j.volume
    }
}

/// The law of one material: brittle concrete between its compressive and tensile stretches,
/// or elastic–plastic steel up to its failure stretch.
fn own_law(m: &Material, delta: f64) -> Result<Law, ModelError> {
    let name = Concrete::NAME;
    let used: &[&str] = match m.kind {
        MaterialKind::Steel => &[
            "youngs_modulus",
            "poisson_ratio",
            "yield_stretch",
            "failure_stretch",
        ],
        _ => &[
            "youngs_modulus",
            "poisson_ratio",
            "tensile_stretch",
            "fracture_energy",
            "compressive_stretch",
        ],
    };
    m.only_uses(used, name)?;
    let e = m.required("youngs_modulus", Dimension::STRESS, name)?;
    let nu = m.require(m.poisson_ratio()?, "poisson_ratio", name)?;
    let c = thesis_micromodulus(e, nu, delta);
    Ok(match m.kind {
        MaterialKind::Concrete => {
            let tensile = tensile_stretch(m, c, delta)?;
            let compressive = m.checked(
                "compressive_stretch",
                Dimension::NUMBER,
                |c| c < 0.0,
                "be < 0",
            )?;
            let compressive = m.require(compressive, "compressive_stretch", name)?;
            Law::Brittle {
                c,
                tensile,
                compressive,
            }
        }
        MaterialKind::Steel => {
            let yield_ = m.required("yield_stretch", Dimension::NUMBER, name)?;
            let failure = m.positive("failure_stretch", Dimension::NUMBER)?;
            let failure = failure.unwrap_or(f64::INFINITY);
            if failure <= yield_ {
                return Err(m.error(format!(
                    "material '{}': need 0 < yield_stretch < failure_stretch",
                    m.name
                )));
            }
            Law::Plastic {
                c,
                yield_,
                failure,
            }
        }
        MaterialKind::Solid => {
            return Err(m.error(format!(
                "material '{}' has kind 'solid'; model 'concrete' takes kind = \"concrete\" or \"steel\"",
                m.name
            )))
        }
    })
}

/// A concrete's tensile critical stretch: `tensile_stretch` as given (the thesis's fixed
/// stretch, f_t/E), or from `fracture_energy` G_F and the horizon, s_t = √(10 G_F/(π c δ⁵)):
/// the energy that breaking every bond across a unit area takes (the PMB relation, with the
/// thesis's micromodulus c). A fixed stretch dissipates G = π c δ⁵ s_t²/10, which grows with δ,
/// so its fracture-controlled strengths fall as the lattice is refined; a fixed G_F keeps that
/// energy, and the stretch falls as 1/√δ instead (validation/README.md, the lap splices).
fn tensile_stretch(m: &Material, c: f64, delta: f64) -> Result<f64, ModelError> {
    let from_energy = |g: f64| (10.0 * g / (PI * c * delta.powi(5))).sqrt();
    m.stretch_or_energy("tensile_stretch", from_energy)?
        .ok_or_else(|| {
            m.error(format!(
                "material '{}' (model 'concrete') needs 'tensile_stretch' or 'fracture_energy'",
                m.name
            ))
        })
}

/// The law between two materials' own laws.
fn combine(a: Law, b: Law, factor: f64) -> Law {
    let series = |x: f64, y: f64| 2.0 * x * y / (x + y);
    match (a, b) {
        (
            Law::Brittle {
                c: ca,
                tensile: ta,
                compressive: pa,
            },
            Law::Brittle {
                c: cb,
                tensile: tb,
                compressive: pb,
            },
        ) => Law::Brittle {
            c: series(ca, cb),
            tensile: ta.min(tb),
            compressive: pa.max(pb),
        },
        (
            Law::Plastic {
                c: ca,
                yield_: ya,
                failure: fa,
            },
            Law::Plastic {
                c: cb,
                yield_: yb,
                failure: fb,
            },
        ) => Law::Plastic {
            c: series(ca, cb),
            yield_: ya.min(yb),
            failure: fa.min(fb),
        },
        (
            Law::Brittle {
                c,
                tensile,
                compressive,
            },
            Law::Plastic { .. },
        )
        | (
            Law::Plastic { .. },
            Law::Brittle {
                c,
                tensile,
                compressive,
            },
        ) => Law::Brittle {
            c: c * factor,
            tensile: tensile * factor,
            compressive: compressive * factor,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::attributes::Attributes;
    use crate::model::lanes::fixture::{assert_same_bits, geom, moved, volume, X0};
    use crate::model::material::PlainNumbers;
    use crate::model::Written;

    fn material(name: &str, index: u16, kind: MaterialKind, keys: &[(&str, f64)]) -> Material {
        let keys = keys
            .iter()
            .map(|&(k, v)| (k.to_string(), Written::Number(v)))
            .collect();
        Material::new(name, index, kind, 2400.0, keys, &PlainNumbers).unwrap()
    }

    /// Two concretes and a steel: material 0 and 1 concrete (limits ±1 %, wider than the
    /// fixture's stretches), 2 steel.
    fn model() -> Concrete {
        let concrete = |name, index, e| {
            let keys = [
                ("youngs_modulus", e),
                ("poisson_ratio", 0.2),
                ("tensile_stretch", 0.01),
                ("compressive_stretch", -0.01),
            ];
            material(name, index, MaterialKind::Concrete, &keys)
        };
        let steel_keys = [
            ("youngs_modulus", 200e9),
            ("poisson_ratio", 0.3),
            ("yield_stretch", 1e-4),
        ];
        let materials = [
            concrete("a", 0, 30e9),
            concrete("b", 1, 40e9),
            material("s", 2, MaterialKind::Steel, &steel_keys),
        ];
        Concrete::build(&ModelBuild {
            materials: &materials,
            horizon: 3.015e-3,
            spacing: 1e-3,
            options: &[],
        })
        .unwrap()
    }

    /// `pair_lanes` gives `pair`'s forces bit for bit on concrete and concrete–steel bonds,
    /// and refuses a group with a steel–steel bond (plastic history) or a bond past a limit.
    #[test]
    fn lanes_give_the_single_bond_forces_bit_for_bit() {
        let m = model();
        let alter: Vec<Motion> = (0..5)
            .map(|p| Motion {
                pos: moved(p),
                vel: [0.0; 3],
            })
            .collect();
        let run = |material: [u16; 5], alter: &[Motion]| {
            let side = |p: usize| Side::<Concrete> {
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
            let laws = js.each_ref().map(|j| m.law(i.material, j.material));
            let lanes = m.pair_lanes(laws.each_ref(), &i, js.each_ref(), geoms.each_ref());
            let single: Vec<Option<(Force3, Force3)>> = (0..LANES)
                .map(|l| {
                    let mut history = PlasticStretch::default();
                    m.pair(&laws[l], &i, &js[l], &geoms[l], &mut history)
                })
                .collect();
            (lanes, single)
        };
        // Concrete of two kinds and a concrete–steel interface bond, stretched and shortened.
        let (lanes, single) = run([0, 1, 0, 2, 1], &alter);
        let single: Vec<(Force3, Force3)> = single.into_iter().map(Option::unwrap).collect();
        let pairs = std::array::from_fn(|l| (single[l].0.as_slice(), single[l].1.as_slice()));
        assert_same_bits(&lanes.expect("no lane breaks"), pairs, "concrete");
        // A steel–steel bond: refused, though `pair` takes it.
        let (lanes, single) = run([2, 1, 0, 2, 1], &alter);
        assert!(lanes.is_none() && single.iter().all(Option::is_some));
        // Lane 2 stretched past the tensile limit, then shortened past the compressive one.
        for push in [1e-4, -1e-4] {
            let mut far = alter.clone();
            far[3].pos[0] += push;
            let (lanes, single) = run([0, 1, 0, 1, 1], &far);
            assert!(lanes.is_none() && single[2].is_none(), "push {push}");
        }
    }
}
