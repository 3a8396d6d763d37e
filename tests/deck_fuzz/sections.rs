//! The sections every model shares: geometry and the shapes of regions, boundaries, loads,
//! initial state, thermostat, pair law, bars, output, probes, analyses, layout and solver.

use super::decks::Family;
use super::values::*;
use proptest::prelude::*;

// Shapes and regions (lengths in {u}: the body is about 4 × 4 × 4 spacings)

const BOX: &[Key] = &[
    ("shape", &["\"box\""]),
    (
        "min",
        &["\"0 0 0 {u}\"", "[0, 0, \"0 {u}\"]", "\"1 1 1 {u}\""],
    ),
    (
        "max",
        &[
            "\"4 4 4 {u}\"",
            "\"6 4 3 {u}\"",
            "\"3 3 8 {u}\"",
            "\"10 10 10 {u}\"",
            "\"12 12 12 {u}\"",
        ],
    ),
];
const SPHERE: &[Key] = &[
    ("shape", &["\"sphere\""]),
    ("center", &["\"2 2 2 {u}\"", "[2, 2, \"2 {u}\"]"]),
    ("radius", &["\"1.5 {u}\"", "\"2 {u}\""]),
];
const CYLINDER: &[Key] = &[
    ("shape", &["\"cylinder\""]),
    ("base", &["\"2 2 0 {u}\""]),
    ("axis", &["\"z\"", "[0, 0, 1]", "[1, 1, 0]"]),
    ("length", &["\"4 {u}\""]),
    ("radius", &["\"1.5 {u}\""]),
];
const PRISM: &[Key] = &[
    ("shape", &["\"prism\""]),
    ("axis", &["\"z\"", "\"y\"", "\"x\""]),
    (
        "polygon",
        &["[[\"0 {u}\", \"0 {u}\"], [\"4 {u}\", \"0 {u}\"], [\"0 {u}\", \"4 {u}\"]]"],
    ),
    ("from", &["\"0 {u}\""]),
    ("to", &["\"4 {u}\""]),
];
const SLAB: &[Key] = &[
    ("shape", &["\"slab\""]),
    ("axis", &["\"x\"", "\"z\""]),
    ("from", &["\"0 {u}\"", "\"-1 {u}\""]),
    ("to", &["\"1 {u}\"", "\"2 {u}\""]),
];

/// The keys of one shape: a box, usually, when `bounded`; any of the five otherwise.
fn shape(bounded: bool, noise: u32) -> Vec<S<Lines>> {
    let of = |ks: &[Key]| keys(ks, &[], noise);
    let mut shapes: Vec<Vec<S<Lines>>> =
        vec![of(BOX), of(BOX), of(SPHERE), of(CYLINDER), of(PRISM)];
    if !bounded {
        shapes.push(of(SLAB));
        shapes.push(of(SLAB));
    }
    vec![one_of(shapes)]
}

fn region(noise: u32) -> S<Lines> {
    let all = keys(&[("shape", &["\"all\""])], &[], noise);
    let ids = keys(&[("ids", &["[0]", "[0, 1, 2]"])], &[], noise);
    let r = prop_oneof![4 => inline(shape(false, noise)), 1 => inline(all), 1 => inline(ids)];
    r.prop_map(|r| vec![format!("region = {r}")]).boxed()
}

pub(crate) fn geometry(noise: u32) -> S<Lines> {
    let rock = ("material", &["\"rock\""][..]);
    let first = table(
        "[[geometry]]",
        [keys(&[rock], &[], noise), keys(BOX, &[], noise)].concat(),
    );
    let add = keys(&[rock], &[("op", &["\"add\""])], noise);
    let add = table("[[geometry]]", [add, shape(true, noise)].concat());
    let subtract = keys(&[("op", &["\"subtract\""])], &[], noise);
    let subtract = table("[[geometry]]", [subtract, shape(false, noise)].concat());
    (first, array(vec![add, subtract], 2))
        .prop_map(|(a, b)| [a, b].concat())
        .boxed()
}

