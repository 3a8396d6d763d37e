//! The bond loops: the optional state pass and the pair pass, generic over the model.
//!
//! These are the only loops over bonds in a time step. Each bond is visited once from its
//! owner; the model returns the generalized force on both ends and the loop adds them, so
//! equal-and-opposite forces and unequal micropolar moments go through the same code.

use crate::attributes::{add_assign, Attributes};
use crate::bonds::BondList;
use crate::model::{Model, Side};
use crate::particles::Particles;

/// Sums the model's per-particle state over intact bonds (owned and ghost ends). Does nothing,
/// at compile time, for a model whose `State` is `()`.
pub fn state_pass<M: Model>(model: &M, p: &mut Particles<M>, bonds: &BondList<M::Bond>) {
    if <M::State as Attributes>::LEN == 0 {
        return;
    }
    match single_material(&p.material) {
        Some(m) => {
            let law = model.law(m, m);
            state_loop(model, p, bonds, |_, _| law)
        }
        None => state_loop(model, p, bonds, |a, b| model.law(a, b)),
    }
}

/// The state pass's bond loop, shaped like [`pair_loop`] (see the comments there).
#[inline(always)]
fn state_loop<M: Model, L: Fn(u16, u16) -> M::Law>(
    model: &M,
    p: &mut Particles<M>,
    bonds: &BondList<M::Bond>,
    law_of: L,
) {
    let Particles {
        n_owned,
        x0,
        volume,
        material,
        fixed,
        alter,
        state,
        ..
    } = p;
    // Sums go straight into `state` (no buffer per step); the sides the model sees carry a
    // zero state, since a state is not an input to its own pass.
    for s in state.iter_mut() {
        *s = M::State::default();
    }
    let zero = M::State::default();
    let n = x0.len();
    assert!(
        *n_owned <= n
            && bonds.offsets.len() == *n_owned + 1
            && [
                volume.len(),
                material.len(),
                fixed.len(),
                alter.len(),
                state.len()
            ]
            .iter()
            .all(|&l| l == n)
            && (bonds.max_partner() < n || bonds.offsets.last() == Some(&0)),
        "bond list does not match the particle store"
    );
    let partners = bonds.partners();
    for i in 0..*n_owned {
        let (x0_i, alter_i, fixed_i) = (x0[i], alter[i], fixed[i]);
        let side_i = Side::<M> {
            x0: &x0_i,
            volume: volume[i],
            material: material[i],
            alter: &alter_i,
            fixed: &fixed_i,
            state: &zero,
        };
        let mut si = M::State::default();
        let range = bonds.offsets[i] as usize..bonds.offsets[i + 1] as usize;
        let (partner, geom) = (&partners[range.clone()], &bonds.geom[range.clone()]);
        let (broken, history) = (&bonds.broken[range.clone()], &bonds.history[range]);
        for k in 0..partner.len() {
            if broken[k] {
                continue;
            }
            let j = partner[k] as usize;
            // SAFETY: as in `pair_loop`: partners are below the store's length, checked above.
            let (side_j, sj) = unsafe {
                (
                    Side::<M> {
                        x0: x0.get_unchecked(j),
                        volume: *volume.get_unchecked(j),
                        material: *material.get_unchecked(j),
                        alter: alter.get_unchecked(j),
                        fixed: fixed.get_unchecked(j),
                        state: &zero,
                    },
                    state.get_unchecked_mut(j),
                )
            };
            let law = law_of(side_i.material, side_j.material);
            let (a, b) = model.state(&law, &side_i, &side_j, &geom[k], &history[k]);
            add_assign(&mut si, &a);
            add_assign(sj, &b);
        }
        add_assign(&mut state[i], &si);
    }
}

/// Turns summed states into final values (after the reverse sum brought ghosts' partials home).
pub fn finish_state<M: Model>(model: &M, p: &mut Particles<M>) {
    if <M::State as Attributes>::LEN == 0 {
        return;
    }
    for i in 0..p.n_owned {
        model.finish_state(&mut p.state[i], &p.fixed[i]);
    }
}

/// Zeroes all forces, then adds every intact bond's forces to its two ends. Marks bonds the
/// model breaks and returns how many broke.
pub fn pair_pass<M: Model>(
    model: &M,
    p: &mut Particles<M>,
    bonds: &mut BondList<M::Bond>,
) -> usize {
    // A scene of one material gets a loop with its law fixed: no material loads, no dispatch.
    match single_material(&p.material) {
        Some(m) => {
            let law = model.law(m, m);
            pair_loop(model, p, bonds, |_, _| law)
        }
        None => pair_loop(model, p, bonds, |a, b| model.law(a, b)),
    }
}

/// The material of every particle, if there is only one.
fn single_material(material: &[u16]) -> Option<u16> {
    let first = *material.first()?;
    material.iter().all(|&m| m == first).then_some(first)
}

