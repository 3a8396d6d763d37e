//! Unit tests of `input/units.rs` (kept apart so the module reads on its own).
use super::*;
use serde::Deserialize;
use UnitSystem::{InchPoundSecond as Ips, MmNewtonSecond as Mm, Si};

fn close(a: f64, b: f64, rel: f64) {
    assert!((a - b).abs() <= rel * b.abs(), "{a} != {b}");
}

#[test]
fn conversions() {
    #[rustfmt::skip]
    let cases = [
        ("3605 ksi", Stress::DIM, Ips, 3.605e6, 1e-12),
        ("4000 psi", Stress::DIM, Ips, 4000.0, 1e-12),
        ("25 GPa", Stress::DIM, Si, 2.5e10, 1e-12),
        ("25 GPa", Stress::DIM, Ips, 25e9 / 6894.757293168361, 1e-12),
        ("25 GPa", Stress::DIM, Mm, 25e3, 1e-12),
        ("145 lb/ft^3", Density::DIM, Ips, 2.1735e-4, 1e-4),
        ("145 lb/ft^3", Density::DIM, Ips, 145.0 / 1728.0 / 386.09, 1e-12),
        ("2400 kg/m^3", Density::DIM, Si, 2400.0, 1e-12),
        ("2400 kg/m^3", Density::DIM, Mm, 2.4e-9, 1e-12),
        ("3 in", Length::DIM, Si, 0.0762, 1e-12),
        ("5 µm", Length::DIM, Si, 5e-6, 1e-12),
        ("7.87 in/s", Velocity::DIM, Si, 7.87 * 0.0254, 1e-12),
        ("7.87in/s", Velocity::DIM, Ips, 7.87, 1e-12),
        ("1.0 lbf*in/in^2", EnergyPerArea::DIM, Ips, 1.0, 1e-12),
        ("1.0 lbf * in / in ** 2", EnergyPerArea::DIM, Ips, 1.0, 1e-12),
        ("1e-7 s", Time::DIM, Si, 1e-7, 1e-12),
        ("-1.5e3 N", Force::DIM, Si, -1500.0, 1e-12),
        ("2 kips", Force::DIM, Ips, 2000.0, 1e-12),
        ("9.81 m/s^2", Acceleration::DIM, Si, 9.81, 1e-12),
        ("1 N/m^6", Micromodulus::DIM, Si, 1.0, 1e-12),
        ("1 N·m", Dim::new(1, 2, -2), Si, 1.0, 1e-12),
    ];
    for (text, dim, sys, want, rel) in cases {
        let (v, d) = parse_quantity(text).unwrap();
        assert_eq!(d, dim, "{text}");
        close(v / sys.si_factor(d), want, rel);
    }
    assert_eq!(Micromodulus::DIM.describe(), "micromodulus (M L^-5 T^-2)");
    assert_eq!(Dim::new(0, 0, 0).describe(), "dimensionless");
    assert_eq!(Dim::new(2, 1, 0).describe(), "M^2 L");
    assert!(parse_quantity("3").unwrap_err().contains("no unit"));
    for bad in ["in", "3 in^", "3 in/", "3 in+s", "3 in^999", "3 in 2"] {
        assert!(parse_quantity(bad).is_err(), "{bad}");
    }
}

#[test]
fn systems_and_labels() {
    assert_eq!(UnitSystem::from_name("US"), Ok(Ips));
    assert_eq!(UnitSystem::from_name("m-kg-s").map(|s| s.name()), Ok("SI"));
    assert!(UnitSystem::from_name("cgs").unwrap_err().contains("mm-N-s"));
    close(Mm.si_factor(MASS), 1000.0, 1e-12);
    close(Ips.si_factor(Density::DIM), LBF / INCH.powi(4), 1e-12);
    assert_eq!(Ips.label(Density::DIM), "lbf*s^2/in^4");
    assert_eq!(Ips.label(STRESS), "psi");
    assert_eq!(Si.label(Micromodulus::DIM), "N/m^6");
    // Every label of a named dimension parses back to that system's unit.
    for sys in [Si, Ips, Mm] {
        for &(dim, _, _) in &KNOWN[..KNOWN.len() - 1] {
            let (v, d) = parse_quantity(&format!("1 {}", sys.label(dim))).unwrap();
            assert_eq!(d, dim, "{}", sys.label(dim));
            close(v, sys.si_factor(dim), 1e-12);
        }
    }
}

#[test]
fn lj_units() {
    assert_eq!(UnitSystem::from_name("lj"), Ok(UnitSystem::Lj));
    assert_eq!(UnitSystem::Lj.name(), "lj");
    assert_eq!(UnitSystem::Lj.boltzmann(), 1.0);
    close(Si.boltzmann(), 1.380649e-23, 1e-15);
    close(Mm.boltzmann(), 1.380649e-20, 1e-15);
    close(Ips.boltzmann(), 1.380649e-23 / (LBF * INCH), 1e-15);
    assert_eq!(UnitSystem::Lj.label(Dim::new(1, 2, -2)), "m*σ^2*τ^-2");
    assert_eq!(Si.label(Dim::new(0, -3, 0)), "m^-3");
    for with in ["3 mm", "3mm", "1 2 3 in", " 2.5 GPa ", "1 m^-3"] {
        assert!(written_with_unit(with), "{with}");
    }
    for without in [
        "3",
        "3e9",
        "1 2 3",
        "1st_support",
        "3D block",
        "fcc",
        "out/1",
    ] {
        assert!(!written_with_unit(without), "{without}");
    }
    let units = UnitSystem::Lj.as_units();
    let dim = crate::model::Dimension::STRESS;
    assert_eq!(units.value(&Written::Text("2.5".into()), dim), Ok(2.5));
    assert_eq!(units.value(&Written::Number(0.8442), dim), Ok(0.8442));
    let err = units
        .value(&Written::Text("3 GPa".into()), dim)
        .unwrap_err();
    assert!(err.contains("lj") && err.contains("plain numbers"), "{err}");
}

