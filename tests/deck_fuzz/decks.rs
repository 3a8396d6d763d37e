//! Decks of every model: what each needs (`FAMILIES`), the sections every deck has and the
//! ones it may have, and the deck's text with its units written in. With `noise`, sections go
//! missing, repeat or come in another order.

use super::sections::*;
use super::values::*;
use proptest::prelude::*;
use proptest::sample::Index;
use proptest::strategy::Union;

/// What a deck of one model needs, with good values; the other sections are shared.
pub(crate) struct Family {
    lj: bool,
    units: &'static [&'static str],
    /// `[model]`: the name (and a bondless model's keys); a bonded one also gets a horizon.
    model: &'static [Key],
    pub(crate) bonded: bool,
    options: &'static [Key],
    /// `[lattice]`: the spacing or density.
    lattice: &'static [Key],
    pub(crate) materials: &'static [(&'static str, &'static [Key])],
    /// `[time]`: how long (a bondless model also gives dt).
    time: &'static [Key],
    /// The model has rotations (micropolar) or a temperature (thermal).
    pub(crate) rotation: bool,
    pub(crate) temperature: bool,
    /// One deck in `md` has `[pair]`; `[velocity]`, `[thermostat]` and `[deform]` come at
    /// multiples of it.
    md: u32,
}

const SI: &[&str] = &[
    "\"SI\"",
    "\"mm-N-s\"",
    "\"in-lbf-s\"",
    "\"si\"",
    "\"US\"",
    "\"inch\"",
];
const SPACING: Key = ("spacing", &["\"1 {u}\"", "\"1.5 {u}\""]);
const DENSITY: Key = ("density", &["\"2200 {d}\""]);
const STRETCH: Key = ("critical_stretch", &["0.0005", "0.01"]);
const STEPS: &[Key] = &[("steps", &["1", "3", "5"])];
const MD_TIME: &[Key] = &[("dt", &["0.005", "\"0.005 {t}\""]), ("steps", &["2", "5"])];
const ROCK: &str = "[materials.rock]";

/// A bonded solid in a dimensional deck; the families below change what differs.
const SOLID: Family = Family {
    lj: false,
    units: SI,
    model: &[("name", &["\"pmb\""])],
    bonded: true,
    options: &[],
    lattice: &[SPACING],
    materials: &[(
        ROCK,
        &[DENSITY, ("bulk_modulus", &["\"14.9 {p}\""]), STRETCH],
    )],
    time: STEPS,
    rotation: false,
    temperature: false,
    md: 8,
};

/// Particles of a bondless model or springs, in lj units, with a pair law.
const MD: Family = Family {
    lj: true,
    units: &["\"lj\""],
    model: &[("name", &["\"point\""])],
    bonded: false,
    lattice: &[
        ("kind", &["\"fcc\"", "\"bcc\"", "\"sc\""]),
        ("density", &["0.8", "0.8442"]),
    ],
    materials: &[(ROCK, &[("density", &["0.8"])])],
    time: MD_TIME,
    md: 1,
    ..SOLID
};

const CONCRETE: &[Key] = &[
    ("kind", &["\"concrete\""]),
    DENSITY,
    ("youngs_modulus", &["\"30 {p}\""]),
    ("poisson_ratio", &["0.25"]),
    ("tensile_stretch", &["1.4e-4"]),
    ("compressive_stretch", &["-1.1e-3"]),
    ("fc", &["\"30 {s}\""]),
];
const STEEL: &[Key] = &[
    ("kind", &["\"steel\""]),
    ("density", &["\"7850 {d}\""]),
    ("youngs_modulus", &["\"200 {p}\""]),
    ("poisson_ratio", &["0.25"]),
    ("yield_stretch", &["0.002"]),
    ("failure_stretch", &["0.01"]),
];
const THERMAL: &[Key] = &[
    DENSITY,
    ("bulk_modulus", &["\"14.9 {p}\""]),
    STRETCH,
    ("thermal_conductivity", &["1", "50"]),
    ("specific_heat", &["800"]),
    ("thermal_expansion", &["1e-5", "0"]),
];

