//! The interface between the engine and a model file in `models/`.
//!
//! A model is physics only: it declares its data (see [`crate::model::attributes`]) and says what one
//! bond does. The engine owns every loop, the decomposition and all I/O, and is generic over
//! `M: Model`, so each model gets its own monomorphized step with no dynamic dispatch per bond.

pub mod attributes;
pub mod elastic;
pub mod lanes;
pub mod material;
pub mod pair;
pub mod rotation;
pub mod sample;

pub use elastic::{ElasticConstant, Isotropic};
pub use material::{Dimension, Material, MaterialKind, ModelError, PairTable, Units, Written};
pub use sample::{stretch_line, Sample, SampleOf};

use crate::model::attributes::Attributes;
use crate::model::lanes::{LaneForces, LANES};

/// A value of `[model.options]`: a number or a word (`influence = "gaussian"`).
#[derive(Clone, Debug, PartialEq)]
pub enum OptionValue {
    Number(f64),
    Word(String),
}

/// Everything a model is built from.
#[derive(Clone, Debug)]
pub struct ModelBuild<'a> {
    pub materials: &'a [Material],
    pub horizon: f64,
    pub spacing: f64,
    /// Model-specific options from the deck's `[model.options]`; a model rejects names it does
    /// not know (see [`check_options`]).
    pub options: &'a [(String, OptionValue)],
}

impl ModelBuild<'_> {
    /// Each material's own constants, in material order, from `own(material, horizon)`; the
    /// first error stops.
    pub fn per_material<T>(
        &self,
        own: impl Fn(&Material, f64) -> Result<T, ModelError>,
    ) -> Result<Vec<T>, ModelError> {
        self.materials
            .iter()
            .map(|m| own(m, self.horizon))
            .collect()
    }

    fn value(&self, name: &str) -> Option<&OptionValue> {
        self.options.iter().find(|(k, _)| k == name).map(|(_, v)| v)
    }

    /// A numeric option; a word there is an error naming the option.
    pub fn option(&self, name: &str) -> Result<Option<f64>, String> {
        match self.value(name) {
            None => Ok(None),
            Some(OptionValue::Number(x)) => Ok(Some(*x)),
            Some(OptionValue::Word(w)) => Err(format!(
                "[model.options] {name} takes a number, not \"{w}\""
            )),
        }
    }

    /// A word option; a number there is an error naming the option.
    pub fn word(&self, name: &str) -> Result<Option<&str>, String> {
        match self.value(name) {
            None => Ok(None),
            Some(OptionValue::Word(w)) => Ok(Some(w)),
            Some(OptionValue::Number(x)) => Err(format!(
                "[model.options] {name} takes a word, not the number {x}"
            )),
        }
    }
}

/// Rejects option names a model does not declare, naming them and listing the known ones.
pub fn check_options(
    model: &str,
    known: &[(&str, &str)],
    given: &[(String, OptionValue)],
) -> Result<(), String> {
    for (k, _) in given {
        if !known.iter().any(|(n, _)| n == k) {
            let names: Vec<&str> = known.iter().map(|(n, _)| *n).collect();
            return Err(format!(
                "model '{model}' has no option '{k}' (its options: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ));
        }
    }
    Ok(())
}

/// Reference data of a bond, fixed when families are found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BondGeom {
    /// |ξ|, the reference bond length.
    pub length: f64,
    /// Partial-volume factor β ∈ (0, 1] scaling the partner volume (docs/theory.md §6).
    pub beta: f64,
}

/// One end of a bond as the model sees it.
pub struct Side<'a, M: Model> {
    pub x0: &'a [f64; 3],
    pub volume: f64,
    pub material: u16,
    pub alter: &'a M::Alter,
    pub fixed: &'a M::Fixed,
    pub state: &'a M::State,
}

impl<M: Model> Side<'_, M> {
    /// Current position: by convention the first three values of the alterable record.
    #[inline(always)]
    pub fn pos(&self) -> [f64; 3] {
        let a = self.alter.as_slice();
        [a[0], a[1], a[2]]
    }
}

