//! The example scenes of issue 23 at a small size, each checked for what it is there to show:
//! the membrane rises where it is pulled, and the cyclic notched bar carries compression through its closed
//! crack with contact and not without. Each run also draws its picture.

use crate::common::{final_positions, run_quietly};
use std::path::Path;

fn example(name: &str) -> String {
    std::fs::read_to_string(format!("inputs/{name}")).unwrap()
}

/// `text` with `old` replaced, which must be there.
fn edit(text: &str, old: &str, new: &str) -> String {
    assert!(text.contains(old), "the example lost '{old}'");
    text.replace(old, new)
}

/// The history's column `name`, row by row.
fn column(dir: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let k = lines
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// A PNG was drawn.
fn assert_picture(dir: &Path) {
    let bytes = std::fs::read(dir.join("picture.png")).expect("picture.png");
    assert!(
        bytes.len() > 10_000 && bytes.starts_with(b"\x89PNG"),
        "picture.png is no picture"
    );
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("pdq-scenes-{}-{name}", std::process::id()))
}

#[test]
fn the_membrane_rises_where_it_is_pulled_and_its_frame_holds() {
    // The whole 50 x 50 sheet, the first 20 of its 150 time units.
    let text = edit(&example("membrane.toml"), "duration = 150", "duration = 20");
    let text = edit(
        &text,
        "picture = \"height\"",
        "picture = \"height\"\nfinal_state = true",
    );
    let dir = temp("membrane");
    run_quietly(&text, "membrane.toml", &dir, Default::default()).unwrap();
    let rise = column(&dir, "pulled_uz");
    let top = *rise.last().unwrap();
    // Four particles pulled with 3.2 in all against 2,500 × 0.001 of gravity: the middle goes
    // up, and keeps going up through the window.
    assert!(top > 0.3, "the pulled particle rose {top}");
    assert!(
        rise.windows(2).skip(1).all(|w| w[1] >= w[0] - 1e-9),
        "{rise:?}"
    );
    // The highest particle of the sheet is a pulled one, and the frame has not moved.
    let x = final_positions(&dir);
    let highest = x.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
    assert!(
        (highest - (1.1 + top)).abs() < 0.05 * top,
        "highest {highest}, pulled {top}"
    );
    for p in x
        .iter()
        .filter(|p| p[0] < 2.2 || p[0] > 107.8 || p[1] < 2.2 || p[1] > 107.8)
    {
        assert_eq!(p[2], 1.1, "a frame particle moved: {p:?}");
    }
    assert_picture(&dir);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_cyclic_bar_carries_compression_through_its_crack_only_with_contact() {
    let with = example("notched_bar_cyclic.toml");
    let without = edit(&with, "law = \"contact\"", "law = \"none\"");
    let mut mean_push = Vec::new();
    for (name, text) in [("contact", &with), ("none", &without)] {
        let dir = temp(name);
        run_quietly(text, "bar.toml", &dir, Default::default()).unwrap();
        let (u, f) = (
            column(&dir, "grip_ux"),
            column(&dir, "reaction_grip_right_x"),
        );
        // The bar cracked through in the first pull.
        let broken = column(&dir, "broken_bonds");
        assert!(
            broken.last().unwrap() > &3000.0,
            "{name}: {:?}",
            broken.last()
        );
        // The reaction on the grip, averaged over the deepest part of the push (more than
        // 0.115 mm back, the faces 0.1 mm past closing are within the contact distance).
        let push: Vec<f64> = u
            .iter()
            .zip(&f)
            .filter(|(u, _)| **u < -0.115e-3)
            .map(|(_, f)| *f)
            .collect();
        assert!(push.len() > 20, "{name}: {} rows in the push", push.len());
        mean_push.push(push.iter().sum::<f64>() / push.len() as f64);
        if name == "contact" {
            assert_picture(&dir);
        }
        std::fs::remove_dir_all(&dir).ok();
    }
    eprintln!(
        "mean grip reaction beyond 0.115 mm of push: with contact {:.1} N, without {:.1} N",
        mean_push[0], mean_push[1]
    );
    // Compression (negative) carried through the closed crack with contact, none without:
    // the free half only rattles on its grip (±300 N, zero on average).
    assert!(mean_push[0] < -200.0, "with contact {}", mean_push[0]);
    assert!(
        mean_push[1].abs() < 100.0,
        "without contact {}",
        mean_push[1]
    );
}