#[test]
fn round_trip() {
    macro_rules! check {
        ($($q:ty),*) => {$(
            for sys in [Si, Ips, Mm] {
                assert_eq!(<$q>::si(-1.2e7).value(sys), -1.2e7 / sys.si_factor(<$q>::DIM));
                assert_eq!(<$q>::plain(-1.2e7).value(sys), -1.2e7);
            }
        )*};
    }
    check!(Length, Area, Time, Velocity, Acceleration, Mass, Density);
    check!(Stress, Force, ForceDensity, EnergyPerArea, Micromodulus);
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct Deck {
    e: Stress,
}

fn stress(src: &str) -> Result<Stress, String> {
    toml::from_str::<Deck>(src)
        .map(|d| d.e)
        .map_err(|e| e.to_string())
}

fn position(src: &str) -> Result<[f64; 3], String> {
    #[derive(Deserialize)]
    struct V {
        x: Position,
    }
    let v: V = toml::from_str(&format!("x = {src}")).map_err(|e| e.to_string())?;
    Ok(v.x.value(Ips))
}

#[test]
fn toml_quantity() {
    let err = stress("\ne = \"3 in\"\n").unwrap_err();
    assert!(err.contains("stress") && err.contains("length") && err.contains("line 2"));
    let msg = r#"expected a stress (M L^-1 T^-2), e.g. "25 GPa", but "3 in" is a length (L)"#;
    assert!(err.contains(msg), "{err}");
    assert_eq!(stress("e = 3e9"), Ok(Stress::plain(3e9)));
    assert_eq!(stress("e = 4000"), Ok(Stress::plain(4000.0)));
    assert_eq!(stress("e = \"25 GPa\"").unwrap().value(Si), 2.5e10);
    assert_eq!(stress("e = \"3605 ksi\"").unwrap().value(Ips), 3.605e6);
    assert_eq!(stress("e = \"30 MPa\"").unwrap().value(Mm), 30.0);
    assert_eq!("5 mm".parse::<Length>().unwrap().value(Si), 0.005);
    let err = stress("e = \"3605 ksii\"").unwrap_err();
    assert!(err.contains(r#"unknown unit "ksii" in "3605 ksii"; known units: m,"#));
    assert!(stress("e = true").is_err() && stress("e = 1\nf = 2").is_err());
}

#[test]
fn toml_vector() {
    assert_eq!(position("\"200 50 30 in\""), Ok([200.0, 50.0, 30.0]));
    assert_eq!(position("[1, 2.5, 3]"), Ok([1.0, 2.5, 3.0]));
    assert_eq!(position("\"0 0 -1e-3\""), Ok([0.0, 0.0, -1e-3]));
    assert_eq!(position(r#"["1 in", "2 in", "3 in"]"#), Ok([1.0, 2.0, 3.0]));
    for bad in [
        "[1, 2]",
        "[1, 2, 3, 4]",
        "\"1 2 in\"",
        "\"1 2 3 4 in\"",
        "[1, 2, \"3 s\"]",
    ] {
        assert!(position(bad).unwrap_err().contains("line 1"), "{bad}");
    }
    assert_eq!(position("\"0.5 1 3 ft\""), Ok([6.0, 12.0, 36.0]));
    let err = position("\"1 2 3 s\"").unwrap_err();
    assert!(err.contains("length") && err.contains("time"), "{err}");
}

#[test]
fn numbers_are_split_off_their_units_in_linear_time() {
    for (text, number, rest) in [
        ("3in", 3.0, "in"),
        ("3 in", 3.0, " in"),
        ("-1.5e3mm", -1500.0, "mm"),
        ("+.5E+1 s", 5.0, " s"),
        ("1. m", 1.0, " m"),
        ("2e m", 2.0, "e m"),
        ("7e+x", 7.0, "e+x"),
    ] {
        assert_eq!(split_number(text), Some((number, rest)), "{text}");
    }
    for text in ["inf m", "-Infinity", "NaN mm", ".", "e5 m", "mm", "", "-"] {
        assert_eq!(split_number(text), None, "{text}");
    }
    // A long number followed by a long run of letters: every prefix of the whole text used
    // to be parsed (seconds at this length).
    let long = format!("{}{}", "1".repeat(200_000), "m".repeat(200_000));
    let start = std::time::Instant::now();
    assert!(parse_quantity(&long).is_err());
    assert!(
        start.elapsed().as_secs_f64() < 1.0,
        "took {:?}",
        start.elapsed()
    );
}