#[inline(always)]
fn pair_loop<M: Model, L: Fn(u16, u16) -> M::Law>(
    model: &M,
    p: &mut Particles<M>,
    bonds: &mut BondList<M::Bond>,
    law_of: L,
) -> usize {
    let Particles {
        n_owned,
        x0,
        volume,
        material,
        fixed,
        alter,
        state,
        force,
        ..
    } = p;
    for f in force.iter_mut() {
        *f = M::Force::default();
    }
    let bonds_max_partner = bonds.max_partner();
    let (offsets, partner, geom, broken, history) = bonds.parts_mut();
    let n = x0.len();
    assert!(
        *n_owned <= n
            && offsets.len() == *n_owned + 1
            && [
                volume.len(),
                material.len(),
                fixed.len(),
                alter.len(),
                state.len(),
                force.len()
            ]
            .iter()
            .all(|&l| l == n)
            && (bonds_max_partner < n || offsets.last() == Some(&0)),
        "bond list does not match the particle store"
    );
    let mut newly_broken = 0;
    for i in 0..*n_owned {
        // Local copies: the compiler cannot tell that the force stores below leave particle
        // i's records alone, so references into the arrays would be reloaded on every bond.
        let (x0_i, alter_i, fixed_i, state_i) = (x0[i], alter[i], fixed[i], state[i]);
        let side_i = Side::<M> {
            x0: &x0_i,
            volume: volume[i],
            material: material[i],
            alter: &alter_i,
            fixed: &fixed_i,
            state: &state_i,
        };
        let mut fi = M::Force::default();
        let range = offsets[i] as usize..offsets[i + 1] as usize;
        let (partner, geom) = (&partner[range.clone()], &geom[range.clone()]);
        let (broken, history) = (&mut broken[range.clone()], &mut history[range]);
        for k in 0..partner.len() {
            if broken[k] {
                continue;
            }
            let j = partner[k] as usize;
            // SAFETY: every partner index is below the particle count (BondList keeps the partner
            // list private and its maximum; checked above), and all
            // per-particle arrays have that length. Unchecked access lets the compiler drop the
            // loads of fields the model never reads, which bounds checks would keep alive.
            let (side_j, fj) = unsafe {
                (
                    Side::<M> {
                        x0: x0.get_unchecked(j),
                        volume: *volume.get_unchecked(j),
                        material: *material.get_unchecked(j),
                        alter: alter.get_unchecked(j),
                        fixed: fixed.get_unchecked(j),
                        state: state.get_unchecked(j),
                    },
                    force.get_unchecked_mut(j),
                )
            };
            let law = law_of(side_i.material, side_j.material);
            match model.pair(&law, &side_i, &side_j, &geom[k], &mut history[k]) {
                Some((a, b)) => {
                    add_assign(&mut fi, &a);
                    add_assign(fj, &b);
                }
                None => {
                    broken[k] = true;
                    newly_broken += 1;
                }
            }
        }
        add_assign(&mut force[i], &fi);
    }
    newly_broken
}

/// The bonds' contributions to fixed data (see [`Model::bond_fixed`]), summed on both ends of
/// every bond, broken or not: one value per particle of the store, ghosts included.
pub fn bond_fixed_sums<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
) -> Vec<M::Fixed> {
    let mut sums = vec![M::Fixed::default(); p.len()];
    if !M::FIXED_FROM_BONDS {
        return sums;
    }
    for (i, j, b) in bonds.iter() {
        let law = model.law(p.material[i], p.material[j]);
        let (fi, fj) = model.bond_fixed(&law, &p.side(i), &p.side(j), &bonds.geom[b]);
        add_assign(&mut sums[i], &fi);
        add_assign(&mut sums[j], &fj);
    }
    sums
}

/// Adds the bond sums to the fixed data of a store that holds whole families (one procCube
/// and no ghosts); procCubes sum across faces in [`crate::parallel::Cube::start`].
pub fn add_bond_fixed<M: Model>(model: &M, p: &mut Particles<M>, bonds: &BondList<M::Bond>) {
    if !M::FIXED_FROM_BONDS {
        return;
    }
    let sums = bond_fixed_sums(model, p, bonds);
    for (f, s) in p.fixed.iter_mut().zip(&sums) {
        add_assign(f, s);
    }
}

/// Elastic energy stored in the intact bonds and in the owned particles.
pub fn strain_energy<M: Model>(model: &M, p: &Particles<M>, bonds: &BondList<M::Bond>) -> f64 {
    let mut e = 0.0;
    for i in 0..p.n_owned {
        e += model.particle_energy(p.material[i], p.volume[i], &p.fixed[i], &p.state[i]);
    }
    for (i, j, b) in bonds.iter() {
        if !bonds.broken[b] {
            let law = model.law(p.material[i], p.material[j]);
            e += model.energy(
                &law,
                &p.side(i),
                &p.side(j),
                &bonds.geom[b],
                &bonds.history[b],
            );
        }
    }
    e
}
