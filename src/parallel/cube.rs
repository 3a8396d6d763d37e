//! From one built scene to procCubes that step on their own: each gets its owned particles,
//! its ghosts, the bonds it evaluates, its share of the boundary conditions and loads, and a
//! [`WallExchange`] over whatever transport the run uses (threads or MPI ranks).
//!
//! Every worker builds the whole scene (deterministic), then keeps its procCube; this keeps
//! setup and its error messages in one place, at the price of each worker holding the scene
//! once while it starts.

use crate::engine::bonds::BondList;
use crate::engine::boundary::{Constraint, Load};
use crate::engine::particles::Particles;
use crate::engine::simulation::Simulation;
use crate::input::setup::Setup;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::comm::{Team, Transport};
use crate::parallel::decomposition::{
    cell_plans, cube_plan, CellPlan, CubePlan, Layout, Procs, Walls,
};
use crate::parallel::wall::WallExchange;

/// One procCube ready to step.
pub struct Cube<M: Model> {
    pub sim: Simulation<M>,
    /// The ghost messages to and from the neighbouring procCubes, over the run's transport.
    pub wall: WallExchange,
    pub plan: CubePlan,
    pub layout: Layout,
    /// Probe number and local index, for the probes whose particle this procCube owns.
    pub probes: Vec<(usize, usize)>,
    /// Global particle count of the scene.
    pub global_particles: usize,
    /// Bonds dropped from the bond list once broken (by a migration), per owned particle.
    pub lost: Vec<u32>,
    /// Those bonds as (smaller, larger) global ids, kept by the owner of the smaller.
    pub dropped: Vec<(u32, u32)>,
    /// Neighbour-list rebuilds, each a migration (the same on every worker: the choice is
    /// collective).
    pub rebuilds: u64,
    /// `[deform]`: the periodic box changing with time (set by the step loop).
    pub deform: Option<crate::parallel::deform::Deform>,
}

/// Boundary conditions, loads and probes of the whole scene, by global id, while each procCube
/// takes its share at the start (later, each particle's places travel with it).
#[derive(Clone, Debug)]
struct Everywhere {
    pub constraints: Vec<(Constraint, Vec<u32>)>,
    pub loads: Vec<(Load, Vec<u32>)>,
    pub probes: Vec<u32>,
}

impl Everywhere {
    fn of<M: Model>(setup: &Setup<M>) -> Everywhere {
        let gid = &setup.sim.particles.gid;
        let by_gid = |list: &[u32]| list.iter().map(|&i| gid[i as usize]).collect();
        Everywhere {
            constraints: setup
                .sim
                .constraints
                .iter()
                .map(|c| (c.clone(), by_gid(&c.particles)))
                .collect(),
            loads: setup
                .sim
                .loads
                .iter()
                .map(|l| (l.clone(), by_gid(&l.particles)))
                .collect(),
            probes: setup.probes.iter().map(|(_, i)| gid[*i]).collect(),
        }
    }

    /// This procCube's share, given the local index of each owned global id (`u32::MAX` if
    /// not owned).
    pub fn share(&self, local: &[u32]) -> (Vec<Constraint>, Vec<Load>, Vec<(usize, usize)>) {
        let mine = |gids: &[u32]| -> Vec<(usize, u32)> {
            gids.iter()
                .enumerate()
                .filter(|(_, &g)| local[g as usize] != u32::MAX)
                .map(|(k, &g)| (k, local[g as usize]))
                .collect()
        };
        let constraints = self
            .constraints
            .iter()
            .map(|(c, gids)| {
                Constraint::new(
                    &c.name,
                    mine(gids).into_iter().map(|(_, l)| l).collect(),
                    c.dofs.clone(),
                    c.motion.clone(),
                    c.history.clone(),
                )
            })
            .collect();
        let loads = self
            .loads
            .iter()
            .map(|(l, gids)| {
                let m = mine(gids);
                Load {
                    name: l.name.clone(),
                    particles: m.iter().map(|&(_, i)| i).collect(),
                    weight: m.iter().map(|&(k, _)| l.weight[k]).collect(),
                    vector: l.vector,
                    dof: l.dof,
                    history: l.history.clone(),
                }
            })
            .collect();
        let probes = self
            .probes
            .iter()
            .enumerate()
            .filter(|(_, &g)| local[g as usize] != u32::MAX)
            .map(|(k, &g)| (k, local[g as usize] as usize))
            .collect();
        (constraints, loads, probes)
    }
}

