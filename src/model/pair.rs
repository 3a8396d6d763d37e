//! The interface between the engine's non-bonded pass and a pair-law file in `pairs/`.
//!
//! A pair law is physics only, like a model: it reads its parameters per material (and per
//! pair of materials, with a mixing rule), and says what force and energy a pair of particles
//! at squared distance r² has. The engine finds the pairs (neighbour lists from the cells with
//! a skin, over owned particles and the wall method's ghosts), sums the forces into the
//! model's first three generalized forces and owns every loop. The pass is monomorphized per
//! law, so the kernel carries no dispatch per pair.

use crate::model::{Material, ModelError};

/// How the coefficients of two materials combine when no `[[pair.between]]` gives them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mixing {
    /// ε = √(ε_a ε_b), σ = √(σ_a σ_b) (LAMMPS's default `pair_modify mix geometric`).
    #[default]
    Geometric,
    /// Lorentz–Berthelot: ε = √(ε_a ε_b), σ = (σ_a + σ_b)/2 (`mix arithmetic`).
    Arithmetic,
}

impl Mixing {
    pub fn name(self) -> &'static str {
        match self {
            Mixing::Geometric => "geometric",
            Mixing::Arithmetic => "arithmetic",
        }
    }

    /// An energy-like coefficient (ε, a Morse well depth): the geometric mean under both rules.
    pub fn energy(self, a: f64, b: f64) -> f64 {
        (a * b).sqrt()
    }

    /// A length-like coefficient (σ, an equilibrium distance).
    pub fn length(self, a: f64, b: f64) -> f64 {
        match self {
            Mixing::Geometric => (a * b).sqrt(),
            Mixing::Arithmetic => 0.5 * (a + b),
        }
    }
}

/// Everything a pair law is built from.
pub struct PairBuild<'a> {
    /// Each material's pair parameters (`[pair.materials.NAME]`), in material order, with the
    /// material's name and index; a material the deck gives no table has no keys.
    pub own: &'a [Material],
    /// Parameters given for one pair of materials (`[[pair.between]]`): they replace the mixed
    /// values for that pair, both ways round. The `Material` holds the pair's keys; its index
    /// counts on past the materials' (`own.len() + k` for the k-th table), so that an error
    /// about it points at its table.
    pub between: &'a [(u16, u16, Material)],
    pub mixing: Mixing,
    /// The cutoff the deck gives for every pair (`[pair] cutoff`), if any, in length units.
    pub cutoff: Option<f64>,
    /// Whether energies are shifted to zero at the cutoff (`[pair] shift`); the deck's default
    /// is the law's.
    pub shift: Option<bool>,
    /// The bonded model's horizon and the lattice spacing (the contact law scales with them).
    pub horizon: f64,
    pub spacing: f64,
    /// Bulk modulus of each material under the bonded model (from its Lamé constants), for
    /// laws whose stiffness is tied to the bonds'.
    pub bulk_modulus: &'a [f64],
}

impl PairBuild<'_> {
    /// The table for materials `a` and `b` if `[[pair.between]]` gives one (either order).
    pub fn between(&self, a: u16, b: u16) -> Option<&Material> {
        self.between
            .iter()
            .find(|(x, y, _)| (*x, *y) == (a, b) || (*x, *y) == (b, a))
            .map(|(_, _, m)| m)
    }
}

/// A non-bonded pair law: what two particles closer than its cutoff do to each other.
pub trait PairLaw: Sized + Clone + Send + Sync + 'static {
    /// The name a deck uses (`[pair] law = "…"`).
    const NAME: &'static str;
    /// One line for `pdq models`.
    const SUMMARY: &'static str;
    /// Keys read from `[pair.materials.NAME]` and `[[pair.between]]`: name and meaning.
    const KEYS: &'static [(&'static str, &'static str)];
    /// Whether pairs joined by an intact bond are left out (contact acts only where bonds do
    /// not). For the other laws the deck decides (`[pair] exclude = "bonded"`).
    const SKIPS_BONDED: bool = false;
    /// Whether [`PairLaw::eval`] needs the product of the two particles' volumes (a
    /// peridynamic force density); `false` hands it 1.
    const VOLUMES: bool = false;
    /// The LAMMPS pair style with the same law, for `pdq bench --peer`; `None`: none.
    const LAMMPS_PEER: Option<&'static str> = None;
    /// What the kernel reads for one pair of materials (precomputed: no square roots or
    /// divisions that do not depend on r).
    type Coeff: Copy + Send + Sync + std::fmt::Debug + 'static;

    fn build(b: &PairBuild) -> Result<Self, ModelError>;

    /// The coefficients of a pair of materials `mi`, `mj`.
    fn coeff(&self, mi: u16, mj: u16) -> Self::Coeff;

    /// The largest cutoff over every pair of materials (the neighbour lists' radius before
    /// their skin).
    fn cutoff(&self) -> f64;

    /// Force and energy of a pair at squared distance `r2` (with `vv` = V_i·V_j if
    /// [`PairLaw::VOLUMES`], else 1): `Some((F/r, U))` inside the pair's cutoff, where F > 0
    /// pushes the two apart (the force on j is (F/r)·(x_j − x_i)); `None` beyond it.
    fn eval(&self, c: &Self::Coeff, r2: f64, vv: f64) -> Option<(f64, f64)>;
}

