//! The deck grammar fuzzed: 10,000 decks a run (6,000 in `generated_decks_never_panic`, 4,000
//! in `mutated_example_decks_never_panic`) go through `pdq::input::deck::parse` and, when
//! they parse, through what `pdq check` does before it builds: the model built from the
//! materials, the particles counted (`geometry::count_particles`), the memory estimated and
//! guarded (`setup::memory`). A scene the estimate finds small (≤ 2,000 particles, 200,000
//! bonds, over at most 100,000 cells) is then checked whole by `pdq::driver::run::check`,
//! which builds it and times a few steps. Nothing may panic, and an error must point at a
//! line of the deck (or at none).
//!
//! The generated decks (`deck_fuzz/decks.rs`, `sections.rs`, `values.rs`) follow the real
//! grammar (docs/deck.md): every section the parser reads, for every model, with good values
//! and, in the noisy ones, edge values (0, negative, `nan`, `inf`, 1e308, empty strings and
//! arrays, wrong types, quantities with malformed or wrong units), missing, repeated and
//! misspelt keys, duplicated, missing, moved and unknown sections. The mutated decks are the
//! example decks (`inputs/`, `tests/decks/`, `validation/`) and clean generated ones with lines
//! deleted, duplicated, swapped or inserted, a value replaced by a random token, or the text
//! cut at a random byte.
//!
//! A deck checked for more than a minute (a hang) aborts the run with the deck on stderr; one
//! that takes more than 2 s is printed. Environment: `PDQ_FUZZ_SCALE=N` runs N times the
//! cases (a longer hunt); `PDQ_FUZZ_STATS=1` prints how far the decks got, every 1,000;
//! `PDQ_FUZZ_ERRORS=1` prints every error (`=2` with its deck); `PDQ_FUZZ_TRACE=FILE` writes
//! each deck to FILE before it is checked (the deck of an allocation abort). Failures are not
//! persisted: the shrunk deck is in the failure message.

use pdq::input::deck::{self, DeckError, Scene};
use pdq::input::geometry;
use pdq::input::setup::{self, memory, memory::Estimate};
use pdq::model::{Model, ModelVisitor};
use proptest::prelude::*;
use proptest::sample::{select, Index};
use proptest::test_runner::Config;
use std::collections::HashMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::thread::ThreadId;
use std::time::{Duration, Instant};

#[path = "deck_fuzz/decks.rs"]
mod decks;
#[path = "deck_fuzz/sections.rs"]
mod sections;
#[path = "deck_fuzz/values.rs"]
mod values;

use values::{pick, random_value, EDGE_NUMBERS, EDGE_STRINGS, S, WRONG_TYPES};

// ---------------------------------------------------------------------------------------
// Mutations

#[derive(Clone, Debug)]
enum Mutation {
    Delete(Index),
    Duplicate(Index),
    Swap(Index, Index),
    Replace(Index, String),
    Insert(Index, String),
    Truncate(Index),
}

fn token() -> S<String> {
    let good = &[
        "\"1 mm\"",
        "3",
        "\"rock\"",
        "\"box\"",
        "\"0 0 0 mm\"",
        "\"auto\"",
    ];
    prop_oneof![
        pick(good),
        pick(EDGE_NUMBERS),
        pick(EDGE_STRINGS),
        pick(WRONG_TYPES),
        random_value(),
    ]
    .boxed()
}

fn inserted_line() -> S<String> {
    let headers = &[
        "[model]",
        "[lattice]",
        "[time]",
        "[[geometry]]",
        "[[boundary]]",
        "[pair]",
        "[output]",
        "[materials.rock]",
        "[[bar]]",
        "[solver]",
        "[parallel]",
        "[deform]",
        "[thermostat]",
        "[velocity]",
        "[[analysis]]",
        "[[probe]]",
        "[[load]]",
        "[[initial]]",
        "[",
        "[[]]",
        "units = \"SI\"",
        "m = 3",
        "shape = \"box\"",
        "#",
        "= 1",
        "x.y.z = 1",
    ];
    prop_oneof![
        pick(headers),
        (pick(&["name", "shape", "steps", "region", "kind"]), token())
            .prop_map(|(k, v)| format!("{k} = {v}")),
    ]
    .boxed()
}

