//! The `pdq` command line.

use clap::{Args, Parser, Subcommand};
use pdq::driver::run;
use pdq::input::deck;
use pdq::lab::bench;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "pdq",
    version,
    about = "PDQ peridynamics: cracking of plain, reinforced and prestressed concrete"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a deck: time history, frames and a timing table in the output directory.
    Run(RunArgs),
    /// Run the validation cases against engineering formulas; write report.md.
    Validate(ValidateArgs),
    /// Numerical stability stress tests: critical time step against the bound, energy drift,
    /// sudden failure (docs/stability.md).
    Stress(StressArgs),
    /// Print what a frame or checkpoint file holds: step, time, particles, attributes, bonds.
    Info { file: PathBuf },
    /// Check a deck: particles, bonds, memory, time step, and an estimated run time.
    Check { deck: PathBuf },
    /// List the models and the attributes each declares.
    Models,
    /// Time the standard benchmark scene (shared/bench): µs per particle-step.
    Bench(BenchArgs),
    /// Plot one column against another from one or more runs' history.csv (or any CSV with a
    /// header), as lines or points (PNG).
    Plot(PlotArgs),
    /// Draw a run's pictures again from its output directory: the history (energies, broken
    /// bonds, grips, probes, temperature and pressure) into DIR/pictures/, and the final state
    /// coloured by damage (or speed, if nothing broke) as DIR/pictures/body.png when the run
    /// wrote final_positions.csv.
    Pictures {
        dir: PathBuf,
        /// The title over each picture (default: the directory's name).
        #[arg(long)]
        title: Option<String>,
    },
    /// Find the voids in a run's saved frames (DIR/frames/), as `[[analysis]] kind = "voids"`
    /// does in situ: DIR/NAME.csv (one row per frame), DIR/NAME_clusters.csv,
    /// DIR/NAME_events.csv, and the voxel labels as DIR/NAME_voxels.xdmf for ParaView.
    Voids {
        dir: PathBuf,
        /// The voxel side in the run's units (for a lattice, its spacing; fcc: the cell side).
        #[arg(long)]
        voxel: f64,
        /// "face" (6 neighbours, the default) or "all" (26).
        #[arg(long, default_value = "face")]
        connectivity: String,
        /// Names the files.
        #[arg(long, default_value = "voids_post")]
        name: String,
        /// Leave out the voxel labels (only the tables).
        #[arg(long)]
        no_labels: bool,
    },
    /// Write a bondless deck's initial state (positions, velocities, one type per material)
    /// as a LAMMPS data file for `read_data`.
    LammpsData {
        deck: PathBuf,
        /// The data file to write.
        output: PathBuf,
    },
}

#[derive(Args)]
struct RunArgs {
    deck: PathBuf,
    /// Run this many steps instead of the deck's.
    #[arg(long)]
    steps: Option<u64>,
    /// Write output here instead of the deck's directory.
    #[arg(long)]
    output: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long)]
    quiet: bool,
    /// Worker threads, one procCube each (not under mpirun, where each rank is one).
    #[arg(long)]
    threads: Option<usize>,
    /// ProcCubes along x, y and z, as NXxNYxNZ (e.g. 2x2x1), or "auto".
    #[arg(long, value_parser = parse_procs)]
    procs: Option<pdq::parallel::decomposition::Procs>,
    /// Ghost messages: "whole" walls or "trimmed" to the cells each neighbour needs.
    #[arg(long, value_parser = parse_walls)]
    walls: Option<pdq::parallel::decomposition::Walls>,
    /// Resume from a checkpoint file, or from the newest readable checkpoint in a
    /// directory (an output directory or its checkpoints/).
    #[arg(long)]
    restart: Option<PathBuf>,
}

#[derive(Args)]
struct PlotArgs {
    /// history.csv files, one line each.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// The column along x.
    #[arg(long)]
    x: String,
    /// The column along y.
    #[arg(long)]
    y: String,
    /// Factors on x and y, as X,Y (e.g. 1000,0.001 for mm and kN from m and N).
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 1.0])]
    scale: Vec<f64>,
    /// Legend names, comma-separated, one per file (default: each file's directory).
    #[arg(long, value_delimiter = ',')]
    labels: Vec<String>,
    #[arg(long, default_value = "")]
    title: String,
    /// The PNG to write.
    #[arg(long)]
    output: PathBuf,
    /// Draw each row as a point (e.g. every particle of final_positions.csv).
    #[arg(long)]
    points: bool,
}