/// Something to do with a pair law chosen by name at run time.
pub trait PairVisitor {
    type Output;
    fn visit<L: PairLaw>(self, law: L) -> Self::Output;
}

/// What `pdq models` prints about a pair law.
#[derive(Clone, Debug)]
pub struct PairInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub keys: &'static [(&'static str, &'static str)],
    pub skips_bonded: bool,
    pub lammps_peer: Option<&'static str>,
}

impl PairInfo {
    pub fn of<L: PairLaw>() -> PairInfo {
        PairInfo {
            name: L::NAME,
            summary: L::SUMMARY,
            keys: L::KEYS,
            skips_bonded: L::SKIPS_BONDED,
            lammps_peer: L::LAMMPS_PEER,
        }
    }
}

/// The registry of pair laws in `pairs/mod.rs`: `pair_registry! { lj::LennardJones, … }`.
#[macro_export]
macro_rules! pair_registry {
    ($($ty:ty),+ $(,)?) => {
        /// Names a deck may use in `[pair] law = …`.
        pub fn names() -> Vec<&'static str> {
            vec![$(<$ty as $crate::model::pair::PairLaw>::NAME),+]
        }

        /// Declared data of every pair law.
        pub fn info() -> Vec<$crate::model::pair::PairInfo> {
            vec![$($crate::model::pair::PairInfo::of::<$ty>()),+]
        }

        /// Builds the pair law called `name` and hands it to `visitor`.
        pub fn visit<V: $crate::model::pair::PairVisitor>(
            name: &str,
            build: &$crate::model::pair::PairBuild,
            visitor: V,
        ) -> Result<V::Output, $crate::model::ModelError> {
            $(
                if name == <$ty as $crate::model::pair::PairLaw>::NAME {
                    let law = <$ty as $crate::model::pair::PairLaw>::build(build)?;
                    return Ok(visitor.visit(law));
                }
            )+
            Err(format!("unknown pair law '{}' (known laws: {})", name, names().join(", ")).into())
        }
    };
}

impl PairBuild<'_> {
    /// Refuses keys a law does not read, in every material's and pair's table.
    pub fn only_uses(&self, law: &str, keys: &[(&str, &str)]) -> Result<(), ModelError> {
        let names: Vec<&str> = keys.iter().map(|(k, _)| *k).collect();
        for m in self
            .own
            .iter()
            .chain(self.between.iter().map(|(_, _, m)| m))
        {
            if let Some(k) = m.given().find(|k| !names.contains(k)) {
                return Err(m.key_error(
                    k,
                    format!(
                        "pair law '{law}' does not use '{k}' (it reads {})",
                        if names.is_empty() {
                            "no keys".to_string()
                        } else {
                            names.join(", ")
                        }
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The value of `key` for materials `a` and `b` in the deck's units: the one
    /// `[[pair.between]]` gives, else `mix` of both materials' own values; `None` if neither.
    /// A pair where only one material gives the key is an error naming the other.
    pub fn value(
        &self,
        a: u16,
        b: u16,
        key: &str,
        dim: crate::model::Dimension,
        mix: impl Fn(f64, f64) -> f64,
    ) -> Result<Option<f64>, ModelError> {
        if let Some(m) = self.between(a, b) {
            if let Some(v) = m.positive(key, dim)? {
                return Ok(Some(v));
            }
        }
        let (ma, mb) = (&self.own[a as usize], &self.own[b as usize]);
        match (ma.positive(key, dim)?, mb.positive(key, dim)?) {
            (Some(x), Some(y)) => Ok(Some(if a == b { x } else { mix(x, y) })),
            (None, None) => Ok(None),
            (Some(_), None) => Err(mb.error(format!(
                "[pair.materials.{}] gives no '{key}' but material '{}' does: give it for both or in a [[pair.between]] table",
                mb.name, ma.name
            ))),
            (None, Some(_)) => Err(ma.error(format!(
                "[pair.materials.{}] gives no '{key}' but material '{}' does: give it for both or in a [[pair.between]] table",
                ma.name, mb.name
            ))),
        }
    }

    /// [`PairBuild::value`] that must be there.
    pub fn required(
        &self,
        a: u16,
        b: u16,
        key: &str,
        dim: crate::model::Dimension,
        mix: impl Fn(f64, f64) -> f64,
        law: &str,
    ) -> Result<f64, ModelError> {
        self.value(a, b, key, dim, mix)?.ok_or_else(|| {
            self.own[a as usize].error(format!(
                "pair law '{law}' needs '{key}' for materials '{}' and '{}': give it in [pair.materials.NAME] or [[pair.between]]",
                self.own[a as usize].name, self.own[b as usize].name
            ))
        })
    }

    /// Every pair of materials' coefficients from `of(a, b)`, in a [`PairTable`]; the first
    /// error stops.
    pub fn table<C: Copy>(
        &self,
        of: impl Fn(u16, u16) -> Result<C, ModelError>,
    ) -> Result<crate::model::PairTable<C>, ModelError> {
        let n = self.own.len() as u16;
        let mut all = Vec::with_capacity(n as usize * n as usize);
        for a in 0..n {
            for b in 0..n {
                all.push(of(a, b)?);
            }
        }
        let index: Vec<u16> = (0..n).collect();
        Ok(crate::model::PairTable::new(&index, |&a, &b| {
            all[a as usize * n as usize + b as usize]
        }))
    }
}
