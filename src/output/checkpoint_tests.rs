//! Unit tests of `output::checkpoint`.

use super::*;

fn sample(step: u64) -> Checkpoint {
    Checkpoint {
        state: Snapshot {
            step,
            time: 1.25e-3,
            dt: 2.5e-7,
            integrator: "velocity-verlet".into(),
            ids: None,
            model: "concrete".into(),
            schema: "pos:3,vel:3|plastic_stretch:1|force:3".into(),
            x0: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]],
            alter: (0..18).map(|k| k as f64 * 0.1 - 0.3).collect(),
            force: (0..9).map(|k| -(k as f64) * 1e3).collect(),
            broken: vec![(0, 2)],
            history_pairs: vec![(0, 1), (1, 2)],
            history: vec![1.5e-4, -2.0e-5],
            thermostat: (step == 20).then(|| crate::engine::thermostat::Saved {
                kind: "nose-hoover".into(),
                values: vec![0.125, -3.5],
            }),
        },
        particles: 3,
        scene_hash: 0x0123_4567_89ab_cdef,
        deck: "beam.toml".into(),
    }
}

#[test]
fn bond_histories_and_broken_bonds_round_trip_and_old_files_are_pruned() {
    let dir = std::env::temp_dir().join(format!("pdq-ckpt-unit-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for step in [10, 20, 30, 40] {
        let (path, size) = sample(step).write(&dir, 2).unwrap();
        assert!(size > 0);
        assert_eq!(Checkpoint::read(&path).unwrap(), sample(step));
    }
    let mut kept: Vec<u64> = list(&dir).into_iter().map(|(s, _)| s).collect();
    kept.sort_unstable();
    assert_eq!(kept, vec![30, 40], "the newest two are kept");
    let (_, newest) = resolve(&dir).unwrap();
    assert_eq!(newest.state.step, 40);
    let _ = std::fs::remove_dir_all(&dir);
}
