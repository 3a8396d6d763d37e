//! The first cracking load of a pretensioned girder loaded at midspan, for the BT-72 girder
//! (thesis problem 4.6, `validation/prestressed_girder.toml`): the smaller of ACI 318-11's two
//! cracking loads, both on the transformed section (steel counted n = E_s/E_c times) with the
//! prestress P_i = E_ps·A_ps·ε_p before release, which on the transformed section already
//! includes the elastic shortening loss:
//! - flexural: the bottom fibre reaches f_r = 7.5√f'c under P_i/A + P_i·e·y_b/I and the
//!   midspan moment of the self-weight and the load, M = w·L²/8 + P·(2L − a)/8 (a the loaded
//!   length, the loading plate's);
//! - web-shear (Eq. 11-12): V_cw = (3.5√f'c + 0.3 f_pc)·b_w·d_p at h/2 from the face of the
//!   support (the inner edge of the bearing plate under it), with f_pc = P/A at the centroid
//!   reduced linearly within the transfer length (§11.3.4, here AASHTO's 60 d_b, as the
//!   model's, where ACI assumes 50 d_b) and d_p ≥ 0.8h; the load is then the midspan load
//!   whose shear there is V_cw.
//!
//! Everything is read from the deck: the section is its first prism along x (the concrete:
//! E_c, f'c, density), the steel its `[[bar]]`s along x (each at its height, with its
//! material's E; the prestressed ones are the strands: P_i from their prestrain, d_b from
//! their area, the transfer length 60 d_b — computed, not read from the bars' own
//! `transfer_length`, which the file gives rounded to 0.01 in), the supports and the loaded
//! length from the named boundaries and load, the face of the support from the box under the
//! first support (the bearing plate), the self-weight from the named gravity load on the
//! concrete area (the bars and plates not counted), b_w the polygon's width at the
//! centroid's height. Only the ACI and AASHTO coefficients are constants here.

use super::{loaded_length, region_centre, support_span, Curve, Reference};
use crate::input::deck::{LoadKind, Scene};
use crate::input::geometry::{Op, Shape};
use crate::input::units::UnitSystem;
use crate::model::{Dimension, Material};
use std::f64::consts::PI;

/// The girder's section and the two cracking loads (in, psi, lbf).
#[derive(Debug)]
pub(super) struct Girder {
    /// Transformed area, centroid above the soffit, second moment about it.
    pub area: f64,
    pub centroid: f64,
    pub inertia: f64,
    pub concrete_area: f64,
    pub prestress: f64,
    pub strands: usize,
    /// Eccentricity of the strands below the centroid.
    pub eccentricity: f64,
    pub self_weight: f64,
    pub span: f64,
    pub transfer_length: f64,
    pub f_pc: f64,
    pub web: f64,
    pub d_p: f64,
    pub v_cw: f64,
    pub web_shear: f64,
    pub f_r: f64,
    pub loaded_length: f64,
    pub flexural: f64,
    pub youngs_modulus: f64,
}

pub(super) fn reference(
    scene: &Scene,
    supports: &[String; 2],
    load: &str,
    weight: &str,
) -> Result<Reference, String> {
    let g = girder(scene, supports, load, weight)?;
    let value = g.flexural.min(g.web_shear);
    let elastic_mid = value * g.span.powi(3) / (48.0 * g.youngs_modulus * g.inertia);
    Ok(Reference {
        value,
        formula: format!(
            "the smaller of ACI 318-11's cracking loads on the transformed section (A = {:.0} in², {:.0} in² of it concrete, y_b = {:.2} in, I = {:.0} in⁴), prestress P_i = {:.0} lbf ({} strands) at e = {:.2} in, self-weight w = {:.1} lbf/in, supports L = {} in apart: web-shear, Eq. 11-12 V_cw = (3.5√f'c + 0.3 f_pc)·b_w·d_p = {:.0} lbf at h/2 from the face of the support (the bearing plate's inner edge; f_pc = {:.0} psi, P_i/A with the elastic shortening loss only, reduced within the transfer length of {:.1} in, AASHTO's 60 d_b as in the model, where ACI's §11.3.4 assumes 50 d_b; b_w = {} in, d_p = {:.1} in), load {:.0} lbf; flexural, the bottom fibre at f_r = 7.5√f'c = {:.1} psi under M = wL²/8 + P(2L − a)/8 (a = {} in, the loading plate), load {:.0} lbf",
            g.area,
            g.concrete_area,
            g.centroid,
            g.inertia,
            g.prestress,
            g.strands,
            g.eccentricity,
            g.self_weight,
            g.span,
            g.v_cw,
            g.f_pc,
            g.transfer_length,
            g.web,
            g.d_p,
            g.web_shear,
            g.f_r,
            g.loaded_length,
            g.flexural,
        ),
        curve: Curve::Points(vec![(0.0, value), (2.0 * elastic_mid, value)]),
    })
}

