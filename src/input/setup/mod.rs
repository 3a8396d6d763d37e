//! From a checked deck to a ready-to-step simulation: geometry → particles → bonds → time step
//! → boundary conditions and loads → thermostat.

use crate::engine::bonds::BondList;
use crate::engine::cells::CellGrid;
use crate::engine::cells::Domain;
use crate::engine::particles::Particles;
use crate::engine::simulation::{stable_time_step, Simulation};
use crate::input::bars::BarBonds;
use crate::input::deck::{DeckError, Scene};
use crate::input::geometry;
use crate::model::attributes::Attributes;
use crate::model::{Model, ModelBuild, ModelVisitor};
use std::time::Instant;

mod maxwell;
pub mod memory;
mod pairs;
pub(crate) mod place;
mod thermostat;
pub(crate) mod time_step;

/// A simulation built from a deck, with what the deck's checks found.
pub struct Setup<M: Model> {
    pub sim: Simulation<M>,
    /// Silling–Askari bound and the particle (store index) that sets it.
    pub dt_critical: f64,
    pub dt_critical_particle: usize,
    /// With `[time] critical_step = "measured"` (explicit runs): the critical step measured on
    /// the stiffest mode (`spectrum::critical_time_step`; for first-order DOFs still their
    /// bound), and the force evaluations it took.
    pub dt_measured: Option<(f64, u64)>,
    pub steps: u64,
    /// Probe name and the store index of the particle nearest to it.
    pub probes: Vec<(String, usize)>,
    pub seconds: f64,
    /// The cells the wall method cuts into procCubes (the store is in their order).
    pub domain: Domain,
    pub horizon: f64,
    pub spacing: f64,
    pub partial_volume: bool,
    /// Energy surface correction factors gᵢᵏ by store index, if the deck asks for them.
    pub correction: Option<Vec<[f64; 3]>>,
    /// Explicit stepping, or relaxation to equilibrium at each load step.
    pub solver: crate::input::deck::SolverSpec,
    /// Calibration factors and prestrain of the bars' own bonds.
    pub bars: BarBonds,
    /// What the memory guard estimated before building.
    pub memory: memory::Estimate,
}

impl<M: Model> Setup<M> {
    /// The critical step Δt was chosen against: the measured one if the deck asked for it,
    /// else the Silling–Askari bound.
    pub fn dt_limit(&self) -> f64 {
        self.dt_measured.map_or(self.dt_critical, |(dt, _)| dt)
    }
}

/// Builds the model named by the deck and hands it to `visitor`.
pub fn with_model<V: ModelVisitor>(scene: &Scene, visitor: V) -> Result<V::Output, DeckError> {
    let build = ModelBuild {
        materials: &scene.materials,
        horizon: scene.horizon,
        spacing: scene.spacing,
        options: &scene.model_options,
    };
    crate::models::visit(&scene.model, &build, visitor).map_err(|e| scene.model_error(&e))
}

/// Builds the simulation of `scene` with `model`: the particles in cell order, their bonds,
/// the time step, then what the deck places on the particles, and the first forces.
pub fn build<M: Model>(model: M, scene: &Scene) -> Result<Setup<M>, DeckError> {
    let start = Instant::now();
    let pair_pass = pairs::pair_pass(&model, scene)?;
    let reach = pair_pass.as_ref().map_or(0.0, |p| p.reach());
    let memory = memory::guard::<M>(scene, reach)?;
    let (mut particles, cloud_bar, domain, gid_to_index) = particles(&model, scene, reach)?;
    let (bonds, correction, bars) = bonds(&model, &mut particles, scene, cloud_bar)?;
    let (dt_critical, dt_critical_particle) = stable_time_step(&model, &particles, &bonds);
    check_stable_step::<M>(scene, dt_critical)?;
    let index = |g: u32| gid_to_index.get(g as usize).copied();
    let scope = place::Scope::whole(&index, gid_to_index.len());
    place::initial_state(&mut particles, scene, &scope)?;
    place::thermal_velocities(&mut particles, scene, &scope)?;
    let constraints = place::constraints(&particles, scene, &scope)?;
    let loads = place::loads(&particles, scene, &scope)?;
    let probes = place::probes(&particles, scene);

    let mut sim = Simulation::new(
        model,
        particles,
        bonds,
        scene.time.safety_factor * dt_critical,
    );
    sim.constraints = constraints;
    sim.loads = loads;
    sim.integrator = scene.time.integrator;
    let stepping = time_step::stepping(&mut sim, scene, dt_critical, dt_critical_particle)?;
    let dt = stepping.dt;
    sim.dt = dt;
    sim.thermostat = thermostat::thermostat(&sim, scene, &scope)?;
    for c in &sim.constraints {
        c.set_velocity(&mut sim.particles, 0.0, dt);
    }
    sim.compute_forces();
    // The pass joins after the bonds' first forces: its lists are built per procCube, from
    // their cells (`Cube::start`).
    sim.pairs = pair_pass;
    let seconds = start.elapsed().as_secs_f64();
    sim.timing = crate::engine::timing::Timing::default();
    sim.timing
        .add(crate::engine::timing::Phase::Setup, start.elapsed());
    Ok(Setup {
        sim,
        dt_critical,
        dt_critical_particle,
        dt_measured: stepping.dt_measured,
        steps: stepping.steps,
        probes,
        seconds,
        domain,
        horizon: scene.horizon,
        spacing: scene.spacing,
        partial_volume: scene.partial_volume,
        correction,
        solver: scene.solver.item.clone(),
        bars,
        memory,
    })
}

