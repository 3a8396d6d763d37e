//! Thesis problem 4.6: a pretensioned BT-72 bulb-tee girder, 9.5 m long, simply supported at
//! its ends, loaded downward at midspan until it cracks.
//!
//! The thesis shows pictures only (flexural cracks in the bottom flange, then web-shear cracks)
//! and names the check an engineer would make; this case makes it. The measure is the first
//! cracking load: the midspan load at which a crack has run, i.e. as many bonds have broken as
//! cross the bottom flange's area (the plain beams' rule, applied to the flange). The
//! reference is the smaller of the two cracking loads of ACI 318-11, both on the transformed
//! section (steel counted n = E_s/E_c times) with the prestress P_i = E_ps·A_ps·ε_p before
//! release, which on the transformed section already includes the elastic shortening loss:
//! - flexural: the bottom fibre reaches f_r = 7.5√f'c under P_i/A + P_i·e·y_b/I and the
//!   midspan moment of the self-weight and the load, M = w·L²/8 + P·(2L − a)/8 (a the loading
//!   plate's length);
//! - web-shear (Eq. 11-12): V_cw = (3.5√f'c + 0.3 f_pc)·b_w·d_p at h/2 from the face of the
//!   support (the bearing plate's inner edge), with f_pc = P/A at the centroid reduced linearly
//!   within the transfer length (§11.3.4, here the model's 60 d_b, where ACI assumes 50 d_b)
//!   and d_p ≥ 0.8h; the load is then the midspan load whose shear there is V_cw.
//!
//! Assumed and said in the report (the thesis's Figures 4.23–4.25 are not in its text): the
//! section is the PCI BT-72 drawn as one polygon (42 in top flange 3.5 in thick with a 2 in
//! taper and 2 in fillets, 6 in web, 26 in bottom flange 6 in thick with a 4.5 in taper;
//! A = 767 in², the PCI value); the three strands (450 mm², 0.6975 in²) lie in the bottom flange
//! 3 in above the soffit, 7 in apart; of the eight bars (400 mm², 0.62 in²), four lie in the
//! bottom flange (3 in and 6 in up) and four in the top flange; the strands are the standard
//! 270 ksi grade stressed to 0.75 f_pu, bonded along their whole length, their prestress
//! growing over AASHTO's transfer length of 60 strand diameters; the beam is 375 in long (a
//! whole number of 3 in planes; the thesis's 9.5 m is 374 in).
//!
//! Supports and load go through steel plates, as in a test: a 9 in × 26 in × 3 in bearing plate
//! under each end, held on the line across its middle (so the ends can turn: held over a
//! length, they could not follow the camber of the prestress and tore the concrete there), and
//! a 36 in × 6 in × 3 in loading plate on the top over the web. A load spread over the whole
//! top flange bent the flange across the web and broke it long before the girder cracked; the
//! thesis's bond-based concrete also splits under a compression of about 4 f_t (its bonds
//! across a compressed direction stretch by ν = ¼ of the shortening), so the plates keep the
//! bearing stresses low. The solve is static (the implicit solve, load steps with bonds
//! breaking between Newton iterations), so the strands' prestress is released without the
//! vibration a sudden release would set off in a dynamic run.
//!
//! For this girder (three strands, a 9.5 m span, 72 in deep) web-shear cracking governs, by
//! ACI as in the run: at the quick 3 in lattice the crack that runs is horizontal, along the
//! junction of the web and the bottom flange over the ends' first 45 in, where the shear and
//! the strands' transfer of prestress meet (validation/README.md), not the inclined crack
//! through the web's centroid that V_cw describes.

use super::formulas::Curve;
use super::measures::{column, read_history};
use super::{Case, Kind, Level, Plot};

/// The thesis's concrete modulus, 3605 ksi (= 57,000√f'c psi), and f'c, in psi.
const CONCRETE_E: f64 = 3.605e6;
const FC: f64 = 4000.0;

/// The thesis's concrete (docs/theory.md §8) as a deck's `[materials.concrete]` table.
fn thesis_concrete() -> String {
    format!(
        r#"[materials.concrete]
kind = "concrete"
density = "145 lb/ft^3"
youngs_modulus = "{CONCRETE_E} psi"
poisson_ratio = 0.25
tensile_stretch = 1.387e-4
compressive_stretch = -1.1e-3
compressive_strength = "{FC} psi"
"#
    )
}