fn mutation() -> S<Mutation> {
    prop_oneof![
        3 => any::<Index>().prop_map(Mutation::Delete),
        2 => any::<Index>().prop_map(Mutation::Duplicate),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Mutation::Swap(a, b)),
        4 => (any::<Index>(), token()).prop_map(|(i, t)| Mutation::Replace(i, t)),
        2 => (any::<Index>(), inserted_line()).prop_map(|(i, t)| Mutation::Insert(i, t)),
        1 => any::<Index>().prop_map(Mutation::Truncate),
    ]
    .boxed()
}

/// The value after the first `=` of a line replaced by `token` (the line itself if none).
fn replace_value(line: &str, token: &str) -> String {
    match line.split_once('=') {
        Some((k, _)) => format!("{k}= {token}"),
        None => token.to_string(),
    }
}

fn mutate(text: &str, m: &Mutation) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    if lines.is_empty() {
        lines.push(String::new());
    }
    let n = lines.len();
    match m {
        Mutation::Delete(i) => drop(lines.remove(i.index(n))),
        Mutation::Duplicate(i) => lines.insert(i.index(n), lines[i.index(n)].clone()),
        Mutation::Swap(a, b) => lines.swap(a.index(n), b.index(n)),
        Mutation::Replace(i, t) => lines[i.index(n)] = replace_value(&lines[i.index(n)], t),
        Mutation::Insert(i, t) => lines.insert(i.index(n + 1), t.clone()),
        Mutation::Truncate(i) => {
            let mut cut = i.index(text.len() + 1);
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            return text[..cut].to_string();
        }
    }
    lines.join("\n") + "\n"
}

/// The example decks of the repository, read once.
fn example_decks() -> &'static [String] {
    static DECKS: OnceLock<Vec<String>> = OnceLock::new();
    DECKS.get_or_init(|| {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut decks = Vec::new();
        for dir in ["inputs", "tests/decks", "validation"] {
            let Ok(files) = std::fs::read_dir(root.join(dir)) else {
                continue;
            };
            let mut paths: Vec<_> = files.filter_map(|e| Some(e.ok()?.path())).collect();
            paths.sort();
            for p in paths
                .iter()
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            {
                decks.push(std::fs::read_to_string(p).expect("read an example deck"));
            }
        }
        assert!(
            decks.len() >= 5,
            "too few example decks found under {root:?}"
        );
        decks
    })
}

fn mutated(base: S<String>, max: usize) -> S<String> {
    (base, prop::collection::vec(mutation(), 1..=max))
        .prop_map(|(text, ms)| ms.iter().fold(text, |t, m| mutate(&t, m)))
        .boxed()
}

// ---------------------------------------------------------------------------------------
// The checks

/// What `pdq check` does before building, for the deck's model `M`: the memory estimate
/// (which counts the particles) and the guard against what the process may have.
struct Guard<'a>(&'a Scene, f64);

impl ModelVisitor for Guard<'_> {
    type Output = (Option<Estimate>, Result<Estimate, DeckError>);
    fn visit<M: Model>(self, _model: M) -> Self::Output {
        let Guard(scene, reach) = self;
        (
            memory::estimate::<M>(scene, reach),
            memory::guard::<M>(scene, reach),
        )
    }
}

/// Lattice sites in the bounding boxes of the added shapes: what counting them costs.
fn sites_to_count(scene: &Scene) -> f64 {
    let l = &scene.lattice;
    let per_site = l.site_volume();
    let ops = scene.geometry_ops();
    let volumes = ops.iter().map(|op| match op {
        geometry::Op::Add { shape, .. } => {
            let (lo, hi) = shape.bounds();
            (0..3)
                .map(|e| (hi[e] - lo[e]).abs() + 3.0 * l.spacing)
                .product::<f64>()
        }
        geometry::Op::Subtract { .. } => 0.0,
    });
    volumes.map(|v| v / per_site).sum::<f64>() * ops.len().max(1) as f64
}