/// The girder of the deck and its two cracking loads.
pub(super) fn girder(
    scene: &Scene,
    supports: &[String; 2],
    load: &str,
    weight: &str,
) -> Result<Girder, String> {
    if scene.units != UnitSystem::InchPoundSecond {
        return Err("the ACI formulas are in psi: the deck must be in units = \"in-lbf-s\"".into());
    }
    let (polygon, material) = scene
        .ops
        .iter()
        .find_map(|op| match &op.item {
            Op::Add {
                shape: Shape::Prism {
                    axis: 0, polygon, ..
                },
                material,
            } => Some((polygon, *material)),
            _ => None,
        })
        .ok_or("the girder formula reads the deck's first prism along x, and it has none")?;
    let concrete = &scene.materials[material as usize];
    let e_c = youngs_modulus(concrete)?;
    let fc = concrete.compressive_strength.ok_or_else(|| {
        format!(
            "material '{}' has no compressive_strength (f'c) for the reference",
            concrete.name
        )
    })?;
    let s = Section::of(scene, polygon, e_c)?;
    let (soffit, top) = polygon.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        (lo.min(p[1]), hi.max(p[1]))
    });
    let height = top - soffit;
    let g = match scene
        .loads
        .iter()
        .find(|l| l.name == weight)
        .map(|l| l.kind)
    {
        Some(LoadKind::Gravity(g)) => -g[2],
        _ => {
            return Err(format!(
                "the girder formula reads a gravity [[load]] named '{weight}'"
            ))
        }
    };
    let self_weight = concrete.density * g * s.concrete_area;
    let span = support_span(scene, supports)?;
    let a = loaded_length(scene, load)?;
    // Flexural: the bottom fibre at f_r.
    let f_r = 7.5 * fc.sqrt();
    let (p, area, yb, i) = (s.prestress, s.area, s.centroid, s.inertia);
    let e = yb - s.strand_height;
    let cracking_moment = (f_r + p / area + p * e * yb / i) * i / yb;
    let flexural = 8.0 * (cracking_moment - self_weight * span * span / 8.0) / (2.0 * span - a);
    // Web-shear at h/2 from the face of the first support, toward the other.
    let support = region_centre(scene, &supports[0])?;
    let inward = (region_centre(scene, &supports[1])? - support).signum();
    let face = bearing_face(scene, support, soffit, inward)?;
    let section = face + inward * height / 2.0;
    let from_end = if inward > 0.0 {
        section - s.strands_from
    } else {
        s.strands_to - section
    };
    let transfer_length = 60.0 * (4.0 * s.strand_area / PI).sqrt();
    let f_pc = p / area * (from_end / transfer_length).min(1.0);
    let d_p = (height - s.strand_height).max(0.8 * height);
    let web = width_at(polygon, soffit + yb);
    let v_cw = (3.5 * fc.sqrt() + 0.3 * f_pc) * web * d_p;
    let web_shear = 2.0 * (v_cw - self_weight * (span / 2.0 - (section - support) * inward));
    Ok(Girder {
        area,
        centroid: yb,
        inertia: i,
        concrete_area: s.concrete_area,
        prestress: p,
        strands: s.strands,
        eccentricity: e,
        self_weight,
        span,
        transfer_length,
        f_pc,
        web,
        d_p,
        v_cw,
        web_shear,
        f_r,
        loaded_length: a,
        flexural,
        youngs_modulus: e_c,
    })
}

