//! `cargo bench`: the standard scene through `pdq::bench` (the same code as `pdq bench`).

fn main() {
    let opts = pdq::bench::BenchOptions {
        model: "pmb".into(),
        threads: vec![1],
        ranks: vec![],
        walls: pdq::decomposition::Walls::Whole,
        procs: pdq::decomposition::Procs::Auto,
        rounds: 1,
        yardstick: true,
        steps: 100,
        n: 40,
        peer: false,
        repeat: 5,
        checkpoint: true,
        savings: false,
    };
    match pdq::bench::run(&opts) {
        Ok(s) => print!("{s}"),
        Err(e) => eprintln!("bench failed: {e}"),
    }
}
