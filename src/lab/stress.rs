//! `pdq stress`: numerical stability stress tests of every model (docs/stability.md).
//!
//! * **Critical time step**: the largest stable Δt of velocity Verlet (and forward Euler for
//!   temperature), found by bisection on blow-up over a fixed number of steps, against the
//!   Silling–Askari bound PDQ uses (docs/theory.md §4), on a regular lattice, a jittered lattice and
//!   a steel–concrete mix. Every particle starts with a random velocity (and rotation rate,
//!   temperature), so every mode of the lattice, the fastest included, is excited.
//! * **Energy drift** over a long elastic vibration at the default safety factor.
//! * **Sudden failure**: a pre-stressed block cut in two at once, a pre-stressed block whose
//!   bonds all exceed their critical stretch, and a block struck by a fast impactor.
//!
//! Each case is a deck run through the same setup and step code as `pdq run`, on one thread;
//! cases run side by side on `threads` threads.

use crate::engine::spectrum::LANCZOS_STEPS;
use crate::input::deck;
use crate::input::setup::{self, Setup};
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model, ModelVisitor, Sample, SampleOf};
use std::fmt::Write as _;
use std::time::Instant;

mod report;
use report::{drift_section, dt_section, failure_section};

#[derive(Clone, Debug)]
pub struct StressOptions {
    /// Fewer and shorter runs (a minute on 2 cores instead of about fifteen).
    pub quick: bool,
    /// Sections to run: any of "dt", "drift", "failure" (all when empty).
    pub sections: Vec<String>,
    /// Models to run (all when empty).
    pub models: Vec<String>,
    /// Cases run side by side.
    pub threads: usize,
}

/// The models stressed, in table order: the registry's with a sample solid.
pub fn models() -> Vec<&'static str> {
    crate::models::info()
        .into_iter()
        .filter(|m| {
            m.sample(&solid(CONCRETE_E, 2400.0, FAILURE_S0, false))
                .is_some()
        })
        .map(|m| m.name)
        .collect()
}

/// The lattices of the critical-time-step table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lattice {
    Regular,
    /// Sites moved by up to 20 % of the spacing.
    Jittered,
    /// Steel bars (E = 200 GPa) in concrete (25 GPa): stiffness contrast 8.
    SteelConcrete,
}

impl Lattice {
    pub fn name(self) -> &'static str {
        match self {
            Lattice::Regular => "regular",
            Lattice::Jittered => "jittered 20 %",
            Lattice::SteelConcrete => "steel–concrete 8×",
        }
    }
}

const SPACING: f64 = 1e-3;
const CONCRETE_E: f64 = 25e9;
const STEEL_E: f64 = 200e9;

/// The plain solid of stiffness `e`, density `rho`, critical stretch `s0` (∞: unbreakable),
/// `steel` for the steel of a steel–concrete lattice.
fn solid(e: f64, rho: f64, s0: f64, steel: bool) -> SampleOf {
    SampleOf::Solid {
        youngs_modulus: e,
        density: rho,
        critical_stretch: s0,
        steel,
        full: false,
    }
}

/// The sample material of the registered model called `model` for `of`.
fn sample(model: &str, of: &SampleOf) -> Result<Sample, String> {
    crate::models::find(model)
        .and_then(|m| m.sample(of))
        .ok_or_else(|| format!("pdq stress: model '{model}' has no sample material"))
}

/// A block of nx × ny × nz lattice sites, m = 3.
fn block_deck(model: &str, n: [usize; 3], lattice: Lattice, s0: f64) -> Result<String, String> {
    let h = SPACING;
    let hi = n.map(|k| k as f64 * h);
    let concrete = sample(model, &solid(CONCRETE_E, 2400.0, s0, false))?;
    let mut t =
        format!("title = \"stress {model}\"\nunits = \"SI\"\n[model]\nname = \"{model}\"\nm = 3\n");
    if !concrete.options.is_empty() {
        let _ = write!(t, "[model.options]\n{}", concrete.options);
    }
    let _ = write!(t, "[lattice]\nspacing = {h:e}\n");
    if lattice == Lattice::Jittered {
        t.push_str("jitter = 0.2\nseed = 7\n");
    }
    let _ = write!(t, "[materials.concrete]\n{}", concrete.material);
    if lattice == Lattice::SteelConcrete {
        let steel = sample(model, &solid(STEEL_E, 7850.0, s0, true))?;
        let _ = write!(t, "[materials.steel]\n{}", steel.material);
    }
    let _ = write!(
        t,
        "[[geometry]]\nshape = \"box\"\nmaterial = \"concrete\"\nmin = [0, 0, 0]\nmax = [{:e}, {:e}, {:e}]\n",
        hi[0], hi[1], hi[2]
    );
    if lattice == Lattice::SteelConcrete {
        // Two bars of 2 × 2 sites along x, a quarter of the way in from each side in y.
        for y in [n[1] / 4, 3 * n[1] / 4 - 2] {
            let z = n[2] / 2 - 1;
            let _ = write!(
                t,
                "[[geometry]]\nshape = \"box\"\nmaterial = \"steel\"\nmin = [0, {:e}, {:e}]\nmax = [{:e}, {:e}, {:e}]\n",
                y as f64 * h,
                z as f64 * h,
                hi[0],
                (y + 2) as f64 * h,
                (z + 2) as f64 * h
            );
        }
    }
    t.push_str("[time]\nsteps = 1\nsafety_factor = 0.8\n[output]\nprogress = false\n");
    Ok(t)
}

