//! Physical quantities in input decks.
//!
//! A deck quantity is either a plain number, taken to be in the deck's unit
//! system, or a string with units such as `"3605 ksi"`. Strings are converted
//! once, at load, so the engine only ever sees numbers in the deck's own system
//! and never carries units through the hot loops. Dimensions are checked at that
//! point because a length typed where a stress belongs is far easier to fix from
//! a load error (toml adds line and column) than from a run that blows up.

use crate::model::{Dimension, Written};
use serde::de::{self, Deserialize, Deserializer, SeqAccess, Visitor};
use std::fmt;
use std::str::FromStr;

/// Pound-force in newtons (exact, from the international pound).
const LBF: f64 = 4.448_221_615_260_5;
const INCH: f64 = 0.0254;
const FOOT: f64 = 0.3048;
/// Standard gravity in in/s² as used in US structural practice. `lb` is a
/// pound-*mass* defined as lbf / g with this g (not the exact 0.45359237 kg), so
/// that "145 lb/ft^3" becomes 145/1728/386.09 lbf·s²/in⁴, the number US concrete
/// engineers already use for density.
const G_IN_S2: f64 = 386.09;
const LB: f64 = LBF / (G_IN_S2 * INCH);
const PSI: f64 = LBF / (INCH * INCH);

/// Exponents of mass, length and time.
///
/// Force-based systems (lbf, N with mm) are still described in M, L, T so that
/// one exponent triple identifies a quantity in every system.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim {
    pub m: i8,
    pub l: i8,
    pub t: i8,
}

const LEN: Dim = Dim::new(0, 1, 0);
const TIME: Dim = Dim::new(0, 0, 1);
const MASS: Dim = Dim::new(1, 0, 0);
const FORCE: Dim = Dim::new(1, 1, -2);
const STRESS: Dim = Dim::new(1, -1, -2);
const ENERGY: Dim = Dim::new(1, 2, -2);

/// Names and a working example for the dimensions decks use; the example is
/// quoted in error messages so the user sees a string that would have worked.
#[rustfmt::skip]
const KNOWN: &[(Dim, &str, &str)] = &[
    (LEN, "length", "3 in"), (Dim::new(0, 2, 0), "area", "2 in^2"),
    (Dim::new(0, 3, 0), "volume", "1 in^3"), (TIME, "time", "1e-6 s"),
    (Dim::new(0, 1, -1), "velocity", "7.87 in/s"), (Dim::new(0, 1, -2), "acceleration", "9.81 m/s^2"),
    (MASS, "mass", "2 kg"), (Dim::new(1, -3, 0), "density", "2400 kg/m^3"),
    (STRESS, "stress", "25 GPa"), (FORCE, "force", "10 kN"),
    (Dim::new(1, -2, -2), "force per volume", "1 lbf/in^3"),
    (Dim::new(1, 0, -2), "energy per area", "1 lbf*in/in^2"),
    (Dim::new(1, -5, -2), "micromodulus", "1e20 N/m^6"), (Dim::new(0, -3, 0), "number density", "8.5e28 m^-3"),
    (Dim::new(0, 0, 0), "dimensionless", "0.5"),
];

impl Dim {
    pub const fn new(m: i8, l: i8, t: i8) -> Self {
        Dim { m, l, t }
    }

    pub fn describe(&self) -> String {
        let exps = [("M", self.m), ("L", self.l), ("T", self.t)]
            .iter()
            .filter(|p| p.1 != 0)
            .map(|p| power(p.0, p.1.into()))
            .collect::<Vec<_>>()
            .join(" ");
        match (self.known(), exps.is_empty()) {
            (_, true) => "dimensionless".to_string(),
            (Some(k), false) => format!("{} ({exps})", k.1),
            (None, false) => exps,
        }
    }

    fn known(&self) -> Option<&'static (Dim, &'static str, &'static str)> {
        KNOWN.iter().find(|k| k.0 == *self)
    }

    /// "a stress (M L^-1 T^-2)", for error messages.
    fn with_article(&self) -> String {
        match self.known() {
            Some(k) if k.1.starts_with(['a', 'e']) => format!("an {}", self.describe()),
            Some(_) => format!("a {}", self.describe()),
            None => format!("a quantity of dimension {}", self.describe()),
        }
    }

    fn example(&self) -> String {
        match self.known() {
            Some(k) => k.2.to_string(),
            None => format!("1 {}", UnitSystem::Si.label(*self)),
        }
    }
}

