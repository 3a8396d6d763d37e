//! Setup per rank: each worker fills only the cells of its procCube and of its walls from the
//! analytic geometry ([`SceneSites`]), numbers its particles as the whole-scene setup would
//! (global ids from counting lattice rows), finds its own bonds and takes its share of the
//! boundary conditions, loads and probes; what the deck needs of the whole scene (the stable
//! step, a region that must select something, a load's total volume, the nearest particle to a
//! probe) is a reduction over the workers. Memory per worker is its procCube and walls, plus one
//! counter per cell and per lattice row; no array spans the scene's particles.
//!
//! The layout is cut from cell counts taken by walking the sites once per candidate grid, and
//! each procCube's store order (held cell by held cell; within a cell by the whole scene's
//! cell, then by global id) is the whole-scene setup's, so both give the same procCubes.

use crate::engine::bonds::BondList;
use crate::engine::cells::Domain;
use crate::engine::particles::Particles;
use crate::engine::simulation::{stiffness_sums, Simulation};
use crate::input::deck::{DeckError, Scene};
use crate::input::geometry::{SceneSites, Site};
use crate::input::setup::place::{self, Scope};
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};
use crate::parallel::comm::{Reduce, Team, Transport};
use crate::parallel::cube::Cube;
use crate::parallel::decomposition::{cell_plans, particle_plan, CellPlan, Layout, Procs, Walls};
use crate::parallel::wall::WallExchange;
use std::cell::RefCell;
use std::collections::HashMap;
use std::time::Instant;

/// One procCube built on its own, with what the run needs to know of the whole scene.
pub struct PartSetup<M: Model> {
    pub cube: Cube<M>,
    /// Silling–Askari bound of the whole scene and the global id of the particle setting it.
    pub dt_critical: f64,
    pub dt_critical_gid: u32,
    pub steps: u64,
    /// The scene's cells (the whole-scene setup's store order is by them).
    pub domain: Domain,
    /// Seconds this worker spent building its procCube.
    pub seconds: f64,
}

/// What every worker computes alike before building its procCube: the scene's sites, its
/// cells and the layout.
pub struct Parts {
    pub sites: SceneSites,
    pub domain: Domain,
    pub layout: Layout,
}

/// The sites, cells and layout of `scene` for `workers` procCubes (deck errors name their
/// line; layout errors are plain).
pub fn parts(scene: &Scene, procs: &Procs, walls: Walls, workers: usize) -> Result<Parts, String> {
    let sites = scene_sites(scene).map_err(|e| e.to_string())?;
    let domain = crate::input::setup::domain_of_box(sites.lo, sites.hi, sites.len(), scene, 0.0)
        .map_err(|e| e.to_string())?;
    let layout = layout(&sites, &domain, procs, walls, workers)?;
    Ok(Parts {
        sites,
        domain,
        layout,
    })
}

/// The scene's sites, with deck errors pointing at the entry that caused them.
fn scene_sites(scene: &Scene) -> Result<SceneSites, DeckError> {
    let ops = scene.geometry_ops();
    SceneSites::new(&scene.lattice, &ops, &scene.geometry_bars())
        .map_err(|e| crate::input::setup::geometry_error(scene, &ops, &e))
}

/// Particles per cell of `domain`'s grid, as `Layout::with_cells` takes them (no store order).
pub fn census(sites: &SceneSites, domain: &Domain) -> (Vec<u32>, Vec<u32>) {
    let g = &domain.grid;
    let mut start = vec![0u32; g.len() + 1];
    sites.for_each_position(|p| start[g.index(g.coords(p)) + 1] += 1);
    for c in 0..g.len() {
        start[c + 1] += start[c];
    }
    (start, Vec::new())
}

/// The layout of `workers` procCubes over `domain`, from cell counts.
pub fn layout(
    sites: &SceneSites,
    domain: &Domain,
    procs: &Procs,
    walls: Walls,
    workers: usize,
) -> Result<Layout, String> {
    let cells = |d: &Domain| census(sites, d);
    match procs {
        Procs::Auto => Layout::auto_with_cells(workers, domain, walls, &cells),
        Procs::Given(p) => {
            let n: usize = p.iter().product();
            if n != workers {
                return Err(format!(
                    "procs = {p:?} makes {n} procCubes but the run has {workers} workers (threads or MPI ranks); one procCube per worker"
                ));
            }
            Layout::with_cells(*p, domain, walls, &cells)
        }
    }
}

