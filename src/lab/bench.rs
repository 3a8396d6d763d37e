//! `pdq bench`: the standard scene of `shared/bench` (a (n+1)³ simple-cubic lattice, spacing
//! 1 mm, horizon 3.015 mm, top three layers moving up at 1 m/s, Δt = 1e-7 s, free boundaries),
//! timed through the same deck → setup → step path as a user's run, the LAMMPS peer on the same
//! scene when asked, and a hand-specialized PMB force loop kept here only as a yardstick for
//! what the generic model path costs.

use crate::input::deck;
use crate::input::setup;
use crate::model::{Model, ModelInfo, ModelVisitor, SampleOf};
use crate::parallel;
use crate::parallel::decomposition::{Procs, Walls};
use std::fmt::Write as _;

mod lj;
mod peer;
mod ranks;
mod savings;
mod voids;
pub mod yardstick;

use peer::{peer, peer_style};
use ranks::ranks_lines;
#[cfg(feature = "mpi")]
use ranks::MpiVisit;
use savings::savings;
pub use yardstick::hand_pmb_pass;

#[derive(Clone, Debug)]
pub struct BenchOptions {
    pub model: String,
    /// "standard" (the peridynamic block of `shared/bench`) or "lj" (the LJ melt).
    pub scene: String,
    /// Thread counts to time, one line each.
    pub threads: Vec<usize>,
    /// MPI rank counts to time (each through `mpirun`), one line each.
    pub ranks: Vec<usize>,
    pub walls: Walls,
    pub procs: Procs,
    /// Whether to time the yardstick (generic against hand-written PMB loop).
    pub yardstick: bool,
    pub steps: u64,
    /// Lattice cells per edge: (n + 1)³ particles, 40 in the standard scene; 4n³ atoms, 20 in
    /// the LJ melt.
    pub n: usize,
    pub peer: bool,
    /// Repetitions of the yardstick comparison (medians are reported).
    pub repeat: usize,
    /// Times through the thread counts (medians are reported when more than one).
    pub rounds: usize,
    /// Also time writing one checkpoint of the scene against 100 steps (one thread).
    pub checkpoint: bool,
    /// Instead of the standard lines: what a scene saves by not using a feature.
    pub savings: bool,
    /// Instead: the label-merge schemes of the voids analysis.
    pub voids: bool,
}

const SPACING: f64 = 0.001;

/// The benchmark's solid, which each model writes in its own keys ([`SampleOf::Benchmark`]):
/// the stiffness of the PMB micromodulus of LAMMPS `peri/pmb` and its critical stretch.
pub const BENCHMARK: SampleOf = SampleOf::Benchmark {
    micromodulus: 1.6863e22,
    horizon: 0.003015,
    critical_stretch: 0.0005,
    density: 2200.0,
};

/// The models with a benchmark solid: the registry's, in its order (`--model all`).
pub fn bench_models() -> Vec<ModelInfo> {
    crate::models::info()
        .into_iter()
        .filter(|m| m.sample(&BENCHMARK).is_some())
        .collect()
}

/// The standard scene as a deck, for the registered model called `model`.
pub fn standard_deck(model: &str, n: usize, steps: u64) -> Result<String, String> {
    match crate::models::find(model) {
        Some(info) if info.sample(&BENCHMARK).is_some() => standard_deck_of(&info, n, steps),
        _ => {
            let names: Vec<&str> = bench_models().iter().map(|m| m.name).collect();
            Err(format!(
                "no standard bench scene for model '{model}' (use {})",
                or_list(&names)
            ))
        }
    }
}

/// "a, b or c".
fn or_list(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
    }
}

