//! The reference formulas a validation file names (`[validation.reference] formula = …`),
//! each computed from the case's own deck — its box, material, supports and load, found by the
//! names the file gives — so that a deck a user varies gets its own reference.
//!
//! The formulas and their sources are in docs/theory.md §7–§8; the ACI ones are written in psi
//! and ask for a deck in `units = "in-lbf-s"`. The lap splice's (`splice.rs`) and the
//! pretensioned girder's (`prestressed.rs`) have files of their own.

use crate::input::deck::{LoadKind, Region, Scene};
use crate::input::geometry::{Op, Shape};
use crate::input::units::{Dim, UnitSystem};
use crate::model::{Dimension, Material};
use serde::Deserialize;

mod prestressed;
mod splice;

/// A formula and the deck items it reads (`[validation.reference]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "formula", rename_all = "snake_case", deny_unknown_fields)]
pub enum Formula {
    /// Timoshenko: δ = PL³/3EI + PL/κGA, κ = 5/6, L from the clamp's face to the load's centre.
    TimoshenkoCantilever { clamp: String, load: String },
    /// Timoshenko: δ = 5wL⁴/384EI + wL²/8κGA, L between the two support lines, w the load over
    /// its length.
    TimoshenkoSimplySupported { supports: [String; 2], load: String },
    /// First cracking of a plain cantilever: P = f_r·(I/c)/L, f_r = 7.5√f'c.
    RuptureCantilever { clamp: String, load: String },
    /// First cracking of a plain simply supported beam: w = 8·f_r·(I/c)/L².
    RuptureSimplySupported { supports: [String; 2], load: String },
    /// ACI 318-11 Eq. 11-3, V_c = 2√f'c·b·d, d the bars' effective depth.
    AciShear {},
    /// The uniform load whose end shear is V_c: w = 2·V_c/L between the support lines.
    AciShearSimplySupported { supports: [String; 2] },
    /// Orangun–Jirsa–Breen splice strength T = (1.2 + 3c/d_b + 50 d_b/l_s)·√f'c·π·d_b·l_s of
    /// the deck's two lapped bars in its first cylinder (`splice.rs`).
    OrangunJirsaBreen {},
    /// The smaller of ACI 318-11's web-shear (Eq. 11-12) and flexural cracking loads of a
    /// pretensioned girder at midspan: the deck's first prism along x, its bars (the
    /// prestressed ones are the strands), the two supports, the midspan load and the gravity
    /// load (`prestressed.rs`).
    AciPrestressedCracking {
        supports: [String; 2],
        load: String,
        weight: String,
    },
}

/// A curve drawn against the measured one.
#[derive(Clone, Debug, PartialEq)]
pub enum Curve {
    Points(Vec<(f64, f64)>),
    /// A constant: the reference load, drawn over the measured curve's range.
    Level(f64),
}

/// What a formula gives: the value, the formula in words with its numbers, and its curve.
pub struct Reference {
    pub value: f64,
    pub formula: String,
    pub curve: Curve,
}

/// Elastic moduli a beam formula uses in place of the deck's isotropic E and G: the lattice's
/// own along the beam's axis (`lattice.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moduli {
    /// Young's modulus along the beam's axis.
    pub youngs: f64,
    /// Shear modulus of the planes through the axis.
    pub shear: f64,
}

impl Formula {
    pub fn evaluate(&self, scene: &Scene) -> Result<Reference, String> {
        self.evaluate_with(scene, None)
    }