/// The particles of the cells `plan` holds, held cell by held cell (periodic images shifted),
/// in the whole-scene store order within each cell; with each held cell's count.
fn held_sites(
    sites: &SceneSites,
    domain: &Domain,
    layout: &Layout,
    plan: &CellPlan,
) -> (Vec<Site>, Vec<u32>) {
    let g = &layout.domain.grid;
    let mut holders: HashMap<usize, Vec<usize>> = HashMap::new();
    let (mut in_y, mut in_z) = (vec![false; g.dims[1]], vec![false; g.dims[2]]);
    for (h, held) in plan.held.iter().enumerate() {
        holders.entry(held.cell).or_default().push(h);
        let c = [
            held.cell % g.dims[0],
            held.cell / (g.dims[2] * g.dims[0]),
            (held.cell / g.dims[0]) % g.dims[2],
        ];
        debug_assert_eq!(g.index(c), held.cell);
        in_y[c[1]] = true;
        in_z[c[2]] = true;
    }
    let j = sites.jitter();
    let row = |y: f64, z: f64| {
        let (y0, y1) = (
            g.coords(&[0.0, y - j, z - j]),
            g.coords(&[0.0, y + j, z + j]),
        );
        (y0[1]..=y1[1]).any(|c| in_y[c]) && (y0[2]..=y1[2]).any(|c| in_z[c])
    };
    let cell = |p: &[f64; 3]| g.index(g.coords(p));
    let found = sites.select(row, |p| holders.contains_key(&cell(p)));
    let whole = &domain.grid;
    let mut by_cell: HashMap<usize, Vec<(usize, Site)>> = HashMap::new();
    for s in found {
        let key = (whole.index(whole.coords(&s.position)), s);
        by_cell.entry(cell(&s.position)).or_default().push(key);
    }
    let mut out = Vec::new();
    let mut counts = Vec::with_capacity(plan.held.len());
    for held in &plan.held {
        let list = by_cell.get_mut(&held.cell).map(|v| {
            v.sort_by_key(|(c, s)| (*c, s.gid));
            &*v
        });
        let list = list.map_or(&[][..], |v| v);
        let shift = [0, 1, 2].map(|a| held.wraps[a] as f64 * layout.domain.period[a]);
        counts.push(list.len() as u32);
        out.extend(list.iter().map(|(_, s)| Site {
            position: [0, 1, 2].map(|a| s.position[a] + shift[a]),
            ..*s
        }));
    }
    (out, counts)
}