// ---------------------------------------------------------------------------------------
// Sections shared by every model

const HISTORY: Key = (
    "history",
    &[
        "{ ramp = \"1 {t}\" }",
        "{ table = [[0, 0], [\"1 {t}\", 1]] }",
    ],
);
const COMPONENTS: Key = ("components", &["[\"x\"]", "[\"all\"]", "[\"x\", \"z\"]"]);

pub(crate) fn boundary(name: Key, f: &Family, noise: u32) -> S<Lines> {
    const FIXED: &[&str] = &["[\"all\"]", "[\"x\", \"z\"]", "[\"rotation\", \"all\"]"];
    let fixed = if f.rotation { FIXED } else { &FIXED[..2] };
    let mut motions = vec![
        keys(&[("fixed", fixed)], &[], noise),
        keys(
            &[("velocity", &["\"0 0 1 {v}\"", "[0, 0, \"1 {v}\"]"])],
            &[COMPONENTS],
            noise,
        ),
        keys(
            &[("displacement", &["\"0 0 0.01 {u}\""])],
            &[COMPONENTS],
            noise,
        ),
    ];
    if f.temperature {
        motions.push(keys(&[("temperature", &["300", "1"])], &[], noise));
        motions.push(keys(&[("fixed", &["[\"temperature\"]"])], &[], noise));
    }
    let mut parts = keys(&[name], &[HISTORY], noise);
    parts.push(region(noise));
    parts.push(one_of(motions));
    table("[[boundary]]", parts)
}

pub(crate) fn load(name: Key, f: &Family, noise: u32) -> S<Lines> {
    let mut kinds = vec![
        ("force_per_particle", &["\"0 0 -1 {f}\""][..]),
        (
            "total_force",
            &["\"0 0 -10 {f}\"", "[0, 0, \"-1 {f}\"]"][..],
        ),
        ("body_force", &["\"0 0 -1 {b}\""][..]),
        ("gravity", &["\"0 0 -9.81 {g}\""][..]),
    ];
    if f.temperature {
        kinds.extend([
            ("heat_flux", &["1"][..]),
            ("heat_source", &["1"]),
            ("total_heat", &["1"]),
        ]);
    }
    let kinds = kinds.into_iter().map(|k| keys(&[k], &[], noise)).collect();
    let mut parts = keys(&[name], &[HISTORY], noise);
    parts.push(maybe(region(noise), 2));
    parts.push(one_of(kinds));
    table("[[load]]", parts)
}

pub(crate) fn initial(f: &Family, noise: u32) -> S<Lines> {
    let mut opts = vec![];
    if f.rotation {
        opts.push(("angular_velocity", &["\"0 0 1 {w}\""][..]));
    }
    if f.temperature {
        opts.push(("temperature", &["300"][..]));
    }
    let mut parts = keys(&[("velocity", &["\"0 0 1 {v}\""])], &opts, noise);
    parts.push(maybe(region(noise), 2));
    table("[[initial]]", parts)
}

pub(crate) fn velocity(noise: u32) -> S<Lines> {
    let need = [
        ("temperature", &["1", "300", "0"][..]),
        ("seed", &["1", "87287"][..]),
    ];
    let mut parts = keys(&need, &[], noise);
    parts.push(maybe(region(noise), 3));
    table("[velocity]", parts)
}

pub(crate) fn thermostat(noise: u32) -> S<Lines> {
    let kinds: [&[Key]; 4] = [
        &[("kind", &["\"rescale\""]), ("every", &["1", "10"])],
        &[("kind", &["\"berendsen\""]), ("damping", &["\"1 {t}\""])],
        &[
            ("kind", &["\"langevin\""]),
            ("damping", &["\"1 {t}\""]),
            ("seed", &["24"]),
        ],
        &[("kind", &["\"nose-hoover\""]), ("damping", &["\"1 {t}\""])],
    ];
    let kinds = kinds.iter().map(|k| keys(k, &[], noise)).collect();
    let opts = [("materials", &["[\"rock\"]"][..])];
    let mut parts = keys(&[("temperature", &["1", "1.5"])], &opts, noise);
    parts.push(one_of(kinds));
    parts.push(maybe(region(noise), 4));
    table("[thermostat]", parts)
}

