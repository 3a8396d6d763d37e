//! The lattice's own elastic constants for a case: a bulk block of the case's model, material,
//! lattice and horizon, deformed homogeneously (`engine::analysis`). A beam along a lattice
//! axis bends with the lattice's E along [100], not with the deck's isotropic E, and shears
//! with its C44; `pdq validate --sweep` compares each cantilever with both.

use crate::engine::analysis::{cubic_constants_at_centre, CubicConstants};
use crate::input::deck::{self, Scene};
use crate::input::geometry::{Op, Shape};
use crate::input::setup;
use crate::input::units::Dim;
use crate::model::{Model, ModelVisitor};
use toml::Value;

/// The cubic constants of the lattice of `deck` (a case's deck table, `scene` its parse),
/// measured at the centre of a block of the deck's first box's material whose centre
/// particle's family and its neighbours' families are whole (half-width ≥ 2δ).
pub fn constants_of(deck: &toml::Table, scene: &Scene) -> Result<CubicConstants, String> {
    let material = scene
        .ops
        .iter()
        .find_map(|op| match &op.item {
            Op::Add {
                shape: Shape::Box { .. },
                material,
            } => Some(*material),
            _ => None,
        })
        .ok_or("the lattice's constants are measured in the deck's first box's material, and it has none")?;
    let name = &scene.materials[material as usize].name;
    let half = (2.0 * scene.horizon / scene.spacing - 1e-9).ceil() as usize;
    let side = (2 * half + 1) as f64 * scene.spacing;
    let length = scene.units.label(Dim::new(0, 1, 0));
    let mut block = toml::Table::new();
    for key in ["units", "model", "lattice", "materials"] {
        if let Some(v) = deck.get(key) {
            block.insert(key.into(), v.clone());
        }
    }
    let mut geometry = toml::Table::new();
    geometry.insert("shape".into(), Value::from("box"));
    geometry.insert("material".into(), Value::from(name.as_str()));
    geometry.insert("min".into(), Value::from(format!("0 0 0 {length}")));
    geometry.insert(
        "max".into(),
        Value::from(format!("{side} {side} {side} {length}")),
    );
    block.insert(
        "geometry".into(),
        Value::Array(vec![Value::Table(geometry)]),
    );
    let mut time = toml::Table::new();
    time.insert("steps".into(), Value::from(1));
    block.insert("time".into(), Value::Table(time));
    let mut output = toml::Table::new();
    output.insert("progress".into(), Value::from(false));
    block.insert("output".into(), Value::Table(output));
    let text = toml::to_string(&block).map_err(|e| e.to_string())?;
    let file = format!("{} (its lattice block)", scene.file);
    let block = deck::parse(&text, &file, "lattice block").map_err(|e| e.to_string())?;

    setup::with_model(&block, Block(&block)).map_err(|e| e.to_string())?
}

/// Builds the block with its model and measures the constants at its centre.
struct Block<'a>(&'a Scene);

impl ModelVisitor for Block<'_> {
    type Output = Result<CubicConstants, String>;
    fn visit<M: Model>(self, model: M) -> Self::Output {
        let mut s = setup::build(model, self.0).map_err(|e| e.to_string())?;
        cubic_constants_at_centre(&mut s.sim)
            .ok_or_else(|| format!("{}: the block has no particles", self.0.file))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The constants measured through a case deck are those of a block written by hand
    /// (tests/continuum.rs checks those against the continuum), and PMB's obey the Cauchy
    /// relation C12 = C44.
    #[test]
    fn a_cantilever_deck_gives_its_lattice_constants() {
        let text = std::fs::read_to_string("validation/cantilever_pmb.toml").unwrap();
        let mut table: toml::Table = toml::from_str(&text).unwrap();
        table.remove("validation");
        let scene = deck::parse(&toml::to_string(&table).unwrap(), "c.toml", "c").unwrap();
        let c = constants_of(&table, &scene).unwrap();
        assert!(
            (c.c12 - c.c44).abs() < 1e-4 * c.c11,
            "Cauchy relation: C12 {} C44 {}",
            c.c12,
            c.c44
        );
        // The energy correction makes C11 = λ + 2μ of the deck's E and ν = ¼; the lattice is
        // stiffer in shear than an isotropic solid (anisotropy 1.16 at m = 3), so E along
        // [100] is below the deck's E (−3.7 %, validation/README.md).
        let e = 10.0e9;
        assert!((c.c11 / (1.2 * e) - 1.0).abs() < 2e-3, "C11 {}", c.c11);
        assert!((c.anisotropy() - 1.16).abs() < 0.01, "{}", c.anisotropy());
        let ratio = c.youngs_modulus_100() / e;
        assert!((ratio - 0.963).abs() < 0.003, "E100/E {ratio}");
    }
}