/// The layout a run asks for: `procs` from the deck or command line, `workers` threads or ranks.
pub fn layout<M: Model>(
    setup: &Setup<M>,
    procs: &Procs,
    workers: usize,
    walls: Walls,
) -> Result<Layout, String> {
    let x0 = &setup.sim.particles.x0;
    match procs {
        Procs::Auto => Layout::auto(workers, &setup.domain, x0, walls),
        Procs::Given(p) => {
            let n: usize = p.iter().product();
            if n != workers {
                return Err(format!(
                    "procs = {p:?} makes {n} procCubes but the run has {workers} worker{} (threads or MPI ranks); one procCube per worker",
                    if workers == 1 { "" } else { "s" }
                ));
            }
            Layout::new(*p, &setup.domain, x0, walls)
        }
    }
}

/// Builds procCube `rank` from the whole scene.
pub fn build_cube<M: Model>(
    setup: &Setup<M>,
    layout: &Layout,
    plans: &[CellPlan],
    rank: usize,
    transport: Box<dyn Transport>,
) -> Cube<M> {
    let plan = cube_plan(layout, plans, rank);
    let g = &setup.sim.particles;
    let idx = |l: usize| plan.global[l] as usize;
    let p = local_particles(
        &setup.sim.model,
        &plan,
        &g.gid,
        &g.x0,
        &g.volume,
        &g.material,
        &g.alter,
    );
    let mut bonds: BondList<M::Bond> =
        plan.find_bonds(&p.x0, setup.horizon, setup.spacing, setup.partial_volume);
    if let Some(g) = &setup.correction {
        let gid = |l: usize| setup.sim.particles.gid[idx(l)];
        crate::engine::correction::correct_bonds(
            &mut bonds,
            &p.x0,
            |l| g[idx(l)],
            |a, b| setup.bars.same_bar(gid(a), gid(b)),
        );
    }
    setup
        .bars
        .apply(&setup.sim.model, &mut bonds, &p.x0, |l| g.gid[idx(l)]);

    // Global id → local index, for owned particles.
    let mut local = vec![u32::MAX; g.len()];
    for l in 0..plan.n_owned {
        local[g.gid[idx(l)] as usize] = l as u32;
    }
    let (constraints, loads, probes) = Everywhere::of(setup).share(&local);
    let mut sim = Simulation::new(setup.sim.model.clone(), p, bonds, setup.sim.dt);
    sim.integrator = setup.sim.integrator;
    sim.constraints = constraints;
    sim.loads = loads;
    sim.pairs = setup.sim.pairs.as_ref().map(|p| p.fresh());
    sim.thermostat = setup.sim.thermostat.clone();
    let wall = WallExchange::new(plan.stages.clone(), transport);
    Cube {
        wall,
        lost: vec![0; plan.n_owned],
        sim,
        plan,
        layout: layout.clone(),
        probes,
        global_particles: g.len(),
        dropped: Vec::new(),
        rebuilds: 0,
        deform: None,
    }
}

/// The particles of `plan`, owned then ghosts, from whole-scene arrays indexed as
/// `plan.global` indexes; ghosts that are periodic images are shifted by their period.
pub(crate) fn local_particles<M: Model>(
    model: &M,
    plan: &CubePlan,
    gid: &[u32],
    x0: &[[f64; 3]],
    volume: &[f64],
    material: &[u16],
    alter: &[M::Alter],
) -> Particles<M> {
    let shifted = |x: &[f64], s: [f64; 3]| [x[0] + s[0], x[1] + s[1], x[2] + s[2]];
    let at = |l: usize| plan.global[l] as usize;
    let n = plan.global.len();
    let mut p = Particles::new(
        model,
        (0..n).map(|l| gid[at(l)]).collect(),
        (0..n).map(|l| shifted(&x0[at(l)], plan.shift[l])).collect(),
        (0..n).map(|l| volume[at(l)]).collect(),
        (0..n).map(|l| material[at(l)]).collect(),
    );
    p.n_owned = plan.n_owned;
    for l in 0..n {
        let mut a = alter[at(l)];
        let pos = shifted(a.as_slice(), plan.shift[l]);
        a.as_mut_slice()[..3].copy_from_slice(&pos);
        p.alter[l] = a;
    }
    p
}

impl<M: Model> Cube<M> {
    /// Makes the bond counts of owned particles whole (bonds evaluated on a neighbour count
    /// there) and computes the first forces. Every worker must call it, as it exchanges.
    pub fn start(&mut self) {
        let mut counts: Vec<f64> = self.sim.bonds.initial.iter().map(|&c| c as f64).collect();
        self.wall.reverse(&mut counts, |a, b| *a += b);
        for (c, v) in self.sim.bonds.initial.iter_mut().zip(&counts) {
            *c = *v as u32;
        }
        if M::FIXED_FROM_BONDS {
            let sim = &mut self.sim;
            let mut sums =
                crate::engine::bond_sums::bond_fixed_sums(&sim.model, &sim.particles, &sim.bonds);
            self.wall
                .reverse(&mut sums, crate::model::attributes::add_assign);
            let p = &mut self.sim.particles;
            for (f, s) in p.fixed.iter_mut().zip(&sums).take(p.n_owned) {
                crate::model::attributes::add_assign(f, s);
            }
            let mut fixed = std::mem::take(&mut self.sim.particles.fixed);
            self.wall.forward(&mut fixed, false);
            self.sim.particles.fixed = fixed;
        }
        for c in &self.sim.constraints {
            c.set_velocity(&mut self.sim.particles, self.sim.time, self.sim.dt);
        }
        if self.sim.pairs.is_some() {
            self.rebuild_pairs();
        }
        self.compute_forces();
    }

