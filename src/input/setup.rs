//! From a checked deck to a ready-to-step simulation: geometry → particles → bonds → time step
//! → boundary conditions and loads.

use crate::engine::bonds::BondList;
use crate::engine::boundary::{Constraint, Load, TEMPERATURE};
use crate::engine::cells::CellGrid;
use crate::engine::cells::Domain;
use crate::engine::particles::Particles;
use crate::engine::simulation::{stable_time_step, Simulation};
use crate::input::bars::BarBonds;
use crate::input::deck::{CriticalStep, DeckError, LoadKind, Region, RunLength, Scene};
use crate::input::geometry;
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model, ModelBuild, ModelVisitor};
use std::time::Instant;

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

/// Store indices of the particles of a region, in store order.
fn select<M: Model>(
    p: &Particles<M>,
    region: &Region,
    gid_to_index: &[u32],
) -> Result<Vec<u32>, String> {
    let n = p.n_owned;
    Ok(match region {
        Region::All => (0..n as u32).collect(),
        Region::Shape(s) => (0..n)
            .filter(|&i| s.contains(p.x0[i]))
            .map(|i| i as u32)
            .collect(),
        Region::Ids(ids) => {
            let mut v = Vec::with_capacity(ids.len());
            for &id in ids {
                match gid_to_index.get(id as usize) {
                    Some(&i) => v.push(i),
                    None => {
                        return Err(format!(
                            "particle id {id} does not exist (ids run from 0 to {})",
                            gid_to_index.len() - 1
                        ))
                    }
                }
            }
            v.sort_unstable();
            v.dedup();
            v
        }
    })
}