    /// The reference with the beam's moduli `moduli` where given (the beam formulas only).
    pub fn evaluate_with(
        &self,
        scene: &Scene,
        moduli: Option<Moduli>,
    ) -> Result<Reference, String> {
        match self {
            Formula::OrangunJirsaBreen {} => return splice::reference(scene),
            Formula::AciPrestressedCracking {
                supports,
                load,
                weight,
            } => return prestressed::reference(scene, supports, load, weight),
            _ => {}
        }
        let beam = Beam {
            moduli,
            ..Beam::of(scene)?
        };
        match self {
            Formula::TimoshenkoCantilever { clamp, load } => {
                timoshenko_cantilever(scene, &beam, clamp, load)
            }
            Formula::TimoshenkoSimplySupported { supports, load } => {
                timoshenko_simply_supported(scene, &beam, supports, load)
            }
            Formula::RuptureCantilever { clamp, load } => {
                let arm = load_centre(scene, load)? - clamp_face(scene, clamp)?;
                let f_r = 7.5 * beam.fc_psi(scene)?.sqrt();
                Ok(Reference {
                    value: f_r * beam.section_modulus() / arm,
                    formula: format!(
                        "beam theory P = f_r·(I/c)/L, f_r = 7.5√f'c = {f_r:.1} psi (f'c = {:.0} psi), I/c = {:.0} in³, L = {arm} in (clamp face to the load's centre)",
                        beam.fc_psi(scene)?,
                        beam.section_modulus()
                    ),
                    curve: Curve::Level(f_r * beam.section_modulus() / arm),
                })
            }
            Formula::RuptureSimplySupported { supports, load } => {
                let span = support_span(scene, supports)?;
                let f_r = 7.5 * beam.fc_psi(scene)?.sqrt();
                let w = 8.0 * f_r * beam.section_modulus() / (span * span);
                Ok(Reference {
                    value: w,
                    formula: format!(
                        "beam theory w = 8·f_r·(I/c)/L², f_r = 7.5√f'c = {f_r:.1} psi, I/c = {:.0} in³, L = {span} in between the support lines",
                        beam.section_modulus()
                    ),
                    curve: Curve::Level(w * loaded_length(scene, load)?),
                })
            }
            Formula::AciShear {} => {
                let (v_c, words) = aci_shear(scene, &beam)?;
                Ok(Reference {
                    value: v_c,
                    formula: format!(
                        "ACI 318-11 Eq. 11-3 V_c = 2√f'c·b·d = {v_c:.0} lbf ({words})"
                    ),
                    curve: Curve::Level(v_c),
                })
            }
            Formula::AciShearSimplySupported { supports } => {
                let (v_c, words) = aci_shear(scene, &beam)?;
                let span = support_span(scene, supports)?;
                Ok(Reference {
                    value: 2.0 * v_c / span,
                    formula: format!(
                        "w = 2·V_c/L with ACI 318-11 Eq. 11-3 V_c = 2√f'c·b·d = {v_c:.0} lbf ({words}), L = {span} in between the support lines"
                    ),
                    curve: Curve::Level(2.0 * v_c / span * beam.length),
                })
            }
            // Evaluated above, without a beam; kept an error rather than a panic.
            Formula::OrangunJirsaBreen {} | Formula::AciPrestressedCracking { .. } => {
                Err(format!("{self:?} is not a beam formula"))
            }
        }
    }
}

/// The beam of a case: the deck's first box, along x, and its material.
struct Beam<'a> {
    /// Along x, and the section's width (y) and depth (z).
    length: f64,
    width: f64,
    depth: f64,
    material: &'a Material,
    /// In place of the material's isotropic E and G.
    moduli: Option<Moduli>,
}