/// The PCI BT-72 section as (y, z) vertices in inches: y across (0 to 42), z up from the soffit.
const SECTION: [[f64; 2]; 14] = [
    [8.0, 0.0],
    [34.0, 0.0],
    [34.0, 6.0],
    [24.0, 10.5],
    [24.0, 64.5],
    [26.0, 66.5],
    [42.0, 68.5],
    [42.0, 72.0],
    [0.0, 72.0],
    [0.0, 68.5],
    [16.0, 66.5],
    [18.0, 64.5],
    [18.0, 10.5],
    [8.0, 6.0],
];
/// The girder's length (in).
const LENGTH: f64 = 375.0;
/// Mass density of the concrete, lbf·s²/in⁴ (145 lb/ft³ over g = 386.09 in/s²).
const CONCRETE_DENSITY: f64 = 145.0 / 1728.0 / 386.09;
const GRAVITY: f64 = 386.09;
/// Strands: 270 ksi grade, E = 28,500 ksi, stressed to 0.75 f_pu before release; yield at
/// 0.9 f_pu.
const STRAND_E: f64 = 28.5e6;
const STRAND_AREA: f64 = 0.6975;
const STRAND_STRESS: f64 = 0.75 * 270.0e3;
const STRAND_YIELD: f64 = 0.9 * 270.0e3;
/// Bars: the thesis's steel (29,000 ksi, yield strain 0.01), 0.62 in² each.
const BAR_E: f64 = 29.0e6;
const BAR_AREA: f64 = 0.62;
/// (y, z) of the strands and of the bars (in).
const STRANDS: [[f64; 2]; 3] = [[14.0, 3.0], [21.0, 3.0], [28.0, 3.0]];
const BARS: [[f64; 2]; 8] = [
    [10.0, 3.0],
    [32.0, 3.0],
    [12.0, 6.0],
    [30.0, 6.0],
    [3.0, 70.0],
    [15.0, 70.0],
    [27.0, 70.0],
    [39.0, 70.0],
];
/// AASHTO LRFD 5.9.4.3.1: the prestress grows linearly over 60 strand diameters from the
/// strand's end (the diameter of a round strand of the thesis's area, 0.94 in).
fn transfer_length() -> f64 {
    60.0 * (4.0 * STRAND_AREA / std::f64::consts::PI).sqrt()
}
/// Area of the bottom flange up to the top of its taper (z ≤ 10.5 in), in².
const BOTTOM_FLANGE_AREA: f64 = 26.0 * 6.0 + 0.5 * (26.0 + 6.0) * 4.5;
/// Height, web width and depth of the strands (in).
const HEIGHT: f64 = 72.0;
const WEB: f64 = 6.0;
/// The steel plates (in): bearing plates under the ends (along the span, across) and the
/// loading plate on the top over the web; all 3 in thick.
const BEARING: [f64; 2] = [9.0, 26.0];
const LOADING: [f64; 2] = [36.0, WEB];
const PLATE_THICKNESS: f64 = 3.0;
/// The load ramp: to `FAST_TO` × the reference in the first `FAST_STEPS` load steps (elastic,
/// nothing breaks), then on to `PEAK` × the reference in steps of `FINE` × the reference.
const FAST_TO: f64 = 0.7;
const FAST_STEPS: u32 = 7;
const FINE: f64 = 0.025;
const PEAK: f64 = 1.5;

/// Area, height of the centroid above the soffit, and second moment about the centroid of
/// the section with each steel area counted `n − 1` more times (the transformed section).
fn transformed_section() -> (f64, f64, f64) {
    // Polygon moments by the shoelace sums, then the steel as points.
    let (mut a, mut sz, mut szz) = (0.0, 0.0, 0.0);
    for k in 0..SECTION.len() {
        let [y0, z0] = SECTION[k];
        let [y1, z1] = SECTION[(k + 1) % SECTION.len()];
        let cross = y0 * z1 - y1 * z0;
        a += cross / 2.0;
        sz += cross * (z0 + z1) / 6.0;
        szz += cross * (z0 * z0 + z0 * z1 + z1 * z1) / 12.0;
    }
    let (a, sz, szz) = (a.abs(), sz.abs(), szz.abs());
    let extra = |e: f64, area: f64| (e / CONCRETE_E - 1.0) * area;
    let steel = STRANDS
        .iter()
        .map(|&[_, z]| (extra(STRAND_E, STRAND_AREA), z))
        .chain(BARS.iter().map(|&[_, z]| (extra(BAR_E, BAR_AREA), z)));
    let (mut at, mut szt, mut szzt) = (a, sz, szz);
    for (area, z) in steel {
        at += area;
        szt += area * z;
        szzt += area * z * z;
    }
    let centroid = szt / at;
    (at, centroid, szzt - at * centroid * centroid)
}