/// Refuses a stable step that is not a positive number, or none at all for a bonded model.
pub fn check_stable_step<M: Model>(scene: &Scene, dt_critical: f64) -> Result<(), DeckError> {
    if dt_critical.is_nan() || dt_critical <= 0.0 {
        return Err(scene.error(
            None,
            format!("the stable time step is {dt_critical:e}: check the materials' stiffness and density"),
        ));
    }
    // A bondless model has no stable step; its deck gives dt (checked with `[time]`).
    if !dt_critical.is_finite() && M::BONDED {
        return Err(scene.error(
            None,
            "no particle has a bond: the horizon is too small for the particle spacing",
        ));
    }
    Ok(())
}

/// The deck's particles, stored in cell order so that bond partners are near each other in
/// memory and the wall method finds each cell's particles in one run; with each particle's
/// bar by global id, the cells and the store index of each global id.
#[allow(clippy::type_complexity)]
fn particles<M: Model>(
    model: &M,
    scene: &Scene,
    reach: f64,
) -> Result<(Particles<M>, Vec<u32>, Domain, Vec<u32>), DeckError> {
    let ops = scene.geometry_ops();
    let cloud = geometry::build(&scene.lattice, &ops, &scene.geometry_bars())
        .map_err(|e| geometry_error(scene, &ops, &e))?;
    let domain = domain(&cloud.position, scene, reach)?;
    let (_, _, order) = domain.grid.bin(&cloud.position);
    let gid: Vec<u32> = order.clone();
    let x0 = order.iter().map(|&g| cloud.position[g as usize]).collect();
    let volume = order.iter().map(|&g| cloud.volume[g as usize]).collect();
    let material = order.iter().map(|&g| cloud.material[g as usize]).collect();
    let mut gid_to_index = vec![0u32; gid.len()];
    for (i, &g) in gid.iter().enumerate() {
        gid_to_index[g as usize] = i as u32;
    }
    let particles = Particles::new(model, gid, x0, volume, material);
    Ok((particles, cloud.bar, domain, gid_to_index))
}

/// A geometry error as a deck error at the entry or bar that caused it; an empty scene is
/// blamed on the last subtraction, the usual culprit.
pub fn geometry_error(
    scene: &Scene,
    ops: &[geometry::Op],
    e: &geometry::GeometryError,
) -> DeckError {
    let subtract = |o: &geometry::Op| e.empty && matches!(o, geometry::Op::Subtract { .. });
    let last_subtract = ops.iter().rposition(subtract).map(|k| scene.ops[k].line);
    let line = e
        .entry
        .map(|k| scene.ops[k].line)
        .or(e.bar.map(|k| scene.bars[k].line))
        .or(last_subtract);
    scene.error(line, e.message.clone())
}