/// Uniform in [−1, 1), a function of (i, k) only.
fn noise(i: usize, k: usize) -> f64 {
    let mut z = (i as u64) << 8 ^ k as u64 ^ 0x5DEE_CE66_D1CE_4E5B;
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    2.0 * ((z >> 11) as f64 / (1u64 << 53) as f64) - 1.0
}

/// Gives every particle a random velocity of up to `speed` per component (rotation rates up to
/// speed / spacing) and a random temperature within ±1 of 20.
fn excite<M: Model>(s: &mut Setup<M>, speed: f64) {
    let n2 = second_order::<M>();
    let p = &mut s.sim.particles;
    for i in 0..p.n_owned {
        let a = p.alter[i].as_mut_slice();
        for k in 0..n2 {
            let scale = if k < 3 { speed } else { speed / SPACING };
            a[n2 + k] = scale * noise(i, k);
        }
        for k in 0..M::FIRST_ORDER {
            a[2 * n2 + k] = 20.0 + noise(i, n2 + k);
        }
    }
}

/// Σ C_k (q_k − mean)² over the first-order DOFs: the "energy" heat conduction dissipates.
fn first_order_spread<M: Model>(s: &Setup<M>) -> f64 {
    let n2 = second_order::<M>();
    let p = &s.sim.particles;
    let mut total = 0.0;
    for k in 0..M::FIRST_ORDER {
        let (mut sum, mut weight) = (0.0, 0.0);
        for i in 0..p.n_owned {
            let c = 1.0 / p.inv_inertia[i].as_slice()[n2 + k];
            sum += c * p.alter[i].as_slice()[2 * n2 + k];
            weight += c;
        }
        let mean = sum / weight;
        for i in 0..p.n_owned {
            let c = 1.0 / p.inv_inertia[i].as_slice()[n2 + k];
            total += c * (p.alter[i].as_slice()[2 * n2 + k] - mean).powi(2);
        }
    }
    total
}

/// Σ C_k q_k over the first-order DOFs (the heat content of a thermal model).
fn first_order_content<M: Model>(s: &Setup<M>) -> f64 {
    let n2 = second_order::<M>();
    let p = &s.sim.particles;
    let mut total = 0.0;
    for i in 0..p.n_owned {
        for k in 0..M::FIRST_ORDER {
            total += p.alter[i].as_slice()[2 * n2 + k] / p.inv_inertia[i].as_slice()[n2 + k];
        }
    }
    total
}

fn any_non_finite<M: Model>(s: &Setup<M>) -> bool {
    let p = &s.sim.particles;
    p.alter[..p.n_owned]
        .iter()
        .any(|a| a.as_slice().iter().any(|v| !v.is_finite()))
}

/// Blow-up: energy (kinetic, or the first-order spread) grown past 100 times its start.
const GROWTH: f64 = 100.0;

/// How far the measured critical step may lie from the empirical one (relative): the top Ritz
/// value approaches λ_max from below, and the bisection's blow-up needs a little excess.
pub const MEASURED_AGREEMENT: f64 = 0.05;

/// The state a trial starts from: the excited particles and the intact bonds (a blown-up trial
/// breaks bonds and, in steel, leaves plastic history, which must not leak into the next).
struct Start<M: Model> {
    alter: Vec<M::Alter>,
    broken: Vec<bool>,
    history: Vec<M::Bond>,
}

impl<M: Model> Start<M> {
    fn of(s: &Setup<M>) -> Self {
        Start {
            alter: s.sim.particles.alter.clone(),
            broken: s.sim.bonds.broken.clone(),
            history: s.sim.bonds.history.clone(),
        }
    }
}

