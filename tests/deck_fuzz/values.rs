//! Values and keys of the deck grammar (docs/deck.md) as proptest strategies. A value is one of
//! its key's good values or, with `noise`, now and then an edge value (0, negative, `nan`,
//! `inf`, 1e308, empty strings and arrays, wrong types, quantities with malformed or wrong
//! units); a key is sometimes missing, given twice or misspelt. Good values write their units
//! as placeholders (`"4 {u}"`), which a dimensional deck fills in and an lj deck drops.

use proptest::prelude::*;
use proptest::sample::select;
use proptest::strategy::Union;

pub(crate) type S<T> = BoxedStrategy<T>;
pub(crate) type Lines = Vec<String>;
/// A key and its good values.
pub(crate) type Key = (&'static str, &'static [&'static str]);

/// Placeholders in good values: the unit a dimensional deck writes (an lj deck writes none).
const UNITS: [(&str, &str); 13] = [
    ("{u}", "mm"),
    ("{t}", "us"),
    ("{v}", "m/s"),
    ("{f}", "N"),
    ("{p}", "GPa"),
    ("{d}", "kg/m^3"),
    ("{a}", "mm^2"),
    ("{g}", "m/s^2"),
    ("{e}", "J"),
    ("{b}", "N/m^3"),
    ("{s}", "MPa"),
    ("{i}", "mm^-1"),
    ("{w}", "s^-1"),
];

pub(crate) fn localize(text: &str, lj: bool) -> String {
    UNITS.iter().fold(text.to_string(), |t, (k, unit)| {
        let with = if lj {
            String::new()
        } else {
            format!(" {unit}")
        };
        t.replace(&format!(" {k}"), &with)
    })
}

pub(crate) const EDGE_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "-0.0",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "+inf",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e-308",
    "5e-324",
    "9223372036854775807",
    "-9223372036854775808",
    "0.5",
    "0.4999999",
    "1",
    "2",
    "1000000",
    "1e12",
    "1e19",
    "4294967296",
    "100000000000",
    "65536",
    "3.5",
    "-2.5e-3",
];

pub(crate) const EDGE_STRINGS: &[&str] = &[
    "\"\"",
    "\" \"",
    "\"0.2 mm\"",
    "\"0.2mm\"",
    "\"0.2 parsec\"",
    "\"mm\"",
    "\"0.2 mm mm\"",
    "\"1 2 3\"",
    "\"1 2 3 mm\"",
    "\"1 2 mm\"",
    "\"1 2 3 4 mm\"",
    "\"nan mm\"",
    "\"inf m\"",
    "\"-inf s\"",
    "\"1e308 km\"",
    "\"1e-320 um\"",
    "\"1 m^127\"",
    "\"1 m^-128\"",
    "\"1 m^300\"",
    "\"1 m^127*m^127\"",
    "\"1 kg*m^-3/\"",
    "\"1 /m\"",
    "\"1 m/\"",
    "\"1 m^\"",
    "\"1 **2\"",
    "\"1 ·\"",
    "\"1 µm\"",
    "\"3in\"",
    "\"--1 mm\"",
    "\"1e999 mm\"",
    "\"0x10 mm\"",
    "\"1_000 mm\"",
    "\"14.9 Gpa\"",
    "\"14.9 GPa\"",
    "\"2200 kg/m^3\"",
    "\"0 0 -9.81 m/s^2\"",
    "\"1 N/m^6\"",
    "\"x\"",
    "\"all\"",
    "\"auto\"",
    "\"é\"",
    "\"\\u0000\"",
    "\"1 m**2\"",
    "\"1 s^-1\"",
    "\"1 2 3 m/s\"",
    "\"1 1 1 kg\"",
    "\"nan nan nan\"",
    "\"1e308 1e308 1e308 km\"",
    "\"1 ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft*ft\"",
    "\"0 s\"",
    "\"1e-300 1e-300 1e-300 km\"",
    "\"1 2 3 in^-1\"",
];

pub(crate) const WRONG_TYPES: &[&str] = &[
    "true",
    "false",
    "[]",
    "[1]",
    "[1, 2]",
    "[1, 2, 3]",
    "[1, 2, 3, 4]",
    "[\"x\", \"y\"]",
    "[\"x\", 1]",
    "[[1, 2], [3]]",
    "[[]]",
    "{}",
    "{ a = 1 }",
    "1979-05-27T07:32:00Z",
    "07:32:00",
    "'''two\nlines'''",
    "\"\"\"\"\"\"",
    "[nan, inf, -inf]",
    "[1e308, 1e308, 1e308]",
    "{ ramp = 0 }",
    "{ table = [] }",
    "{ table = [[1, 0], [0, 1]] }",
    "{ table = [[0, nan]] }",
    "{ ramp = 1, table = [[0, 0]] }",
    "{ shape = \"all\", min = 1 }",
    "{ ids = [] }",
    "{ ids = [4294967295] }",
    "{ shape = \"slab\", axis = \"w\", from = 0, to = 1 }",
    "[[0, 0], [1, 0]]",
    "[[0, 0], [1, 1], [2, 2]]",
    "[-1, 1, 1]",
    "[0, 0, 0]",
    "[4294967296, 4294967296, 1]",
    "[9223372036854775807, 2, 1]",
];

pub(crate) fn pick(xs: &'static [&'static str]) -> S<String> {
    select(xs).prop_map(String::from).boxed()
}

