//! The bond loops: the optional state pass and the pair pass, generic over the model.
//!
//! These are the only loops over bonds in a time step. Each bond is visited once from its
//! owner; the model returns the generalized force on both ends and the loop adds them, so
//! equal-and-opposite forces and unequal micropolar moments go through the same code.

use std::marker::PhantomData;

use crate::engine::bond_geoms::GeomSlice;
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
            let law = OneLaw(model.law(m, m));
            sweep::<_, _, _, _, _, DAMAGE>(ends, bonds, out, law, visit)
        }
        None => sweep::<_, _, _, _, _, DAMAGE>(ends, bonds, out, LawPerPair(model), visit),
    }
}

/// Where a sweep takes each bond's law from.
trait Laws<M: Model> {
    /// The law between materials `a` and `b`.
    fn of(&self, a: u16, b: u16) -> M::Law;
    /// `f` of the laws between `a` and each of `b`.
    fn group<R>(&self, a: u16, b: [u16; LANES], f: impl FnOnce([&M::Law; LANES]) -> R) -> R;
}

/// One material: one law, read from one place (not copied per bond: four fresh copies on
/// the stack, read back as one vector, stalled the lane loop on store forwarding).
struct OneLaw<L>(L);

impl<M: Model> Laws<M> for OneLaw<M::Law> {
    #[inline(always)]
    fn of(&self, _: u16, _: u16) -> M::Law {
        self.0
    }
    #[inline(always)]
    fn group<R>(&self, _: u16, _: [u16; LANES], f: impl FnOnce([&M::Law; LANES]) -> R) -> R {
        f([&self.0; LANES])
    }
}

/// Several materials: the model's law of each pair.
struct LawPerPair<'a, M>(&'a M);

impl<M: Model> Laws<M> for LawPerPair<'_, M> {
    #[inline(always)]
    fn of(&self, a: u16, b: u16) -> M::Law {
        self.0.law(a, b)
    }
    #[inline(always)]
    fn group<R>(&self, a: u16, b: [u16; LANES], f: impl FnOnce([&M::Law; LANES]) -> R) -> R {
        let laws = b.map(|b| self.0.law(a, b));
        f(laws.each_ref())
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

    #[inline(always)]
    fn visit_lanes(
        &self,
        law: [&M::Law; LANES],
        i: &Side<M>,
        j: [&Side<M>; LANES],
        geom: [&BondGeom; LANES],
    ) -> Option<LaneForces> {
        self.0.state_lanes(law, i, j, geom)
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
    laws: L,
    visit: V,
) -> usize
where
    M: Model,
    T: Attributes,
    St: States<M::State>,
    L: Laws<M>,
    V: BondVisit<M, T>,
{
    for o in out.iter_mut() {
        *o = T::default();
    }
    ends_check(&ends, out.len(), bonds);
    let Ends {
        n_owned,
        x0,
        volume,
        material,
        fixed,
        alter,
        state,
    } = ends;
    let (offsets, partner, geom, broken, history) = bonds.parts_mut();
    // SAFETY: every partner index is below the particle count (BondList keeps the partner
    // list private and its maximum; checked above), and all per-particle arrays have that
    // length. Unchecked access lets the compiler drop the loads of fields the model never
    // reads, which bounds checks would keep alive.
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
    let mut sweeper = Sweeper::<M, T, _, L, V, DAMAGE> {
        side,
        laws,
        visit,
        out,
        model: PhantomData,
    };
    let mut newly_broken = 0;
    for i in 0..n_owned {
        // Local copies: the compiler cannot tell that the stores into `out` below leave
        // particle i's records alone, so references into the arrays would be reloaded on
        // every bond.
        let (x0_i, alter_i, fixed_i, state_i) = (x0[i], alter[i], fixed[i], state.copy(i));
        let owner = Side::<M> {
            x0: &x0_i,
            volume: volume[i],
            material: material[i],
            alter: &alter_i,
            fixed: &fixed_i,
            state: &state_i,
        };
        let range = offsets[i] as usize..offsets[i + 1] as usize;
        let family = Family {
            partner: &partner[range.clone()],
            geom: geom.slice(range.clone()),
            broken: &mut broken[range.clone()],
            history: &mut history[range],
        };
        // SAFETY: the partners are in bounds of `out` and of `side`, as above.
        let (oi, broke) = unsafe { sweeper.family(&owner, family) };
        newly_broken += broke;
        add_assign(&mut sweeper.out[i], &oi);
    }
    newly_broken
}

/// One owner's bonds, as the sweep visits them.
struct Family<'a, M: Model> {
    partner: &'a [u32],
    geom: GeomSlice<'a>,
    broken: &'a mut [bool],
    history: &'a mut [M::Bond],
}