/// Builds procCube `rank` of `layout` on its own (see the module doc). Every worker must call
/// it: the whole-scene checks are reductions.
pub fn build_part<M: Model>(
    model: M,
    scene: &Scene,
    parts: &Parts,
    rank: usize,
    transport: Box<dyn Transport>,
) -> Result<PartSetup<M>, DeckError> {
    let start = Instant::now();
    let (sites, domain, layout) = (&parts.sites, &parts.domain, &parts.layout);
    let plans = cell_plans(layout);
    let (found, counts) = held_sites(sites, domain, layout, &plans[rank]);
    let gids: Vec<u32> = found.iter().map(|s| s.gid).collect();
    let plan = particle_plan(rank, &plans[rank], &counts, gids, layout.domain.period);
    let mut p = Particles::new(
        &model,
        plan.global.clone(),
        found.iter().map(|s| s.position).collect(),
        found.iter().map(|s| s.volume).collect(),
        found.iter().map(|s| s.material).collect(),
    );
    let bar_of: Vec<u32> = found.iter().map(|s| s.bar).collect();
    drop(found);
    p.n_owned = plan.n_owned;
    let mut bonds: BondList<M::Bond> =
        plan.find_bonds(&p.x0, scene.horizon, scene.spacing, scene.partial_volume);
    let mut wall = WallExchange::new(plan.stages.clone(), transport);
    bars(&model, &mut p, &mut bonds, scene, &bar_of, &mut wall)?;
    drop(bar_of);
    let own_step = owned_stable_step(&model, &mut p, &bonds, &mut wall);
    let team = RefCell::new(Team::new(wall.transport()));
    coincident(&p, &bonds, scene, &team)?;
    let (dt_critical, dt_critical_gid) = stable_step::<M, _>(own_step, &team, scene)?;
    let local: HashMap<u32, u32> = (0..p.n_owned).map(|l| (p.gid[l], l as u32)).collect();
    let index = |g: u32| local.get(&g).copied();
    let sum = |x: f64| team.borrow_mut().sum(x);
    let scope = Scope {
        index: &index,
        total: sites.len(),
        sum: &sum,
    };
    place::initial_state(&mut p, scene, &scope)?;
    let constraints = place::constraints(&p, scene, &scope)?;
    let loads = place::loads(&p, scene, &scope)?;
    let probes = probes(&p, scene, &team);
    let limit_name = format!("Silling–Askari bound, set by particle {dt_critical_gid}");
    let (dt, steps) = crate::input::setup::time_step::below_limit(scene, dt_critical, &limit_name)?;
    drop(team);
    let mut sim = Simulation::new(model, p, bonds, dt);
    sim.integrator = scene.time.integrator;
    sim.constraints = constraints;
    sim.loads = loads;
    for c in &sim.constraints {
        c.set_velocity(&mut sim.particles, 0.0, dt);
    }
    let n_owned = plan.n_owned;
    let cube = Cube {
        wall,
        lost: vec![0; n_owned],
        sim,
        plan,
        layout: layout.clone(),
        probes,
        global_particles: sites.len(),
        dropped: Vec::new(),
        rebuilds: 0,
        deform: None,
    };
    Ok(PartSetup {
        cube,
        dt_critical,
        dt_critical_gid,
        steps,
        domain: domain.clone(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Two particles in one place (overlapping shapes and bars) would make a bond of length zero.
fn coincident<M: Model, T: Transport>(
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
    scene: &Scene,
    team: &RefCell<Team<T>>,
) -> Result<(), DeckError> {
    let found = bonds
        .iter()
        .find(|&(_, _, b)| bonds.geom[b].length < 1e-6 * scene.spacing);
    let any = team
        .borrow_mut()
        .max(if found.is_some() { 1.0 } else { 0.0 });
    if any == 0.0 {
        return Ok(());
    }
    let what = found.map_or("on another procCube".to_string(), |(i, j, _)| {
        format!(
            "{} and {} (at {:?} and {:?})",
            p.gid[i], p.gid[j], p.x0[i], p.x0[j]
        )
    });
    Err(scene.error(
        None,
        format!(
            "particles {what} coincide: overlapping bars or shapes put two particles in one place"
        ),
    ))
}

/// The bars' calibration and prestrains (`input/bars.rs`) on a procCube built on its own: a
/// bar particle's energy is completed over the walls (its bonds held by neighbours), and each
/// bar's sums over every procCube, so γ is the whole-scene setup's to round-off. `bar_of` is
/// the bar of each store particle.
fn bars<M: Model>(
    model: &M,
    q: &mut Particles<M>,
    bonds: &mut BondList<M::Bond>,
    scene: &Scene,
    bar_of: &[u32],
    wall: &mut WallExchange,
) -> Result<(), DeckError> {
    if scene.bars.is_empty() {
        return Ok(());
    }
    let base = whole_fixed(model, q, bonds, wall);
    let wall = RefCell::new(wall);
    let bar = |l: usize| bar_of[l];
    let share = crate::input::bars::Share {
        bar: &bar,
        complete: &mut |w: &mut [f64]| wall.borrow_mut().reverse(w, |a, b| *a += *b),
        sum: &mut |v: &mut [f64]| Team::new(wall.borrow_mut().transport()).reduce(v, Reduce::Sum),
    };
    let factor = crate::input::setup::bar_factors(model, q, bonds, scene, share);
    q.fixed = base;
    let applied = crate::input::bars::BarBonds {
        bar_of: Vec::new(),
        factor: factor?,
        bars: scene.geometry_bars(),
        prestrain: scene.bar_prestrain(),
    };
    applied.apply_by_store(model, bonds, &q.x0, bar);
    Ok(())
}

/// The fixed values bonds make (the weighted volume) made whole over the walls, for a pass that
/// needs them before `Cube::start` does; returns the values to put back afterwards.
fn whole_fixed<M: Model>(
    model: &M,
    q: &mut Particles<M>,
    bonds: &BondList<M::Bond>,
    wall: &mut WallExchange,
) -> Vec<M::Fixed> {
    use crate::model::attributes::add_assign;
    let base = q.fixed.clone();
    if M::FIXED_FROM_BONDS {
        let mut sums = crate::engine::bond_sums::bond_fixed_sums(model, q, bonds);
        wall.reverse(&mut sums, add_assign);
        for (f, s) in q.fixed.iter_mut().zip(&sums).take(q.n_owned) {
            add_assign(f, s);
        }
        wall.forward(&mut q.fixed, false);
    }
    base
}

/// The Silling–Askari bound of the owned particles: each particle's stiffness summed over
/// the bonds of every procCube (the wall's reverse messages), after the fixed values bonds make
/// (the weighted volume) are whole; the smallest step and its particle's global id.
fn owned_stable_step<M: Model>(
    model: &M,
    q: &mut Particles<M>,
    bonds: &BondList<M::Bond>,
    wall: &mut WallExchange,
) -> (f64, u32) {
    use crate::model::attributes::add_assign;
    // `Cube::start` makes the fixed values whole again; these are for the bound only.
    let base = whole_fixed(model, q, bonds, wall);
    let mut sums = stiffness_sums(model, q, bonds);
    wall.reverse(&mut sums, add_assign);
    let n2 = second_order::<M>();
    let mut best = (f64::INFINITY, u32::MAX);
    for (i, s) in sums.iter().enumerate().take(q.n_owned) {
        let inv = q.inv_inertia[i].as_slice();
        for (k, &s) in s.as_slice().iter().enumerate() {
            if s > 0.0 {
                let inertia = 1.0 / (inv[k] * q.volume[i] * s);
                let dt = if k < n2 {
                    (2.0 * inertia).sqrt()
                } else {
                    inertia
                };
                if (dt, q.gid[i]) < best {
                    best = (dt, q.gid[i]);
                }
            }
        }
    }
    q.fixed = base;
    best
}

/// The whole scene's stable step from each procCube's own: the smallest, ties to the smaller
/// global id; checked as the whole-scene setup checks it.
fn stable_step<M: Model, T: Transport>(
    own: (f64, u32),
    team: &RefCell<Team<T>>,
    scene: &Scene,
) -> Result<(f64, u32), DeckError> {
    let mut t = team.borrow_mut();
    let mut dt = [own.0];
    t.reduce(&mut dt, Reduce::Min);
    let mut gid = [if own.0 == dt[0] {
        own.1 as f64
    } else {
        f64::INFINITY
    }];
    t.reduce(&mut gid, Reduce::Min);
    let dt = dt[0];
    crate::input::setup::check_stable_step::<M>(scene, dt)?;
    Ok((dt, gid[0] as u32))
}

/// Each probe's particle where this procCube owns it: the particle nearest the probe's point
/// over every procCube, ties to the smaller global id.
fn probes<M: Model, T: Transport>(
    p: &Particles<M>,
    scene: &Scene,
    team: &RefCell<Team<T>>,
) -> Vec<(usize, usize)> {
    let mut t = team.borrow_mut();
    let mut mine = Vec::new();
    for (k, pr) in scene.probes.iter().enumerate() {
        let near = place::nearest(p, pr.at);
        let mut d = [near.map_or(f64::INFINITY, |n| n.0)];
        t.reduce(&mut d, Reduce::Min);
        let gid = |n: (f64, usize)| {
            if n.0 == d[0] {
                p.gid[n.1] as f64
            } else {
                f64::INFINITY
            }
        };
        let mut g = [near.map_or(f64::INFINITY, gid)];
        t.reduce(&mut g, Reduce::Min);
        if let Some((_, i)) = near.filter(|n| gid(*n) == g[0]) {
            mine.push((k, i));
        }
    }
    mine
}
