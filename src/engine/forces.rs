//! The bond loops: the optional state pass and the pair pass, generic over the model.
//!
//! These are the only loops over bonds in a time step. Each bond is visited once from its
//! owner; the model returns the generalized force on both ends and the loop adds them, so
//! equal-and-opposite forces and unequal micropolar moments go through the same code.

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::model::attributes::{add_assign, Attributes};
use crate::model::lanes::{LaneForces, F4, LANES, MAX_COMPONENTS};
use crate::model::{BondGeom, Model, Side};

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

    /// Four intact bonds of particle `i` at once (see [`Model::pair_lanes`]), or `None`: one
    /// by one.
    #[inline(always)]
    fn visit_lanes(
        &self,
        _law: [&M::Law; LANES],
        _i: &Side<M>,
        _j: [&Side<M>; LANES],
        _geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        None
    }
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

    #[inline(always)]
    fn visit_lanes(
        &self,
        law: [&M::Law; LANES],
        i: &Side<M>,
        j: [&Side<M>; LANES],
        geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        self.0.pair_lanes(law, i, j, geom)
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
    let lengths = [
        volume.len(),
        material.len(),
        fixed.len(),
        alter.len(),
        out.len(),
    ];
    let (n, n_state) = (x0.len(), state.len());
    check_store::<M>(n_owned, n, &lengths, n_state, offsets, bonds_max_partner);
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
        let (partner, geom) = (&partner[range.clone()], geom.slice(range.clone()));
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
            // Bonds k..end go one by one.
            let mut end = k + 1;
            // Four intact bonds at once if the model asks (`Model::BOND_LANES`): the next four
            // intact ones, as one lane group. The sums are made in bond order either way, and
            // broken bonds add nothing, so skipping them changes nothing. If one of the four
            // breaks, the model says so and they go one by one.
            if M::BOND_LANES == LANES {
                let (at, n, next) = intact_group::<DAMAGE>(broken, k);
                if n == LANES {
                    let js = at.map(|b| partner[b] as usize);
                    let sides = js.map(side);
                    let laws = sides
                        .each_ref()
                        .map(|s| law_of(side_i.material, s.material));
                    let geoms = at.map(|b| geom.get(b));
                    let lanes = (laws.each_ref(), sides.each_ref());
                    if let Some(f) = visit.visit_lanes(lanes.0, &side_i, lanes.1, geoms) {
                        // SAFETY: partners are in bounds, as above.
                        unsafe { add_lanes(&mut oi, out, js, &f) };
                        k = next;
                        continue;
                    }
                }
                // A refused group, or fewer than four intact bonds left (then `next` is the
                // end of the list): one by one up to where the search stopped.
                end = next;
            }
            while k < end {
                if !(DAMAGE && broken[k]) {
                    let j = partner[k] as usize;
                    let sj = side(j);
                    let r = visit.visit(
                        &law_of(side_i.material, sj.material),
                        &side_i,
                        &sj,
                        geom.get(k),
                        &mut history[k],
                    );
                    // SAFETY: partners are in bounds, as above.
                    newly_broken += add_or_break::<T, DAMAGE>(
                        r,
                        &mut oi,
                        unsafe { out.get_unchecked_mut(j) },
                        &mut broken[k],
                    );
                }
                k += 1;
            }
        }
        add_assign(&mut out[i], &oi);
    }
    newly_broken
}

/// The bond list and the particle store must agree: this is what makes the unchecked partner
/// access of [`sweep`] sound.
fn check_store<M: Model>(
    n_owned: usize,
    n: usize,
    lengths: &[usize],
    states: usize,
    offsets: &[u32],
    max_partner: usize,
) {
    assert!(
        n_owned <= n
            && offsets.len() == n_owned + 1
            && states >= n
            && lengths.iter().all(|&l| l == n)
            && (max_partner < n || offsets.last() == Some(&0)),
        "bond list does not match the particle store"
    );
    assert!(
        M::BOND_LANES == 1 || <M::Bond as Attributes>::LEN == 0,
        "a model with lanes keeps no bond history"
    );
}

/// The next `LANES` intact bonds of a particle's list from `k` on: their places, how many
/// were found (fewer at the list's end) and where the search stopped.
#[inline(always)]
fn intact_group<const DAMAGE: bool>(broken: &[bool], k: usize) -> ([usize; LANES], usize, usize) {
    let mut at = [0usize; LANES];
    let (mut n, mut next) = (0, k);
    while n < LANES && next < broken.len() {
        if !DAMAGE || !broken[next] {
            at[n] = next;
            n += 1;
        }
        next += 1;
    }
    (at, n, next)
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

/// Adds a lane group's forces: lane by lane (bond order) to the owner's sum `oi`, and lane l
/// to partner `js[l]`. Each record is handled four components at a time: the four bonds'
/// components are turned into one vector per bond, then added as vectors, which makes the
/// same sums as adding value by value.
///
/// # Safety
/// Every `js[l]` is below `out.len()`.
#[inline(always)]
unsafe fn add_lanes<T: Attributes>(oi: &mut T, out: &mut [T], js: [usize; LANES], f: &LaneForces) {
    let n = T::LEN;
    assert!(
        n <= MAX_COMPONENTS,
        "a model with lanes has at most 8 force components"
    );
    let mut c = 0;
    while c < n {
        let m = (n - c).min(LANES);
        let block = |v: &[F4; MAX_COMPONENTS]| F4::transpose([v[c], v[c + 1], v[c + 2], v[c + 3]]);
        let (ti, tj) = (block(&f.i), block(&f.j));
        let own = &mut oi.as_mut_slice()[c..c + m];
        let mut sum = F4::load_partial(own);
        for t in ti {
            sum = sum + t;
        }
        sum.store_partial(own);
        for (l, t) in tj.into_iter().enumerate() {
            // SAFETY: the caller keeps js[l] in bounds.
            let o = &mut unsafe { out.get_unchecked_mut(js[l]) }.as_mut_slice()[c..c + m];
            (F4::load_partial(o) + t).store_partial(o);
        }
        c += LANES;
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