/// Whether `steps` steps at Δt = `factor` × bound stay bounded, from the excited state.
fn stable<M: Model>(s: &mut Setup<M>, start: &Start<M>, factor: f64, steps: u64) -> bool {
    let sim = &mut s.sim;
    sim.particles.alter.copy_from_slice(&start.alter);
    sim.bonds.broken.copy_from_slice(&start.broken);
    sim.bonds.history.copy_from_slice(&start.history);
    sim.dt = factor * s.dt_critical;
    sim.time = 0.0;
    sim.step = 0;
    sim.compute_forces();
    let e0 = sim.kinetic_energy();
    let t0 = first_order_spread(s);
    for step in 0..steps {
        s.sim.advance();
        if step % 10 == 9 || step + 1 == steps {
            let e = s.sim.kinetic_energy();
            if !e.is_finite() || e > GROWTH * e0 || any_non_finite(s) {
                return false;
            }
            if M::FIRST_ORDER > 0 {
                let t = first_order_spread(s);
                if !t.is_finite() || t > GROWTH * t0 {
                    return false;
                }
            }
        }
    }
    true
}

/// One row of the critical-time-step table.
#[derive(Clone, Debug)]
pub struct CriticalStep {
    pub model: String,
    pub lattice: Lattice,
    pub particles: usize,
    pub bound: f64,
    /// Largest stable and smallest unstable factor found (× bound); `hi` is ∞ if the search
    /// range held no unstable factor.
    pub lo: f64,
    pub hi: f64,
    /// The critical step measured on the stiffest mode (`[time] critical_step = "measured"`),
    /// × bound.
    pub measured: f64,
    pub steps: u64,
    pub seconds: f64,
}

/// Bisection of the stable factor between 0.25 and 8 (× bound).
pub fn critical_step(
    model: &str,
    lattice: Lattice,
    n: usize,
    steps: u64,
    halvings: usize,
) -> Result<CriticalStep, String> {
    let text = block_deck(model, [n; 3], lattice, f64::INFINITY)?;
    let scene = deck::parse(&text, "<stress>", "stress").map_err(|e| e.to_string())?;
    let started = Instant::now();
    let (particles, bound, lo, hi, measured) = setup::with_model(
        &scene,
        Bisect {
            scene: &scene,
            steps,
            halvings,
        },
    )
    .map_err(|e| e.to_string())??;
    Ok(CriticalStep {
        model: model.into(),
        lattice,
        particles,
        bound,
        lo,
        hi,
        measured,
        steps,
        seconds: started.elapsed().as_secs_f64(),
    })
}

struct Bisect<'a> {
    scene: &'a deck::Scene,
    steps: u64,
    halvings: usize,
}

impl ModelVisitor for Bisect<'_> {
    type Output = Result<(usize, f64, f64, f64, f64), String>;
    fn visit<M: Model>(self, model: M) -> Self::Output {
        let mut s = setup::build(model, self.scene).map_err(|e| e.to_string())?;
        let measured = crate::engine::spectrum::critical_time_step(&mut s.sim)
            .map_or(f64::INFINITY, |(dt, _)| dt)
            / s.dt_critical;
        excite(&mut s, 0.01);
        let start = Start::of(&s);
        let (mut lo, mut hi) = (0.25, 8.0);
        if !stable(&mut s, &start, lo, self.steps) {
            return Err(format!(
                "{}: unstable at 0.25 × the bound; the bound is not a bound",
                M::NAME
            ));
        }
        if stable(&mut s, &start, hi, self.steps) {
            return Ok((
                s.sim.particles.n_owned,
                s.dt_critical,
                hi,
                f64::INFINITY,
                measured,
            ));
        }
        // Geometric bisection: the factor's relative precision halves each time.
        for _ in 0..self.halvings {
            let mid = (lo * hi).sqrt();
            if stable(&mut s, &start, mid, self.steps) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok((s.sim.particles.n_owned, s.dt_critical, lo, hi, measured))
    }
}

/// One row of the energy-drift table.
#[derive(Clone, Debug)]
pub struct Drift {
    pub model: String,
    pub particles: usize,
    pub steps: u64,
    pub dt_factor: f64,
    pub energy: f64,
    /// Largest |E − E₀| / E₀ over the run (sampled every `steps / 1000` steps).
    pub largest: f64,
    /// (mean E over the last tenth − mean over the first tenth) / E₀.
    pub drift: f64,
    /// Relative change of the first-order content (heat) over the run, if the model has one.
    pub content_change: Option<f64>,
    pub seconds: f64,
}