    /// One time step, ghosts exchanged with the neighbours; the bonds that broke in it. Fails
    /// only if a neighbour-list rebuild's shuffle does.
    pub fn advance(&mut self) -> Result<usize, String> {
        if self.sim.thermostat.is_some() {
            let mut team = Team::new(self.wall.transport());
            self.sim
                .thermostat_begin(&mut |v| team.reduce(v, crate::parallel::comm::Reduce::Sum));
        }
        self.sim.begin_step();
        if self.sim.pairs.is_some() {
            self.refresh_pairs()?;
        }
        let broken = self.sim.compute_forces_with(&mut self.wall);
        self.sim.end_step();
        self.deform_box()?;
        if self.sim.thermostat.is_some() {
            let mut team = Team::new(self.wall.transport());
            self.sim
                .thermostat_end(&mut |v| team.reduce(v, crate::parallel::comm::Reduce::Sum));
        }
        Ok(broken)
    }

    /// Rebuilds the neighbour lists when some particle, on any procCube, has moved more than
    /// half the skin since they were built. Ownership and ghosts are redrawn first (a shuffle
    /// from current positions), so that every pair within reach lies in neighbouring cells
    /// and is found once. Every worker must call it at every step: the test is a reduction.
    fn refresh_pairs(&mut self) -> Result<(), String> {
        let t = std::time::Instant::now();
        let far = self
            .sim
            .pairs
            .as_ref()
            .is_some_and(|pairs| pairs.moved_too_far(&self.sim.particles));
        if self.team().max(if far { 1.0 } else { 0.0 }) > 0.0 {
            // Particles go to the cells of their current positions; the lists are built there.
            self.rebin()?;
        }
        self.sim
            .timing
            .lap(crate::engine::timing::Phase::Neighbours, t);
        Ok(())
    }

    /// Redraws ownership from current positions and builds the neighbour lists (the start of
    /// a run with a pair law; every worker must call it).
    fn rebuild_pairs(&mut self) {
        // Ghosts must hold current positions (a restart restored only the owned ones).
        crate::engine::simulation::Exchange::forward(&mut self.wall, &mut self.sim.particles);
        self.build_pair_list();
    }

    /// Builds the neighbour lists from the current cells; ghosts must hold current positions.
    pub(crate) fn build_pair_list(&mut self) {
        if let Some(pairs) = &mut self.sim.pairs {
            let cells = crate::engine::pair_pass::CellPairs {
                cell_range: &self.plan.cell_range,
                half_shell: &self.plan.half_shell,
            };
            pairs.rebuild(&self.sim.particles, &cells, &self.sim.bonds);
        }
    }

    /// Forces at the current state, ghosts exchanged; the bonds that broke.
    pub fn compute_forces(&mut self) -> usize {
        self.sim.compute_forces_with(&mut self.wall)
    }

    /// Reductions and gathers over every procCube of the run, in rank order.
    pub fn team(&mut self) -> Team<&mut dyn Transport> {
        Team::new(self.wall.transport())
    }

    /// Damage of the owned particles: broken over initial bonds, counting bonds evaluated on
    /// neighbouring procCubes (exchanges, so every worker must call it).
    pub fn damage(&mut self) -> Vec<f64> {
        let n = self.sim.particles.len();
        let mut broken = vec![0.0f64; n];
        let b = &self.sim.bonds;
        let (offsets, partners) = (b.offsets(), b.partners());
        // A scan of each family's flags, and the counting only where one is set: called at
        // every history row, this was a fifth of a cracking run's time as a loop over all bonds.
        for (i, w) in offsets.windows(2).enumerate() {
            let (start, end) = (w[0] as usize, w[1] as usize);
            let flags = &b.broken[start..end];
            if !flags.contains(&true) {
                continue;
            }
            for (k, _) in flags.iter().enumerate().filter(|(_, &f)| f) {
                broken[i] += 1.0;
                broken[partners[start + k] as usize] += 1.0;
            }
        }
        self.wall.reverse(&mut broken, |a, b| *a += b);
        let b = &self.sim.bonds;
        (0..self.sim.particles.n_owned)
            .map(|i| {
                if b.initial[i] == 0 {
                    0.0
                } else {
                    (broken[i] + self.lost[i] as f64) / b.initial[i] as f64
                }
            })
            .collect()
    }