fn power(name: &str, e: i32) -> String {
    if e == 1 {
        name.to_string()
    } else {
        format!("{name}^{e}")
    }
}

fn mismatch(expected: Dim, text: &str, found: Dim) -> String {
    let (want, ex, got) = (
        expected.with_article(),
        expected.example(),
        found.with_article(),
    );
    format!("expected {want}, e.g. \"{ex}\", but \"{text}\" is {got}")
}

/// Unit system a deck computes in. Each is coherent (force = mass·length/s²), so
/// the engine's formulas need no conversion constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnitSystem {
    Si,
    InchPoundSecond,
    /// mm, N, s; the coherent mass unit is then the tonne (N·s²/mm).
    MmNewtonSecond,
    /// Lennard-Jones reduced units: lengths in σ, energies in ε, masses in m, times in
    /// τ = σ√(m/ε), temperatures in ε/k_B (k_B = 1). They have no fixed size in SI (σ, ε and m
    /// are the substance's), so a deck in them takes plain numbers only: a string with a unit
    /// is refused where the deck is read (`input/deck/plain.rs`, and [`crate::model::Units`]
    /// for material keys).
    Lj,
}

/// Boltzmann's constant in J/K (exact since the 2019 SI).
const BOLTZMANN_SI: f64 = 1.380_649e-23;

impl UnitSystem {
    pub fn from_name(name: &str) -> Result<Self, String> {
        match name.trim() {
            "SI" | "si" | "m-kg-s" => Ok(UnitSystem::Si),
            "in-lbf-s" | "inch" | "US" => Ok(UnitSystem::InchPoundSecond),
            "mm-N-s" => Ok(UnitSystem::MmNewtonSecond),
            "lj" | "LJ" => Ok(UnitSystem::Lj),
            other => Err(format!(
                "unknown unit system \"{other}\"; accepted: \"SI\", \"si\", \"m-kg-s\" \
                 (m, kg, s), \"in-lbf-s\", \"inch\", \"US\" (in, lbf, s), \"mm-N-s\" (mm, N, s), \
                 \"lj\" (Lennard-Jones reduced units: σ, ε, m, τ; plain numbers only)"
            )),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            UnitSystem::Si => "SI",
            UnitSystem::InchPoundSecond => "in-lbf-s",
            UnitSystem::MmNewtonSecond => "mm-N-s",
            UnitSystem::Lj => "lj",
        }
    }

    /// Boltzmann's constant k_B in this system's energy unit per kelvin (per reduced
    /// temperature unit ε/k_B in `lj`, where it is 1 by definition): SI 1.380649e-23 J/K,
    /// in-lbf-s 1.380649e-23 / (4.448… · 0.0254) lbf·in/K, mm-N-s 1.380649e-20 N·mm/K. The
    /// dimensional systems all measure temperature in kelvin; none of them has a unit of its own
    /// for it.
    pub fn boltzmann(&self) -> f64 {
        match self {
            UnitSystem::Lj => 1.0,
            _ => BOLTZMANN_SI / self.si_factor(ENERGY),
        }
    }

    /// (length unit in m, force unit in N, length label, force label). `lj` has none: its
    /// quantities are never converted (plain numbers only); NaN marks the size as unknown.
    fn base(&self) -> (f64, f64, &'static str, &'static str) {
        match self {
            UnitSystem::Si => (1.0, 1.0, "m", "N"),
            UnitSystem::InchPoundSecond => (INCH, LBF, "in", "lbf"),
            UnitSystem::MmNewtonSecond => (1e-3, 1.0, "mm", "N"),
            UnitSystem::Lj => (f64::NAN, f64::NAN, "σ", "ε/σ"),
        }
    }

    /// The mass unit is derived (force·s²/length) rather than chosen, which is
    /// what makes in-lbf-s and mm-N-s coherent. The time unit is always 1 s. In `lj`, where a
    /// unit has no size in SI, every factor is NaN (only a dimensionless one is 1).
    pub fn si_factor(&self, dim: Dim) -> f64 {
        let (len, force, _, _) = self.base();
        (force / len).powi(dim.m.into()) * len.powi(dim.l.into())
    }