/// A peridynamic model: data declarations plus the physics of one bond.
///
/// Layout convention: `Force` holds one generalized force per degree of freedom, the
/// second-order ones (translations, rotations) first and the `FIRST_ORDER` ones (temperature)
/// last. `Alter` holds the n₂ = `Force::LEN − FIRST_ORDER` generalized coordinates (current
/// position first), then their n₂ velocities, then the first-order values; anything after that
/// is free for the model. The integrators rely on it, so a model needs no integration code
/// (a model whose coordinates are not a vector space, such as finite rotations, overrides
/// [`Model::drift`]).
pub trait Model: Sized + Clone + Send + Sync + 'static {
    /// The name a deck uses (`[model] name = "…"`).
    const NAME: &'static str;
    /// One line for `pdq models`.
    const SUMMARY: &'static str;
    /// Options accepted in `[model.options]`: name and meaning.
    const OPTIONS: &'static [(&'static str, &'static str)] = &[];
    /// How many of the last generalized forces are rates of first-order degrees of freedom
    /// (heat flowing into a particle), integrated by forward Euler: q += Δt·F / inertia.
    const FIRST_ORDER: usize = 0;
    /// Whether [`Model::bond_fixed`] adds bond sums to the fixed data (LPS weighted volume).
    const FIXED_FROM_BONDS: bool = false;
    /// Whether the bond loops hand the model four intact bonds of a particle at a time
    /// ([`Model::pair_lanes`], [`crate::model::lanes`]): 1 (one bond per call) or
    /// [`crate::model::lanes::LANES`]. The law is written once, generic over
    /// [`crate::model::lanes::Real`] (PMB, LPS, micropolar, concrete), so results are the same
    /// either way (sums in bond order, no fused operations). For models with at most
    /// [`crate::model::lanes::MAX_COMPONENTS`] generalized forces. `pair_lanes` sees no bond
    /// history: a model that keeps some (`Bond` ≠ `()`) refuses every group whose law would
    /// read or change it (concrete: a steel bond's plastic stretch), and those go to `pair`.
    const BOND_LANES: usize = 1;
    /// The LAMMPS pair style of the same law (`"peri/pmb"`), which `pdq bench --peer` runs on
    /// the benchmark scene; `None`: LAMMPS has none.
    const LAMMPS_PEER: Option<&'static str> = None;
    /// Whether the model's particles have bonds. A bondless model (`point`: particles that
    /// only move) is given no horizon: the deck leaves `horizon` and `m` out, no bond is
    /// searched for, and with no bond to bound the time step the deck gives `[time] dt`.
    const BONDED: bool = true;

    /// Changes during a run: generalized coordinates, then their velocities, then extras.
    type Alter: Attributes;
    /// Constant per-particle data beyond the engine's reference position, volume, material.
    type Fixed: Attributes;
    /// History kept on every bond (plastic stretch …); the engine keeps the broken flag.
    type Bond: Attributes;
    /// Per-particle value summed over bonds before forces (LPS dilatation); `()` = no pass.
    type State: Attributes;
    /// One generalized force per integrated degree of freedom.
    type Force: Attributes;
    /// What a bond between two materials needs (micromodulus, critical stretches …). The
    /// engine looks it up with [`Model::law`] and hands it to every bond call; in a scene of
    /// one material it looks it up once per pass, so the bond loop carries no material dispatch.
    type Law: Copy + Send + Sync + 'static;

    fn build(b: &ModelBuild) -> Result<Self, ModelError>;

    /// A material of this model for a scene written in code (the benchmark, the stress tests'
    /// blocks, the tests' decks; [`crate::model::sample`]). `None`: it has none, and those
    /// tools leave the model out.
    fn sample(_of: &SampleOf) -> Option<Sample> {
        None
    }

    /// Whether a bond of this scene can break (some critical stretch is finite). When none can,
    /// the engine runs the pair pass without damage bookkeeping: no broken flags read or
    /// written, no break test per bond in the loop.
    fn breaks(&self) -> bool {
        true
    }

    /// Constant data of a particle.
    fn fixed(&self, _material: u16, _volume: f64) -> Self::Fixed {
        Self::Fixed::default()
    }

    /// Contribution of a bond, in the reference configuration, to both ends' fixed data; summed
    /// once when families are found, over the whole family even across procCube faces (LPS
    /// weighted volume m_i = Σ ω L² V_j β). Only called if `FIXED_FROM_BONDS`.
    fn bond_fixed(
        &self,
        _law: &Self::Law,
        _i: &Side<Self>,
        _j: &Side<Self>,
        _geom: &BondGeom,
    ) -> (Self::Fixed, Self::Fixed) {
        (Self::Fixed::default(), Self::Fixed::default())
    }

    /// A particle at rest in its reference configuration: position set, everything else zero;
    /// a model whose zero is not "at rest" (an identity quaternion) fills it in here.
    fn at_rest(&self, _alter: &mut Self::Alter) {}

    /// Mass (or rotational inertia, or heat capacity) of each generalized degree of freedom.
    fn inertia(&self, material: u16, volume: f64, fixed: &Self::Fixed) -> Self::Force;

    /// The law of a bond between materials `mi` and `mj`.
    fn law(&self, mi: u16, mj: u16) -> Self::Law;

    /// Stiffness of a bond for each degree of freedom, for the stable time step (docs/theory.md §4):
    /// C_ij = c/|ξ| for translations (Silling–Askari), the moment per unit rotation for
    /// rotations, the conductance per unit temperature difference for first-order DOFs; all
    /// per unit volume of both ends.
    fn bond_stiffness(&self, law: &Self::Law, geom: &BondGeom) -> Self::Force;

    /// The shape of adaptive dynamic relaxation's fictitious mass (`src/solve/adr.rs`): a
    /// bond's share of its ends' tangent stiffness, per DOF, in the units of
    /// [`Model::bond_stiffness`], which it defaults to. Only its distribution over the
    /// particles matters (the scale is measured); a state-based model whose stiffness depends
    /// on its ends' fixed values (LPS: their weighted volumes) says so here.
    fn relaxation_stiffness(
        &self,
        law: &Self::Law,
        _i: &Side<Self>,
        _j: &Side<Self>,
        geom: &BondGeom,
    ) -> Self::Force {
        self.bond_stiffness(law, geom)
    }

    /// The history of a bond held at an initial stretch `strain` under law `law` (a prestrained
    /// bar's own bonds, `[[bar]] prestrain`): the bond is unstressed at length (1 − strain)·|ξ|,
    /// so at its reference length it pulls its ends together with the force of that stretch.
    /// A model without a history that can hold a rest length refuses, with the reason.
    fn prestrained(&self, _law: &Self::Law, _strain: f64) -> Result<Self::Bond, String> {
        Err(format!(
            "model '{}' cannot prestrain bonds (it keeps no plastic stretch); use model \"concrete\" with a steel bar",
            Self::NAME
        ))
    }

    /// Continuum Lamé constants (λ, μ) the model is calibrated to for `material`: the targets
    /// of the energy surface correction and of validation.
    fn lame(&self, material: u16) -> (f64, f64);

    /// q += h·v on the coordinates of one particle. The default adds; a model whose
    /// coordinates are not a vector space (finite rotations) composes instead.
    #[inline(always)]
    fn drift(&self, alter: &mut Self::Alter, h: f64) {
        let n = <Self::Force as Attributes>::LEN - Self::FIRST_ORDER;
        let a = alter.as_mut_slice();
        for k in 0..n {
            a[k] += h * a[n + k];
        }
    }

    /// Elastic energy of a particle that is not in any one bond (LPS: K θ²/2 · V_i).
    fn particle_energy(
        &self,
        _material: u16,
        _volume: f64,
        _fixed: &Self::Fixed,
        _state: &Self::State,
    ) -> f64 {
        0.0
    }

    /// Contribution of an intact bond to both ends' state (only called if `State` is not `()`).
    fn state(
        &self,
        _law: &Self::Law,
        _i: &Side<Self>,
        _j: &Side<Self>,
        _geom: &BondGeom,
        _bond: &Self::Bond,
    ) -> (Self::State, Self::State) {
        (Self::State::default(), Self::State::default())
    }

    /// [`Model::state`] of four intact bonds of particle `i` at once, as
    /// [`Model::pair_lanes`] is to [`Model::pair`]: component k of the `State` record in
    /// element k, bit for bit `state`'s values. `None` (the default): one by one.
    fn state_lanes(
        &self,
        _law: [&Self::Law; LANES],
        _i: &Side<Self>,
        _j: [&Side<Self>; LANES],
        _geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        None
    }

    /// Turns a particle's summed state into its final value (e.g. θ = 3/m·Σ…); it may also
    /// fill fields the pair pass wants per particle (LPS keeps 1/m there), which the sums leave
    /// at zero.
    fn finish_state(&self, _state: &mut Self::State, _fixed: &Self::Fixed) {}

    /// Generalized forces on both ends of an intact bond, already multiplied by both volumes.
    /// `None` means the bond breaks now: the engine marks it and never calls it again.
    fn pair(
        &self,
        law: &Self::Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        bond: &mut Self::Bond,
    ) -> Option<(Self::Force, Self::Force)>;

    /// [`Model::pair`] of four intact bonds of particle `i` at once (lane `l`: partner `j[l]`,
    /// law `law[l]`), for models with `BOND_LANES` = 4; it sees no bond history, so it must
    /// refuse a group whose history `pair` would read or change. `None` when it refuses the
    /// group or any of the four breaks now: the engine then calls `pair` on each. The forces come
    /// component by component ([`crate::model::lanes::LaneForces`]) and must be those of `pair` bit
    /// for bit.
    fn pair_lanes(
        &self,
        _law: [&Self::Law; LANES],
        _i: &Side<Self>,
        _j: [&Side<Self>; LANES],
        _geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        None
    }

    /// Elastic energy stored in an intact bond (whole bond, both volumes included); with
    /// [`Model::particle_energy`] it makes the strain energy.
    fn energy(
        &self,
        law: &Self::Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        bond: &Self::Bond,
    ) -> f64;
}