/// An elastic vibration of a free block: a stretching mode along x plus 10 % random
/// velocities, unbreakable bonds, the deck's default safety factor.
pub fn drift(model: &str, n: usize, steps: u64, measured: bool) -> Result<Drift, String> {
    let mut text = block_deck(model, [n; 3], Lattice::Regular, f64::INFINITY)?;
    if measured {
        text = text.replace(
            "safety_factor = 0.8\n",
            "safety_factor = 0.8\ncritical_step = \"measured\"\n",
        );
    }
    let scene = deck::parse(&text, "<stress>", "stress").map_err(|e| e.to_string())?;
    struct Visit<'a>(&'a deck::Scene, u64);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<Drift, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let started = Instant::now();
            let mut s = setup::build(model, self.0).map_err(|e| e.to_string())?;
            excite(&mut s, 0.01);
            let n2 = second_order::<M>();
            let p = &mut s.sim.particles;
            let (lo, hi) = p.x0[..p.n_owned]
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                    (a.min(x[0]), b.max(x[0]))
                });
            let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            for i in 0..p.n_owned {
                let x = p.x0[i][0];
                p.alter[i].as_mut_slice()[n2] += 0.1 * (x - centre) / half;
            }
            let steps = self.1;
            let every = (steps / 1000).max(1);
            s.sim.compute_forces();
            let energy = |s: &Setup<M>| s.sim.kinetic_energy() + s.sim.strain_energy();
            let e0 = energy(&s);
            let c0 = first_order_content(&s);
            let mut samples = vec![e0];
            for step in 1..=steps {
                s.sim.advance();
                if step % every == 0 {
                    samples.push(energy(&s));
                }
            }
            let largest = samples
                .iter()
                .map(|e| (e - e0).abs() / e0)
                .fold(0.0, f64::max);
            let tenth = (samples.len() / 10).max(1);
            let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
            let drift = (mean(&samples[samples.len() - tenth..]) - mean(&samples[..tenth])) / e0;
            let content_change = (M::FIRST_ORDER > 0).then(|| (first_order_content(&s) - c0) / c0);
            Ok(Drift {
                model: M::NAME.into(),
                particles: s.sim.particles.n_owned,
                steps,
                dt_factor: s.sim.dt / s.dt_critical,
                energy: e0,
                largest,
                drift,
                content_change,
                seconds: started.elapsed().as_secs_f64(),
            })
        }
    }
    setup::with_model(&scene, Visit(&scene, steps)).map_err(|e| e.to_string())?
}

/// The sudden-failure scenes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Failure {
    /// A block stretched to half its critical stretch, every bond across its middle cut at
    /// step 0.
    Cut,
    /// A block stretched to three times its critical stretch: every bond within 55° of the
    /// stretch breaks in the first step.
    Shatter,
    /// A block struck on top by an impactor moving at this speed (m/s) into it; the impactor
    /// is a 6 × 6 × 3 patch of the block's own particles, so it hits through its bonds (PDQ has
    /// no contact forces).
    Impact(f64),
}

impl Failure {
    pub fn name(self) -> String {
        match self {
            Failure::Cut => "pre-stressed block cut in two at once".into(),
            Failure::Shatter => "pre-stressed block, every bond over s0 at once".into(),
            Failure::Impact(v) => format!("impact at {v} m/s"),
        }
    }
}

/// One row of the sudden-failure table.
#[derive(Clone, Debug)]
pub struct FailureRun {
    pub model: String,
    pub case: Failure,
    pub particles: usize,
    pub steps: u64,
    pub broken: usize,
    pub bonds: usize,
    /// Largest and final total energy (kinetic + elastic) over the initial one.
    pub largest: f64,
    pub last: f64,
    pub finite: bool,
    /// Largest distance a particle moved in one step, in lattice spacings.
    pub fastest: f64,
    pub seconds: f64,
}

const FAILURE_S0: f64 = 1e-3;