    /// Labels are written in the unit grammar (except "1" for dimensionless), so
    /// a label read back with a number parses to this system's unit.
    pub fn label(&self, dim: Dim) -> String {
        use UnitSystem::*;
        if *self == Lj {
            return lj_label(dim);
        }
        let named = match (self, (dim.m, dim.l, dim.t)) {
            (_, (0, 0, 0)) => "1",
            (Si, (1, 0, 0)) => "kg",
            (Si, (1, -3, 0)) => "kg/m^3",
            (Si, (1, -1, -2)) => "Pa",
            (InchPoundSecond, (1, -1, -2)) => "psi",
            (MmNewtonSecond, (1, 0, 0)) => "t",
            (MmNewtonSecond, (1, -3, 0)) => "t/mm^3",
            (MmNewtonSecond, (1, -1, -2)) => "MPa",
            _ => "",
        };
        if !named.is_empty() {
            return named.to_string();
        }
        // M^m L^l T^t = F^m L^(l-m) T^(t+2m), since M = F T^2 / L.
        let (_, _, l, f) = self.base();
        let (dm, dl, dt) = (i32::from(dim.m), i32::from(dim.l), i32::from(dim.t));
        let parts = [(f, dm), (l, dl - dm), ("s", dt + 2 * dm)];
        let num: Vec<String> = parts
            .iter()
            .filter(|p| p.1 > 0)
            .map(|p| power(p.0, p.1))
            .collect();
        let den = parts.iter().filter(|p| p.1 < 0);
        if num.is_empty() {
            // "m^-3", not "1/m^3": the unit grammar reads a name first.
            return den.map(|p| power(p.0, p.1)).collect::<Vec<_>>().join("*");
        }
        let mut out = num.join("*");
        for p in den {
            out += &format!("/{}", power(p.0, -p.1));
        }
        out
    }
}

/// An `lj` unit as m^a σ^b τ^c ("1" for a number): a label to read, not to parse, as lj decks
/// take no units.
fn lj_label(dim: Dim) -> String {
    let parts = [("m", dim.m), ("σ", dim.l), ("τ", dim.t)];
    let used: Vec<String> = parts
        .iter()
        .filter(|p| p.1 != 0)
        .map(|p| power(p.0, p.1.into()))
        .collect();
    if used.is_empty() {
        "1".to_string()
    } else {
        used.join("*")
    }
}

/// Whether a deck string is a quantity written with a unit: one number or three, then a unit
/// expression ("3 mm", "3mm", "1 2 3 in"). A name that happens to start with a digit
/// ("1st_support", "3D block") is not one: what follows its number is no unit.
pub fn written_with_unit(s: &str) -> bool {
    let toks: Vec<&str> = s.split_whitespace().collect();
    let numbers = toks.iter().take_while(|t| t.parse::<f64>().is_ok()).count();
    if numbers > 0 && numbers < toks.len() {
        return parse_unit(&toks[numbers..].join(" "), s).is_ok();
    }
    match split_number(s.trim()) {
        Some((_, rest)) if !rest.trim().is_empty() => parse_unit(rest.trim(), s).is_ok(),
        _ => false,
    }
}

/// Unit name, size in SI, dimension. Case-sensitive; `g` is the gram and `t` the
/// tonne, `lb`/`lbm` the pound-mass (see [`G_IN_S2`]), `lbf` the pound-force.
#[rustfmt::skip]
const UNITS: &[(&str, f64, Dim)] = &[
    ("m", 1.0, LEN), ("cm", 0.01, LEN), ("mm", 1e-3, LEN), ("um", 1e-6, LEN), ("km", 1e3, LEN),
    ("in", INCH, LEN), ("ft", FOOT, LEN), ("yd", 3.0 * FOOT, LEN),
    ("s", 1.0, TIME), ("ms", 1e-3, TIME), ("us", 1e-6, TIME), ("min", 60.0, TIME), ("h", 3600.0, TIME),
    ("kg", 1.0, MASS), ("g", 1e-3, MASS), ("t", 1e3, MASS),
    ("lb", LB, MASS), ("lbm", LB, MASS), ("slug", LBF / FOOT, MASS),
    ("N", 1.0, FORCE), ("kN", 1e3, FORCE), ("MN", 1e6, FORCE),
    ("lbf", LBF, FORCE), ("kip", 1e3 * LBF, FORCE), ("kips", 1e3 * LBF, FORCE),
    ("Pa", 1.0, STRESS), ("kPa", 1e3, STRESS), ("MPa", 1e6, STRESS), ("GPa", 1e9, STRESS),
    ("psi", PSI, STRESS), ("ksi", 1e3 * PSI, STRESS), ("psf", LBF / (FOOT * FOOT), STRESS),
    ("J", 1.0, ENERGY), ("kJ", 1e3, ENERGY),
];

