//! The bond loops: the optional state pass and the pair pass, generic over the model.
//!
//! These are the only loops over bonds in a time step. Each bond is visited once from its
//! owner; the model returns the generalized force on both ends and the loop adds them, so
//! equal-and-opposite forces and unequal micropolar moments go through the same code.

use crate::attributes::{add_assign, Attributes};
use crate::bonds::BondList;
use crate::model::{BondGeom, Model, Side};
use crate::particles::Particles;

/// Sums the model's per-particle state over intact bonds (owned and ghost ends). Does nothing,
/// at compile time, for a model whose `State` is `()`.
pub fn state_pass<M: Model>(model: &M, p: &mut Particles<M>, bonds: &mut BondList<M::Bond>) {
    if <M::State as Attributes>::LEN == 0 {
        return;
    }
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
    let zero = M::State::default();
    let ends = Ends {
        n_owned: *n_owned,
        x0,
        volume,
        material,
        fixed,
        alter,
        state: ZeroState(&zero),
    };
    // Broken bonds leave the state too, so it skips them like the pair pass.
    if model.breaks() {
        sweep_with_laws::<_, _, _, _, true>(model, ends, bonds, state, StateOfBond(model));
    } else {
        sweep_with_laws::<_, _, _, _, false>(model, ends, bonds, state, StateOfBond(model));
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
    let ends = Ends {
        n_owned: *n_owned,
        x0,
        volume,
        material,
        fixed,
        alter,
        state: &state[..],
    };
    if model.breaks() {
        sweep_with_laws::<_, _, _, _, true>(model, ends, bonds, force, PairOfBond(model))
    } else {
        // Nothing can break, so nothing ever broke: a scene's bonds start intact, and a
        // checkpoint with broken bonds belongs to another scene (its materials differ).
        debug_assert_eq!(bonds.broken_count(), 0, "unbreakable bonds marked broken");
        sweep_with_laws::<_, _, _, _, false>(model, ends, bonds, force, PairOfBond(model))
    }
}

/// [`sweep`] with the model's laws. A scene of one material gets a loop with its law fixed: no
/// material loads, no dispatch.
#[inline(always)]
fn sweep_with_laws<M, T, St, V, const DAMAGE: bool>(
    model: &M,
    ends: Ends<'_, M, St>,
    bonds: &mut BondList<M::Bond>,
    out: &mut [T],
    visit: V,
) -> usize
where
    M: Model,
    T: Attributes,
    St: States<M::State>,
    V: BondVisit<M, T>,
{
    match single_material(ends.material) {
        Some(m) => {
            let law = model.law(m, m);
            sweep::<_, _, _, _, _, DAMAGE>(ends, bonds, out, |_, _| law, visit)
        }
        None => sweep::<_, _, _, _, _, DAMAGE>(ends, bonds, out, |a, b| model.law(a, b), visit),
    }
}

/// The material of every particle, if there is only one.
fn single_material(material: &[u16]) -> Option<u16> {
    let first = *material.first()?;
    material.iter().all(|&m| m == first).then_some(first)
}

/// Where the bond ends' states come from: the particles' own (the pair pass), or one zero state
/// (the state pass, whose output the states are). A type each, so each loop is compiled for its
/// source with no test per bond.
trait States<S> {
    fn len(&self) -> usize;
    /// # Safety
    /// `i < self.len()`.
    unsafe fn get_unchecked(&self, i: usize) -> &S;
    fn copy(&self, i: usize) -> S;
}

impl<S: Copy> States<S> for &[S] {
    fn len(&self) -> usize {
        <[S]>::len(self)
    }
    #[inline(always)]
    unsafe fn get_unchecked(&self, i: usize) -> &S {
        // SAFETY: the caller keeps i in bounds.
        unsafe { <[S]>::get_unchecked(self, i) }
    }
    #[inline(always)]
    fn copy(&self, i: usize) -> S {
        self[i]
    }
}

struct ZeroState<'a, S>(&'a S);

impl<S: Copy> States<S> for ZeroState<'_, S> {
    fn len(&self) -> usize {
        usize::MAX
    }
    #[inline(always)]
    unsafe fn get_unchecked(&self, _: usize) -> &S {
        self.0
    }
    #[inline(always)]
    fn copy(&self, _: usize) -> S {
        *self.0
    }
}

/// What a sweep asks of the model for each bond. Not a closure: a closure holding a large
/// bond law (micropolar) was left out of line by the compiler, which cost 40 %; these calls are
/// forced inline.
trait BondVisit<M: Model, T> {
    fn visit(
        &self,
        law: &M::Law,
        i: &Side<M>,
        j: &Side<M>,
        geom: &BondGeom,
        bond: &mut M::Bond,
    ) -> Option<(T, T)>;
}

/// The state pass: each bond's contributions to its ends' states; it never breaks a bond.
struct StateOfBond<'a, M>(&'a M);

impl<M: Model> BondVisit<M, M::State> for StateOfBond<'_, M> {
    #[inline(always)]
    fn visit(
        &self,
        law: &M::Law,
        i: &Side<M>,
        j: &Side<M>,
        geom: &BondGeom,
        bond: &mut M::Bond,
    ) -> Option<(M::State, M::State)> {
        Some(self.0.state(law, i, j, geom, bond))
    }
}

/// The pair pass: each bond's generalized forces on its ends, or `None` when it breaks.
struct PairOfBond<'a, M>(&'a M);

impl<M: Model> BondVisit<M, M::Force> for PairOfBond<'_, M> {
    #[inline(always)]
    fn visit(
        &self,
        law: &M::Law,
        i: &Side<M>,
        j: &Side<M>,
        geom: &BondGeom,
        bond: &mut M::Bond,
    ) -> Option<(M::Force, M::Force)> {
        self.0.pair(law, i, j, geom, bond)
    }
}