/// A float written as TOML writes it.
fn toml_float(x: f64) -> String {
    match x {
        _ if x.is_nan() => "nan".into(),
        f64::INFINITY => "inf".into(),
        f64::NEG_INFINITY => "-inf".into(),
        _ => format!("{x:?}"),
    }
}

pub(crate) fn random_value() -> S<String> {
    let units = &["mm", "GPa", "s", "kg/m^3", "m/s", "N", "furlong", "m^-1"];
    prop_oneof![
        any::<f64>().prop_map(toml_float),
        any::<i64>().prop_map(|i| i.to_string()),
        (any::<f64>(), pick(units)).prop_map(|(x, u)| format!("\"{x} {u}\"")),
        "[a-z0-9 .^*/-]{0,12}".prop_map(|s| format!("\"{s}\"")),
    ]
    .boxed()
}

/// A value of a key whose good values are `good`: with `noise`, sometimes a bad one.
pub(crate) fn value(good: &'static [&'static str], noise: u32) -> S<String> {
    if noise == 0 {
        return pick(good);
    }
    prop_oneof![
        40 => pick(good),
        noise => pick(EDGE_NUMBERS),
        noise => pick(EDGE_STRINGS),
        noise => pick(WRONG_TYPES),
        noise => random_value(),
    ]
    .boxed()
}

/// The lines of a key: `name = value`; with `noise`, sometimes missing, repeated or misspelt.
pub(crate) fn key((name, good): Key, noise: u32) -> S<Lines> {
    let v = value(good, noise);
    let one = v.clone().prop_map(move |v| vec![format!("{name} = {v}")]);
    if noise == 0 {
        return one.boxed();
    }
    prop_oneof![
        60 => one,
        noise => Just(Vec::new()),
        noise => (v.clone(), v.clone())
            .prop_map(move |(a, b)| vec![format!("{name} = {a}"), format!("{name} = {b}")]),
        noise => v.prop_map(move |v| vec![format!("{name}s = {v}")]),
    ]
    .boxed()
}

/// One in `n` times `s`, else nothing.
pub(crate) fn maybe(s: S<Lines>, n: u32) -> S<Lines> {
    prop_oneof![n - 1 => Just(Vec::new()), 1 => s].boxed()
}

/// The required keys, and each optional one in one deck of four.
pub(crate) fn keys(required: &[Key], optional: &[Key], noise: u32) -> Vec<S<Lines>> {
    let mut all: Vec<S<Lines>> = required.iter().map(|k| key(*k, noise)).collect();
    all.extend(optional.iter().map(|k| maybe(key(*k, noise), 4)));
    all
}

/// The lines of all `parts`, in order.
pub(crate) fn group(parts: Vec<S<Lines>>) -> S<Lines> {
    parts.prop_map(|ps| ps.concat()).boxed()
}

/// The keys of one of `choices`.
pub(crate) fn one_of(choices: Vec<Vec<S<Lines>>>) -> S<Lines> {
    Union::new(choices.into_iter().map(group)).boxed()
}

/// A `[header]` and its keys' lines.
pub(crate) fn table(header: &'static str, parts: Vec<S<Lines>>) -> S<Lines> {
    group(parts)
        .prop_map(move |lines| [vec![header.to_string()], lines].concat())
        .boxed()
}

/// The keys as an inline table, `{ k = v, ... }`.
pub(crate) fn inline(parts: Vec<S<Lines>>) -> S<String> {
    group(parts)
        .prop_map(|ps| format!("{{ {} }}", ps.join(", ")))
        .boxed()
}

/// Up to `max` entries of an array of tables, each from one of `entries`.
/// Each of `entries` one time in `n`, in order (their names differ).
pub(crate) fn each(entries: Vec<S<Lines>>, n: u32) -> S<Lines> {
    group(entries.into_iter().map(|e| maybe(e, n)).collect())
}

pub(crate) fn array(entries: Vec<S<Lines>>, max: usize) -> S<Lines> {
    let one = Union::new(entries);
    prop::collection::vec(one, 0..=max)
        .prop_map(|es| es.concat())
        .boxed()
}