/// Parse "<number> <unit expression>" into (value in SI, dimension).
pub fn parse_quantity(text: &str) -> Result<(f64, Dim), String> {
    parse_parts(text, None).map(|(num, factor, dim)| (num * factor, dim))
}

/// (number, SI size of its unit, dimension), kept apart so [`Quantity`] can
/// convert without a round trip through SI. A text that is not a number and a unit is told
/// what is expected, with `example` if one is given.
fn parse_parts(text: &str, example: Option<&str>) -> Result<(f64, f64, Dim), String> {
    let ex = match example {
        Some(e) => format!("expected a number followed by a unit, e.g. \"{e}\""),
        None => "expected a number followed by a unit".to_string(),
    };
    let (num, rest) = split_number(text.trim())
        .ok_or_else(|| format!("\"{text}\" does not start with a number; {ex}"))?;
    if rest.trim().is_empty() {
        return Err(format!("\"{text}\" has no unit; {ex}"));
    }
    let (factor, dim) = parse_unit(rest.trim(), text)?;
    Ok((num, factor, dim))
}

/// Split the longest prefix that is an f64 literal off `s` ("3in" works too). Only prefixes
/// of the literal's shape ([`literal_end`]) are tried: trying every prefix of the whole text
/// took time quadratic in its length (a 60 kB value, 1 s; found by tests/deck_fuzz.rs).
fn split_number(s: &str) -> Option<(f64, &str)> {
    let end = (1..=literal_end(s))
        .rev()
        .find(|&i| s[..i].parse::<f64>().is_ok())?;
    let v: f64 = s[..end].parse().ok()?;
    v.is_finite().then_some((v, &s[end..]))
}

/// The end of the longest prefix of `s` shaped like an f64 literal (ASCII, so every byte up
/// to it is a char boundary): a sign, then `inf`, `infinity` or `nan` in any case, or digits
/// with at most one point and an exponent with digits. No longer prefix parses as an f64.
fn literal_end(s: &str) -> usize {
    let b = s.as_bytes();
    let digits = |mut j: usize| {
        while b.get(j).is_some_and(u8::is_ascii_digit) {
            j += 1;
        }
        j
    };
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    for word in ["infinity", "inf", "nan"] {
        let end = i + word.len();
        if b.get(i..end)
            .is_some_and(|w| w.eq_ignore_ascii_case(word.as_bytes()))
        {
            return end;
        }
    }
    i = digits(i);
    if b.get(i) == Some(&b'.') {
        i = digits(i + 1);
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let end = digits(i + 1 + sign);
        if end > i + 1 + sign {
            i = end;
        }
    }
    i
}