/// The standard scene as a deck, for any model with a benchmark solid (a registered one, or
/// one run through `run_model`): the same block, the model's own sample of the benchmark's
/// solid, and its own Δt where it needs a shorter one than the peer's 1e-7 s.
pub fn standard_deck_of(model: &ModelInfo, n: usize, steps: u64) -> Result<String, String> {
    let sample = model.sample(&BENCHMARK).ok_or_else(|| {
        format!(
            "model '{}' has no sample of the benchmark's solid",
            model.name
        )
    })?;
    let h = SPACING;
    let hi = (n as f64 + 0.5) * h;
    let (model, material) = (model.name, sample.material);
    // Model options come after the material table in TOML, so they close the deck's [model].
    let options = if sample.options.is_empty() {
        String::new()
    } else {
        format!("[model.options]\n{}", sample.options)
    };
    Ok(format!(
        r#"title = "standard benchmark scene ({model})"
units = "SI"
[model]
name = "{model}"
horizon = 0.003015
{options}
[lattice]
spacing = {h:e}
origin = [{o:e}, {o:e}, {o:e}]
[materials.solid]
{material}
[[geometry]]
shape = "box"
material = "solid"
min = [{o:e}, {o:e}, {o:e}]
max = [{hi:e}, {hi:e}, {hi:e}]
[time]
steps = {steps}
dt = {dt:e}
force_dt = true
[[initial]]
region = {{ shape = "slab", axis = "z", from = {top:e}, to = 1.0 }}
velocity = [0, 0, 1]
[output]
progress = false
history_every = {steps}
"#,
        o = -0.5 * h,
        top = (n as f64 - 2.5) * h,
        dt = sample.dt.unwrap_or(1e-7),
    ))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// One `bench median` line per worker count (`count`: `threads=2`, `threads=1 ranks=2`): the
/// median of its runs' µs per particle-step and of their paired speed-ups, if any.
fn median_lines<'a>(
    out: &mut String,
    name: &str,
    counts: impl Iterator<Item = (String, &'a (Vec<f64>, Vec<f64>))>,
) {
    for (count, (us, speedups)) in counts {
        let _ = write!(
            out,
            "bench median model={name} {count} runs={} us_per_particle_step={:.4}",
            us.len(),
            median(us.clone())
        );
        if !speedups.is_empty() {
            let _ = write!(out, " speedup={:.2}", median(speedups.clone()));
        }
        let _ = writeln!(out);
    }
}

/// Runs the benchmark and returns the lines it printed. `--model all` runs every model with a
/// benchmark solid (the LAMMPS peer for those that have one) and ends with a Markdown table.
pub fn run(opts: &BenchOptions) -> Result<String, String> {
    if opts.threads.contains(&0) || opts.ranks.contains(&0) {
        return Err("threads and ranks must be at least 1".into());
    }
    if opts.voids {
        return Ok(voids::schemes(opts.rounds));
    }
    if opts.savings {
        return savings(opts);
    }
    if !["standard", "lj"].contains(&opts.scene.as_str()) {
        return Err(format!(
            "unknown bench scene '{}' (use standard or lj)",
            opts.scene
        ));
    }
    if opts.scene == "lj" {
        // The yardstick is a hand-written PMB loop: nothing to compare a pair law with.
        return run_one(&BenchOptions {
            yardstick: false,
            ..opts.clone()
        });
    }
    if opts.model == "all" {
        let mut out = String::new();
        for model in bench_models() {
            let one = BenchOptions {
                model: model.name.into(),
                peer: opts.peer && model.lammps_peer.is_some(),
                yardstick: opts.yardstick && model.name == yardstick::MODEL,
                ..opts.clone()
            };
            out.push_str(&run(&one)?);
        }
        let table = suite_table(&out);
        out.push('\n');
        out.push_str(&table);
        return Ok(out);
    }
    run_one(opts)
}

/// What the lines call the benchmark: the model, or for the LJ melt its pair law.
fn bench_name(opts: &BenchOptions) -> &str {
    if opts.scene == "lj" {
        "lj"
    } else {
        &opts.model
    }
}

fn run_one(opts: &BenchOptions) -> Result<String, String> {
    let text = if opts.scene == "lj" {
        lj::lj_deck(opts.n)?
    } else {
        standard_deck(&opts.model, opts.n, opts.steps)?
    };
    let scene = deck::parse(&text, "<bench>", "bench").map_err(|e| e.to_string())?;
    struct Visit<'a>(&'a deck::Scene, &'a BenchOptions);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<(String, Medians), String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let setup = setup::build(model, self.0).map_err(|e| e.to_string())?;
            bench_setup(setup, self.1)
        }
    }
    #[cfg(feature = "mpi")]
    if crate::parallel::comm_mpi::launched_by_mpirun() {
        return setup::with_model(&scene, MpiVisit(&scene, opts)).map_err(|e| e.to_string())?;
    }
    let (mut out, ours) =
        setup::with_model(&scene, Visit(&scene, opts)).map_err(|e| e.to_string())??;
    out.push_str(&ranks_lines(opts)?);
    if opts.peer {
        out.push_str(&peer_lines(opts, &ours)?);
    }
    Ok(out)
}

/// µs per particle-step by thread count (medians over rounds).
type Medians = std::collections::BTreeMap<usize, f64>;

