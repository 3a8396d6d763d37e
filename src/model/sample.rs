//! What a model says about itself for scenes written in code: the benchmark of `pdq bench`, the
//! blocks of `pdq stress` and the tests' decks. Each model writes its own sample material in
//! its own keys ([`crate::model::Model::sample`]), so the tools that build those scenes iterate
//! the registry and never name a model.

/// The scene a model is asked a sample material for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleOf {
    /// The solid of the benchmark scene (`pdq bench`, `shared/bench`): as stiff as a bond-based
    /// solid of micromodulus `micromodulus` at horizon `horizon` (bulk modulus K = πδ⁴c/18), its
    /// bonds breaking at `critical_stretch`, of `density`. The given numbers are written as
    /// they are (`{}`: `0.0005`), moduli derived from them in exponent form (`{:e}`), with δ⁴
    /// as `horizon.powf(4.0)`: correctly rounded in every build, where `powi`'s products
    /// differ in the last bit from the value an optimized build folds a constant `powi` to.
    /// A model with a LAMMPS peer of other constants gives the peer's, so both run the same
    /// scene.
    Benchmark {
        micromodulus: f64,
        horizon: f64,
        critical_stretch: f64,
        density: f64,
    },
    /// A solid of Young's modulus `youngs_modulus` and `density` whose bonds break at
    /// `critical_stretch` (∞: never, and the key is left out), numbers in exponent form.
    /// `steel`: the steel of a steel–concrete mix (a model without a steel kind gives its
    /// solid). `full`: the model's optional terms switched on (thermal expansion, micropolar's
    /// relative-rotation stiffness, LPS's dilatation term at ν ≠ ¼), for tests that exercise all of its data; without them
    /// the plain law, whose mechanical energy is conserved on its own (`pdq stress`).
    Solid {
        youngs_modulus: f64,
        density: f64,
        critical_stretch: f64,
        steel: bool,
        full: bool,
    },
}

/// A model's sample material: the lines of a deck it needs, and what the scene must know.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sample {
    /// The lines of its `[materials.NAME]` table, `key = value` each.
    pub material: String,
    /// The lines of the `[model.options]` table it needs (empty: none).
    pub options: String,
    /// A fixed time step for the scene, when the model's stable step is shorter than the one
    /// the scene takes for the others (micropolar's rotations on the benchmark scene).
    pub dt: Option<f64>,
    /// The registered model whose mechanics this sample repeats (thermal without expansion
    /// is PMB plus conduction): the sudden-failure table of `pdq stress` leaves it out.
    pub mechanics_of: Option<&'static str>,
}

impl Sample {
    /// A sample of these material lines, with no options.
    pub fn new(material: String) -> Self {
        Sample {
            material,
            ..Sample::default()
        }
    }

    /// With these `[model.options]` lines.
    pub fn with_options(self, options: &str) -> Self {
        Sample {
            options: options.to_string(),
            ..self
        }
    }

    /// With a fixed time step of its own.
    pub fn with_dt(self, dt: f64) -> Self {
        Sample {
            dt: Some(dt),
            ..self
        }
    }

    /// Whose mechanics are those of model `name`.
    pub fn mechanics_of(self, name: &'static str) -> Self {
        Sample {
            mechanics_of: Some(name),
            ..self
        }
    }
}

/// The line `key = s0` (exponent form), or nothing when s0 is ∞ (the bonds never break).
pub fn stretch_line(key: &str, s0: f64) -> String {
    if s0.is_finite() {
        format!("{key} = {s0:e}\n")
    } else {
        String::new()
    }
}