/// Cells a horizon (or pair reach) wide over the bounding box of the added shapes and bars.
/// A periodic scene stores all of them, however few hold particles: 72 particles 1 m apart at
/// a 3 mm horizon took 7 GB and a minute to lay out (a finding of this test, not fixed here),
/// so such scenes are not built.
fn cells_spanned(scene: &Scene) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut take = |p: [f64; 3]| {
        for e in 0..3 {
            (lo[e], hi[e]) = (lo[e].min(p[e]), hi[e].max(p[e]));
        }
    };
    for op in scene.geometry_ops() {
        if let geometry::Op::Add { shape, .. } = op {
            let (a, b) = shape.bounds();
            take(a);
            take(b);
        }
    }
    for b in scene.geometry_bars() {
        take(b.from);
        take(b.to);
    }
    let cell = scene.horizon.max(scene.spacing).max(pair_reach(scene));
    (0..3).map(|e| (hi[e] - lo[e]) / cell + 3.0).product()
}

/// The pair law's reach as the memory guard takes it: cutoff and skin.
fn pair_reach(scene: &Scene) -> f64 {
    scene.pair.as_ref().map_or(0.0, |p| {
        let cutoff = p.cutoff.unwrap_or(2.5 * scene.spacing);
        cutoff + p.skin.unwrap_or(0.3 * cutoff)
    })
}

/// How far the decks got: refused by the parser, parsed but too big to count, refused by the
/// model or the memory guard, not built (big), refused by the check, checked.
const OUTCOMES: [&str; 6] = [
    "parse",
    "uncounted",
    "model/guard",
    "unbuilt",
    "check",
    "ok",
];

/// Counts an outcome; `PDQ_FUZZ_STATS=1` prints the tally every 1,000 decks.
fn tally(outcome: usize) {
    static TALLY: [AtomicUsize; 6] = [const { AtomicUsize::new(0) }; 6];
    TALLY[outcome].fetch_add(1, Ordering::Relaxed);
    let counts = TALLY.each_ref().map(|t| t.load(Ordering::Relaxed));
    if std::env::var_os("PDQ_FUZZ_STATS").is_some() && counts.iter().sum::<usize>() % 1000 == 0 {
        let parts: Vec<String> = OUTCOMES
            .iter()
            .zip(counts)
            .map(|(o, c)| format!("{o} {c}"))
            .collect();
        eprintln!("decks: {}", parts.join(", "));
    }
}

/// `PDQ_FUZZ_ERRORS=1` prints every error (`=2`: with its deck), to see what the decks reach.
fn show(message: &str, deck: &str) {
    match std::env::var("PDQ_FUZZ_ERRORS").as_deref() {
        Ok("1") => eprintln!("error: {message}"),
        Ok("2") => eprintln!("error: {message}\n{deck}\n----"),
        _ => {}
    }
}

/// The checks after a successful parse of a deck of `lines` lines; `Err` names what is wrong.
fn check_scene(scene: &Scene, lines: usize) -> Result<(), String> {
    if sites_to_count(scene) > 4e6 {
        tally(1);
        return Ok(()); // counting them takes more than milliseconds: not a cheap check
    }
    let (ops, bars) = (scene.geometry_ops(), scene.geometry_bars());
    let count = geometry::count_particles(&scene.lattice, &ops, &bars);
    let (estimate, guarded) = match setup::with_model(scene, Guard(scene, pair_reach(scene))) {
        Err(e) => {
            tally(2);
            return error_line_ok(e.line, lines); // the model refuses the materials
        }
        Ok(x) => x,
    };
    if estimate.map(|e| e.particles) != count {
        return Err(format!(
            "count_particles {count:?}, but the estimate {estimate:?}"
        ));
    }
    let e = match guarded {
        Err(e) => {
            tally(2);
            return error_line_ok(e.line, lines);
        }
        Ok(e) => e,
    };
    let cells = cells_spanned(scene);
    let big = e.particles > 2000.0 || e.bonds > 2e5 || e.pairs > 2e5;
    if count.is_none() || big || cells.is_nan() || cells > 1e5 {
        tally(3);
        return Ok(()); // not built: it could be big
    }
    match pdq::driver::run::check(scene) {
        Err(message) => {
            tally(4);
            show(&message, "");
            error_line_ok(message_line(&message), lines)
        }
        Ok(_) => {
            tally(5);
            Ok(())
        }
    }
}