/// What stays the same through one sweep: how a partner is read (`side`), where the laws come
/// from, what the model is asked for each bond (`visit`), and the records the partners'
/// contributions go into (`out`).
struct Sweeper<'o, M, T, S, L, V, const DAMAGE: bool> {
    side: S,
    laws: L,
    visit: V,
    out: &'o mut [T],
    model: PhantomData<fn() -> M>,
}

impl<'s, M, T, S, L, V, const DAMAGE: bool> Sweeper<'_, M, T, S, L, V, DAMAGE>
where
    M: Model + 's,
    T: Attributes,
    S: Fn(usize) -> Side<'s, M>,
    L: Laws<M>,
    V: BondVisit<M, T>,
{
    /// Visits the family's intact bonds in bond order, adding each partner's contribution into
    /// `out`; returns the owner's sum and how many bonds broke. Four bonds go at once if the
    /// model asks (`Model::BOND_LANES`) and the next four are intact, as one lane group;
    /// otherwise, or if the model refuses the group (one of its bonds breaks now), they go
    /// one by one. The sums are made in bond order either way.
    ///
    /// # Safety
    /// Every partner is below `out.len()` and is a particle `side` may read.
    #[inline(always)]
    unsafe fn family(&mut self, owner: &Side<'_, M>, mut family: Family<'_, M>) -> (T, usize) {
        // The owner's sum: in `oi`, or in `lane_sum` while lane groups run.
        let mut oi = T::default();
        let mut lane_sum = OwnerSum::from(&oi);
        let mut in_lanes = M::BOND_LANES == LANES;
        let mut newly_broken = 0;
        let len = family.partner.len();
        let mut k = 0;
        while k < len {
            let mut end = k + 1;
            if M::BOND_LANES == LANES && k + LANES <= len {
                if !in_lanes {
                    lane_sum = OwnerSum::from(&oi);
                    in_lanes = true;
                }
                let group = Group {
                    owner,
                    js: std::array::from_fn(|l| family.partner[k + l] as usize),
                    geoms: std::array::from_fn(|l| family.geom.get(k + l)),
                };
                let intact = !DAMAGE || !family.broken[k..k + LANES].iter().any(|&b| b);
                // SAFETY: the caller keeps the partners in bounds.
                if intact && unsafe { self.group(&group, &mut lane_sum) } {
                    k += LANES;
                    continue;
                }
                end = k + LANES;
            }
            if in_lanes {
                lane_sum.store(&mut oi);
                in_lanes = false;
            }
            // SAFETY: the caller keeps the partners in bounds.
            newly_broken += unsafe { self.one_by_one(owner, &mut family, k..end, &mut oi) };
            k = end;
        }
        if in_lanes {
            lane_sum.store(&mut oi);
        }
        (oi, newly_broken)
    }

    /// Visits the intact bonds `bonds` of `family` one at a time, adding into the owner's sum
    /// `oi` and the partners' records, or breaking them; returns how many broke.
    ///
    /// # Safety
    /// As [`Sweeper::family`].
    #[inline(always)]
    unsafe fn one_by_one(
        &mut self,
        owner: &Side<'_, M>,
        family: &mut Family<'_, M>,
        bonds: std::ops::Range<usize>,
        oi: &mut T,
    ) -> usize {
        let mut newly_broken = 0;
        for k in bonds {
            if DAMAGE && family.broken[k] {
                continue;
            }
            let j = family.partner[k] as usize;
            let sj = (self.side)(j);
            let law = self.laws.of(owner.material, sj.material);
            let geom = family.geom.get(k);
            let r = self
                .visit
                .visit(&law, owner, &sj, geom, &mut family.history[k]);
            // SAFETY: the caller keeps the partners in bounds.
            newly_broken += add_or_break::<T, DAMAGE>(
                r,
                oi,
                unsafe { self.out.get_unchecked_mut(j) },
                &mut family.broken[k],
            );
        }
        newly_broken
    }

    /// Runs a lane group through the model's lane law and adds its forces to the owner's sum
    /// `oi` and to the partners; false (nothing added) if the model refuses it.
    ///
    /// # Safety
    /// Every partner in the group is below `out.len()` and is a particle `side` may read.
    #[inline(always)]
    unsafe fn group(&mut self, group: &Group<'_, M>, oi: &mut OwnerSum) -> bool {
        let sides = group.js.map(&self.side);
        let materials = sides.each_ref().map(|s| s.material);
        let visit = &self.visit;
        let forces = self.laws.group(group.owner.material, materials, |laws| {
            visit.visit_lanes(laws, group.owner, sides.each_ref(), group.geoms)
        });
        match forces {
            Some(f) => {
                // SAFETY: the caller keeps the partners in bounds.
                unsafe { add_lanes(oi, self.out, group.js, &f) };
                true
            }
            None => false,
        }
    }
}

