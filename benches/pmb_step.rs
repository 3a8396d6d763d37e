//! `cargo bench`: the standard scene through `pdq::lab::bench` (the same code as `pdq bench`).

fn main() {
    let opts = pdq::lab::bench::BenchOptions {
        model: "pmb".into(),
        scene: "standard".into(),
        threads: vec![1],
        ranks: vec![],
        walls: pdq::parallel::decomposition::Walls::Whole,
        procs: pdq::parallel::decomposition::Procs::Auto,
        rounds: 1,
        yardstick: true,
        steps: 100,
        n: 40,
        peer: false,
        repeat: 5,
        checkpoint: true,
        savings: false,
        voids: false,
    };
    match pdq::lab::bench::run(&opts) {
        Ok(s) => print!("{s}"),
        Err(e) => eprintln!("bench failed: {e}"),
    }
}