#[derive(Args)]
struct ValidateArgs {
    /// Coarse versions of every case (the default).
    #[arg(long, conflicts_with = "full")]
    quick: bool,
    /// The finer resolution.
    #[arg(long, conflicts_with = "thesis")]
    full: bool,
    /// The thesis's resolution (the lap splices at 0.1 in, the girder and the reinforced
    /// beams at 1 in): hours on 2 cores; with --checkpoint-minutes and --resume.
    #[arg(long, conflicts_with = "quick")]
    thesis: bool,
    /// Cases to run (all when none is named).
    cases: Vec<String>,
    /// The directory of the case files (NAME.toml and suite.toml; validation/README.md).
    #[arg(long, default_value = "validation")]
    case_dir: PathBuf,
    /// Output directory.
    #[arg(long, default_value = "out/validate")]
    output: PathBuf,
    /// Threads per explicit or ADR case (default: the cores available; the implicit solve
    /// runs on one); with --sweep, the procCubes of each sweep run (default 1).
    #[arg(long)]
    threads: Option<usize>,
    /// Instead of the cases: ADR against an explicit load ramp on the LPS cantilever
    /// (force evaluations to the same residual).
    #[arg(long)]
    compare_adr: bool,
    /// With --compare-adr: the explicit run ramps the load over this many periods of the
    /// first bending mode (then holds it for three); a longer ramp leaves less vibration.
    #[arg(long, default_value_t = 5.0)]
    ramp_periods: f64,
    /// Quasi-static solver of the elastic cases: "implicit" (Newton with the assembled
    /// tangent, one thread; the same answers as ADR in a fraction of the time; matrix-free
    /// where the factor would not fit), "newton_krylov" (Newton, matrix-free; the default:
    /// the same answers to 1e-8, in half the time at --quick and a fraction at --full) or
    /// "adr".
    #[arg(long, value_parser = ["adr", "implicit", "newton_krylov"])]
    solver: Option<String>,
    /// Instead of the cases: the elastic cantilever swept over resolution, m and solver;
    /// error against run time (sweep.md, sweep.png).
    #[arg(long)]
    sweep: bool,
    /// Sweep: models, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "pmb,lps")]
    models: Vec<String>,
    /// Sweep: lattice planes across the section (odd), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "5,7,9")]
    planes: Vec<usize>,
    /// Sweep: horizon ratios m, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "2,3,4")]
    m: Vec<f64>,
    /// Sweep: solvers, comma-separated (implicit, newton_krylov, adr).
    #[arg(long, value_delimiter = ',', default_value = "implicit")]
    solvers: Vec<String>,
    /// Sweep: the relative residual each solve stops at (default: the case file's, 1e-9
    /// for the implicit and matrix-free solves; ask 1e-8 from about 25 planes on).
    #[arg(long)]
    tolerance: Option<f64>,
    /// Checkpoint each case every T minutes of wall time (long --full runs).
    #[arg(long, value_name = "T")]
    checkpoint_minutes: Option<f64>,
    /// Resume each case from the newest checkpoint in its output directory, where there is
    /// one (a run stopped by SIGTERM, Ctrl-C or a time limit).
    #[arg(long)]
    resume: bool,
    /// Instead of the cases: each elastic beam case's formula against 3D linear elasticity
    /// by finite elements on the case's geometry (fe_check.md).
    #[arg(long)]
    fe_check: bool,
    /// --fe-check: element orders, comma-separated, each a solve.
    #[arg(long, value_delimiter = ',', default_value = "2,3")]
    fe_orders: Vec<usize>,
    /// --fe-check: elements across the beam's depth.
    #[arg(long, default_value_t = 4)]
    fe_elements: usize,
}

#[derive(Args)]
struct StressArgs {
    /// Smaller and shorter runs (about a minute).
    #[arg(long)]
    quick: bool,
    /// Sections to run, comma-separated: dt, drift, failure (default all).
    #[arg(long, value_delimiter = ',')]
    sections: Vec<String>,
    /// Models to run, comma-separated (default all).
    #[arg(long, value_delimiter = ',')]
    models: Vec<String>,
    /// Cases run side by side.
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Also write the report to this file.
    #[arg(long)]
    output: Option<PathBuf>,
}