fn youngs_modulus(m: &Material) -> Result<f64, String> {
    let e = m.quantity("youngs_modulus", Dimension::STRESS);
    e.map_err(|e| e.to_string())?
        .ok_or_else(|| format!("material '{}' has no youngs_modulus", m.name))
}

/// The transformed section and the strands.
struct Section {
    area: f64,
    /// Above the soffit.
    centroid: f64,
    inertia: f64,
    concrete_area: f64,
    prestress: f64,
    strands: usize,
    /// The strands' mean height above the soffit, area of one, and their extent along x.
    strand_height: f64,
    strand_area: f64,
    strands_from: f64,
    strands_to: f64,
}

impl Section {
    /// The polygon's moments by the shoelace sums, then each bar as a point of its area
    /// counted E/E_c − 1 more times.
    fn of(scene: &Scene, polygon: &[[f64; 2]], e_c: f64) -> Result<Section, String> {
        let soffit = polygon.iter().map(|p| p[1]).fold(f64::MAX, f64::min);
        let (mut a, mut sz, mut szz) = (0.0, 0.0, 0.0);
        for k in 0..polygon.len() {
            let [y0, z0] = polygon[k];
            let [y1, z1] = polygon[(k + 1) % polygon.len()];
            let (z0, z1) = (z0 - soffit, z1 - soffit);
            let cross = y0 * z1 - y1 * z0;
            a += cross / 2.0;
            sz += cross * (z0 + z1) / 6.0;
            szz += cross * (z0 * z0 + z0 * z1 + z1 * z1) / 12.0;
        }
        let (a, sz, szz) = (a.abs(), sz.abs(), szz.abs());
        let (mut at, mut szt, mut szzt) = (a, sz, szz);
        let (mut prestress, mut strands, mut strand_z) = (0.0, 0, 0.0);
        let (mut strand_area, mut from, mut to) = (0.0, f64::MAX, f64::MIN);
        for b in &scene.bars {
            let bar = &b.bar;
            if bar.from[1] != bar.to[1] || bar.from[2] != bar.to[2] {
                return Err("the girder formula reads bars along x".into());
            }
            let e = youngs_modulus(&scene.materials[bar.material as usize])?;
            let z = 0.5 * (bar.from[2] + bar.to[2]) - soffit;
            let extra = (e / e_c - 1.0) * bar.area;
            at += extra;
            szt += extra * z;
            szzt += extra * z * z;
            if b.prestrain.strain != 0.0 {
                prestress += bar.area * b.prestrain.strain * e;
                strands += 1;
                strand_z += z;
                strand_area = bar.area;
                from = from.min(bar.from[0].min(bar.to[0]));
                to = to.max(bar.from[0].max(bar.to[0]));
            }
        }
        if strands == 0 {
            return Err("the girder formula needs prestressed bars (the strands)".into());
        }
        let centroid = szt / at;
        Ok(Section {
            area: at,
            centroid,
            inertia: szzt - at * centroid * centroid,
            concrete_area: a,
            prestress,
            strands,
            strand_height: strand_z / strands as f64,
            strand_area,
            strands_from: from,
            strands_to: to,
        })
    }
}

/// The face of the support at `support`: the edge, toward midspan (`inward`), of the box
/// under the girder (below `soffit`) whose length holds the support's middle.
fn bearing_face(scene: &Scene, support: f64, soffit: f64, inward: f64) -> Result<f64, String> {
    scene
        .ops
        .iter()
        .find_map(|op| match &op.item {
            Op::Add {
                shape: Shape::Box { min, max },
                ..
            } if min[0] <= support && support <= max[0] && max[2] <= soffit => {
                Some(if inward > 0.0 { max[0] } else { min[0] })
            }
            _ => None,
        })
        .ok_or_else(|| {
            format!("the girder formula reads the bearing plate under the support at x = {support}: a [[geometry]] box below the girder, and the deck has none")
        })
}