pub fn failure(model: &str, case: Failure, steps: u64) -> Result<FailureRun, String> {
    let n = match case {
        Failure::Impact(_) => [16, 16, 12],
        _ => [20, 8, 8],
    };
    let text = block_deck(model, n, Lattice::Regular, FAILURE_S0)?;
    let scene = deck::parse(&text, "<stress>", "stress").map_err(|e| e.to_string())?;
    struct Visit<'a>(&'a deck::Scene, Failure, u64, [usize; 3]);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<FailureRun, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let started = Instant::now();
            let Visit(scene, case, steps, n) = self;
            let mut s = setup::build(model, scene).map_err(|e| e.to_string())?;
            let n2 = second_order::<M>();
            let h = SPACING;
            let centre = n.map(|k| 0.5 * k as f64 * h);
            let p = &mut s.sim.particles;
            match case {
                Failure::Cut | Failure::Shatter => {
                    let strain = if case == Failure::Cut {
                        0.5 * FAILURE_S0
                    } else {
                        3.0 * FAILURE_S0
                    };
                    for i in 0..p.n_owned {
                        p.alter[i].as_mut_slice()[0] += strain * (p.x0[i][0] - centre[0]);
                    }
                }
                Failure::Impact(v) => {
                    for i in 0..p.n_owned {
                        let x = p.x0[i];
                        let inside = (x[0] - centre[0]).abs() < 3.0 * h
                            && (x[1] - centre[1]).abs() < 3.0 * h
                            && x[2] > (n[2] as f64 - 3.0) * h;
                        if inside {
                            p.alter[i].as_mut_slice()[n2 + 2] = -v;
                        }
                    }
                }
            }
            if case == Failure::Cut {
                let x0 = &s.sim.particles.x0;
                let across: Vec<usize> = s
                    .sim
                    .bonds
                    .iter()
                    .filter(|&(i, j, _)| (x0[i][0] - centre[0]) * (x0[j][0] - centre[0]) < 0.0)
                    .map(|(_, _, b)| b)
                    .collect();
                for b in across {
                    s.sim.bonds.broken[b] = true;
                }
            }
            let energy = |s: &Setup<M>| s.sim.kinetic_energy() + s.sim.strain_energy();
            let e0 = energy(&s);
            s.sim.compute_forces();
            let (mut largest, mut last, mut finite, mut fastest) = (1.0f64, 1.0, true, 0.0f64);
            // Every step: an energy spike from a breaking front lasts only a few steps.
            for _ in 0..steps {
                s.sim.advance();
                {
                    let p = &s.sim.particles;
                    finite &= !any_non_finite(&s);
                    for a in &p.alter[..p.n_owned] {
                        let a = a.as_slice();
                        let v2: f64 = a[n2..n2 + 3].iter().map(|v| v * v).sum();
                        fastest = fastest.max(v2.sqrt() * s.sim.dt / h);
                    }
                    last = energy(&s) / e0;
                    if !last.is_finite() {
                        finite = false;
                        break;
                    }
                    largest = largest.max(last);
                }
            }
            Ok(FailureRun {
                model: M::NAME.into(),
                case,
                particles: s.sim.particles.n_owned,
                steps,
                broken: s.sim.bonds.broken_count(),
                bonds: s.sim.bonds.len(),
                largest,
                last,
                finite,
                fastest,
                seconds: started.elapsed().as_secs_f64(),
            })
        }
    }
    setup::with_model(&scene, Visit(&scene, case, steps, n)).map_err(|e| e.to_string())?
}

/// Runs the stress tests and returns the report (Markdown tables).
pub fn run(opts: &StressOptions) -> Result<String, String> {
    let all = models();
    for m in &opts.models {
        if !all.contains(&m.as_str()) {
            return Err(format!(
                "pdq stress: unknown model '{m}' (use {})",
                all.join(", ")
            ));
        }
    }
    for s in &opts.sections {
        if !["dt", "drift", "failure"].contains(&s.as_str()) {
            return Err(format!(
                "pdq stress: unknown section '{s}' (use dt, drift or failure)"
            ));
        }
    }
    let models: Vec<&str> = all
        .into_iter()
        .filter(|m| opts.models.is_empty() || opts.models.iter().any(|o| o == m))
        .collect();
    let wants = |s: &str| opts.sections.is_empty() || opts.sections.iter().any(|o| o == s);
    let threads = opts.threads.max(1);
    let mut out = String::new();
    // What a stable engine must show; any of these fails the command (CI runs it).
    let mut broken_expectations = Vec::new();
    if wants("dt") {
        out.push_str(&dt_section(
            &models,
            opts.quick,
            threads,
            &mut broken_expectations,
        )?);
    }
    if wants("drift") {
        out.push_str(&drift_section(&models, opts.quick, threads)?);
    }
    if wants("failure") {
        out.push_str(&failure_section(
            &models,
            opts.quick,
            threads,
            &mut broken_expectations,
        )?);
    }
    if !broken_expectations.is_empty() {
        return Err(format!(
            "{out}stability expectations broken:\n{}",
            broken_expectations.join("\n")
        ));
    }
    Ok(out)
}