#[derive(Args)]
struct BenchArgs {
    #[arg(long, default_value = "pmb")]
    model: String,
    /// "standard": the peridynamic block of shared/bench (--model picks the model); "lj": the
    /// LJ melt of inputs/lj_melt.toml (LAMMPS bench/in.lj; its peer is lj/cut).
    #[arg(long, default_value = "standard", value_parser = ["standard", "lj"])]
    scene: String,
    /// Thread counts to time, comma-separated (one procCube per thread).
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    threads: Vec<usize>,
    /// MPI rank counts to time through mpirun, comma-separated (needs the `mpi` feature;
    /// default 1,2 in an MPI build, none otherwise).
    #[arg(long, value_delimiter = ',')]
    ranks: Vec<usize>,
    /// Ghost messages: whole walls or trimmed.
    #[arg(long, value_parser = parse_walls, default_value = "whole")]
    walls: pdq::parallel::decomposition::Walls,
    /// ProcCubes as NXxNYxNZ for every thread count (default: chosen per count).
    #[arg(long, value_parser = parse_procs)]
    procs: Option<pdq::parallel::decomposition::Procs>,
    /// Skip the generic-against-hand-written force pass comparison.
    #[arg(long)]
    no_yardstick: bool,
    #[arg(long, default_value_t = 200)]
    steps: u64,
    /// Lattice cells per edge: (n+1)³ particles, default 40, in the standard scene; 4n³ atoms,
    /// default 20 (32,000 atoms), in the LJ melt.
    #[arg(long)]
    n: Option<usize>,
    /// Also run LAMMPS (`lmp`, or $PDQ_LMP) on the same scene.
    #[arg(long)]
    peer: bool,
    /// Repetitions of the generic-vs-hand force pass comparison.
    #[arg(long, default_value_t = 7)]
    repeat: usize,
    /// Times through the thread counts, alternating; medians are printed when above 1.
    #[arg(long, default_value_t = 1)]
    rounds: usize,
    /// Also time writing a checkpoint of the scene against 100 steps (one thread).
    #[arg(long)]
    checkpoint: bool,
    /// Instead: the scene with and without each feature a deck may leave out (damage
    /// checks, state pass, rotations, shuffling), `--rounds` times; prints a table.
    #[arg(long)]
    savings: bool,
    /// Instead: the voids analysis's three label-merge schemes against procCubes (threads)
    /// and the size of the largest void, `--rounds` times; prints a table.
    #[arg(long)]
    voids: bool,
}