/// The LAMMPS peer at each thread count as that many MPI ranks, `rounds` times, and the ratio
/// of the medians to PDQ's at the same core count.
fn peer_lines(opts: &BenchOptions, ours: &Medians) -> Result<String, String> {
    let mut out = String::new();
    for &t in &opts.threads {
        let mut theirs = Vec::new();
        for _ in 0..opts.rounds.max(1) {
            match peer(opts, t)? {
                Ok((line, us)) => {
                    out.push_str(&line);
                    theirs.push(us);
                }
                Err(skipped) => {
                    out.push_str(&skipped);
                    return Ok(out);
                }
            }
        }
        let (theirs, runs) = (median(theirs.clone()), theirs.len());
        let _ = writeln!(
            out,
            "bench ratio lammps/pdq={:.2} (model={} vs {}, {t} core{} each: {t} thread{} against {t} rank{}; medians of {runs} runs, LAMMPS {theirs:.4} us, PDQ {:.4} us)",
            theirs / ours.get(&t).copied().unwrap_or(f64::NAN),
            bench_name(opts),
            peer_style(opts),
            if t == 1 { "" } else { "s" },
            if t == 1 { "" } else { "s" },
            if t == 1 { "" } else { "s" },
            ours.get(&t).copied().unwrap_or(f64::NAN),
        );
    }
    Ok(out)
}

/// The standard line of one parallel run. Memory is what the engine stores for the model's
/// declared records: per particle (engine fields, Alter, Fixed, State, Force and inverse
/// inertia) and per bond (partner, geometry, broken flag, history), ghosts and buffers aside.
fn line(
    name: &str,
    bytes: [usize; 2],
    particles: usize,
    steps: u64,
    threads: usize,
    ranks: usize,
    t: &parallel::Timed,
) -> String {
    let us = 1e6 * t.seconds / (particles as f64 * steps as f64);
    let head = format!(
        "bench model={name} particles={particles} steps={steps} threads={threads} ranks={ranks} us_per_particle_step={us:.4}"
    );
    let tail = format!(
        "seconds={:.3} comm_percent={:.1} bytes_per_step={:.0} bytes_per_particle={}",
        t.seconds,
        100.0 * t.comm_seconds / t.seconds.max(1e-300),
        t.bytes_per_step,
        bytes[0],
    );
    if t.bonds == 0 {
        // A bondless scene (the LJ melt): its cost is per particle and pair.
        return format!("{head} {tail}");
    }
    format!(
        "{head} ns_per_bond={:.3} bonds_per_second={:.4e} bonds={} broken={} {tail} bytes_per_bond={}",
        1e9 * t.seconds / (t.bonds as f64 * steps as f64),
        t.bonds as f64 * steps as f64 / t.seconds,
        t.bonds,
        t.broken,
        bytes[1],
    )
}

/// The engine's bytes per particle and per bond of model `M`.
fn bytes_of<M: Model>() -> [usize; 2] {
    [
        crate::engine::particles::Particles::<M>::bytes_per_particle(),
        crate::engine::bonds::BondList::<M::Bond>::bytes_per_bond(),
    ]
}

/// `key=value` of a standard line.
fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
}

/// The Markdown table of a `--model all` run, from its standard lines: one row per model,
/// thread or rank count and launcher, with the median over rounds.
fn suite_table(lines: &str) -> String {
    let mut t = String::from(
        "| model | threads | MPI ranks | µs per particle-step (median) | runs | ns per bond | bonds per second | bytes per particle | bytes per bond | LAMMPS / PDQ |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let runs: Vec<&str> = lines
        .lines()
        .filter(|l| l.starts_with("bench model="))
        .collect();
    let mut seen: Vec<(String, String, bool)> = Vec::new();
    for l in &runs {
        let get = |k| field(l, k).unwrap_or("–");
        let mpi = field(l, "launcher") == Some("mpirun");
        let key = (
            get("model").to_string(),
            format!("{}/{}", get("threads"), get("ranks")),
            mpi,
        );
        if seen.contains(&key) {
            continue;
        }
        let same: Vec<f64> = runs
            .iter()
            .filter(|r| {
                field(r, "model") == field(l, "model")
                    && field(r, "threads") == field(l, "threads")
                    && field(r, "ranks") == field(l, "ranks")
                    && (field(r, "launcher") == Some("mpirun")) == mpi
            })
            .filter_map(|r| field(r, "us_per_particle_step")?.parse().ok())
            .collect();
        let us = median(same.clone());
        let per = |k| {
            field(l, k)
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or(f64::NAN)
        };
        let (particles, bonds) = (per("particles"), per("bonds"));
        let ns = 1e3 * us * particles / bonds;
        let ratio = if mpi || get("threads") != "1" {
            ""
        } else {
            lines
                .lines()
                .filter(|r| r.starts_with("bench ratio"))
                .find(|r| field(r, "(model") == Some(key.0.as_str()))
                .and_then(|r| field(r, "lammps/pdq"))
                .unwrap_or("")
        };
        let _ = writeln!(
            t,
            "| {} | {} | {} | {us:.4} | {} | {ns:.2} | {:.3e} | {} | {} | {ratio} |",
            key.0,
            get("threads"),
            if mpi { get("ranks") } else { "–" },
            same.len(),
            1e9 / ns,
            get("bytes_per_particle"),
            get("bytes_per_bond")
        );
        seen.push(key);
    }
    for l in lines.lines().filter(|l| l.starts_with("bench peer=")) {
        if let (Some(peer), Some(us)) = (field(l, "bench peer"), field(l, "us_per_particle_step")) {
            let _ = writeln!(
                t,
                "| {peer} | 1 | {} | {us} | 1 | | | | | |",
                field(l, "ranks").unwrap_or("1")
            );
        }
    }
    t
}

/// The time to gather and write a checkpoint of the scene (after 100 steps on one thread),
/// against the time of those 100 steps.
fn checkpoint_line<M: Model>(
    setup: &setup::Setup<M>,
    opts: &BenchOptions,
) -> Result<String, String> {
    let layout = parallel::layout(setup, &Procs::Given([1, 1, 1]), 1, opts.walls)?;
    let mut cube = parallel::thread_cubes(setup, &layout).remove(0);
    cube.start();
    let steps = 100;
    let t = std::time::Instant::now();
    for _ in 0..steps {
        cube.advance()?;
    }
    let step_seconds = t.elapsed().as_secs_f64();
    let dir = std::env::temp_dir().join(format!("pdq-bench-checkpoint-{}", std::process::id()));
    let t = std::time::Instant::now();
    let c = crate::output::checkpoint::Checkpoint::gather(&mut cube, 0, "<bench>")
        .ok_or("the checkpoint was not gathered")?;
    let (_, bytes) = c
        .write(&dir, 1)
        .map_err(|e| format!("writing a checkpoint in {}: {e}", dir.display()))?;
    let seconds = t.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&dir);
    Ok(format!(
        "bench checkpoint model={} particles={} bonds={} bytes={bytes} seconds={seconds:.3} steps={steps} step_seconds={step_seconds:.3} percent_of_steps={:.1}\n",
        M::NAME,
        setup.sim.particles.n_owned,
        cube.sim.bonds.len(),
        100.0 * seconds / step_seconds
    ))
}