/// Gross concrete area of the polygon (in²).
fn concrete_area() -> f64 {
    let mut a = 0.0;
    for k in 0..SECTION.len() {
        let [y0, z0] = SECTION[k];
        let [y1, z1] = SECTION[(k + 1) % SECTION.len()];
        a += (y0 * z1 - y1 * z0) / 2.0;
    }
    a.abs()
}

/// Total prestress before release, lbf.
fn prestress_force() -> f64 {
    STRANDS.len() as f64 * STRAND_AREA * STRAND_STRESS
}

/// Self-weight of the concrete per length, lbf/in.
fn self_weight() -> f64 {
    CONCRETE_DENSITY * GRAVITY * concrete_area()
}

/// The midspan load at which the bottom fibre reaches f_r, for supports `span` apart and a
/// loading plate of length `a` (lbf).
fn flexural_cracking_load(span: f64, a: f64) -> f64 {
    let (area, yb, i) = transformed_section();
    let f_r = 7.5 * FC.sqrt();
    let p = prestress_force();
    let e = yb - STRANDS[0][1];
    let cracking_moment = (f_r + p / area + p * e * yb / i) * i / yb;
    8.0 * (cracking_moment - self_weight() * span * span / 8.0) / (2.0 * span - a)
}

/// ACI 318-11 Eq. 11-12 at h/2 from the face of the support (the bearing plate's inner edge),
/// for support lines at `support` from the girder's ends and `span` apart: (V_cw, f_pc, the
/// midspan load whose shear there is V_cw).
fn web_shear_cracking(span: f64, support: f64) -> (f64, f64, f64) {
    let (area, _, _) = transformed_section();
    // h/2 from the face of the support, the bearing plate's inner edge; the strands start at
    // the girder's end.
    let section = BEARING[0] + HEIGHT / 2.0;
    let f_pc = prestress_force() / area * (section / transfer_length()).min(1.0);
    let d_p = (HEIGHT - STRANDS[0][1]).max(0.8 * HEIGHT);
    let v_cw = (3.5 * FC.sqrt() + 0.3 * f_pc) * WEB * d_p;
    let load = 2.0 * (v_cw - self_weight() * (span / 2.0 - (section - support)));
    (v_cw, f_pc, load)
}

/// The girder at `level`: a 3 in lattice (`--quick`, about 11,700 particles) or a 2 in one
/// (`--full`, about 37,000; the thesis's 1 in lattice, about 290,000 particles, would need a
/// factored tangent far beyond this machine's memory).
/// The `[[bar]]`s of one kind of steel along the girder's length, prestressed if asked.
fn steel(name: &str, area: f64, at: &[[f64; 2]], prestress: Option<f64>) -> String {
    at.iter()
        .map(|[y, z]| {
            let pre = prestress.map_or(String::new(), |s| {
                format!(
                    "prestress = \"{s} psi\"\ntransfer_length = \"{:.2} in\"\n",
                    transfer_length()
                )
            });
            format!(
                "[[bar]]\nmaterial = \"{name}\"\narea = \"{area} in^2\"\nfrom = \"0 {y} {z} in\"\nto = \"{LENGTH} {y} {z} in\"\n{pre}"
            )
        })
        .collect::<String>()
}

/// The centre of the web across the section (in).
const CENTRE: f64 = 21.0;

/// The bearing plates under the ends and the loading plate on the top, as `[[geometry]]`.
fn plates() -> String {
    let mid = LENGTH / 2.0;
    let plate = |x0: f64, x1: f64, y_width: f64, z0: f64| {
        format!(
            "[[geometry]]\nshape = \"box\"\nmaterial = \"steel\"\nmin = \"{x0} {} {z0} in\"\nmax = \"{x1} {} {} in\"\n",
            CENTRE - y_width / 2.0,
            CENTRE + y_width / 2.0,
            z0 + PLATE_THICKNESS
        )
    };
    [
        plate(0.0, BEARING[0], BEARING[1], -PLATE_THICKNESS),
        plate(LENGTH - BEARING[0], LENGTH, BEARING[1], -PLATE_THICKNESS),
        plate(
            mid - LOADING[0] / 2.0,
            mid + LOADING[0] / 2.0,
            LOADING[1],
            HEIGHT,
        ),
    ]
    .concat()
}