pub(crate) fn pair(noise: u32) -> S<Lines> {
    let opts = [
        ("skin", &["\"0.3 {u}\""][..]),
        ("mixing", &["\"geometric\"", "\"arithmetic\""][..]),
        ("exclude", &["\"bonded\"", "\"none\""][..]),
    ];
    let lj_keys = [
        ("epsilon", &["\"1 {e}\""][..]),
        ("sigma", &["\"1 {u}\""][..]),
    ];
    let morse_keys = [
        ("well_depth", &["\"1 {e}\""][..]),
        ("alpha", &["\"2 {i}\""][..]),
        ("r0", &["\"1 {u}\""][..]),
    ];
    let cut = [
        ("cutoff", &["\"2.5 {u}\"", "\"1.5 {u}\""][..]),
        ("shift", &["true", "false"]),
    ];
    let law = |name: &'static [&'static str], more: &[Key]| {
        vec![table(
            "[pair]",
            keys(&[("law", name)], &[&opts[..], more].concat(), noise),
        )]
    };
    let lj = law(&["\"lj\""], &cut);
    let lj_tables = table("[pair.materials.rock]", keys(&lj_keys, &[], noise));
    let between = [("materials", &["[\"rock\", \"rock\"]"][..]), lj_keys[0]];
    let between = maybe(table("[[pair.between]]", keys(&between, &[], noise)), 5);
    let morse = table("[pair.materials.rock]", keys(&morse_keys, &[], noise));
    let contact = [
        ("contact_distance", &["\"0.9 {u}\""][..]),
        ("stiffness_factor", &["15"]),
    ];
    let contact = maybe(
        table("[pair.materials.rock]", keys(&[], &contact, noise)),
        3,
    );
    one_of(vec![
        [lj, vec![lj_tables.clone(), between]].concat(),
        [law(&["\"wca\""], &[]), vec![lj_tables]].concat(),
        [law(&["\"morse\""], &cut), vec![morse]].concat(),
        [law(&["\"contact\""], &[]), vec![contact]].concat(),
        law(&["\"none\""], &[]),
    ])
}

pub(crate) fn deform(noise: u32) -> S<Lines> {
    let need = [(
        "strain_rate",
        &["[0.004, 0.004, 0.004]", "[0.01, 0, 0]"][..],
    )];
    table("[deform]", keys(&need, &[("every", &["1", "10"])], noise))
}

pub(crate) fn bar(f: &Family, noise: u32) -> S<Lines> {
    let steel: &'static [&'static str] = match f.materials.len() {
        1 => &["\"rock\""],
        _ => &["\"steel\""],
    };
    let need = [
        ("material", steel),
        ("area", &["\"0.5 {a}\""][..]),
        ("from", &["\"0.5 2 2 {u}\""][..]),
    ];
    let ends: [&[Key]; 3] = [
        &[("to", &["\"3.5 2 2 {u}\""])],
        &[
            ("direction", &["[1, 0, 0]", "[1, 1, 1]"]),
            ("length", &["\"3 {u}\""]),
        ],
        &[
            ("azimuth", &["30"]),
            ("elevation", &["10"]),
            ("length", &["\"3 {u}\""]),
        ],
    ];
    let transfer = [("transfer_length", &["\"1 {u}\""][..])];
    let prestrain = [
        keys(&[("prestrain", &["0.001", "-0.001"])], &transfer, noise),
        keys(&[("prestress", &["\"100 {s}\""])], &transfer, noise),
    ];
    let mut parts = keys(&need, &[("spacing", &["\"0.5 {u}\"", "\"1 {u}\""])], noise);
    parts.push(one_of(ends.iter().map(|k| keys(k, &[], noise)).collect()));
    parts.push(maybe(one_of(prestrain.to_vec()), 3));
    table("[[bar]]", parts)
}