    /// Broken bonds of this procCube, those dropped by shuffles included.
    pub fn broken_count(&self) -> usize {
        self.sim.bonds.broken_count() + self.dropped.len()
    }

    /// The broken bonds of this procCube as (smaller, larger) global id pairs.
    pub fn broken_pairs(&self) -> Vec<(u32, u32)> {
        let b = &self.sim.bonds;
        let gid = &self.sim.particles.gid;
        b.iter()
            .filter(|&(_, _, k)| b.broken[k])
            .map(|(i, j, _)| (gid[i].min(gid[j]), gid[i].max(gid[j])))
            .chain(self.dropped.iter().copied())
            .collect()
    }
}

/// Builds every procCube of `layout` for threads of this process.
pub fn thread_cubes<M: Model>(setup: &Setup<M>, layout: &Layout) -> Vec<Cube<M>> {
    let plans = cell_plans(layout);
    crate::parallel::comm::Threads::team(layout.cubes())
        .into_iter()
        .enumerate()
        .map(|(k, t)| build_cube(setup, layout, &plans, k, Box::new(t)))
        .collect()
}

/// Runs `work` on every procCube, each on its own thread, and returns their results in order.
pub fn on_threads<M: Model, R: Send>(
    cubes: Vec<Cube<M>>,
    work: impl Fn(Cube<M>) -> R + Sync,
) -> Vec<R> {
    if cubes.len() == 1 {
        return cubes.into_iter().map(&work).collect();
    }
    std::thread::scope(|s| {
        let handles: Vec<_> = cubes
            .into_iter()
            .map(|c| {
                let w = &work;
                s.spawn(move || w(c))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// What one timed stretch of steps measured, reduced over all procCubes.
#[derive(Clone, Debug)]
pub struct Timed {
    /// Wall time of the slowest procCube.
    pub seconds: f64,
    pub bonds: usize,
    pub broken: usize,
    /// The root procCube's phase table.
    pub timing: crate::engine::timing::Timing,
    /// Bytes each procCube sent per step, summed over procCubes.
    pub bytes_per_step: f64,
    /// The slowest procCube's communication time (including waiting for neighbours).
    pub comm_seconds: f64,
}

impl<M: Model> Cube<M> {
    /// Runs `steps` steps after a common start and measures them (every worker must call it).
    pub fn timed_steps(self, steps: u64) -> Timed {
        self.timed_steps_shuffling(steps, 0)
            .expect("no shuffle, nothing to fail")
    }

    /// [`Cube::timed_steps`] with a shuffle check every `shuffle_every` steps (0: never), as a
    /// run with `[parallel] shuffle_every` makes; fails as the shuffle does.
    pub fn timed_steps_shuffling(
        mut self,
        steps: u64,
        shuffle_every: u64,
    ) -> Result<Timed, String> {
        use crate::engine::timing::Phase;
        use crate::parallel::comm::Reduce;
        self.start();
        self.sim.timing = Default::default();
        let before = self.wall.traffic;
        // A reduction is a barrier: everyone starts the clock together.
        self.team().sum(0.0);
        let t = std::time::Instant::now();
        for step in 1..=steps {
            self.advance()?;
            if shuffle_every > 0 && step % shuffle_every == 0 {
                let t = std::time::Instant::now();
                self.shuffle()?;
                self.sim.timing.lap(Phase::Communication, t);
            }
        }
        let secs = t.elapsed().as_secs_f64();
        let after = self.wall.traffic;
        let mut v = [
            secs,
            self.sim.timing.get(Phase::Communication).as_secs_f64(),
        ];
        self.team().reduce(&mut v, Reduce::Max);
        let mut s = [
            self.sim.bonds.len() as f64,
            self.broken_count() as f64,
            (after.bytes - before.bytes) as f64 / steps.max(1) as f64,
        ];
        self.team().reduce(&mut s, Reduce::Sum);
        Ok(Timed {
            seconds: v[0],
            comm_seconds: v[1],
            bonds: s[0] as usize,
            broken: s[1] as usize,
            bytes_per_step: s[2],
            timing: self.sim.timing.clone(),
        })
    }
}

/// Runs independent jobs (whole runs: stress trials, validation cases) `threads` at a time,
/// each taking the next job as it finishes one; the results in job order. A job that panics
/// ends the scope with its panic.
pub fn side_by_side<T: Send, J: Sync>(
    jobs: &[J],
    threads: usize,
    work: impl Fn(&J) -> T + Sync,
) -> Vec<T> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: std::sync::Mutex<Vec<Option<T>>> =
        std::sync::Mutex::new((0..jobs.len()).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads.clamp(1, jobs.len().max(1)) {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(job) = jobs.get(k) else { break };
                let r = work(job);
                results.lock().unwrap_or_else(|e| e.into_inner())[k] = Some(r);
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect()
}