impl<'a> Beam<'a> {
    fn of(scene: &'a Scene) -> Result<Beam<'a>, String> {
        let (min, max, material) = first_box(scene)?;
        Ok(Beam {
            length: max[0] - min[0],
            width: max[1] - min[1],
            depth: max[2] - min[2],
            material: &scene.materials[material],
            moduli: None,
        })
    }

    fn inertia(&self) -> f64 {
        self.width * self.depth.powi(3) / 12.0
    }

    /// I/c.
    fn section_modulus(&self) -> f64 {
        self.inertia() / (self.depth / 2.0)
    }

    fn youngs_modulus(&self) -> Result<f64, String> {
        if let Some(m) = self.moduli {
            return Ok(m.youngs);
        }
        let e = self.material.quantity("youngs_modulus", Dimension::STRESS);
        e.map_err(|e| e.to_string())?.ok_or_else(|| {
            format!(
                "material '{}' has no youngs_modulus for the reference",
                self.material.name
            )
        })
    }

    /// ν as given, else ¼: the only one a bond-based (PMB) solid has.
    fn poisson_ratio(&self) -> Result<f64, String> {
        let nu = self.material.poisson_ratio().map_err(|e| e.to_string())?;
        Ok(nu.unwrap_or(0.25))
    }

    /// κGA with κ = 5/6.
    fn shear_stiffness(&self) -> Result<f64, String> {
        let g = match self.moduli {
            Some(m) => m.shear,
            None => self.youngs_modulus()? / (2.0 * (1.0 + self.poisson_ratio()?)),
        };
        Ok(5.0 / 6.0 * g * self.width * self.depth)
    }

    /// f'c in psi (the ACI formulas' unit).
    fn fc_psi(&self, scene: &Scene) -> Result<f64, String> {
        if scene.units != UnitSystem::InchPoundSecond {
            return Err(
                "the ACI formulas are in psi: the deck must be in units = \"in-lbf-s\"".into(),
            );
        }
        self.material.compressive_strength.ok_or_else(|| {
            format!(
                "material '{}' has no compressive_strength (f'c) for the reference",
                self.material.name
            )
        })
    }

    /// "h = …, E = …, ν = …" in the deck's units.
    fn describe(&self, scene: &Scene) -> Result<String, String> {
        let length = scene.units.label(Dim::new(0, 1, 0));
        let stress = scene.units.label(Dim::new(1, -1, -2));
        if let Some(m) = self.moduli {
            return Ok(format!(
                "h = {:.3} {length}, the lattice's E along the axis {:.4e} {stress} and G = C44 {:.4e} {stress}",
                self.depth, m.youngs, m.shear
            ));
        }
        Ok(format!(
            "h = {:.3} {length}, E = {:.4e} {stress}, ν = {}",
            self.depth,
            self.youngs_modulus()?,
            self.poisson_ratio()?
        ))
    }
}

/// The deck's first box, its corners and its material's index: the beam.
fn first_box(scene: &Scene) -> Result<([f64; 3], [f64; 3], usize), String> {
    scene
        .ops
        .iter()
        .find_map(|op| match &op.item {
            Op::Add {
                shape: Shape::Box { min, max },
                material,
            } => Some((*min, *max, *material as usize)),
            _ => None,
        })
        .ok_or_else(|| {
            "the reference formulas of beams read the deck's first box, and it has none".into()
        })
}

/// A beam's body and the isotropic moduli its formulas use (`fe_check.rs`).
pub(super) struct BeamBody {
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub youngs: f64,
    pub poisson: f64,
}

pub(super) fn beam_body(scene: &Scene) -> Result<BeamBody, String> {
    let (min, max, _) = first_box(scene)?;
    let beam = Beam::of(scene)?;
    Ok(BeamBody {
        min,
        max,
        youngs: beam.youngs_modulus()?,
        poisson: beam.poisson_ratio()?,
    })
}

/// A slab or box region as a box, a slab spanning the body `lo`–`hi` across its axis.
pub(super) fn region_box(
    region: &Region,
    lo: [f64; 3],
    hi: [f64; 3],
    what: &str,
) -> Result<([f64; 3], [f64; 3]), String> {
    match region {
        Region::Shape(Shape::Slab { axis, from, to }) => {
            let (mut a, mut b) = (lo, hi);
            (a[*axis], b[*axis]) = (*from, *to);
            Ok((a, b))
        }
        Region::Shape(Shape::Box { min, max }) => Ok((*min, *max)),
        _ => Err(format!("{what}: a slab or a box is needed")),
    }
}

fn timoshenko_cantilever(
    scene: &Scene,
    beam: &Beam,
    clamp: &str,
    load: &str,
) -> Result<Reference, String> {
    let face = clamp_face(scene, clamp)?;
    let span = load_centre(scene, load)? - face;
    let p = total_force(scene, load)?[2];
    let (ei, ga) = (
        beam.youngs_modulus()? * beam.inertia(),
        beam.shear_stiffness()?,
    );
    let deflection = |xi: f64| p * xi * xi * (3.0 * span - xi) / (6.0 * ei) + p * xi / ga;
    Ok(Reference {
        value: p.abs() * span.powi(3) / (3.0 * ei) + p.abs() * span / ga,
        formula: format!(
            "Timoshenko PL³/3EI + PL/κGA, κ = 5/6; L = {span:.3} {}, {}",
            scene.units.label(Dim::new(0, 1, 0)),
            beam.describe(scene)?
        ),
        // w(ξ) = Pξ²(3L − ξ)/6EI + Pξ/κGA from the clamp's face.
        curve: Curve::Points(
            (0..=50)
                .map(|k| span * k as f64 / 50.0)
                .map(|xi| (face + xi, deflection(xi)))
                .collect(),
        ),
    })
}

fn timoshenko_simply_supported(
    scene: &Scene,
    beam: &Beam,
    supports: &[String; 2],
    load: &str,
) -> Result<Reference, String> {
    let span = support_span(scene, supports)?;
    let left = region_centre(scene, &supports[0])?;
    let w = -total_force(scene, load)?[2] / loaded_length(scene, load)?;
    let (ei, ga) = (
        beam.youngs_modulus()? * beam.inertia(),
        beam.shear_stiffness()?,
    );
    let deflection = |x: f64| {
        w * x * (span.powi(3) - 2.0 * span * x * x + x.powi(3)) / (24.0 * ei)
            + w * x * (span - x) / (2.0 * ga)
    };
    Ok(Reference {
        value: 5.0 * w * span.powi(4) / (384.0 * ei) + w * span * span / (8.0 * ga),
        formula: format!(
            "5wL⁴/384EI + wL²/8κGA, κ = 5/6; L = {span:.3} {} between the support lines, w = {w:.1} {}, {}",
            scene.units.label(Dim::new(0, 1, 0)),
            scene.units.label(Dim::new(1, 0, -2)),
            beam.describe(scene)?
        ),
        curve: Curve::Points(
            (0..=60)
                .map(|k| span * k as f64 / 60.0)
                .map(|x| (left + x, -deflection(x)))
                .collect(),
        ),
    })
}

/// V_c = 2√f'c·b·d with d the effective depth of the deck's bars (their mean height, from
/// the face away from them), and the reinforcement in words.
fn aci_shear(scene: &Scene, beam: &Beam) -> Result<(f64, String), String> {
    let fc = beam.fc_psi(scene)?;
    if scene.bars.is_empty() {
        return Err("ACI's V_c is for a reinforced beam: the deck has no [[bar]]".into());
    }
    let n = scene.bars.len() as f64;
    let z = scene
        .bars
        .iter()
        .map(|b| 0.5 * (b.bar.from[2] + b.bar.to[2]))
        .sum::<f64>()
        / n;
    let top = z > beam.depth / 2.0;
    let d = if top { z } else { beam.depth - z };
    let area: f64 = scene.bars.iter().map(|b| b.bar.area).sum();
    let words = format!(
        "f'c = {fc:.0} psi, b = {} in, d = {d} in; {} bars of {:.2} in² (ρ = {:.3}) at the {}",
        beam.width,
        scene.bars.len(),
        area / n,
        area / (beam.width * d),
        if top { "top" } else { "bottom" }
    );
    Ok((2.0 * fc.sqrt() * beam.width * d, words))
}

pub(super) fn boundary_region<'s>(scene: &'s Scene, name: &str) -> Result<&'s Region, String> {
    scene
        .boundaries
        .iter()
        .find(|b| b.name == name)
        .map(|b| &b.region)
        .ok_or_else(|| {
            format!("the reference reads a [[boundary]] named '{name}', and the deck has none")
        })
}

