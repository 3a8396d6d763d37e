//! The memory guard (issue 25): the estimate counts the particles the geometry makes exactly
//! (subtractions and overlaps included) and bounds the bonds from above; a scene that will
//! not fit (the 32-million-particle block of the issue) is refused by `pdq check` and
//! `pdq run` with the estimate and the remedies, before anything is allocated.

use pdq::driver::run::{check, run, RunOptions};
use pdq::input::deck;
use pdq::input::setup::build_as;
use pdq::models::pmb::Pmb;
use pdq::models::point::Point;

#[test]
fn the_estimate_counts_the_particles_exactly_and_bounds_the_bonds() {
    for file in ["inputs/pmb_block.toml", "tests/decks/holes.toml"] {
        let text = std::fs::read_to_string(file).unwrap();
        let scene = deck::parse(&text, file, "guard").unwrap();
        let setup = build_as::<Pmb>(&scene).unwrap();
        let e = setup.memory;
        let n = setup.sim.particles.len() as f64;
        let bonds = setup.sim.bonds.len() as f64;
        assert_eq!(e.particles, n, "{file}");
        assert!(
            e.bonds >= bonds && e.bonds < 1.6 * bonds,
            "{file}: {} bonds estimated, {bonds} found",
            e.bonds
        );
        assert!(e.peak > e.records && e.records > 0.0);
    }
    // fcc, bondless, with a pair law: its neighbour pairs instead of bonds.
    let text = std::fs::read_to_string("inputs/lj_melt.toml")
        .unwrap()
        .replace("max = [33.5, 33.5, 33.5]", "max = [13.4, 13.4, 13.4]");
    let scene = deck::parse(&text, "lj_melt.toml", "guard").unwrap();
    let setup = build_as::<Point>(&scene).unwrap();
    assert_eq!(setup.memory.particles, 2048.0);
    assert_eq!(setup.memory.bonds, 0.0);
    // fcc at density 0.8442 within 2.8 sigma: the shells at a/√2, a, a√1.5, a√2 and a√2.5
    // hold 12 + 6 + 24 + 12 + 24 sites (a = 1.6796).
    assert_eq!(setup.memory.pairs, 2048.0 * 78.0 / 2.0);
}

#[test]
fn a_scene_too_large_for_the_machine_is_refused_with_the_estimate_and_remedies() {
    // The deck: the example block at 0.05 mm (32 million particles, m = 3).
    let text = std::fs::read_to_string("inputs/pmb_block.toml").unwrap();
    for old in ["spacing = \"1 mm\"", "horizon = \"3.015 mm\""] {
        assert!(text.contains(old), "inputs/pmb_block.toml lost '{old}'");
    }
    let text = text
        .replace("spacing = \"1 mm\"", "spacing = \"0.05 mm\"")
        .replace("horizon = \"3.015 mm\"", "horizon = \"0.15075 mm\"");
    let scene = deck::parse(&text, "pmb_block_fine.toml", "fine").unwrap();
    let e = check(&scene).unwrap_err();
    for words in [
        "will not fit in memory",
        "3.160e7 particles",
        "GiB to set up",
        "this process may have",
        "Nothing was allocated",
        "a coarser lattice",
        "a smaller horizon",
    ] {
        assert!(e.contains(words), "'{words}' not in: {e}");
    }
    let dir = std::env::temp_dir().join(format!("pdq-guard-{}", std::process::id()));
    let opts = RunOptions {
        output: Some(dir.clone()),
        quiet: true,
        ..Default::default()
    };
    let e = run(&scene, &opts).unwrap_err();
    assert!(e.contains("will not fit in memory"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_horizon_of_a_million_spacings_is_refused_at_once() {
    // Found by tests/deck_fuzz.rs: the estimate counted the sites within the horizon one by
    // one, (2·10⁶)³ of them, and `pdq check` never ended.
    let text = std::fs::read_to_string("inputs/pmb_block.toml")
        .unwrap()
        .replace("horizon = \"3.015 mm\"", "m = 1e6");
    let scene = deck::parse(&text, "pmb_block_wide.toml", "wide").unwrap();
    let start = std::time::Instant::now();
    let e = check(&scene).unwrap_err();
    assert!(e.contains("will not fit in memory"), "{e}");
    assert!(
        start.elapsed().as_secs_f64() < 5.0,
        "took {:?}",
        start.elapsed()
    );
}
