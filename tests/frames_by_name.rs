//! Every attribute a model declares reaches the output frames under its declared name, and the
//! values are the model's (rotations and moments for micropolar, temperature and heat for
//! thermal, the dilatation for LPS).

use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;

mod common;

/// Array names and one value per particle of the last frame's `name` array (first component),
/// read back from the HDF5 file.
fn last_frame(dir: &std::path::Path, name: &str) -> (Vec<String>, Vec<f64>) {
    let mut frames: Vec<_> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "h5"))
        .collect();
    frames.sort();
    let f = hdf5_pure::File::open(frames.last().unwrap()).unwrap();
    let names = f.root().datasets().unwrap();
    assert!(
        names.iter().any(|n| n == name),
        "no array '{name}' in {names:?}"
    );
    let d = f.dataset(name).unwrap();
    let comps = d.shape().unwrap().get(1).copied().unwrap_or(1) as usize;
    let values = d.read_f64().unwrap();
    (names, values.chunks(comps).map(|c| c[0]).collect())
}

fn run_frames(model: &str) -> std::path::PathBuf {
    let text = common::model_pull_deck(model)
        .replace("steps = 500", "steps = 60")
        .replace(
            "history_every = 100",
            "history_every = 30\nframes_every = 30",
        );
    let scene = deck::parse(&text, "t.toml", "t").unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-frames-{model}-{}", std::process::id()));
    run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    dir
}

#[test]
fn declared_attributes_reach_the_frames_by_name() {
    for (model, declared, moving) in [
        (
            "micropolar",
            &[
                "pos",
                "rotation",
                "vel",
                "angular_velocity",
                "orientation",
                "frame",
                "force",
                "moment",
            ][..],
            "rotation",
        ),
        (
            "thermal",
            &[
                "pos",
                "vel",
                "temperature",
                "conduction_sum",
                "force",
                "heat",
            ][..],
            "temperature",
        ),
        (
            "lps",
            &[
                "pos",
                "vel",
                "weighted_volume",
                "dilatation",
                "inverse_weighted_volume",
                "force",
            ][..],
            "dilatation",
        ),
    ] {
        let dir = run_frames(model);
        let (names, values) = last_frame(&dir, moving);
        for d in declared {
            assert!(
                names.iter().any(|n| n == d),
                "{model}: no '{d}' array in {names:?}"
            );
        }
        let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        eprintln!("{model}: largest |{moving}| in the last frame {largest:.3e}");
        assert!(
            largest > 0.0 && values.iter().all(|v| v.is_finite()),
            "{model}: '{moving}' is not a live field"
        );
        let _ = std::fs::remove_dir_all(dir);
    }
}