/// The polygon's width across (y) at height `z`: the sum of its chords there.
fn width_at(polygon: &[[f64; 2]], z: f64) -> f64 {
    let mut ys: Vec<f64> = (0..polygon.len())
        .filter_map(|k| {
            let [y0, z0] = polygon[k];
            let [y1, z1] = polygon[(k + 1) % polygon.len()];
            ((z0 <= z) != (z1 <= z)).then(|| y0 + (z - z0) * (y1 - y0) / (z1 - z0))
        })
        .collect();
    ys.sort_by(f64::total_cmp);
    ys.chunks_exact(2).map(|c| c[1] - c[0]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The girder of `validation/prestressed_girder.toml` (the --quick deck).
    fn case() -> (Scene, Girder) {
        let text = std::fs::read_to_string("validation/prestressed_girder.toml").unwrap();
        let scene = crate::input::deck::parse(&text, "g.toml", "g").unwrap();
        let supports = ["pin".to_string(), "roller".to_string()];
        let g = girder(&scene, &supports, "load", "weight").unwrap();
        (scene, g)
    }

    /// (E_s/E_c − 1)·A of the deck's steel: 3 strands and 8 bars.
    fn steel_extra() -> f64 {
        let n = |e: f64| e / 3.605e6 - 1.0;
        3.0 * 0.6975 * n(28.5e6) + 8.0 * 0.62 * n(29.0e6)
    }

    #[test]
    fn the_section_is_the_pci_bt72() {
        // PCI Bridge Design Manual: A = 767 in², y_b = 36.60 in, I = 545,894 in⁴. The polygon
        // leaves out the PCI drawing's small corner chamfers.
        let (_, g) = case();
        assert!((g.concrete_area - 767.0).abs() < 1e-9);
        // Transformed: 3 × 0.6975 × (n_ps − 1) + 8 × 0.62 × (n_s − 1) more area, lower centroid.
        assert!((g.area - 767.0 - steel_extra()).abs() < 1e-9);
        let (yb, i) = (g.centroid, g.inertia);
        assert!(yb < 36.60 && yb > 35.5, "y_b = {yb}");
        assert!(i > 545_000.0 && i < 620_000.0, "I = {i}");
        assert_eq!(
            (g.web, g.d_p, g.span, g.loaded_length),
            (6.0, 69.0, 366.0, 36.0)
        );
        assert_eq!(g.strands, 3);
        assert!((g.prestress - 3.0 * 0.6975 * 202_500.0).abs() < 1e-9 * g.prestress);
        // 145 lb/ft³ on 767 in².
        let w = 145.0 / 1728.0 * 767.0;
        assert!((g.self_weight - w).abs() < 1e-12 * w);
    }

    #[test]
    fn web_shear_governs_the_cracking_of_this_girder() {
        let (_, g) = case();
        // At h/2 = 36 in from the bearing plate's inner edge (9 in from the end) the prestress
        // has grown to 45/56.5 of its full value; the section is 40.5 in from the support line.
        let transfer = 60.0 * (4.0 * 0.6975 / PI).sqrt();
        assert_eq!(g.transfer_length, transfer);
        let full = g.prestress / g.area;
        assert!((g.f_pc / full - 45.0 / transfer).abs() < 1e-12);
        let expected = (3.5 * 4000f64.sqrt() + 0.3 * g.f_pc) * 6.0 * 69.0;
        assert!((g.v_cw - expected).abs() < 1e-9 * expected);
        let load = 2.0 * (g.v_cw - g.self_weight * (g.span / 2.0 - 40.5));
        assert!((g.web_shear - load).abs() < 1e-6);
        assert!(g.web_shear < g.flexural);
    }

    #[test]
    fn the_flexural_load_puts_the_bottom_fibre_at_f_r() {
        let (_, g) = case();
        let (p, a, yb, i) = (g.prestress, g.area, g.centroid, g.inertia);
        let m = g.self_weight * g.span.powi(2) / 8.0
            + g.flexural * (2.0 * g.span - g.loaded_length) / 8.0;
        let bottom = m * yb / i - p / a - p * g.eccentricity * yb / i;
        assert!(
            (bottom - 7.5 * 4000f64.sqrt()).abs() < 1e-9 * bottom,
            "{bottom}"
        );
    }
}