const FAMILIES: [Family; 7] = [
    SOLID,
    Family {
        model: &[("name", &["\"lps\""])],
        options: &[(
            "influence",
            &["\"one\"", "\"inverse_length\"", "\"gaussian\""],
        )],
        materials: &[(
            ROCK,
            &[
                DENSITY,
                ("youngs_modulus", &["\"30 {p}\""]),
                ("poisson_ratio", &["0.2", "0.3"]),
                STRETCH,
            ],
        )],
        ..SOLID
    },
    Family {
        model: &[("name", &["\"micropolar\""])],
        options: &[("kappa", &["0", "0.05"])],
        materials: &[(
            ROCK,
            &[
                DENSITY,
                ("E", &["\"30 {p}\""]),
                ("nu", &["0.2", "0.25"]),
                STRETCH,
            ],
        )],
        rotation: true,
        ..SOLID
    },
    Family {
        model: &[("name", &["\"concrete\""])],
        options: &[("interface_factor", &["3", "1.5"])],
        materials: &[(ROCK, CONCRETE), ("[materials.steel]", STEEL)],
        ..SOLID
    },
    Family {
        model: &[("name", &["\"thermal\""])],
        options: &[("reference_temperature", &["0", "293"])],
        materials: &[(ROCK, THERMAL)],
        temperature: true,
        ..SOLID
    },
    MD,
    Family {
        model: &[("name", &["\"membrane\""]), ("m", &["1.5"])],
        lattice: &[("spacing", &["1", "\"1.2\""])],
        materials: &[(ROCK, &[("density", &["1"]), ("spring_constant", &["300"])])],
        md: 2,
        ..MD
    },
];

const LATTICE_OPT: &[Key] = &[
    ("origin", &["\"0 0 0 {u}\"", "[0, 0, \"0.5 {u}\"]"]),
    ("periodic", &["[\"x\"]", "[\"x\", \"y\", \"z\"]", "[]"]),
    ("jitter", &["0.1", "0"]),
    ("seed", &["7"]),
];
const BONDED_OPT: &[Key] = &[
    ("partial_volume", &["true", "false"]),
    ("surface_correction", &["\"none\"", "\"energy\""]),
];
const TIME_OPT: &[Key] = &[
    ("integrator", &["\"verlet\"", "\"leapfrog\"", "\"euler\""]),
    ("force_dt", &["false", "true"]),
    ("stop_at_broken_bonds", &["1", "10"]),
];
const STABLE_OPT: &[Key] = &[
    ("safety_factor", &["0.8", "1"]),
    ("critical_step", &["\"bound\"", "\"measured\""]),
    ("static_until", &["\"0.01 {t}\""]),
];

/// `[model]`: the family's keys, a bonded model's horizon as `m` or `horizon`.
fn model(f: &Family, noise: u32) -> S<Lines> {
    if !f.bonded {
        return table("[model]", keys(f.model, &[], noise));
    }
    let mut parts = keys(f.model, BONDED_OPT, noise);
    parts.push(one_of(vec![
        keys(&[("m", &["3", "3.015", "2", "1.5"])], &[], noise),
        keys(&[("horizon", &["\"3.015 {u}\"", "\"2 {u}\""])], &[], noise),
    ]));
    table("[model]", parts)
}

fn lattice(f: &Family, noise: u32) -> S<Lines> {
    let kind = [("kind", &["\"sc\"", "\"fcc\"", "\"bcc\""][..])];
    let kind = if f.lj { &[][..] } else { &kind[..] };
    table(
        "[lattice]",
        keys(f.lattice, &[kind, LATTICE_OPT].concat(), noise),
    )
}

fn time(f: &Family, noise: u32) -> S<Lines> {
    let opts = if f.bonded {
        [TIME_OPT, STABLE_OPT].concat()
    } else {
        TIME_OPT.to_vec()
    };
    let mut parts = keys(&f.time[..f.time.len() - 1], &opts, noise);
    let last = f.time[f.time.len() - 1];
    let duration = ("duration", &["\"1 {t}\"", "\"0.05 {t}\""][..]);
    parts.push(one_of(vec![
        keys(&[last], &[], noise),
        keys(&[duration], &[], noise),
    ]));
    table("[time]", parts)
}

