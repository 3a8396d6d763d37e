//! Materials as a deck gives them, and what a model reads of them.
//!
//! A `[materials.NAME]` table has two keys every model shares — `kind` and `density` — and
//! any others a model declares by reading them: `youngs_modulus` as a stress, `yield_stretch`
//! as a number, a new model's own parameter as whatever dimension it asks for. The deck does
//! not know those keys: it hands each value as written ([`Written`]) with the unit system
//! that converts it ([`Units`]), and the model reads what it needs through [`Material`]'s
//! typed getters, which check dimension, sign and presence and name the key when they
//! refuse. A key no model getter was asked about is refused by [`Material::only_uses`].
//! Errors are typed ([`ModelError`]), so the deck reports them at the key's or the
//! material's line without reading the message.

use std::fmt;

/// What a material is made of, as far as a model needs to know to pick a bond law.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialKind {
    /// A generic elastic-brittle solid.
    Solid,
    /// Plain concrete (the thesis's `ConcConc` law).
    Concrete,
    /// Reinforcing or prestressing steel.
    Steel,
}

impl MaterialKind {
    pub fn name(self) -> &'static str {
        match self {
            MaterialKind::Solid => "solid",
            MaterialKind::Concrete => "concrete",
            MaterialKind::Steel => "steel",
        }
    }
}

/// Exponents of mass, length and time of a material property.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dimension {
    pub mass: i8,
    pub length: i8,
    pub time: i8,
}

impl Dimension {
    pub const fn new(mass: i8, length: i8, time: i8) -> Self {
        Dimension { mass, length, time }
    }
    /// A plain number: stretches, ratios, and the thermal constants (in the deck's units).
    pub const NUMBER: Dimension = Dimension::new(0, 0, 0);
    pub const LENGTH: Dimension = Dimension::new(0, 1, 0);
    pub const DENSITY: Dimension = Dimension::new(1, -3, 0);
    pub const STRESS: Dimension = Dimension::new(1, -1, -2);
    pub const ENERGY_PER_AREA: Dimension = Dimension::new(1, 0, -2);
    /// Force per volume² per length (N/m⁶): the bond micromodulus.
    pub const MICROMODULUS: Dimension = Dimension::new(1, -5, -2);
    /// Energy (J): pair-law well depths.
    pub const ENERGY: Dimension = Dimension::new(1, 2, -2);
    /// One over a length (1/m): the Morse width.
    pub const INVERSE_LENGTH: Dimension = Dimension::new(0, -1, 0);
    pub const MASS: Dimension = Dimension::new(1, 0, 0);
}

/// A value as the deck wrote it.
#[derive(Clone, Debug, PartialEq)]
pub enum Written {
    Number(f64),
    /// A quantity with units (`"30 GPa"`), or a word.
    Text(String),
    /// Something else (a table, an array, a boolean): named for the error message.
    Other(&'static str),
}

/// Converts a written value of a given dimension into the deck's unit system. The input
/// layer implements it for its unit systems, so a model never sees a unit.
pub trait Units: fmt::Debug + Send + Sync {
    fn value(&self, written: &Written, dim: Dimension) -> Result<f64, String>;
}

/// Values already in the deck's unit system, given as plain numbers (a material built in
/// code, as the unit tests do); text is refused.
#[derive(Debug)]
pub struct PlainNumbers;

impl Units for PlainNumbers {
    fn value(&self, written: &Written, _dim: Dimension) -> Result<f64, String> {
        match written {
            Written::Number(x) => Ok(*x),
            Written::Text(t) => Err(format!("\"{t}\": only plain numbers here")),
            Written::Other(what) => Err(format!("takes a number, not {what}")),
        }
    }
}

/// Short names a deck may use for a key (`E = "30 GPa"`).
const ALIASES: [(&str, &str); 4] = [
    ("E", "youngs_modulus"),
    ("nu", "poisson_ratio"),
    ("K", "bulk_modulus"),
    ("G0", "fracture_energy"),
];

/// The full name of a key given by its short name (`E` → `youngs_modulus`).
pub fn canonical_key(key: &str) -> &str {
    ALIASES
        .iter()
        .find(|(short, _)| *short == key)
        .map_or(key, |(_, long)| long)
}

/// A material of the deck: its name and place, the two keys every model shares, and every
/// other key as written.
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Its number in the deck (the particles' material index).
    pub index: u16,
    pub kind: MaterialKind,
    pub density: f64,
    /// f'c, for reference values such as f_r = 7.5√f'c (not the physics); any model takes it.
    pub compressive_strength: Option<f64>,
    /// Every other key, aliases resolved, in deck order.
    keys: Vec<(String, Written)>,
    units: &'static dyn Units,
}

impl PartialEq for Material {
    fn eq(&self, o: &Self) -> bool {
        (
            &self.name,
            self.index,
            self.kind,
            self.density,
            self.compressive_strength,
            &self.keys,
        ) == (
            &o.name,
            o.index,
            o.kind,
            o.density,
            o.compressive_strength,
            &o.keys,
        )
    }
}

impl Material {
    /// A material with these keys (aliases resolved; a key given under two names is refused).
    pub fn new(
        name: &str,
        index: u16,
        kind: MaterialKind,
        density: f64,
        keys: Vec<(String, Written)>,
        units: &'static dyn Units,
    ) -> Result<Self, ModelError> {
        let mut m = Material {
            name: name.to_string(),
            index,
            kind,
            density,
            compressive_strength: None,
            keys: Vec::new(),
            units,
        };
        for (k, v) in keys {
            let k = canonical_key(&k).to_string();
            if m.keys.iter().any(|(have, _)| *have == k) {
                return Err(
                    m.key_error(&k, format!("'{k}' is given twice (once by its short name)"))
                );
            }
            m.keys.push((k, v));
        }
        Ok(m)
    }