/// Number of second-order degrees of freedom of model `M` (coordinates with velocities).
#[inline(always)]
pub fn second_order<M: Model>() -> usize {
    <M::Force as Attributes>::LEN - M::FIRST_ORDER
}

/// Lamé constants (λ, μ) of a bond-based solid of micromodulus `c` and horizon `delta`:
/// K = πδ⁴c/18 and ν = 1/4, so λ = μ = 3K/5 (docs/theory.md §1).
pub fn bond_based_lame(c: f64, delta: f64) -> (f64, f64) {
    let k = std::f64::consts::PI * delta.powi(4) * c / 18.0;
    (0.6 * k, 0.6 * k)
}

/// Bond stretch and the current bond vector: shared by every bond-based law.
#[inline(always)]
pub fn stretch<M: Model>(i: &Side<M>, j: &Side<M>, geom: &BondGeom) -> (f64, [f64; 3], f64) {
    let (a, b) = (i.pos(), j.pos());
    let y = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
    ((r - geom.length) / geom.length, y, r)
}

/// Something to do with a model chosen by name at run time: the one place where a deck's
/// string becomes a concrete type, after which everything is monomorphized.
pub trait ModelVisitor {
    type Output;
    fn visit<M: Model>(self, model: M) -> Self::Output;
}

