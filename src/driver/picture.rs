//! `picture.png`, the final state from the side and in 3D, coloured as the deck asked: each
//! procCube rasterizes its own particles in the frame of the whole body, and the root
//! composites the pieces (`output::views`), so that no rank holds the scene.

use super::step_loop::Plan;
use crate::input::deck::Colouring;
use crate::model::Model;
use crate::output::views::{self, Pixel};
use crate::parallel::comm::Reduce;
use crate::parallel::Cube;

/// Draws `picture.png` (a collective: every worker calls it); the root's result, `Ok`
/// elsewhere.
pub(super) fn write_picture<M: Model>(
    cube: &mut Cube<M>,
    plan: &Plan,
    colouring: Colouring,
) -> Result<(), String> {
    let step = cube.sim.step;
    let damage = cube.damage();
    let p = &cube.sim.particles;
    let n = p.n_owned;
    let points: Vec<[f64; 3]> = (0..n).map(|i| p.pos(i)).collect();
    let raw: Vec<f64> = match colouring {
        Colouring::Damage => damage,
        Colouring::Material => (0..n).map(|i| p.material[i] as f64).collect(),
        Colouring::Speed => (0..n)
            .map(|i| p.velocity(i).iter().map(|v| v * v).sum::<f64>().sqrt())
            .collect(),
        // `Auto` was resolved when the run was planned.
        Colouring::Height | Colouring::Auto => points.iter().map(|x| x[2]).collect(),
    };
    let ids = p.gid[..n].to_vec();
    let finite = raw.iter().filter(|x| x.is_finite());
    let mut range = [
        finite.clone().fold(f64::INFINITY, |a, &x| a.min(x)),
        -finite.fold(f64::NEG_INFINITY, |a, &x| a.max(x)),
    ];
    let mut extent = views::extent(&points);
    let time = cube.sim.time;
    let mut team = cube.team();
    team.reduce(&mut range, Reduce::Min);
    team.reduce(&mut extent, Reduce::Min);
    let (lo, hi) = (range[0], -range[1]);
    let last = plan.material_names.len().saturating_sub(1) as f64;
    let (lo, hi, scale) = match colouring {
        Colouring::Damage => (0.0, 1.0, crate::output::plot::damage_scale()),
        Colouring::Material => {
            let names = &plan.material_names;
            let ends = [
                names.first().cloned().unwrap_or_default(),
                names.last().cloned().unwrap_or_default(),
            ];
            (0.0, last, ends)
        }
        Colouring::Speed => (0.0, hi, ["speed 0".into(), format!("{hi:.3e}")]),
        Colouring::Height | Colouring::Auto => {
            (lo, hi, [format!("z {lo:.3e}"), format!("{hi:.3e}")])
        }
    };
    let values: Vec<f64> = if colouring == Colouring::Damage {
        raw
    } else {
        raw.iter()
            .map(|x| (x - lo) / (hi - lo).max(1e-300))
            .collect()
    };
    let mine = views::raster(&points, &ids, &values, plan.spacing, &extent);
    let bytes = mine.as_ref().map_or(Vec::new(), |px| Pixel::to_bytes(px));
    let Some(pieces) = team.gather(&bytes) else {
        return Ok(());
    };
    mine?;
    let image = views::composite(pieces.iter().flat_map(|b| Pixel::from_bytes(b)));
    let what = match colouring {
        Colouring::Material => {
            format!("material ({}, blue to red)", plan.material_names.join(", "))
        }
        other => other.name().to_string(),
    };
    let title = format!(
        "{}: step {step}, t = {:.4e}, coloured by {what}",
        plan.title, time
    );
    views::draw(&plan.dir.join("picture.png"), &title, &image, &scale)
}