    /// The keys the deck gave, besides `kind`, `density` and `compressive_strength`.
    pub fn given(&self) -> impl Iterator<Item = &str> {
        self.keys.iter().map(|(k, _)| k.as_str())
    }

    /// An error about this material.
    pub fn error(&self, message: impl Into<String>) -> ModelError {
        ModelError::Material {
            material: self.index,
            key: None,
            message: message.into(),
        }
    }

    /// An error about one of its keys (reported at the key's line).
    pub fn key_error(&self, key: &str, message: impl Into<String>) -> ModelError {
        ModelError::Material {
            material: self.index,
            key: Some(key.to_string()),
            message: message.into(),
        }
    }

    /// Refuses keys the model would silently ignore, naming the first and what it reads.
    pub fn only_uses(&self, used: &[&str], model: &str) -> Result<(), ModelError> {
        match self.given().find(|k| !used.contains(k)) {
            Some(k) => Err(self.key_error(
                k,
                format!(
                    "material '{}': model '{model}' does not use '{k}' (it reads {})",
                    self.name,
                    used.join(", ")
                ),
            )),
            None => Ok(()),
        }
    }

    /// The value of `key` in the deck's unit system, if given; a value of another dimension
    /// is refused, naming the key.
    pub fn quantity(&self, key: &str, dim: Dimension) -> Result<Option<f64>, ModelError> {
        let Some((_, w)) = self.keys.iter().find(|(k, _)| k == key) else {
            return Ok(None);
        };
        self.units
            .value(w, dim)
            .map(Some)
            .map_err(|e| self.key_error(key, format!("material '{}': {key}: {e}", self.name)))
    }

    /// A plain number (stretches, ratios).
    pub fn number(&self, key: &str) -> Result<Option<f64>, ModelError> {
        self.quantity(key, Dimension::NUMBER)
    }

    /// A quantity that must be finite and > 0 when given.
    pub fn positive(&self, key: &str, dim: Dimension) -> Result<Option<f64>, ModelError> {
        self.checked(key, dim, |x| x.is_finite() && x > 0.0, "be > 0")
    }

    /// A quantity that must satisfy `ok` when given ("{key} must {what}").
    pub fn checked(
        &self,
        key: &str,
        dim: Dimension,
        ok: impl Fn(f64) -> bool,
        what: &str,
    ) -> Result<Option<f64>, ModelError> {
        match self.quantity(key, dim)? {
            Some(x) if !ok(x) => Err(self.key_error(
                key,
                format!("material '{}': {key} must {what} (got {x})", self.name),
            )),
            v => Ok(v),
        }
    }

    /// Poisson's ratio, in (−1, ½) when given.
    pub fn poisson_ratio(&self) -> Result<Option<f64>, ModelError> {
        self.checked(
            "poisson_ratio",
            Dimension::NUMBER,
            |nu| nu > -1.0 && nu < 0.5,
            "lie in (-1, 0.5)",
        )
    }