pub(super) fn load_region<'s>(scene: &'s Scene, name: &str) -> Result<&'s Region, String> {
    scene
        .loads
        .iter()
        .find(|l| l.name == name)
        .map(|l| &l.region)
        .ok_or_else(|| {
            format!("the reference reads a [[load]] named '{name}', and the deck has none")
        })
}

/// The extent along x of a slab across x or of a box.
fn x_extent(region: &Region, what: &str) -> Result<(f64, f64), String> {
    match region {
        Region::Shape(Shape::Slab { axis: 0, from, to }) => Ok((*from, *to)),
        Region::Shape(Shape::Box { min, max }) => Ok((min[0], max[0])),
        _ => Err(format!(
            "{what}: the reference needs a slab across x or a box"
        )),
    }
}

/// Where the clamp ends: the beam starts there.
pub(super) fn clamp_face(scene: &Scene, clamp: &str) -> Result<f64, String> {
    Ok(x_extent(boundary_region(scene, clamp)?, clamp)?.1)
}

pub(super) fn region_centre(scene: &Scene, support: &str) -> Result<f64, String> {
    let (a, b) = x_extent(boundary_region(scene, support)?, support)?;
    Ok(0.5 * (a + b))
}

/// The distance between the middles of two supports.
fn support_span(scene: &Scene, supports: &[String; 2]) -> Result<f64, String> {
    Ok((region_centre(scene, &supports[1])? - region_centre(scene, &supports[0])?).abs())
}