fn bench_setup<M: Model>(
    mut setup: setup::Setup<M>,
    opts: &BenchOptions,
) -> Result<(String, Medians), String> {
    let n = setup.sim.particles.n_owned;
    let mut out = String::new();
    if opts.checkpoint {
        out.push_str(&checkpoint_line(&setup, opts)?);
    }
    // Runs alternate through the thread counts `rounds` times; each speed-up is taken against
    // the one-thread run just before it, so a slow spell of a shared machine hits both.
    let mut last_one = None;
    let mut per_count: std::collections::BTreeMap<usize, (Vec<f64>, Vec<f64>)> = Default::default();
    let rounds = opts.rounds.max(1);
    let order: Vec<usize> = (0..rounds)
        .flat_map(|_| opts.threads.iter().copied())
        .collect();
    for &threads in &order {
        let layout = parallel::layout(&setup, &opts.procs, threads, opts.walls)?;
        let cubes = parallel::thread_cubes(&setup, &layout);
        let timed = parallel::on_threads(cubes, |c| c.timed_steps(opts.steps));
        let t = &timed[0];
        let us = 1e6 * t.seconds / (n as f64 * opts.steps as f64);
        let name = bench_name(opts);
        let _ = write!(
            out,
            "{}",
            line(name, bytes_of::<M>(), n, opts.steps, threads, 1, t)
        );
        let entry = per_count.entry(threads).or_default();
        entry.0.push(us);
        if threads == 1 {
            last_one = Some(us);
        } else if let Some(base) = last_one {
            let _ = write!(out, " speedup={:.2}", base / us);
            entry.1.push(base / us);
        }
        let _ = writeln!(out, " layout={}", layout.describe().replace(' ', "_"));
        if timed.len() > 1 {
            for (k, c) in timed.iter().enumerate() {
                use crate::engine::timing::Phase;
                let _ = writeln!(
                    out,
                    "# procCube {k}: forces {:.3} s, communication {:.3} s, integration {:.3} s",
                    c.timing.get(Phase::Forces).as_secs_f64(),
                    c.timing.get(Phase::Communication).as_secs_f64(),
                    c.timing.get(Phase::Integration).as_secs_f64()
                );
            }
        }
        for l in t.timing.table(0.0).lines() {
            let _ = writeln!(out, "# {l}");
        }
    }
    if rounds > 1 {
        let counts = per_count.iter().map(|(t, r)| (format!("threads={t}"), r));
        median_lines(&mut out, bench_name(opts), counts);
    }
    let ours: Medians = per_count
        .iter()
        .map(|(&threads, (us, _))| (threads, median(us.clone())))
        .collect();
    if !opts.yardstick {
        return Ok((out, ours));
    }
    out.push_str(&yardstick::compare(&mut setup.sim, opts.repeat));
    Ok((out, ours))
}