/// [`check_store`] for one sweep's per-particle arrays, its output and its bond list.
fn ends_check<M: Model, St: States<M::State>, B: Attributes>(
    ends: &Ends<'_, M, St>,
    n_out: usize,
    bonds: &BondList<B>,
) {
    let lengths = [
        ends.volume.len(),
        ends.material.len(),
        ends.fixed.len(),
        ends.alter.len(),
        n_out,
    ];
    let n = ends.x0.len();
    let offsets = bonds.offsets();
    check_store(
        ends.n_owned,
        n,
        &lengths,
        ends.state.len(),
        offsets,
        bonds.max_partner(),
    );
}

/// The bond list and the particle store must agree: this is what makes the unchecked partner
/// access of [`sweep`] sound.
fn check_store(
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
}

/// Four intact bonds of one owner, for a model with lanes.
struct Group<'a, M: Model> {
    owner: &'a Side<'a, M>,
    js: [usize; LANES],
    geoms: [&'a BondGeom; LANES],
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

/// The owner's running force sum while lane groups run: components 4b..4b + 4 in `self.0[b]`,
/// kept in registers rather than stored and reloaded for every group.
#[derive(Clone, Copy)]
struct OwnerSum([F4; 2]);

impl OwnerSum {
    #[inline(always)]
    fn from<T: Attributes>(o: &T) -> OwnerSum {
        let s = o.as_slice();
        let block = |c: usize| F4::load_partial(if c < s.len() { &s[c..] } else { &[] });
        OwnerSum([block(0), block(LANES)])
    }

    #[inline(always)]
    fn store<T: Attributes>(self, o: &mut T) {
        let s = o.as_mut_slice();
        let n = s.len();
        self.0[0].store_partial(&mut s[..n.min(LANES)]);
        if n > LANES {
            self.0[1].store_partial(&mut s[LANES..]);
        }
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
unsafe fn add_lanes<T: Attributes>(
    oi: &mut OwnerSum,
    out: &mut [T],
    js: [usize; LANES],
    f: &LaneForces,
) {
    let n = T::LEN;
    assert!(
        n <= MAX_COMPONENTS,
        "a model with lanes has at most 8 force components"
    );
    let mut c = 0;
    while c < n {
        let m = (n - c).min(LANES);
        let block = |v: &[F4; MAX_COMPONENTS]| F4::transpose([v[c], v[c + 1], v[c + 2], v[c + 3]]);
        let ti = block(&f.i);
        // Equal and opposite forces need no second transpose.
        let tj = if f.opposite {
            ti.map(|t| -t)
        } else {
            block(&f.j)
        };
        let sum = &mut oi.0[c / LANES];
        for t in ti {
            *sum = *sum + t;
        }
        for (l, t) in tj.into_iter().enumerate() {
            // SAFETY: the caller keeps js[l] in bounds.
            let o = &mut unsafe { out.get_unchecked_mut(js[l]) }.as_mut_slice()[c..c + m];
            (F4::load_partial(o) + t).store_partial(o);
        }
        c += LANES;
    }
}