fn load_centre(scene: &Scene, load: &str) -> Result<f64, String> {
    let (a, b) = x_extent(load_region(scene, load)?, load)?;
    Ok(0.5 * (a + b))
}

fn loaded_length(scene: &Scene, load: &str) -> Result<f64, String> {
    let (a, b) = x_extent(load_region(scene, load)?, load)?;
    Ok(b - a)
}

pub(super) fn total_force(scene: &Scene, load: &str) -> Result<[f64; 3], String> {
    match scene.loads.iter().find(|l| l.name == load).map(|l| l.kind) {
        Some(LoadKind::Total(f)) => Ok(f),
        Some(_) => Err(format!(
            "the reference needs load '{load}' given as total_force"
        )),
        None => Err(format!(
            "the reference reads a [[load]] named '{load}', and the deck has none"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        crate::input::deck::parse(text, "t.toml", "t").unwrap()
    }

    const CANTILEVER: &str = r#"units = "SI"
[model]
name = "pmb"
m = 3
[lattice]
spacing = "0.01 m"
[materials.solid]
density = "2400 kg/m^3"
youngs_modulus = "10 GPa"
[[geometry]]
shape = "box"
material = "solid"
min = "0 0 0 m"
max = "0.74 0.07 0.07 m"
[time]
steps = 1
[[boundary]]
name = "clamp"
region = { shape = "slab", axis = "x", from = "0 m", to = "0.03 m" }
fixed = ["all"]
[[load]]
name = "tip"
region = { shape = "slab", axis = "x", from = "0.72 m", to = "0.74 m" }
total_force = "0 0 -1000 N"
"#;

    /// PL³/3EI + PL/κGA by hand for L = 0.70 m, h = 0.07 m, E = 10 GPa, ν = ¼.
    #[test]
    fn the_cantilever_reference_is_timoshenko_from_the_deck() {
        let f = Formula::TimoshenkoCantilever {
            clamp: "clamp".into(),
            load: "tip".into(),
        };
        let r = f.evaluate(&scene(CANTILEVER)).unwrap();
        let (l, h, e) = (0.70f64, 0.07f64, 10e9);
        let by_hand = 1000.0 * l.powi(3) / (3.0 * e * h.powi(4) / 12.0)
            + 1000.0 * l / (5.0 / 6.0 * e / 2.5 * h * h);
        assert!(
            (r.value - by_hand).abs() < 1e-12 * by_hand,
            "{} {by_hand}",
            r.value
        );
        // Twice the load, twice the deflection: the reference follows the deck.
        let twice = scene(&CANTILEVER.replace("-1000 N", "-2000 N"));
        assert!((f.evaluate(&twice).unwrap().value - 2.0 * by_hand).abs() < 1e-12 * by_hand);
    }

    #[test]
    fn a_missing_item_is_named() {
        let f = Formula::TimoshenkoCantilever {
            clamp: "wall".into(),
            load: "tip".into(),
        };
        let e = f.evaluate(&scene(CANTILEVER)).err().unwrap();
        assert!(e.contains("'wall'"), "{e}");
        let e = Formula::AciShear {}
            .evaluate(&scene(CANTILEVER))
            .err()
            .unwrap();
        assert!(e.contains("in-lbf-s"), "{e}");
    }
}