/// The line of a `fuzz.toml:LINE: message`.
fn message_line(message: &str) -> Option<usize> {
    let rest = message.strip_prefix("fuzz.toml:")?;
    rest.split(':').next()?.trim().parse().ok()
}

/// An error's line is a line of the deck (`lines` of them; the end of a cut one), if any.
fn error_line_ok(line: Option<usize>, lines: usize) -> Result<(), String> {
    match line {
        Some(l) if l == 0 || l > lines + 1 => Err(format!("an error at line {l} of {lines}")),
        _ => Ok(()),
    }
}

/// Cases running, by thread, for the watchdog.
fn running() -> &'static Mutex<HashMap<ThreadId, (Instant, String)>> {
    static RUNNING: OnceLock<Mutex<HashMap<ThreadId, (Instant, String)>>> = OnceLock::new();
    RUNNING.get_or_init(|| {
        std::thread::spawn(|| loop {
            std::thread::sleep(Duration::from_secs(1));
            let map = running().lock().unwrap_or_else(|e| e.into_inner());
            if let Some((t, deck)) = map.values().find(|(t, _)| t.elapsed().as_secs() > 60) {
                eprintln!(
                    "a deck has been checked for {:?} (a hang):\n{deck}",
                    t.elapsed()
                );
                std::process::abort();
            }
        });
        Mutex::new(HashMap::new())
    })
}

/// Starts watching this thread's deck, or stops and says how long it took.
fn watch(deck: Option<&str>) -> Duration {
    let mut map = running().lock().unwrap_or_else(|e| e.into_inner());
    let id = std::thread::current().id();
    match deck {
        Some(d) => drop(map.insert(id, (Instant::now(), d.to_string()))),
        None => return map.remove(&id).map_or(Duration::ZERO, |(t, _)| t.elapsed()),
    }
    Duration::ZERO
}

/// Parses `text` and checks what parses; a panic, a misplaced line or a wrong count fails.
fn fuzz_one(text: &str) -> Result<(), TestCaseError> {
    if let Ok(path) = std::env::var("PDQ_FUZZ_TRACE") {
        let _ = std::fs::write(path, text);
    }
    watch(Some(text));
    let lines = text.lines().count();
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        match deck::parse(text, "fuzz.toml", "fuzz") {
            Err(e) => {
                tally(0);
                show(&e.to_string(), text);
                error_line_ok(e.line, lines)
            }
            Ok(scene) => check_scene(&scene, lines),
        }
    }));
    let took = watch(None);
    if took > Duration::from_secs(2) {
        eprintln!("slow deck ({took:?}):\n{text}\n----");
    }
    match outcome {
        Err(_) => Err(TestCaseError::fail(format!(
            "panicked on the deck:\n{text}"
        ))),
        Ok(Err(what)) => Err(TestCaseError::fail(format!("{what} on the deck:\n{text}"))),
        Ok(Ok(())) => Ok(()),
    }
}

/// `cases`, times `PDQ_FUZZ_SCALE` if set (for a longer hunt).
fn config(cases: u32) -> Config {
    let scale = std::env::var("PDQ_FUZZ_SCALE")
        .ok()
        .and_then(|s| s.parse().ok());
    Config {
        cases: cases * scale.unwrap_or(1),
        failure_persistence: None,
        max_shrink_iters: 2000,
        ..Config::default()
    }
}

/// Generated decks: clean, clean with one to three mutations, a little and very noisy.
fn generated_decks() -> S<String> {
    prop_oneof![
        3 => decks::deck(0),
        3 => mutated(decks::deck(0), 3),
        2 => decks::deck(1),
        2 => decks::deck(3),
    ]
    .boxed()
}

proptest! {
    // 6,000 of the 10,000 cases.
    #![proptest_config(config(6_000))]
    #[test]
    fn generated_decks_never_panic(text in generated_decks()) {
        fuzz_one(&text)?;
    }
}

proptest! {
    // 4,000 of the 10,000 cases.
    #![proptest_config(config(4_000))]
    #[test]
    fn mutated_example_decks_never_panic(
        text in mutated(select(example_decks().to_vec()).boxed(), 4)
    ) {
        fuzz_one(&text)?;
    }
}