pub fn build<M: Model>(model: M, scene: &Scene) -> Result<Setup<M>, DeckError> {
    let start = Instant::now();
    let cloud = geometry::build(&scene.lattice, &scene.ops, &scene.bars).map_err(|e| {
        // An empty scene is blamed on the last subtraction, the usual culprit.
        let subtract = |o: &geometry::Op| e.empty && matches!(o, geometry::Op::Subtract { .. });
        let last_subtract = scene
            .ops
            .iter()
            .rposition(subtract)
            .map(|k| scene.op_lines[k]);
        let line = e
            .entry
            .map(|k| scene.op_lines[k])
            .or(e.bar.map(|k| scene.bar_lines[k]))
            .or(last_subtract);
        scene.error(line, e.message.clone())
    })?;

    // Store particles in cell order so that bond partners are near each other in memory, and
    // so that the wall method finds each cell's particles in one run.
    let domain = domain(&cloud.position, scene)?;
    let (_, _, order) = domain.grid.bin(&cloud.position);
    let gid: Vec<u32> = order.clone();
    let x0 = order.iter().map(|&g| cloud.position[g as usize]).collect();
    let volume = order.iter().map(|&g| cloud.volume[g as usize]).collect();
    let material = order.iter().map(|&g| cloud.material[g as usize]).collect();
    let mut gid_to_index = vec![0u32; gid.len()];
    for (i, &g) in gid.iter().enumerate() {
        gid_to_index[g as usize] = i as u32;
    }
    let mut particles = Particles::new(&model, gid, x0, volume, material);
    let bonds = BondList::<M::Bond>::find(
        &particles.x0,
        particles.n_owned,
        scene.horizon,
        scene.spacing,
        scene.partial_volume,
    );
    let mut bonds = bonds;
    crate::engine::forces::add_bond_fixed(&model, &mut particles, &bonds);
    let correction = if scene.surface_correction {
        if <M::State as Attributes>::LEN > 0 {
            return Err(scene.error(
                Some(scene.model_line),
                format!("[model] surface_correction = \"energy\" is for bond-based models; model '{}' is state-based (its weighted volume already uses the discrete family)", M::NAME),
            ));
        }
        let g = crate::engine::correction::energy_factors(&model, &mut particles, &bonds);
        let bar = |i: usize| cloud.bar[particles.gid[i] as usize];
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

    let bars = bar_bonds(&model, &mut particles, &bonds, scene, cloud.bar)?;
    bars.apply(&model, &mut bonds, &particles.x0, |i| particles.gid[i]);

    // Time step.
    let (dt_critical, dt_critical_particle) = stable_time_step(&model, &particles, &bonds);
    if dt_critical.is_nan() || dt_critical <= 0.0 {
        return Err(scene.error(
            None,
            format!("the stable time step is {dt_critical:e}: check the materials' stiffness and density"),
        ));
    }
    if !dt_critical.is_finite() {
        return Err(scene.error(
            None,
            "no particle has a bond: the horizon is too small for the particle spacing",
        ));
    }
    // Initial velocities and temperatures.
    let n2 = second_order::<M>();
    for init in &scene.initial {
        let at = |what: &str| scene.error(Some(init.line), format!("initial: {what}"));
        let sel = select(&particles, &init.region, &gid_to_index).map_err(|e| at(&e))?;
        if sel.is_empty() {
            return Err(at("the region selects no particle"));
        }
        if init.angular_velocity.is_some() && n2 < 6 {
            return Err(at(&format!(
                "model '{}' has no rotations for 'angular_velocity'",
                M::NAME
            )));
        }
        if init.temperature.is_some() && M::FIRST_ORDER == 0 {
            return Err(at(&format!("model '{}' has no temperature", M::NAME)));
        }
        for i in sel {
            let a = particles.alter[i as usize].as_mut_slice();
            if let Some(v) = init.velocity {
                a[n2..n2 + 3].copy_from_slice(&v);
            }
            if let Some(w) = init.angular_velocity {
                a[n2 + 3..n2 + 6].copy_from_slice(&w);
            }
            if let Some(t) = init.temperature {
                a[2 * n2] = t;
            }
        }
    }

    // Boundary conditions and loads.
    let mut constraints = Vec::new();
    for b in &scene.boundaries {
        let sel = select(&particles, &b.region, &gid_to_index)
            .map_err(|e| scene.error(Some(b.line), format!("boundary '{}': {e}", b.name)))?;
        if sel.is_empty() {
            return Err(scene.error(
                Some(b.line),
                format!("boundary '{}': the region selects no particle", b.name),
            ));
        }
        let mut dofs = Vec::with_capacity(b.dofs.len());
        for &d in &b.dofs {
            dofs.push(
                dof_index::<M>(d).map_err(|e| {
                    scene.error(Some(b.line), format!("boundary '{}': {e}", b.name))
                })?,
            );
        }
        constraints.push(Constraint::new(
            &b.name,
            sel,
            dofs,
            b.motion.clone(),
            b.history.clone(),
        ));
    }
    let mut loads = Vec::new();
    for l in &scene.loads {
        let sel = select(&particles, &l.region, &gid_to_index)
            .map_err(|e| scene.error(Some(l.line), format!("load '{}': {e}", l.name)))?;
        if sel.is_empty() {
            return Err(scene.error(
                Some(l.line),
                format!("load '{}': the region selects no particle", l.name),
            ));
        }
        let volume_of = |i: &u32| particles.volume[*i as usize];
        if l.kind.is_heat() && M::FIRST_ORDER == 0 {
            return Err(scene.error(
                Some(l.line),
                format!(
                    "load '{}': model '{}' has no temperature to heat",
                    l.name,
                    M::NAME
                ),
            ));
        }
        let (vector, weight): ([f64; 3], Vec<f64>) = match l.kind {
            LoadKind::PerParticle(v) => (v, vec![1.0; sel.len()]),
            LoadKind::Total(v) => {
                let total: f64 = sel.iter().map(volume_of).sum();
                (v, sel.iter().map(|i| volume_of(i) / total).collect())
            }
            LoadKind::BodyForce(v) => (v, sel.iter().map(volume_of).collect()),
            LoadKind::Gravity(g) => (
                g,
                sel.iter()
                    .map(|&i| 1.0 / particles.inv_inertia[i as usize].as_slice()[0])
                    .collect(),
            ),
            LoadKind::HeatFlux(q) => (
                [q, 0.0, 0.0],
                sel.iter().map(|i| volume_of(i) / scene.spacing).collect(),
            ),
            LoadKind::HeatSource(q) => ([q, 0.0, 0.0], sel.iter().map(volume_of).collect()),
            LoadKind::TotalHeat(q) => {
                let total: f64 = sel.iter().map(volume_of).sum();
                (
                    [q, 0.0, 0.0],
                    sel.iter().map(|i| volume_of(i) / total).collect(),
                )
            }
        };
        loads.push(Load {
            name: l.name.clone(),
            particles: sel,
            weight,
            vector,
            dof: if l.kind.is_heat() { n2 } else { 0 },
            history: l.history.clone(),
        });
    }

    // Probes: the particle nearest to each point.
    let probes = scene
        .probes
        .iter()
        .map(|pr| {
            let nearest = (0..particles.n_owned)
                .min_by(|&a, &b| {
                    dist2(particles.x0[a], pr.at).total_cmp(&dist2(particles.x0[b], pr.at))
                })
                .unwrap_or(0);
            (pr.name.clone(), nearest)
        })
        .collect();

    let mut sim = Simulation::new(
        model,
        particles,
        bonds,
        scene.time.safety_factor * dt_critical,
    );
    sim.constraints = constraints;
    sim.loads = loads;
    sim.integrator = scene.time.integrator;

    if let Some(until) = scene.time.static_until {
        static_start_allowed::<M>(scene, until)?;
    }

    // Time step: the bound, or the limit of central differences measured on the stiffest mode
    // (explicit runs only: relaxation's pseudo time has its own limit).
    let explicit = matches!(scene.solver, crate::input::deck::SolverSpec::Explicit);
    let measured = scene.time.critical_step == CriticalStep::Measured;
    if measured && !explicit {
        return Err(scene.error(
            Some(scene.time_line),
            "[time] critical_step = \"measured\" is for explicit runs: a quasi-static [solver] has no time step to limit",
        ));
    }
    let dt_measured = if measured {
        Some(crate::engine::spectrum::critical_time_step(&mut sim).ok_or_else(|| {
            scene.error(
                Some(scene.time_line),
                "[time] critical_step = \"measured\": no free degree of freedom has a bond, so there is no stiffest mode to measure; use the bound",
            )
        })?)
    } else {
        None
    };
    let (limit, limit_name) = match dt_measured {
        Some((dt, _)) => (dt, "measured on the stiffest mode".to_string()),
        None => (
            dt_critical,
            format!(
                "Silling–Askari bound, set by particle {} at {:?}",
                sim.particles.gid[dt_critical_particle], sim.particles.x0[dt_critical_particle]
            ),
        ),
    };
    let dt = match scene.time.dt {
        Some(dt) => {
            if dt > limit && !scene.time.force_dt {
                return Err(scene.error(
                    Some(scene.time_line),
                    format!(
                        "[time] dt = {dt:.4e} is above the stable time step {limit:.4e} ({limit_name}); lower dt, use safety_factor, or set force_dt = true to run anyway"
                    ),
                ));
            }
            dt
        }
        None => scene.time.safety_factor * limit,
    };
    // A static start reaches `static_until` without steps; the steps follow it.
    let mut steps = match scene.time.length {
        RunLength::Steps(n) => n,
        RunLength::Duration(d) => ((d - scene.time.static_until.unwrap_or(0.0)) / dt).ceil() as u64,
    };
    // Relaxation follows the loads through the same time span in `load_steps` equal steps;
    // a "step" is then a load step and Δt its length in the loads' time.
    let dt = match scene.solver {
        crate::input::deck::SolverSpec::Relaxation { load_steps, .. } => {
            let span = match scene.time.length {
                RunLength::Steps(n) => n as f64 * dt,
                RunLength::Duration(d) => d,
            };
            steps = load_steps;
            span / load_steps as f64
        }
        crate::input::deck::SolverSpec::Explicit => dt,
    };
    if steps > 1_000_000_000_000 {
        return Err(scene.error(
            Some(scene.time_line),
            format!("[time] the run would take {steps} steps of {dt:.4e}: shorten the duration"),
        ));
    }

    sim.dt = dt;
    for c in &sim.constraints {
        c.set_velocity(&mut sim.particles, 0.0, dt);
    }
    sim.compute_forces();
    let seconds = start.elapsed().as_secs_f64();
    sim.timing = crate::engine::timing::Timing::default();
    sim.timing
        .add(crate::engine::timing::Phase::Setup, start.elapsed());
    Ok(Setup {
        sim,
        dt_critical,
        dt_critical_particle,
        dt_measured,
        steps,
        probes,
        seconds,
        domain,
        horizon: scene.horizon,
        spacing: scene.spacing,
        partial_volume: scene.partial_volume,
        correction,
        solver: scene.solver.clone(),
        bars,
    })
}

/// Refuses a static start (`[time] static_until`) that cannot be made: under a quasi-static
/// solver (which has no explicit steps to start), with initial velocities (it starts at
/// rest), with periodic axes or temperature (which the implicit solve does not take).
fn static_start_allowed<M: Model>(scene: &Scene, until: f64) -> Result<(), DeckError> {
    let line = Some(scene.time_line);
    if !matches!(scene.solver, crate::input::deck::SolverSpec::Explicit) {
        return Err(scene.error(
            line,
            "[time] static_until starts an explicit run from a static solve; with a quasi-static [solver] every load step is static already: leave it out",
        ));
    }
    if let Some(i) = scene
        .initial
        .iter()
        .find(|i| i.velocity.is_some() || i.angular_velocity.is_some())
    {
        return Err(scene.error(
            Some(i.line),
            format!("[[initial]] velocities cannot be combined with [time] static_until = {until:e}: the static start begins the run at rest"),
        ));
    }
    if scene.periodic.iter().any(|&p| p) {
        return Err(scene.error(
            line,
            "[time] static_until: the static start's implicit solve does not handle periodic axes (it finds who feels whom from reference positions); leave static_until out",
        ));
    }
    if M::FIRST_ORDER > 0 {
        return Err(scene.error(
            line,
            format!(
                "[time] static_until: the static start solves for mechanical equilibrium, and model '{}' has temperature (first-order degrees of freedom); leave it out",
                M::NAME
            ),
        ));
    }
    Ok(())
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
    let mut modulus = Vec::with_capacity(scene.bars.len());
    for b in &scene.bars {
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
            &scene.bars,
            &modulus,
            &bar_of,
            scene.horizon,
        )
    } else {
        vec![1.0; scene.bars.len()]
    };
    for (k, (bar, p)) in scene.bars.iter().zip(&scene.bar_prestrain).enumerate() {
        if p.strain != 0.0 {
            let law = model.law(bar.material, bar.material);
            model
                .prestrained(&law, p.strain)
                .map_err(|m| scene.error(Some(scene.bar_lines[k]), format!("bar {k}: {m}")))?;
        }
    }
    Ok(BarBonds {
        bar_of,
        factor,
        bars: scene.bars.clone(),
        prestrain: scene.bar_prestrain.clone(),
    })
}

