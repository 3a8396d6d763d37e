//! Thesis problem 4.5: the lap-splice pullout. A concrete cylinder, 6 in across and 12 in
//! long, holds two 1 in steel bars, each 12 in long, that overlap inside it and stick out of
//! opposite ends; the protruding parts are pulled apart at a constant velocity (7.87, 2.0 or
//! 0.5 in/s, the thesis's three runs) and held in the cylinder's cross-section plane.
//!
//! The thesis gives the materials and the velocities but its Figure 4.18 (the bars' placement)
//! is not in its text. Assumed here, and said in the report: each bar sticks out 3 in, so the
//! lap is 6 in (6 bar diameters); the bars' axes are 2 in apart (1 in clear), each 1 in from
//! the cylinder's axis, which leaves 1.5 in of cover.
//!
//! The measure is the peak pull force, against the splice strength of Orangun, Jirsa and Breen
//! (1977; the basis of ACI 408 and of ACI 318's development lengths): an average bond stress
//! u = (1.2 + 3c/d_b + 50 d_b/l_s)·√f'c psi over the lap's bar surface, T = u·π·d_b·l_s, with
//! c the smaller of the cover and half the clear spacing between neighbouring splices (no
//! transverse steel). The gap between the two bars of one splice does not count: the tests
//! behind the formula had contact splices, and ACI treats a non-contact splice as one. This
//! splice has no neighbour, so c is the cover. The formula is a regression of beam-splice
//! tests, most of them longer than 6 d_b, so the reference is an engineering estimate, reported
//! and not gated.
//!
//! The pulled parts are driven only beyond a horizon from the cylinder's end faces: a driven
//! particle closer than that would be bonded to the end concrete and pull on it directly, a
//! grip that the test does not have. Between the grip and the face the bar is held across
//! (y, z) but free along its axis: a bar is a line of particles and has no bending stiffness,
//! so without this the cylinder turns about y under the two opposite pulls (a rigid rotation
//! takes up the imposed motion at no force), which the real bars' bending stiffness prevents.

use super::formulas::Curve;
use super::measures::{column, read_history};
use super::{Case, Kind, Level, Plot};

/// Bar diameter and the cylinder's size (in).
const BAR_DIAMETER: f64 = 1.0;
const CYLINDER_RADIUS: f64 = 3.0;
const CYLINDER_LENGTH: f64 = 12.0;
/// How far each bar sticks out of the concrete, and its length.
const PROTRUSION: f64 = 3.0;
const BAR_LENGTH: f64 = 12.0;
/// Each bar's axis sits this far from the cylinder's axis (in z: −1 and +1 in).
const BAR_OFFSET: f64 = 1.0;
/// The thesis's concrete modulus for this problem, 3504 ksi, in psi; f'c follows from ACI
/// 318-11 §8.5.1, E = 57,000√f'c, as the thesis states no compressive strength for it.
const SPLICE_CONCRETE_E: f64 = 3.504e6;
/// The thesis's concrete tensile strength and steel for this problem (psi).
const SPLICE_CONCRETE_TENSILE: f64 = 600.0;
const STEEL_E: f64 = 29.0e6;
const STEEL_YIELD: f64 = 150.0e3;
/// The run goes on until each bar end has moved this far (in), well past the peak force.
const END_TRAVEL: f64 = 0.015;

/// The lap length: the overlap of the two embedded lengths.
fn lap_length() -> f64 {
    2.0 * (BAR_LENGTH - PROTRUSION) - CYLINDER_LENGTH
}

/// √f'c in psi, from E = 57,000√f'c.
fn sqrt_fc() -> f64 {
    SPLICE_CONCRETE_E / 57_000.0
}

/// The confinement c of the formula: the clear cover from a bar to the cylinder's surface
/// (the splice has no neighbouring splice), at most 2.5 d_b.
fn confinement() -> f64 {
    (CYLINDER_RADIUS - BAR_OFFSET - BAR_DIAMETER / 2.0).min(2.5 * BAR_DIAMETER)
}

/// Orangun–Jirsa–Breen splice strength T = u·π·d_b·l_s (lbf).
fn splice_strength() -> f64 {
    let c = confinement();
    let l_s = lap_length();
    let u = (1.2 + 3.0 * c / BAR_DIAMETER + 50.0 * BAR_DIAMETER / l_s) * sqrt_fc();
    u * std::f64::consts::PI * BAR_DIAMETER * l_s
}

/// The velocities of the thesis's three runs (in/s), with the name suffix of each case.
pub(super) const VELOCITIES: [(&str, f64); 3] = [("fast", 7.87), ("medium", 2.0), ("slow", 0.5)];