pub(crate) fn output(noise: u32) -> S<Lines> {
    let opts = [
        ("history_every", &["1", "10"][..]),
        ("frames_every", &["0", "5"][..]),
        ("progress", &["false"][..]),
        ("final_state", &["true"][..]),
        ("checkpoint_every", &["0", "100"][..]),
        ("checkpoint_minutes", &["0.5"][..]),
        ("checkpoint_keep", &["1", "3"][..]),
        ("restart", &["\"/nonexistent/pdq_fuzz\""][..]),
        ("picture", &["\"damage\"", "\"none\"", "\"height\""][..]),
    ];
    let dir = [("directory", &["\"/tmp/pdq_deck_fuzz_out\""][..])];
    table("[output]", keys(&dir, &opts, noise))
}

pub(crate) fn probe(name: Key, noise: u32) -> S<Lines> {
    let need = [name, ("at", &["\"4 2 2 {u}\"", "[1, 1, 1]"][..])];
    table(
        "[[probe]]",
        keys(&need, &[("stop_beyond", &["\"1 {u}\""])], noise),
    )
}

pub(crate) fn analysis(bonded: bool, noise: u32) -> S<Lines> {
    let kinds: &'static [&'static str] = if bonded {
        &["\"voids\"", "\"cracks\""]
    } else {
        &["\"voids\""]
    };
    let need = [("kind", kinds), ("every", &["1", "250"][..])];
    let opts = [
        ("name", &["\"holes\""][..]),
        ("voxel", &["\"1 {u}\""][..]),
        ("connectivity", &["\"face\"", "\"all\""][..]),
        (
            "scheme",
            &["\"boundary\"", "\"min-label\"", "\"gather\""][..],
        ),
    ];
    table("[[analysis]]", keys(&need, &opts, noise))
}

pub(crate) fn parallel(noise: u32) -> S<Lines> {
    let opts = [
        ("walls", &["\"whole\"", "\"trimmed\""][..]),
        ("shuffle_every", &["0", "10"][..]),
    ];
    let layout: [&[Key]; 3] = [
        &[("procs", &["\"auto\""]), ("threads", &["1", "2"])],
        &[("procs", &["[1, 1, 1]", "[2, 1, 1]", "[1, 1, 2]"])],
        &[("threads", &["1", "2"])],
    ];
    let cells: [&[Key]; 2] = [
        &[("skin", &["0.25", "0"])],
        &[("cell_factor", &["1.5", "1"])],
    ];
    let mut parts = keys(&[], &opts, noise);
    parts.push(maybe(
        one_of(layout.iter().map(|k| keys(k, &[], noise)).collect()),
        2,
    ));
    parts.push(maybe(
        one_of(cells.iter().map(|k| keys(k, &[], noise)).collect()),
        3,
    ));
    table("[parallel]", parts)
}

pub(crate) fn solver(noise: u32) -> S<Lines> {
    let opts = [
        ("load_steps", &["1", "2"][..]),
        ("tolerance", &["1e-4"][..]),
        ("max_iterations", &["10"][..]),
    ];
    let kinds = vec![
        keys(&[("kind", &["\"explicit\""])], &[], noise),
        keys(&[("kind", &["\"adr\"", "\"implicit\""])], &opts, noise),
    ];
    table("[solver]", vec![one_of(kinds)])
}

pub(crate) fn unknown(noise: u32) -> S<Lines> {
    let junk = [("colour", &["\"red\"", "1"][..])];
    prop_oneof![
        table("[nonsense]", keys(&junk, &[], noise)),
        table("[model.extra]", keys(&junk, &[], noise)),
        table("[validation]", keys(&junk, &[], noise)),
        group(keys(&junk, &[], noise)),
    ]
    .boxed()
}