/// Cells of side ≥ the horizon over the scene. A periodic axis spans the lattice box (particle
/// positions ± half a spacing) exactly, so that its cells tile one period.
fn domain(points: &[[f64; 3]], scene: &Scene) -> Result<Domain, DeckError> {
    // With shuffling, bonds are found from current cells: the skin keeps a stretched bond
    // between neighbouring cells.
    let min_cell = scene.horizon * (1.0 + scene.parallel.skin);
    let mut grid = CellGrid::covering(points, min_cell);
    let mut period = [0.0; 3];
    for a in 0..3 {
        if !scene.periodic[a] {
            continue;
        }
        let lo = points.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min);
        let hi = points
            .iter()
            .map(|p| p[a])
            .fold(f64::NEG_INFINITY, f64::max);
        let length = hi - lo + scene.spacing;
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
        grid.origin[a] = lo - 0.5 * scene.spacing;
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

/// The model's index of a DOF the deck names (x, y, z, rotations, temperature).
fn dof_index<M: Model>(d: usize) -> Result<usize, String> {
    let n2 = second_order::<M>();
    if d == TEMPERATURE {
        return if M::FIRST_ORDER > 0 {
            Ok(n2)
        } else {
            Err(format!("model '{}' has no temperature", M::NAME))
        };
    }
    if d >= n2 {
        return Err(format!(
            "model '{}' has no rotations (it has {n2} degrees of freedom per particle)",
            M::NAME
        ));
    }
    Ok(d)
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

/// Builds model `M` from the deck's materials and horizon (the deck's model name is not
/// consulted): for tests and tools that know their model at compile time.
pub fn build_as<M: Model>(scene: &Scene) -> Result<Setup<M>, DeckError> {
    let b = ModelBuild {
        materials: &scene.materials,
        horizon: scene.horizon,
        spacing: scene.spacing,
        options: &scene.model_options,
    };
    let model = M::build(&b).map_err(|e| scene.model_error(&e))?;
    build(model, scene)
}