/// The girder's deck at spacing `dx` with its support lines at `support` from the ends and
/// the load ramped in units of `reference`.
fn girder_deck(dx: f64, support: f64, reference: f64) -> String {
    let mid = LENGTH / 2.0;
    let plates = plates();
    let polygon = SECTION
        .iter()
        .map(|[y, z]| format!("[\"{y} in\", \"{z} in\"]"))
        .collect::<Vec<_>>()
        .join(", ");
    // Bonds crossing the bottom flange (π m⁴/4 per dx² of a plane at m = 3, as for the plain
    // beams' quarter section).
    let crack_bonds =
        (std::f64::consts::PI * 3f64.powi(4) / 4.0 * BOTTOM_FLANGE_AREA / (dx * dx)).ceil();
    // The load history: time 1 s is the reference load.
    let fine_steps = ((PEAK - FAST_TO) / FINE).round() as u32;
    let steps = FAST_STEPS + fine_steps;
    let (t_fast, t_end) = (FAST_STEPS as f64, steps as f64);
    format!(
        r#"title = "validation: pretensioned BT-72 girder (thesis 4.6), {dx} in lattice"
units = "in-lbf-s"
[model]
name = "concrete"
m = 3
surface_correction = "energy"
[lattice]
spacing = "{dx} in"
{concrete}[materials.strand]
kind = "steel"
density = "490 lb/ft^3"
youngs_modulus = "{STRAND_E} psi"
poisson_ratio = 0.3
yield_stretch = {strand_yield:.6e}
[materials.steel]
kind = "steel"
density = "490 lb/ft^3"
youngs_modulus = "{BAR_E} psi"
poisson_ratio = 0.3
yield_stretch = 0.01
[[geometry]]
shape = "prism"
material = "concrete"
axis = "x"
polygon = [{polygon}]
from = "0 in"
to = "{LENGTH} in"
{plates}{strands}{bars}[[boundary]]
name = "pin"
region = {{ shape = "box", min = "{s0} 0 -{PLATE_THICKNESS} in", max = "{s1} 42 {row} in" }}
fixed = ["x", "y", "z"]
[[boundary]]
name = "roller"
region = {{ shape = "box", min = "{r0} 0 -{PLATE_THICKNESS} in", max = "{r1} 42 {row} in" }}
fixed = ["y", "z"]
[[load]]
name = "weight"
gravity = "0 0 -{GRAVITY} in/s^2"
[[load]]
name = "load"
region = {{ shape = "box", min = "{l0} 0 {HEIGHT} in", max = "{l1} 42 {top} in" }}
total_force = "0 0 -{reference} lbf"
history = {{ table = [[0, 0], ["{t_fast} s", {FAST_TO}], ["{t_end} s", {PEAK}]] }}
[[probe]]
name = "tip"
at = "{mid} {y} 0 in"
[time]
duration = "{t_end} s"
stop_at_broken_bonds = {crack_bonds}
[solver]
kind = "implicit"
load_steps = {steps}
tolerance = 1e-6
max_iterations = 40
[output]
progress = false
history_every = 1
frames_every = 100000000
"#,
        concrete = thesis_concrete(),
        strand_yield = STRAND_YIELD / STRAND_E,
        strands = steel("strand", STRAND_AREA, &STRANDS, Some(STRAND_STRESS)),
        bars = steel("steel", BAR_AREA, &BARS, None),
        s0 = support - dx / 2.0,
        s1 = support + dx / 2.0,
        r0 = LENGTH - support - dx / 2.0,
        r1 = LENGTH - support + dx / 2.0,
        // The bearing plates' bottom row of sites only.
        row = -PLATE_THICKNESS + 0.6 * dx,
        l0 = mid - LOADING[0] / 2.0,
        l1 = mid + LOADING[0] / 2.0,
        top = HEIGHT + PLATE_THICKNESS,
        // Off the web's centre plane by half a spacing: on a particle, not between two.
        y = CENTRE - dx / 2.0,
    )
}