/// The pullout at `velocity` (in/s) per bar end.
pub(super) fn lap_splice(level: Level, suffix: &str, velocity: f64) -> Case {
    let dx = match level {
        Level::Quick => 0.5,
        Level::Full => 0.25,
    };
    let horizon = 3.0 * dx;
    let area = std::f64::consts::PI * BAR_DIAMETER * BAR_DIAMETER / 4.0;
    let duration = END_TRAVEL / velocity;
    let reference = splice_strength();
    // The lattice is shifted by half a spacing across the cylinder so that sites lie on the
    // bars' lines: bar particles then replace concrete sites instead of sitting between them.
    let half = dx / 2.0;
    let (left_from, left_to) = (-PROTRUSION, BAR_LENGTH - PROTRUSION);
    let (right_from, right_to) = (CYLINDER_LENGTH - left_to, CYLINDER_LENGTH + PROTRUSION);
    let deck = format!(
        r#"title = "validation: lap-splice pullout (thesis 4.5) at {velocity} in/s, {dx} in lattice"
units = "in-lbf-s"
[model]
name = "concrete"
m = 3
surface_correction = "energy"
[lattice]
spacing = "{dx} in"
origin = "0 -{half} -{half} in"
[materials.concrete]
kind = "concrete"
density = "2400 kg/m^3"
youngs_modulus = "{SPLICE_CONCRETE_E} psi"
poisson_ratio = 0.22
tensile_stretch = {tensile:.5e}
compressive_stretch = -1.1e-3
[materials.steel]
kind = "steel"
density = "7850 kg/m^3"
youngs_modulus = "{STEEL_E} psi"
poisson_ratio = 0.3
yield_stretch = {yield_stretch:.5e}
[[geometry]]
shape = "cylinder"
material = "concrete"
base = "0 0 0 in"
axis = "x"
length = "{CYLINDER_LENGTH} in"
radius = "{CYLINDER_RADIUS} in"
[[bar]]
material = "steel"
area = "{area:.6} in^2"
from = "{left_from} 0 -{BAR_OFFSET} in"
to = "{left_to} 0 -{BAR_OFFSET} in"
[[bar]]
material = "steel"
area = "{area:.6} in^2"
from = "{right_from} 0 {BAR_OFFSET} in"
to = "{right_to} 0 {BAR_OFFSET} in"
[[boundary]]
name = "left_grip"
region = {{ shape = "slab", axis = "x", from = "{left_lo} in", to = "{left_hi} in" }}
velocity = "-{velocity} 0 0 in/s"
[[boundary]]
name = "right_grip"
region = {{ shape = "slab", axis = "x", from = "{right_lo} in", to = "{right_hi} in" }}
velocity = "{velocity} 0 0 in/s"
[[boundary]]
name = "left_guide"
region = {{ shape = "slab", axis = "x", from = "{left_hi} in", to = "0 in" }}
fixed = ["y", "z"]
[[boundary]]
name = "right_guide"
region = {{ shape = "slab", axis = "x", from = "{CYLINDER_LENGTH} in", to = "{right_lo} in" }}
fixed = ["y", "z"]
[[probe]]
name = "left_bar_end"
at = "{left_probe} 0 -{BAR_OFFSET} in"
[[probe]]
name = "right_bar_end"
at = "{right_probe} 0 {BAR_OFFSET} in"
[time]
duration = "{duration} s"
critical_step = "measured"
[output]
progress = false
history_every = 10
frames_every = 100000000
"#,
        tensile = SPLICE_CONCRETE_TENSILE / SPLICE_CONCRETE_E,
        yield_stretch = STEEL_YIELD / STEEL_E,
        left_lo = left_from - dx,
        // Half-open slabs, from ≤ x < to; no bar particle lies on these planes.
        left_hi = -horizon,
        right_lo = CYLINDER_LENGTH + horizon,
        right_hi = right_to + dx,
        left_probe = left_from + half,
        right_probe = right_to - half,
    );
    Case {
        name: format!("lap_splice_{suffix}"),
        quantity: format!("peak pull force at {velocity} in/s"),
        unit: "lbf".into(),
        kind: Kind::Strength,
        reference,
        thesis: None,
        formula: format!(
            "Orangun–Jirsa–Breen splice strength T = (1.2 + 3c/d_b + 50 d_b/l_s)·√f'c·π·d_b·l_s with d_b = {BAR_DIAMETER} in, l_s = {} in, c = {} in (the cover; a single splice), √f'c = {:.1} psi (from E = 57,000√f'c); the bars' placement is assumed (the thesis's Figure 4.18 is not in its text); the thesis shows pictures only",
            lap_length(),
            confinement(),
            sqrt_fc()
        ),
        tolerance_percent: 15.0,
        deck,
        extract: Box::new(|_, dir| peak_pull(dir)),
        damage_views: true,
        plot: Some(Plot {
            x_label: "separation of the two bars' gripped ends (in)".into(),
            y_label: "pull force (lbf)".into(),
            reference: Curve::Points(vec![(0.0, reference), (2.0 * END_TRAVEL, reference)]),
            measured: Box::new(pull_against_separation),
        }),
    }
}

/// The largest pull force of the run: the right grip's support reaction along the bar.
fn peak_pull(dir: &std::path::Path) -> Result<f64, String> {
    let curve = pull_against_separation(dir)?;
    if let Some(&(_, f)) = curve.iter().find(|(_, f)| !f.is_finite()) {
        return Err(format!("the pull force in history.csv is not finite ({f})"));
    }
    curve
        .iter()
        .map(|&(_, f)| f)
        .reduce(f64::max)
        .ok_or_else(|| "history.csv has no rows".to_string())
}

/// (separation of the two gripped bar ends, pull force) over the history rows.
fn pull_against_separation(dir: &std::path::Path) -> Result<Vec<(f64, f64)>, String> {
    let (header, rows) = read_history(dir)?;
    let col = |name: &str| column(&header, name);
    let (force, right, left) = (
        col("reaction_right_grip_x")?,
        col("right_bar_end_ux")?,
        col("left_bar_end_ux")?,
    );
    Ok(rows
        .iter()
        .map(|r| (r[right] - r[left], r[force]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lap_and_the_reference_follow_from_the_geometry() {
        assert_eq!(lap_length(), 6.0);
        assert_eq!(confinement(), 1.5);
        // u = (1.2 + 4.5 + 50/6)·61.47 psi over π·1·6 in².
        let expected = (1.2 + 4.5 + 50.0 / 6.0) * (3.504e6 / 57_000.0) * std::f64::consts::PI * 6.0;
        assert!((splice_strength() - expected).abs() < 1e-9 * expected);
        assert!((splice_strength() - 16_261.0).abs() < 5.0);
    }
}