    /// A value the model cannot do without.
    pub fn require(&self, value: Option<f64>, key: &str, model: &str) -> Result<f64, ModelError> {
        value.ok_or_else(|| {
            self.error(format!(
                "material '{}' needs '{key}' for model '{model}'",
                self.name
            ))
        })
    }

    /// A quantity the model cannot do without, > 0.
    pub fn required(&self, key: &str, dim: Dimension, model: &str) -> Result<f64, ModelError> {
        let value = self.positive(key, dim)?;
        self.require(value, key, model)
    }

    /// Exactly one of `keys` (each > 0, of its dimension): its position in `keys` and value.
    /// None given, or several, is refused with `needs` as the remedy.
    pub fn one_of(
        &self,
        keys: &[(&str, Dimension)],
        model: &str,
        needs: &str,
    ) -> Result<(usize, f64), ModelError> {
        let mut found = None;
        for (k, &(key, dim)) in keys.iter().enumerate() {
            if let Some(v) = self.positive(key, dim)? {
                if found.is_some() {
                    let names: Vec<String> = keys.iter().map(|(n, _)| format!("'{n}'")).collect();
                    return Err(self.error(format!(
                        "material '{}': give one of {} for model '{model}', not several",
                        self.name,
                        or_list(&names)
                    )));
                }
                found = Some((k, v));
            }
        }
        found.ok_or_else(|| {
            self.error(format!(
                "material '{}' needs {needs} for model '{model}'",
                self.name
            ))
        })
    }

    /// The critical stretch: `critical_stretch` as given, or from `fracture_energy` G0 by the
    /// model's formula `from_energy(G0)`, or none (∞: the bonds never break); both is an error.
    pub fn critical_stretch_or(
        &self,
        from_energy: impl FnOnce(f64) -> f64,
    ) -> Result<f64, ModelError> {
        Ok(self
            .stretch_or_energy("critical_stretch", from_energy)?
            .unwrap_or(f64::INFINITY))
    }

    /// The stretch under `key`, or the one `from_energy` gives for `fracture_energy`: a law
    /// breaks at one or the other. `None` where neither is given; both are an error.
    pub fn stretch_or_energy(
        &self,
        key: &str,
        from_energy: impl FnOnce(f64) -> f64,
    ) -> Result<Option<f64>, ModelError> {
        let s = self.positive(key, Dimension::NUMBER)?;
        let g0 = self.positive("fracture_energy", Dimension::ENERGY_PER_AREA)?;
        match (s, g0) {
            (Some(_), Some(_)) => Err(self.error(format!(
                "material '{}': give '{key}' or 'fracture_energy', not both",
                self.name
            ))),
            (s, g0) => Ok(s.or_else(|| g0.map(from_energy))),
        }
    }
}

/// "'a', 'b' or 'c'".
fn or_list(names: &[String]) -> String {
    match names {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
    }
}

/// Why a model could not be built from the deck, and where.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelError {
    /// About material number `material`, at `key` when one key is to blame.
    Material {
        material: u16,
        key: Option<String>,
        message: String,
    },
    /// About the model as a whole: an option, the horizon.
    Model(String),
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelError::Material { message, .. } | ModelError::Model(message) => {
                f.write_str(message)
            }
        }
    }
}

impl std::error::Error for ModelError {}

impl From<String> for ModelError {
    fn from(message: String) -> Self {
        ModelError::Model(message)
    }
}

impl From<&str> for ModelError {
    fn from(message: &str) -> Self {
        ModelError::Model(message.to_string())
    }
}

/// The law of every pair of materials, from each material's own law by `combine`: looked up
/// by the material indices of a bond's ends.
#[derive(Clone, Debug, PartialEq)]
pub struct PairTable<L> {
    laws: Vec<L>,
    n: usize,
}

impl<L: Copy> PairTable<L> {
    pub fn new<O>(own: &[O], combine: impl Fn(&O, &O) -> L) -> Self {
        let n = own.len();
        let mut laws = Vec::with_capacity(n * n);
        for a in own {
            for b in own {
                laws.push(combine(a, b));
            }
        }
        PairTable { laws, n }
    }

    #[inline(always)]
    pub fn get(&self, mi: u16, mj: u16) -> L {
        self.laws[mi as usize * self.n + mj as usize]
    }

    /// Every pair's law, row by row.
    pub fn all(&self) -> &[L] {
        &self.laws
    }
}