/// The bonds within the horizon, with the surface correction if the deck asks for it and the
/// bars' calibration and prestrain applied; `bar_of` is each particle's bar by global id.
#[allow(clippy::type_complexity)]
fn bonds<M: Model>(
    model: &M,
    particles: &mut Particles<M>,
    scene: &Scene,
    bar_of: Vec<u32>,
) -> Result<(BondList<M::Bond>, Option<Vec<[f64; 3]>>, BarBonds), DeckError> {
    if !M::BONDED {
        if let Some(b) = scene.bars.iter().find(|b| b.prestrain.strain != 0.0) {
            return Err(scene.error(
                Some(b.line),
                format!(
                    "[[bar]] prestrain: model '{}' has no bonds to prestrain",
                    M::NAME
                ),
            ));
        }
        return Ok((no_bonds(particles.len()), None, BarBonds::default()));
    }
    let mut bonds = BondList::<M::Bond>::find(
        &particles.x0,
        particles.n_owned,
        scene.horizon,
        scene.spacing,
        scene.partial_volume,
    );
    crate::engine::bond_sums::add_bond_fixed(model, particles, &bonds);
    let correction = if scene.surface_correction {
        if <M::State as Attributes>::LEN > 0 {
            return Err(scene.error(
                Some(scene.model_lines.model),
                format!("[model] surface_correction = \"energy\" is for bond-based models; model '{}' is state-based (its weighted volume already uses the discrete family)", M::NAME),
            ));
        }
        let g = crate::engine::correction::energy_factors(model, particles, &bonds);
        let bar = |i: usize| bar_of[particles.gid[i] as usize];
        crate::engine::correction::correct_bonds(
            &mut bonds,
            &particles.x0,
            |i| g[i],
            |i, j| bar(i) != geometry::NOT_A_BAR && bar(i) == bar(j),
        );
        Some(g)
    } else {
        None
    };
    // Particles in one place (overlapping bars, say) would make a bond of length zero.
    if let Some((i, j, _)) = bonds
        .iter()
        .find(|&(_, _, b)| bonds.geom[b].length < 1e-6 * scene.spacing)
    {
        return Err(scene.error(
            None,
            format!(
                "particles {} and {} coincide (at {:?} and {:?}): overlapping bars or shapes put two particles in one place",
                particles.gid[i], particles.gid[j], particles.x0[i], particles.x0[j]
            ),
        ));
    }
    let bars = bar_bonds(model, particles, &bonds, scene, bar_of)?;
    bars.apply(model, &mut bonds, &particles.x0, |i| particles.gid[i]);
    Ok((bonds, correction, bars))
}

/// The bond list of a bondless model: every family empty. (A search at its horizon, 0, would
/// find the same, but cells of side 0 cannot cover a scene.)
fn no_bonds<H: Attributes>(n: usize) -> BondList<H> {
    let mut families = crate::engine::bonds::Families::new(n, 0.0, 1.0, false);
    for i in 0..n {
        families.close(i, &mut []);
    }
    families.finish()
}

/// The bars' calibration factors (bond-based models) and prestrained bond histories; see
/// `input/bars.rs`. `bar_of` is by global id.
fn bar_bonds<M: Model>(
    model: &M,
    particles: &mut Particles<M>,
    bonds: &BondList<M::Bond>,
    scene: &Scene,
    bar_of: Vec<u32>,
) -> Result<BarBonds, DeckError> {
    if scene.bars.is_empty() {
        return Ok(BarBonds::default());
    }
    let gid = particles.gid.clone();
    let bar = |l: usize| bar_of[gid[l] as usize];
    let share = crate::input::bars::Share {
        bar: &bar,
        complete: &mut |_| {},
        sum: &mut |_| {},
    };
    let factor = bar_factors(model, particles, bonds, scene, share)?;
    Ok(BarBonds {
        bar_of,
        factor,
        bars: scene.geometry_bars(),
        prestrain: scene.bar_prestrain(),
    })
}

/// Each bar's calibration factor γ (1 for state-based models), after checking that the model
/// accepts each bar's prestrain; `share` says how the store's particles take part.
pub(crate) fn bar_factors<M: Model>(
    model: &M,
    particles: &mut Particles<M>,
    bonds: &BondList<M::Bond>,
    scene: &Scene,
    share: crate::input::bars::Share,
) -> Result<Vec<f64>, DeckError> {
    let bars = scene.geometry_bars();
    let mut modulus = Vec::with_capacity(bars.len());
    for b in &bars {
        let given = scene.materials[b.material as usize]
            .positive("youngs_modulus", crate::model::Dimension::STRESS)
            .map_err(|e| scene.model_error(&e))?;
        modulus.push(given.unwrap_or_else(|| {
            let (l, mu) = model.lame(b.material);
            mu * (3.0 * l + 2.0 * mu) / (l + mu)
        }));
    }
    let factor = if <M::State as Attributes>::LEN == 0 {
        crate::input::bars::calibrate(
            model,
            particles,
            bonds,
            &bars,
            &modulus,
            share,
            scene.horizon,
        )
    } else {
        vec![1.0; scene.bars.len()]
    };
    for (k, b) in scene.bars.iter().enumerate() {
        if b.prestrain.strain != 0.0 {
            let law = model.law(b.bar.material, b.bar.material);
            model
                .prestrained(&law, b.prestrain.strain)
                .map_err(|m| scene.error(Some(b.line), format!("bar {k}: {m}")))?;
        }
    }
    Ok(factor)
}