/// `[materials.*]`: the family's tables, and, with noise, sometimes a key of another model.
fn materials(f: &Family, noise: u32) -> S<Lines> {
    let stray = [
        ("micromodulus", &["\"1e20 N/m^6\""][..]),
        ("yield_stretch", &["0.002"]),
    ];
    let tables = f.materials.iter().map(|(header, ks)| {
        let stray = if noise > 0 { &stray[..] } else { &[] };
        table(header, keys(ks, stray, noise))
    });
    group(tables.collect())
}

/// The sections every deck has (with noise, each is sometimes missing).
fn required(f: &Family, noise: u32) -> Vec<S<Lines>> {
    let top = [("units", f.units), ("title", &["\"fuzz\""][..])];
    let options = table("[model.options]", keys(&[], f.options, noise));
    let sections = vec![
        group(keys(&top[..1], &top[1..], noise)),
        model(f, noise),
        maybe(options, if f.options.is_empty() { 20 } else { 3 }),
        lattice(f, noise),
        materials(f, noise),
        geometry(noise),
        time(f, noise),
    ];
    match noise {
        0 => sections,
        _ => sections.into_iter().map(|s| maybe(s, 40)).collect(),
    }
}

/// The optional sections, each present now and then.
fn optional(f: &Family, noise: u32) -> Vec<S<Lines>> {
    let names = [
        ("name", &["\"clamp\""][..]),
        ("name", &["\"grip\"", "\"push\""]),
    ];
    let bounds = names.map(|n| boundary(n, f, noise)).to_vec();
    let loads = [("name", &["\"pull\""][..]), ("name", &["\"weight\""])];
    let loads = loads.map(|n| load(n, f, noise)).to_vec();
    let probes = [("name", &["\"tip\""][..]), ("name", &["\"mid\""])].map(|n| probe(n, noise));
    vec![
        maybe(bar(f, noise), 5),
        each(bounds, 2),
        each(loads, 3),
        maybe(initial(f, noise), 6),
        maybe(velocity(noise), 2 * f.md),
        maybe(output(noise), 4),
        each(probes.to_vec(), 4),
        maybe(analysis(f.bonded, noise), 5),
        maybe(parallel(noise), 5),
        maybe(solver(noise), 6),
        maybe(pair(noise), f.md + 1),
        maybe(thermostat(noise), 2 * f.md),
        maybe(deform(noise), 3 * f.md),
        maybe(unknown(noise), if noise == 0 { 1000 } else { 15 }),
    ]
}

/// The deck's text; with noise, a section now and then repeated or moved to the end.
fn arrange(mut blocks: Vec<Lines>, repeat: Option<Index>, shuffle: Option<Index>) -> String {
    if let Some(i) = repeat {
        let b = i.get(&blocks).clone();
        blocks.push(b);
    }
    if let Some(i) = shuffle {
        let n = blocks.len();
        blocks.swap(i.index(n), n - 1);
    }
    blocks.concat().join("\n") + "\n"
}

/// A deck of family `f`, its units written in.
fn family_deck(f: &'static Family, noise: u32) -> S<String> {
    let sections = [required(f, noise), optional(f, noise)].concat();
    let rare = |n: f64| match noise {
        0 => Just(None).boxed(),
        _ => prop::option::weighted(1.0 / n, any::<Index>()).boxed(),
    };
    (sections, rare(10.0), rare(20.0))
        .prop_map(move |(blocks, r, s)| localize(&arrange(blocks, r, s), f.lj))
        .boxed()
}

/// A deck of any model: clean (`noise` 0, every value good: what fails are the sections'
/// combinations) or noisy.
pub(crate) fn deck(noise: u32) -> S<String> {
    Union::new(FAMILIES.iter().map(|f| family_deck(f, noise))).boxed()
}
