//! The yardstick of `pdq bench`: the generic pair pass against a PMB force loop written by
//! hand for this one model, on the same state; what the generic model path costs.

use super::median;
use crate::engine::forces;
use crate::engine::simulation::Simulation;
use crate::model::Model;
use crate::models::pmb::{Motion, Pmb};
use std::fmt::Write as _;
use std::time::Instant;

/// The model the hand-written loop is written for.
pub(super) const MODEL: &str = Pmb::NAME;

/// The yardstick's line, for a PMB simulation (empty for any other model). Runs alternate
/// (hand first on even repeats, generic first on odd ones) and the overhead is the median of
/// the per-repeat ratios, so a slow spell of a shared machine hits both.
pub(super) fn compare<M: Model>(sim: &mut Simulation<M>, repeat: usize) -> String {
    let n = sim.particles.n_owned;
    let mut out = String::new();
    for _ in 0..2 {
        sim.advance();
    }
    if let Some(pmb) = (&sim.model as &dyn std::any::Any).downcast_ref::<Pmb>() {
        let law = pmb.laws()[0];
        let (mut generic, mut hand, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
        let mut identical = true;
        let mut hand_force = vec![[0.0f64; 3]; sim.particles.len()];
        let saved = sim.bonds.broken.clone();
        for r in 0..repeat.max(1) {
            let mut hand_broken = saved.clone();
            let time_hand = |sim: &Simulation<M>, broken: &mut [bool], force: &mut [[f64; 3]]| {
                let alter: &[Motion] =
                    bytemuck::cast_slice(bytemuck::cast_slice::<_, f64>(&sim.particles.alter));
                let t = Instant::now();
                hand_pmb_pass(
                    alter,
                    &sim.particles.volume,
                    sim.bonds.offsets(),
                    sim.bonds.partners(),
                    &sim.bonds.geom,
                    broken,
                    force,
                    law.c,
                    law.s0,
                );
                t.elapsed().as_secs_f64()
            };
            let (th, tg) = if r % 2 == 0 {
                let th = time_hand(sim, &mut hand_broken, &mut hand_force);
                let t = Instant::now();
                forces::pair_pass(&sim.model, &mut sim.particles, &mut sim.bonds);
                (th, t.elapsed().as_secs_f64())
            } else {
                let t = Instant::now();
                forces::pair_pass(&sim.model, &mut sim.particles, &mut sim.bonds);
                let tg = t.elapsed().as_secs_f64();
                (time_hand(sim, &mut hand_broken, &mut hand_force), tg)
            };
            hand.push(th);
            generic.push(tg);
            ratio.push(tg / th);
            let g: &[f64] = bytemuck::cast_slice(&sim.particles.force);
            identical &= g.chunks(3).zip(&hand_force).all(|(a, b)| a == &b[..]);
            identical &= sim.bonds.broken == hand_broken;
            sim.bonds.broken = saved.clone();
        }
        let _ = writeln!(
            out,
            "bench yardstick=hand-pmb particles={n} force_pass_ms_generic={:.3} force_pass_ms_hand={:.3} generic_overhead_percent={:+.1} identical_forces={identical} repeats={}",
            1e3 * median(generic),
            1e3 * median(hand),
            100.0 * (median(ratio) - 1.0),
            repeat.max(1)
        );
    }
    out
}

/// The PMB force pass written by hand for this one model: the yardstick of the generic path.
/// Not used by the engine.
#[allow(clippy::too_many_arguments)]
pub fn hand_pmb_pass(
    alter: &[Motion],
    volume: &[f64],
    offsets: &[u32],
    partner: &[u32],
    geom: &crate::engine::bond_geoms::BondGeoms,
    broken: &mut [bool],
    force: &mut [[f64; 3]],
    c: f64,
    s0: f64,
) {
    force.fill([0.0; 3]);
    for i in 0..offsets.len() - 1 {
        let xi = alter[i].pos;
        let vi = volume[i];
        let mut fi = [0.0; 3];
        for b in offsets[i] as usize..offsets[i + 1] as usize {
            if broken[b] {
                continue;
            }
            let j = partner[b] as usize;
            let xj = alter[j].pos;
            let y = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
            let r = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
            let l = geom[b].length;
            let e = r - l;
            if e > s0 * l {
                broken[b] = true;
                continue;
            }
            let f = c * geom[b].beta * vi * volume[j] * e / (l * r);
            let fv = [f * y[0], f * y[1], f * y[2]];
            fi[0] += fv[0];
            fi[1] += fv[1];
            fi[2] += fv[2];
            force[j][0] -= fv[0];
            force[j][1] -= fv[1];
            force[j][2] -= fv[2];
        }
        force[i][0] += fi[0];
        force[i][1] += fi[1];
        force[i][2] += fi[2];
    }
}