/// What `pdq models` prints about a model.
#[derive(Clone, Debug)]
pub struct ModelInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub options: &'static [(&'static str, &'static str)],
    pub alter: &'static [crate::model::attributes::Field],
    pub fixed: &'static [crate::model::attributes::Field],
    pub bond: &'static [crate::model::attributes::Field],
    pub state: &'static [crate::model::attributes::Field],
    pub force: &'static [crate::model::attributes::Field],
    /// [`Model::FIRST_ORDER`]: how many degrees of freedom are rates (temperature).
    pub first_order: usize,
    /// [`Model::LAMMPS_PEER`].
    pub lammps_peer: Option<&'static str>,
    /// [`Model::BONDED`].
    pub bonded: bool,
    /// [`Model::sample`].
    pub sample: fn(&SampleOf) -> Option<Sample>,
}

impl ModelInfo {
    pub fn of<M: Model>() -> Self {
        ModelInfo {
            name: M::NAME,
            summary: M::SUMMARY,
            options: M::OPTIONS,
            alter: <M::Alter as Attributes>::FIELDS,
            fixed: <M::Fixed as Attributes>::FIELDS,
            bond: <M::Bond as Attributes>::FIELDS,
            state: <M::State as Attributes>::FIELDS,
            force: <M::Force as Attributes>::FIELDS,
            first_order: M::FIRST_ORDER,
            lammps_peer: M::LAMMPS_PEER,
            bonded: M::BONDED,
            sample: M::sample,
        }
    }

    /// Its sample material for `of`, if it has one.
    pub fn sample(&self, of: &SampleOf) -> Option<Sample> {
        (self.sample)(of)
    }
}

/// Generates the lookup of models by name (`names`, `info`, `find`, `visit`) from a list of
/// types.
/// Used once, in `models/mod.rs`.
#[macro_export]
macro_rules! model_registry {
    ($($ty:ty),+ $(,)?) => {
        /// Names a deck may use in `[model] name = …`.
        pub fn names() -> Vec<&'static str> {
            vec![$(<$ty as $crate::model::Model>::NAME),+]
        }

        /// Declared data of every model.
        pub fn info() -> Vec<$crate::model::ModelInfo> {
            vec![$($crate::model::ModelInfo::of::<$ty>()),+]
        }

        /// Declared data of the model called `name`.
        pub fn find(name: &str) -> Option<$crate::model::ModelInfo> {
            info().into_iter().find(|m| m.name == name)
        }

        /// Builds the model called `name` and hands it to `visitor`.
        pub fn visit<V: $crate::model::ModelVisitor>(
            name: &str,
            build: &$crate::model::ModelBuild,
            visitor: V,
        ) -> Result<V::Output, $crate::model::ModelError> {
            $(
                if name == <$ty as $crate::model::Model>::NAME {
                    let model = <$ty as $crate::model::Model>::build(build)?;
                    return Ok(visitor.visit(model));
                }
            )+
            Err(format!("unknown model '{}' (known models: {})", name, names().join(", ")).into())
        }
    };
}