/// Unit grammar: factor (("*" | "·" | "/") factor)*, factor = name ("^" | "**") int;
/// "/" divides by the next factor only, so "lbf*in/in^2" is lbf·in·in⁻².
fn parse_unit(expr: &str, whole: &str) -> Result<(f64, Dim), String> {
    let expr = expr.replace("**", "^").replace('·', "*");
    let (mut rest, mut sign, mut factor, mut d) = (expr.as_str(), 1, 1.0f64, [0i32; 3]);
    loop {
        let end = rest.find(['*', '/']).unwrap_or(rest.len());
        let (name, exp) = match rest[..end].split_once('^') {
            None => (rest[..end].trim(), 1),
            Some((n, e)) => (
                n.trim(),
                e.trim()
                    .parse::<i8>()
                    .map_err(|_| format!("bad exponent \"{}\" in \"{whole}\"", e.trim()))?,
            ),
        };
        if name.is_empty() {
            return Err(format!("missing a unit name in \"{whole}\""));
        }
        // Accept the micro sign and Greek mu for "u".
        let name = name.replace(['µ', 'μ'], "u");
        let &(_, f, ud) = UNITS.iter().find(|u| u.0 == name).ok_or_else(|| {
            let known: Vec<&str> = UNITS.iter().map(|u| u.0).collect();
            let known = known.join(", ");
            format!("unknown unit \"{name}\" in \"{whole}\"; known units: {known}")
        })?;
        let e = sign * i32::from(exp);
        factor *= f.powi(e);
        for (acc, u) in d.iter_mut().zip([ud.m, ud.l, ud.t]) {
            *acc += i32::from(u) * e;
        }
        if end == rest.len() {
            break;
        }
        sign = if rest[end..].starts_with('/') { -1 } else { 1 };
        rest = &rest[end + 1..];
    }
    let conv = |x: i32| i8::try_from(x).map_err(|_| format!("exponent too large in \"{whole}\""));
    Ok((factor, Dim::new(conv(d[0])?, conv(d[1])?, conv(d[2])?)))
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Repr {
    /// Already in the deck's unit system, whichever that turns out to be.
    Plain(f64),
    Si(f64),
    /// A number and the SI size of its unit, as written in the deck.
    Unit(f64, f64),
}

/// A deck quantity of fixed dimension. It keeps a plain number unconverted
/// because the deck's unit system may only be known after the whole deck is
/// read; conversion happens in [`Quantity::value`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantity<const M: i8, const L: i8, const T: i8>(Repr);

impl<const M: i8, const L: i8, const T: i8> Quantity<M, L, T> {
    pub const DIM: Dim = Dim::new(M, L, T);

    pub fn plain(v: f64) -> Self {
        Quantity(Repr::Plain(v))
    }

    pub fn si(v: f64) -> Self {
        Quantity(Repr::Si(v))
    }

    pub fn value(&self, sys: UnitSystem) -> f64 {
        match self.0 {
            Repr::Plain(v) => v,
            Repr::Si(v) => v / sys.si_factor(Self::DIM),
            Repr::Unit(v, factor) => convert(v, factor / sys.si_factor(Self::DIM)),
        }
    }
}

/// Scale by a ratio of unit sizes. Ratios within 1e-12 of an integer or of its
/// reciprocal are snapped, so "3 in" in an inch deck is exactly 3.0 and "5 mm"
/// in SI is 5/1000 correctly rounded, not 5 * 0.0254 / 0.0254 = 4.999...; region
/// bounds compared against coordinates would otherwise flip on the last bit.
fn convert(v: f64, ratio: f64) -> f64 {
    let snap = |r: f64| {
        if (r - r.round()).abs() < 1e-12 * r {
            r.round()
        } else {
            r
        }
    };
    if ratio >= 1.0 {
        v * snap(ratio)
    } else {
        v / snap(1.0 / ratio)
    }
}

/// Like the deck strings; a string that is only a number (e.g. "3e9") is
/// accepted as a plain number, as TOML users often quote numbers.
impl<const M: i8, const L: i8, const T: i8> FromStr for Quantity<M, L, T> {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        parse_as(s, Self::DIM).map(Quantity)
    }
}

/// A deck string of dimension `dim`: a plain number, or a number with a unit of that
/// dimension.
fn parse_as(s: &str, dim: Dim) -> Result<Repr, String> {
    if let Ok(v) = s.trim().parse::<f64>() {
        return Ok(Repr::Plain(v));
    }
    let (v, factor, found) = parse_parts(s, Some(&dim.example()))?;
    if found != dim {
        return Err(mismatch(dim, s, found));
    }
    Ok(Repr::Unit(v, factor))
}

/// What a model reads of a material key, converted as [`Quantity::value`] converts: the
/// dimension is the model's, known only when it asks.
impl crate::model::Units for UnitSystem {
    fn value(&self, written: &Written, dim: Dimension) -> Result<f64, String> {
        let dim = Dim::new(dim.mass, dim.length, dim.time);
        if let (UnitSystem::Lj, Written::Text(s)) = (self, written) {
            if written_with_unit(s) {
                return Err(format!(
                    "\"{s}\" has a unit, but a deck in units = \"lj\" takes plain numbers (in σ, ε, m, τ)"
                ));
            }
        }
        let repr = match written {
            Written::Number(v) => Repr::Plain(*v),
            Written::Text(s) => parse_as(s, dim)?,
            Written::Other(what) => {
                return Err(format!(
                    "expected {} as a number or a string like \"{}\", not {what}",
                    dim.with_article(),
                    dim.example()
                ))
            }
        };
        Ok(match repr {
            Repr::Plain(v) => v,
            Repr::Si(v) => v / self.si_factor(dim),
            Repr::Unit(v, factor) => convert(v, factor / self.si_factor(dim)),
        })
    }
}

impl UnitSystem {
    /// This system as the converter a model's materials read through.
    pub fn as_units(self) -> &'static dyn crate::model::Units {
        match self {
            UnitSystem::Si => &UnitSystem::Si,
            UnitSystem::InchPoundSecond => &UnitSystem::InchPoundSecond,
            UnitSystem::MmNewtonSecond => &UnitSystem::MmNewtonSecond,
            UnitSystem::Lj => &UnitSystem::Lj,
        }
    }
}