/// The girder case at `level`: its deck, the smaller ACI cracking load, and the measure.
pub(super) fn prestressed_girder(level: Level) -> Case {
    let dx = match level {
        Level::Quick => 3.0,
        Level::Full => 2.0,
    };
    // The support lines: the lattice plane nearest the bearing plates' middle, at each end.
    let support = ((BEARING[0] / 2.0 / dx).floor() + 0.5) * dx;
    let span = LENGTH - 2.0 * support;
    let flexural = flexural_cracking_load(span, LOADING[0]);
    let (v_cw, f_pc, web_shear) = web_shear_cracking(span, support);
    let reference = flexural.min(web_shear);
    let (area, yb, inertia) = transformed_section();
    let deck = girder_deck(dx, support, reference);
    let elastic_mid = reference * span.powi(3) / (48.0 * CONCRETE_E * inertia);
    Case {
        name: "prestressed_girder".into(),
        quantity: "first cracking load (midspan; a crack has run)".into(),
        unit: "lbf".into(),
        kind: Kind::Strength,
        reference,
        thesis: None,
        formula: format!(
            "the smaller of ACI 318-11's cracking loads on the transformed section (A = {area:.0} in², y_b = {yb:.2} in, I = {inertia:.0} in⁴; the gross PCI BT-72 has 767 in², 36.60 in, 545,894 in⁴), prestress P_i = 3 × {STRAND_AREA} in² × {:.1} ksi = {:.0} lbf (270 ksi strand at 0.75 f_pu) at e = {:.2} in, self-weight w = {:.1} lbf/in, supports L = {span} in apart: web-shear, Eq. 11-12 V_cw = (3.5√f'c + 0.3 f_pc)·b_w·d_p = {v_cw:.0} lbf at h/2 from the face of the support (the bearing plate's inner edge; f_pc = {f_pc:.0} psi, P_i/A with the elastic shortening loss only, reduced within the transfer length of {:.1} in, AASHTO's 60 d_b as in the model, where ACI's §11.3.4 assumes 50 d_b; b_w = {WEB} in, d_p = {:.1} in), load {web_shear:.0} lbf; flexural, the bottom fibre at f_r = 7.5√f'c = {:.1} psi under M = wL²/8 + P(2L − a)/8 (a = {} in, the loading plate), load {flexural:.0} lbf; strand and bar placement assumed (the thesis's figures are not in its text); the thesis shows pictures only",
            STRAND_STRESS / 1e3,
            prestress_force(),
            yb - STRANDS[0][1],
            self_weight(),
            transfer_length(),
            (HEIGHT - STRANDS[0][1]).max(0.8 * HEIGHT),
            7.5 * FC.sqrt(),
            LOADING[0],
        ),
        tolerance_percent: 15.0,
        deck,
        extract: Box::new(|summary, dir| {
            if !summary.stopped_at_broken {
                return Err(format!(
                    "the girder did not crack within the ramp (to {PEAK} × the reference): {} broken bonds at the end",
                    summary.broken
                ));
            }
            super::last_of(dir, "load_load")
        }),
        damage_views: true,
        plot: Some(Plot {
            x_label: "midspan deflection of the soffit (in)".into(),
            y_label: "midspan load (lbf)".into(),
            reference: Curve::Points(vec![(0.0, reference), (2.0 * elastic_mid, reference)]),
            measured: Box::new(load_deflection),
        }),
    }
}

/// (midspan deflection, applied midspan load) over the history rows.
fn load_deflection(dir: &std::path::Path) -> Result<Vec<(f64, f64)>, String> {
    let (header, rows) = read_history(dir)?;
    let col = |name: &str| column(&header, name);
    let (load, uz) = (col("load_load")?, col("tip_uz")?);
    Ok(rows.iter().map(|r| (-r[uz], r[load])).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_section_is_the_pci_bt72() {
        // PCI Bridge Design Manual: A = 767 in², y_b = 36.60 in, I = 545,894 in⁴. The polygon
        // leaves out the PCI drawing's small corner chamfers.
        assert!((concrete_area() - 767.0).abs() < 1e-9);
        let (a, yb, i) = transformed_section();
        // Transformed: 3 × 0.6975 × (n_ps − 1) + 8 × 0.62 × (n_s − 1) more area, lower centroid.
        let n = |e: f64| e / CONCRETE_E - 1.0;
        let extra = 3.0 * STRAND_AREA * n(STRAND_E) + 8.0 * BAR_AREA * n(BAR_E);
        assert!((a - 767.0 - extra).abs() < 1e-9);
        assert!(yb < 36.60 && yb > 35.5, "y_b = {yb}");
        assert!(i > 545_000.0 && i < 620_000.0, "I = {i}");
    }

    #[test]
    fn web_shear_governs_the_cracking_of_this_girder() {
        let (support, span) = (4.5, LENGTH - 9.0);
        let (v_cw, f_pc, load) = web_shear_cracking(span, support);
        // At h/2 = 36 in from the bearing plate's inner edge (9 in from the end) the prestress
        // has grown to 45/56.5 of its full value; the section is 40.5 in from the support line.
        let (a, _, _) = transformed_section();
        let full = prestress_force() / a;
        assert!((f_pc / full - 45.0 / transfer_length()).abs() < 1e-12);
        let expected = (3.5 * 4000f64.sqrt() + 0.3 * f_pc) * 6.0 * 69.0;
        assert!((v_cw - expected).abs() < 1e-9 * expected);
        assert!((load - 2.0 * (v_cw - self_weight() * (span / 2.0 - 40.5))).abs() < 1e-6);
        assert!(load < flexural_cracking_load(span, 36.0));
    }
}
