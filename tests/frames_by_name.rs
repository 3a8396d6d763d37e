//! Every attribute a model declares reaches the output frames under its declared name, and the
//! values are the model's (rotations and moments for micropolar, temperature and heat for
//! thermal, the dilatation for LPS).

use pdq::deck;
use pdq::run::{run, RunOptions};

mod common;

/// Array names and one value per particle of the last frame's `name` array (first component).
fn last_frame(dir: &std::path::Path, name: &str) -> (Vec<String>, Vec<f64>) {
    let mut frames: Vec<_> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    frames.sort();
    let bytes = std::fs::read(frames.last().unwrap()).unwrap();
    let start = bytes
        .windows(13)
        .position(|w| w == b"<AppendedData")
        .unwrap();
    let header = String::from_utf8_lossy(&bytes[..start]);
    let mut names = Vec::new();
    let mut wanted = None;
    for tag in header.split("<DataArray").skip(1) {
        let attr = |key: &str| {
            let at = tag.find(&format!(" {key}=\""))? + key.len() + 3;
            Some(tag[at..at + tag[at..].find('"')?].to_string())
        };
        // The point coordinates' array has no name.
        let Some(this) = attr("Name") else { continue };
        if this == name {
            let comps: usize = attr("NumberOfComponents").unwrap().parse().unwrap();
            wanted = Some((attr("offset").unwrap().parse::<usize>().unwrap(), comps));
        }
        names.push(this);
    }
    // Appended raw data: after the '_' marker, each array is a u64 byte count and the values.
    let data = &bytes[start..];
    let data = &data[data.iter().position(|&b| b == b'_').unwrap() + 1..];
    let (offset, comps) = wanted.unwrap_or_else(|| panic!("no array '{name}' in {names:?}"));
    let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
    let values: Vec<f64> = data[offset + 8..offset + 8 + len]
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
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