/// The cores this process may use.
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Cmd::Run(a) => run_deck(a),
        Cmd::Validate(a) => validate(a).map(|()| false),
        Cmd::Stress(a) => stress(a).map(|()| false),
        Cmd::Info { file } => pdq::output::info::info(&file).map(|s| {
            print!("{s}");
            false
        }),
        Cmd::Check { deck: path } => deck::load(&path)
            .map_err(|e| e.to_string())
            .and_then(|scene| run::check(&scene))
            .map(|s| {
                print!("{s}");
                false
            }),
        Cmd::Plot(a) => plot(a).map(|()| false),
        Cmd::Pictures { dir, title } => {
            let title = title.unwrap_or_else(|| {
                dir.file_name()
                    .map_or_else(|| dir.display().to_string(), |d| d.to_string_lossy().into())
            });
            pdq::output::pictures::redraw(&dir, &title).map(|files| {
                for f in files {
                    println!("{}", f.display());
                }
                false
            })
        }
        Cmd::Voids {
            dir,
            voxel,
            connectivity,
            name,
            no_labels,
        } => post_voids(&dir, voxel, &connectivity, name, !no_labels).map(|()| false),
        Cmd::LammpsData { deck: path, output } => deck::load(&path)
            .map_err(|e| e.to_string())
            .and_then(|scene| pdq::driver::export::lammps_data(&scene))
            .and_then(|data| {
                std::fs::write(&output, data.text())
                    .map_err(|e| format!("writing {}: {e}", output.display()))
            })
            .map(|()| false),
        Cmd::Models => {
            print!("{}", models_text());
            Ok(false)
        }
        Cmd::Bench(a) => bench_command(a).map(|()| false),
    };
    match result {
        Ok(true) => ExitCode::from(pdq::output::signals::EXIT_INTERRUPTED),
        Ok(false) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `pdq plot`.
fn plot(a: PlotArgs) -> Result<(), String> {
    let [sx, sy] = a.scale[..] else {
        return Err(format!(
            "--scale takes two factors, X,Y (got {})",
            a.scale.len()
        ));
    };
    pdq::output::curves::plot_curves(&pdq::output::curves::CurvePlot {
        files: a.files,
        x: a.x,
        y: a.y,
        scale: [sx, sy],
        labels: a.labels,
        title: a.title,
        output: a.output,
        points: a.points,
    })
}

/// `pdq run`; whether a signal interrupted the run (its checkpoint and outputs are written).
fn run_deck(a: RunArgs) -> Result<bool, String> {
    let scene = deck::load(&a.deck).map_err(|e| e.to_string())?;
    pdq::output::signals::install()?;
    // `--procs NXxNYxNZ` without `--threads` runs one thread per procCube.
    let threads = a.threads.or(match &a.procs {
        Some(pdq::parallel::decomposition::Procs::Given(v)) => Some(v.iter().product()),
        _ => None,
    });
    let summary = run::run(
        &scene,
        &run::RunOptions {
            steps: a.steps,
            output: a.output,
            quiet: a.quiet,
            threads,
            procs: a.procs,
            walls: a.walls,
            restart: a.restart,
        },
    )?;
    Ok(summary.interrupted.is_some())
}

/// `pdq validate`: the cases, or the sweep, or ADR against an explicit ramp.
fn validate(a: ValidateArgs) -> Result<(), String> {
    let threads = a.threads.unwrap_or_else(cores);
    if a.sweep {
        let plan = pdq::lab::validate::SweepPlan {
            models: &a.models,
            planes: &a.planes,
            ms: &a.m,
            solvers: &a.solvers,
            threads: a.threads.unwrap_or(1),
            tolerance: a.tolerance,
        };
        let s = pdq::lab::validate::sweep(&a.output, &a.case_dir, &plan)?;
        print!("{s}");
        return Ok(());
    }
    let level = if a.thesis {
        pdq::lab::validate::Level::Thesis
    } else if a.full {
        pdq::lab::validate::Level::Full
    } else {
        pdq::lab::validate::Level::Quick
    };
    if a.fe_check {
        let (report, _) = pdq::lab::validate::fe_check::fe_check(
            &pdq::lab::validate::fe_check::FeCheckOptions {
                cases: a.case_dir,
                level,
                only: a.cases,
                output: a.output,
                orders: a.fe_orders,
                elements_across: a.fe_elements,
            },
        )?;
        print!("{report}");
        return Ok(());
    }
    if a.compare_adr {
        let s = pdq::lab::validate::compare_adr(&a.output, &a.case_dir, threads, a.ramp_periods)?;
        print!("{s}");
        return Ok(());
    }
    let (table, failures) = pdq::lab::validate::run_all(&pdq::lab::validate::ValidateOptions {
        cases: a.case_dir,
        solver: match a.solver.as_deref() {
            Some(word) => pdq::lab::validate::ElasticSolver::named(word)?,
            None => pdq::lab::validate::ElasticSolver::NewtonKrylov,
        },
        level,
        only: a.cases,
        output: a.output,
        threads,
        long: pdq::lab::validate::LongRun {
            checkpoint_minutes: match a.checkpoint_minutes {
                Some(t) if !(t > 0.0 && t.is_finite()) => {
                    return Err(format!("--checkpoint-minutes must be > 0 (got {t})"))
                }
                Some(t) => t,
                None => 0.0,
            },
            resume: a.resume,
        },
    })?;
    print!("{table}");
    if failures.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} of the validation failed:\n  {}",
            if failures.len() == 1 {
                "a case"
            } else {
                "cases"
            },
            failures.join("\n  ")
        ))
    }
}

/// `pdq stress`: the report, printed and written where asked.
fn stress(a: StressArgs) -> Result<(), String> {
    let report = pdq::lab::stress::run(&pdq::lab::stress::StressOptions {
        quick: a.quick,
        sections: a.sections,
        models: a.models,
        threads: a.threads,
    })?;
    print!("{report}");
    match a.output {
        Some(path) => {
            std::fs::write(&path, &report).map_err(|e| format!("writing {}: {e}", path.display()))
        }
        None => Ok(()),
    }
}

/// `pdq bench`.
fn bench_command(a: BenchArgs) -> Result<(), String> {
    let s = bench::run(&bench::BenchOptions {
        model: a.model,
        threads: a.threads,
        ranks: if a.ranks.is_empty() && cfg!(feature = "mpi") && !launched_by_mpirun() {
            vec![1, 2]
        } else {
            a.ranks
        },
        walls: a.walls,
        procs: a.procs.unwrap_or(pdq::parallel::decomposition::Procs::Auto),
        yardstick: !a.no_yardstick,
        steps: a.steps,
        n: a.n.unwrap_or(if a.scene == "lj" { 20 } else { 40 }),
        scene: a.scene,
        peer: a.peer,
        repeat: a.repeat,
        rounds: a.rounds,
        checkpoint: a.checkpoint,
        savings: a.savings,
        voids: a.voids,
    })?;
    print!("{s}");
    Ok(())
}

