//! Each mechanical model against continuum elasticity: a block under homogeneous uniaxial
//! strain, the virial stress at its centre particle (whose family and neighbours' families are
//! whole), and the E and ν that stress implies, against the E and ν the deck gives.

use pdq::engine::analysis::{cubic_constants_at_centre, young_poisson, CubicConstants};
use pdq::input::{deck, setup};
use pdq::model::Model;

/// A cube of `n`³ particles (n odd, so one sits at the centre) on a 1 mm lattice with horizon
/// m·spacing.
fn block_deck(model: &str, m: f64, material: &str, options: &str, n: usize) -> String {
    format!(
        r#"
units = "SI"
[model]
name = "{model}"
m = {m}
{options}
[lattice]
spacing = "1 mm"
[materials.solid]
density = "2000 kg/m^3"
{material}
[[geometry]]
shape = "box"
material = "solid"
min = "0 0 0 mm"
max = "{e} {e} {e} mm"
[time]
steps = 1
[output]
progress = false
"#,
        e = n
    )
}

/// The cubic constants at the centre of a block (`cubic_constants_at_centre`).
pub fn constants<M: Model>(text: &str) -> CubicConstants {
    let scene = deck::parse(text, "block.toml", "block").unwrap_or_else(|e| panic!("{e}"));
    let mut s = setup::build_as::<M>(&scene).unwrap_or_else(|e| panic!("{e}"));
    cubic_constants_at_centre(&mut s.sim).expect("the block has particles")
}

/// E and ν of the isotropic (orientation-averaged) solid the block stands for.
pub fn recovered<M: Model>(text: &str) -> (f64, f64) {
    let c = constants::<M>(text);
    let (lambda, mu) = c.isotropic_lame();
    println!(
        "  C11 {:.4e} C12 {:.4e} C44 {:.4e} anisotropy {:.4}",
        c.c11,
        c.c12,
        c.c44,
        c.anisotropy()
    );
    young_poisson(lambda, mu)
}

fn check(label: &str, got: (f64, f64), e: f64, nu: f64, tol: f64) {
    // ν = 0 has no relative scale: its error is the value itself.
    let dnu = if nu == 0.0 { got.1 } else { (got.1 - nu) / nu };
    let de = (got.0 - e) / e;
    println!(
        "{label}: E = {:.4e} ({:+.2}%), nu = {:.4} ({:+.2}%)",
        got.0,
        100.0 * de,
        got.1,
        100.0 * dnu
    );
    assert!(
        de.abs() < tol && dnu.abs() < tol,
        "{label}: E and nu off by {:.2}% and {:.2}%",
        100.0 * de,
        100.0 * dnu
    );
}

#[test]
fn lps_recovers_e_and_nu() {
    use pdq::models::lps::Lps;
    for influence in ["one", "inverse_length", "gaussian"] {
        for nu in [0.1, 0.2, 0.3, 0.4] {
            let text = block_deck(
                "lps",
                3.0,
                &format!("youngs_modulus = \"10 GPa\"\npoisson_ratio = {nu}"),
                &format!("[model.options]\ninfluence = \"{influence}\""),
                13,
            );
            let got = recovered::<Lps>(&text);
            check(&format!("lps {influence} m=3 nu={nu}"), got, 10e9, nu, 0.02);
        }
    }
}

#[test]
fn pmb_recovers_e_and_nu_with_the_energy_correction() {
    use pdq::models::pmb::Pmb;
    let material = "youngs_modulus = \"10 GPa\"";
    // Uncorrected, the lattice's discrete family is softer than the continuum integral the
    // micromodulus comes from; ν = 1/4 holds whatever the lattice (Cauchy relation).
    let raw = recovered::<Pmb>(&block_deck("pmb", 3.0, material, "", 13));
    println!(
        "pmb m=3 uncorrected: E {:+.2}%, nu {:.4}",
        100.0 * (raw.0 / 10e9 - 1.0),
        raw.1
    );
    assert!((raw.1 - 0.25).abs() < 1e-3, "PMB nu = {}", raw.1);
    for (m, n, tol) in [(3.0, 13, 0.05), (4.0, 17, 0.02)] {
        let text = block_deck("pmb", m, material, "surface_correction = \"energy\"", n);
        let got = recovered::<Pmb>(&text);
        check(
            &format!("pmb m={m} energy correction"),
            got,
            10e9,
            0.25,
            tol,
        );
    }
}

#[test]
fn micropolar_recovers_e_and_nu() {
    use pdq::models::micropolar::Micropolar;
    for nu in [0.0, 0.1, 0.2, 0.25] {
        let material = format!("youngs_modulus = \"10 GPa\"\npoisson_ratio = {nu}");
        let raw = recovered::<Micropolar>(&block_deck("micropolar", 3.0, &material, "", 13));
        println!(
            "micropolar m=3 nu={nu} uncorrected: E {:+.2}%, nu {:.4}",
            100.0 * (raw.0 / 10e9 - 1.0),
            raw.1
        );
        let text = block_deck(
            "micropolar",
            4.0,
            &material,
            "surface_correction = \"energy\"",
            17,
        );
        let got = recovered::<Micropolar>(&text);
        check(
            &format!("micropolar m=4 energy correction nu={nu}"),
            got,
            10e9,
            nu,
            0.02,
        );
    }
}