struct QuantityVisitor<const M: i8, const L: i8, const T: i8>;

impl<'de, const M: i8, const L: i8, const T: i8> Visitor<'de> for QuantityVisitor<M, L, T> {
    type Value = Quantity<M, L, T>;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let d = Quantity::<M, L, T>::DIM;
        write!(
            f,
            "{} as a number or a string like \"{}\"",
            d.with_article(),
            d.example()
        )
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        Ok(Quantity::plain(v as f64))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        Ok(Quantity::plain(v))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
        v.parse().map_err(E::custom)
    }
}

impl<'de, const M: i8, const L: i8, const T: i8> Deserialize<'de> for Quantity<M, L, T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(QuantityVisitor)
    }
}

/// A 3-vector of quantities. The single-string form "200 50 30 in" exists
/// because decks list many points and repeating the unit three times is noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vector<const M: i8, const L: i8, const T: i8>(pub [Quantity<M, L, T>; 3]);

impl<const M: i8, const L: i8, const T: i8> Vector<M, L, T> {
    pub const DIM: Dim = Dim::new(M, L, T);

    pub fn value(&self, sys: UnitSystem) -> [f64; 3] {
        self.0.map(|q| q.value(sys))
    }
}

/// "x y z unit" (unit optional: then plain numbers).
impl<const M: i8, const L: i8, const T: i8> FromStr for Vector<M, L, T> {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let toks: Vec<&str> = s.split_whitespace().collect();
        let nums: Vec<f64> = toks.iter().map_while(|t| t.parse().ok()).collect();
        if nums.len() != 3 {
            let ex = Self::DIM.example();
            let unit = ex.split_once(' ').map_or("", |x| x.1);
            return Err(format!(
                "expected three numbers then an optional unit, e.g. \"1 2 3 {unit}\", found \"{s}\""
            ));
        }
        let unit = toks[3..].join(" ");
        let factor = if unit.is_empty() {
            None
        } else {
            Some(parse_unit(&unit, s)?)
        };
        match factor {
            None => Ok(Vector([0, 1, 2].map(|i| Quantity::plain(nums[i])))),
            Some((_, dim)) if dim != Self::DIM => Err(mismatch(Self::DIM, s, dim)),
            Some((f, _)) => Ok(Vector([0, 1, 2].map(|i| Quantity(Repr::Unit(nums[i], f))))),
        }
    }
}

struct VectorVisitor<const M: i8, const L: i8, const T: i8>;

impl<'de, const M: i8, const L: i8, const T: i8> Visitor<'de> for VectorVisitor<M, L, T> {
    type Value = Vector<M, L, T>;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an array of 3 values or a string like \"200 50 30 in\"")
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
        v.parse().map_err(E::custom)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut items = Vec::with_capacity(3);
        while let Some(q) = seq.next_element()? {
            items.push(q);
        }
        let n = items.len();
        let items = items
            .try_into()
            .map_err(|_| de::Error::invalid_length(n, &self))?;
        Ok(Vector(items))
    }
}

impl<'de, const M: i8, const L: i8, const T: i8> Deserialize<'de> for Vector<M, L, T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(VectorVisitor)
    }
}

pub type Length = Quantity<0, 1, 0>;
pub type Area = Quantity<0, 2, 0>;
pub type Time = Quantity<0, 0, 1>;
pub type Velocity = Quantity<0, 1, -1>;
pub type Acceleration = Quantity<0, 1, -2>;
pub type Mass = Quantity<1, 0, 0>;
pub type Density = Quantity<1, -3, 0>;
/// Particles per unit volume (`[lattice] density`).
pub type NumberDensity = Quantity<0, -3, 0>;
pub type Stress = Quantity<1, -1, -2>;
pub type Force = Quantity<1, 1, -2>;
/// Force per volume (body force).
pub type ForceDensity = Quantity<1, -2, -2>;
/// Fracture energy G0; dimensionally the same as force per length.
pub type EnergyPerArea = Quantity<1, 0, -2>;
/// PMB micromodulus c, N/m^6 = kg m^-5 s^-2.
pub type Micromodulus = Quantity<1, -5, -2>;
pub type Position = Vector<0, 1, 0>;
pub type VelocityVector = Vector<0, 1, -1>;
pub type ForceVector = Vector<1, 1, -2>;
pub type AccelerationVector = Vector<0, 1, -2>;

#[cfg(test)]
#[path = "units_tests.rs"]
mod tests;