/// Whether this process is an MPI rank started by mpirun (always false without the feature).
fn launched_by_mpirun() -> bool {
    #[cfg(feature = "mpi")]
    return pdq::parallel::comm_mpi::launched_by_mpirun();
    #[cfg(not(feature = "mpi"))]
    false
}

fn parse_procs(s: &str) -> Result<pdq::parallel::decomposition::Procs, String> {
    if s == "auto" {
        return Ok(pdq::parallel::decomposition::Procs::Auto);
    }
    let v: Vec<usize> = s
        .split('x')
        .map(|p| p.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{s}': give NXxNYxNZ, e.g. 2x2x1, or auto"))?;
    match v.as_slice() {
        &[x, y, z] if x > 0 && y > 0 && z > 0 => {
            Ok(pdq::parallel::decomposition::Procs::Given([x, y, z]))
        }
        _ => Err(format!(
            "'{s}': give three counts of at least 1, e.g. 2x2x1"
        )),
    }
}

fn parse_walls(s: &str) -> Result<pdq::parallel::decomposition::Walls, String> {
    match s {
        "whole" => Ok(pdq::parallel::decomposition::Walls::Whole),
        "trimmed" => Ok(pdq::parallel::decomposition::Walls::Trimmed),
        _ => Err(format!("'{s}': use whole or trimmed")),
    }
}

fn models_text() -> String {
    let fields = |f: &[pdq::model::attributes::Field]| {
        if f.is_empty() {
            "()".to_string()
        } else {
            f.iter()
                .map(|f| format!("{}[{}]", f.name, f.len))
                .collect::<Vec<_>>()
                .join(" ")
        }
    };
    let mut s = String::new();
    for m in pdq::models::info() {
        s.push_str(&format!("{}: {}\n", m.name, m.summary));
        s.push_str(&format!("  alter  {}\n", fields(m.alter)));
        s.push_str(&format!("  fixed  {}\n", fields(m.fixed)));
        s.push_str(&format!("  bond   {}\n", fields(m.bond)));
        s.push_str(&format!("  state  {}\n", fields(m.state)));
        s.push_str(&format!("  force  {}\n", fields(m.force)));
        for (k, v) in m.options {
            s.push_str(&format!("  option {k}: {v}\n"));
        }
    }
    s.push_str("\npair laws ([pair] law = ...):\n");
    for p in pdq::pairs::info() {
        s.push_str(&format!("{}: {}\n", p.name, p.summary));
        for (k, v) in p.keys {
            s.push_str(&format!("  key    {k}: {v}\n"));
        }
        if p.skips_bonded {
            s.push_str("  leaves out pairs joined by an intact bond\n");
        }
    }
    s
}

/// `pdq voids DIR`: the voids of a run's frames, afterwards.
fn post_voids(
    dir: &std::path::Path,
    voxel: f64,
    connectivity: &str,
    name: String,
    labels: bool,
) -> Result<(), String> {
    use pdq::voids::Connectivity;
    let connectivity = match connectivity {
        "face" => Connectivity::Face,
        "all" => Connectivity::All,
        c => {
            return Err(format!(
                "--connectivity '{c}' is not known (use \"face\": 6 neighbours, or \"all\": 26)"
            ))
        }
    };
    if !(voxel.is_finite() && voxel > 0.0) {
        return Err(format!("--voxel must be a length > 0, got {voxel}"));
    }
    if !name
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        || name.is_empty()
    {
        return Err(format!(
            "--name '{name}' must be letters, digits, '_' or '-'"
        ));
    }
    let ask = pdq::driver::post::PostVoids {
        voxel,
        connectivity,
        name,
        labels,
    };
    let s = pdq::driver::post::voids_from_frames(dir, &ask)?;
    println!(
        "{} frames ({:.1} MB read) in {:.3} s: {} voids at the last; tables {}/{}*.csv{}",
        s.frames,
        s.bytes_read as f64 / 1e6,
        s.seconds,
        s.voids,
        dir.display(),
        ask.name,
        if ask.labels {
            format!(", voxel labels {}/{}_voxels.xdmf", dir.display(), ask.name)
        } else {
            String::new()
        }
    );
    Ok(())
}