/// The per-particle data a bond loop reads.
struct Ends<'a, M: Model, St> {
    n_owned: usize,
    x0: &'a [[f64; 3]],
    volume: &'a [f64],
    material: &'a [u16],
    fixed: &'a [M::Fixed],
    alter: &'a [M::Alter],
    state: St,
}

/// The bond loop of both passes: every intact bond of every owned particle, once, from its
/// owner. `visit` gives the two ends' contributions, added into `out` (zeroed first), or `None`
/// to break the bond; returns how many broke. Without `DAMAGE` every bond is intact and stays
/// so: the broken flags are neither read nor written (unbreakable scenes).
#[inline(always)]
fn sweep<M, T, St, L, V, const DAMAGE: bool>(
    ends: Ends<'_, M, St>,
    bonds: &mut BondList<M::Bond>,
    out: &mut [T],
    law_of: L,
    visit: V,
) -> usize
where
    M: Model,
    T: Attributes,
    St: States<M::State>,
    L: Fn(u16, u16) -> M::Law,
    V: BondVisit<M, T>,
{
    let Ends {
        n_owned,
        x0,
        volume,
        material,
        fixed,
        alter,
        state,
    } = ends;
    for o in out.iter_mut() {
        *o = T::default();
    }
    let bonds_max_partner = bonds.max_partner();
    let (offsets, partner, geom, broken, history) = bonds.parts_mut();
    let n = x0.len();
    assert!(
        n_owned <= n
            && offsets.len() == n_owned + 1
            && state.len() >= n
            && [
                volume.len(),
                material.len(),
                fixed.len(),
                alter.len(),
                out.len()
            ]
            .iter()
            .all(|&l| l == n)
            && (bonds_max_partner < n || offsets.last() == Some(&0)),
        "bond list does not match the particle store"
    );
    let mut newly_broken = 0;
    for i in 0..n_owned {
        // Local copies: the compiler cannot tell that the stores into `out` below leave
        // particle i's records alone, so references into the arrays would be reloaded on
        // every bond.
        let (x0_i, alter_i, fixed_i, state_i) = (x0[i], alter[i], fixed[i], state.copy(i));
        let side_i = Side::<M> {
            x0: &x0_i,
            volume: volume[i],
            material: material[i],
            alter: &alter_i,
            fixed: &fixed_i,
            state: &state_i,
        };
        let mut oi = T::default();
        let range = offsets[i] as usize..offsets[i + 1] as usize;
        let (partner, geom) = (&partner[range.clone()], &geom[range.clone()]);
        let (broken, history) = (&mut broken[range.clone()], &mut history[range]);
        // SAFETY: every partner index is below the particle count (BondList keeps the
        // partner list private and its maximum; checked above), and all per-particle arrays
        // have that length. Unchecked access lets the compiler drop the loads of fields the
        // model never reads, which bounds checks would keep alive.
        let side = |j: usize| unsafe {
            Side::<M> {
                x0: x0.get_unchecked(j),
                volume: *volume.get_unchecked(j),
                material: *material.get_unchecked(j),
                alter: alter.get_unchecked(j),
                fixed: fixed.get_unchecked(j),
                state: state.get_unchecked(j),
            }
        };
        let len = partner.len();
        let mut k = 0;
        while k < len {
            // Two intact bonds at once if the model asks (`Model::PAIRED_BONDS`): two copies of
            // the same arithmetic in one block, which the compiler pairs into vector
            // instructions, one lane per bond. The sums are made in bond order either way.
            let two = M::PAIRED_BONDS && k + 1 < len && (!DAMAGE || (!broken[k] && !broken[k + 1]));
            let n = if two { 2 } else { 1 };
            if DAMAGE && !two && broken[k] {
                k += 1;
                continue;
            }
            let (h1, h2) = history[k..].split_at_mut(1);
            let j1 = partner[k] as usize;
            let s1 = side(j1);
            let r1 = visit.visit(
                &law_of(side_i.material, s1.material),
                &side_i,
                &s1,
                &geom[k],
                &mut h1[0],
            );
            let r2 = two.then(|| {
                let j2 = partner[k + 1] as usize;
                let s2 = side(j2);
                let law = law_of(side_i.material, s2.material);
                (
                    j2,
                    visit.visit(&law, &side_i, &s2, &geom[k + 1], &mut h2[0]),
                )
            });
            // SAFETY (both): partners are in bounds, as above.
            newly_broken += add_or_break::<T, DAMAGE>(
                r1,
                &mut oi,
                unsafe { out.get_unchecked_mut(j1) },
                &mut broken[k],
            );
            if let Some((j2, r2)) = r2 {
                newly_broken += add_or_break::<T, DAMAGE>(
                    r2,
                    &mut oi,
                    unsafe { out.get_unchecked_mut(j2) },
                    &mut broken[k + 1],
                );
            }
            k += n;
        }
        add_assign(&mut out[i], &oi);
    }
    newly_broken
}

/// Adds a bond's contributions to its two ends, or marks it broken; returns how many broke.
/// Without `DAMAGE` a `None` (which an unbreakable law never returns) adds nothing.
#[inline(always)]
fn add_or_break<T: Attributes, const DAMAGE: bool>(
    r: Option<(T, T)>,
    oi: &mut T,
    oj: &mut T,
    broken: &mut bool,
) -> usize {
    match r {
        Some((a, b)) => {
            add_assign(oi, &a);
            add_assign(oj, &b);
            0
        }
        None if DAMAGE => {
            *broken = true;
            1
        }
        None => 0,
    }
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