/// Cells of side ≥ the horizon and ≥ the pair law's `reach` (cutoff + skin) over the scene. A
/// periodic axis spans the lattice box exactly,
/// so that its cells tile one period: the whole lattice cells its particles occupy (simple
/// cubic: their extent ± half a spacing, as before the other kinds; fcc and bcc, whose sites lie
/// on the cell faces: from the lowest cell face to the highest cell's far face, so n cells are
/// exactly n·a long).
fn domain(points: &[[f64; 3]], scene: &Scene, reach: f64) -> Result<Domain, DeckError> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    domain_of_box(lo, hi, points.len(), scene, reach)
}

/// [`domain`] of `points` particles whose positions span the box `[lo, hi]`.
pub fn domain_of_box(
    lo: [f64; 3],
    hi: [f64; 3],
    points: usize,
    scene: &Scene,
    reach: f64,
) -> Result<Domain, DeckError> {
    // With shuffling, bonds are found from current cells: the skin keeps a stretched bond
    // between neighbouring cells.
    let min_cell = (cell_reach(scene) * (1.0 + scene.parallel.skin)).max(reach);
    let mut grid = CellGrid::covering_box(lo, hi, points, min_cell);
    let mut period = [0.0; 3];
    for a in 0..3 {
        if !scene.periodic[a] {
            continue;
        }
        let (start, length) = periodic_span(&scene.lattice, a, lo[a], hi[a]);
        let n = (length / (min_cell * (1.0 + 1e-9))).floor() as usize;
        if n < 3 {
            return Err(scene.error(
                None,
                format!(
                    "[lattice] periodic axis {} is {:.4e} long; it must be longer than three horizons{} ({:.4e}) to hold three cells; make the body longer along it or drop the axis from 'periodic'",
                    ["x", "y", "z"][a],
                    length,
                    if scene.parallel.skin > 0.0 { " with the shuffle skin" } else { "" },
                    3.0 * min_cell
                ),
            ));
        }
        grid.origin[a] = start;
        grid.dims[a] = n;
        grid.size[a] = length / n as f64;
        period[a] = length;
    }
    Ok(Domain {
        grid,
        periodic: scene.periodic,
        period,
    })
}

/// Where the period along axis `a` starts and how long it is, for particles from `lo` to `hi`
/// along it: the whole lattice cells they occupy.
fn periodic_span(lattice: &geometry::Lattice, a: usize, lo: f64, hi: f64) -> (f64, f64) {
    let s = lattice.spacing;
    if lattice.kind == geometry::LatticeKind::Sc {
        return (lo - 0.5 * s, hi - lo + s);
    }
    // A site on a cell face may round to just below it; the basis offsets are 0 and ½, so a
    // millionth of a cell decides nothing else.
    let o = lattice.origin[a];
    let cell = |x: f64| ((x - o) / s + 1e-6).floor();
    let (first, last) = (cell(lo), cell(hi));
    (o + first * s, (last - first + 1.0) * s)
}

/// The distance the cells must span: the horizon, or for a bondless model (horizon 0) one
/// lattice cell, until a pair law gives it a cutoff of its own.
fn cell_reach(scene: &Scene) -> f64 {
    if scene.horizon > 0.0 {
        scene.horizon
    } else {
        scene.spacing
    }
}

/// Builds model `M` from the deck's materials and horizon (the deck's model name is not
/// consulted): for tests and tools that know their model at compile time.
pub fn build_as<M: Model>(scene: &Scene) -> Result<Setup<M>, DeckError> {
    build(model_as(scene)?, scene)
}

/// Model `M` with the deck's materials and horizon (see [`build_as`]).
pub fn model_as<M: Model>(scene: &Scene) -> Result<M, DeckError> {
    let b = ModelBuild {
        materials: &scene.materials,
        horizon: scene.horizon,
        spacing: scene.spacing,
        options: &scene.model_options,
    };
    M::build(&b).map_err(|e| scene.model_error(&e))
}
