//! `pdq bench --voids`: the three label-merge schemes of `voids/labels.rs` timed against the
//! number of procCubes (threads) and the size of the largest void, as Hemani et al. compare
//! theirs. The grid is a block of 160 × 64 × 64 voxels at one site each, cut into procCubes
//! along x; the voids are either 160 small spheres, or one tube along the whole block (the
//! largest void spans every procCube), or a slab crack across the section (one void touching
//! every face of the middle procCubes).

use crate::parallel::comm::{Team, Threads};
use crate::voids::{deposit, label, Connectivity, Region, Scheme, VoxelGrid};
use std::fmt::Write as _;
use std::time::Instant;

const DIMS: [usize; 3] = [160, 64, 64];

/// The sites of the block less those of the `shape`'s voids.
fn sites(shape: &str) -> Vec<[f64; 3]> {
    let removed = |s: [f64; 3]| match shape {
        "spheres" => {
            let c = s.map(|x| x.rem_euclid(16.0) - 8.0);
            c.iter().map(|x| x * x).sum::<f64>() < 9.0
                && (4.0..156.0).contains(&s[0])
                && (4.0..60.0).contains(&s[1])
                && (4.0..60.0).contains(&s[2])
        }
        "tube" => {
            s[0] > 2.0 && s[0] < 157.0 && (s[1] - 32.0).abs() < 3.0 && (s[2] - 32.0).abs() < 3.0
        }
        _ => (s[0] - 80.0).abs() < 40.0 && s[1] > 2.0 && s[1] < 61.0 && (s[2] - 32.0).abs() < 1.0,
    };
    let mut p = Vec::new();
    for z in 0..DIMS[2] {
        for y in 0..DIMS[1] {
            for x in 0..DIMS[0] {
                let s = [x as f64, y as f64, z as f64];
                if !removed(s) {
                    p.push(s);
                }
            }
        }
    }
    p
}

/// Median seconds of the labelling (after the deposit) on `n` procCubes along x, the voids
/// found and the halo exchanges taken.
fn time(points: &[[f64; 3]], n: usize, scheme: Scheme, rounds: usize) -> (f64, usize, u32) {
    let grid = VoxelGrid::around(points, 1.0).expect("a small grid");
    let walls = [
        (1..n).map(|k| (k * DIMS[0] / n) as f64 - 0.5).collect(),
        Vec::new(),
        Vec::new(),
    ];
    let mut runs: Vec<(f64, usize, u32)> = (0..rounds)
        .map(|_| {
            let results: Vec<(f64, usize, u32)> = std::thread::scope(|s| {
                let handles: Vec<_> = Threads::team(n)
                    .into_iter()
                    .map(|t| {
                        let (grid, walls) = (&grid, &walls);
                        s.spawn(move || {
                            let mut team = Team::new(t);
                            let rank = team.rank();
                            let region = Region::new(grid.clone(), walls.clone(), rank).unwrap();
                            // Each procCube deposits the sites in its region.
                            let mine: Vec<[f64; 3]> = points
                                .iter()
                                .filter(|p| {
                                    grid.coords_of(p).is_some_and(|c| region.local(c).is_some())
                                })
                                .copied()
                                .collect();
                            let (occupied, _) = deposit(&mut team, &region, &mine, None);
                            let empty: Vec<bool> = occupied.iter().map(|o| !o).collect();
                            team.max(0.0);
                            let t = Instant::now();
                            let found =
                                label(&mut team, &region, &empty, &[], Connectivity::Face, scheme);
                            // The slowest procCube decides.
                            let seconds = team.max(t.elapsed().as_secs_f64());
                            (seconds, found.clusters.len(), found.rounds)
                        })
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().unwrap()).collect()
            });
            results[0]
        })
        .collect();
    runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    runs[runs.len() / 2]
}

/// The table of schemes against procCubes and void shapes, `rounds` runs each (medians).
pub fn schemes(rounds: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "voids bench: {}x{}x{} voxels, procCubes along x on threads, median of {rounds}; ms to label (after the deposit), voids found, halo exchanges",
        DIMS[0], DIMS[1], DIMS[2]
    );
    let _ = writeln!(s, "| voids | procCubes | boundary | min-label | gather |");
    let _ = writeln!(s, "|---|---|---|---|---|");
    for shape in ["spheres", "tube", "slab"] {
        let points = sites(shape);
        for n in [1, 2, 4, 8] {
            let mut row = format!("| {shape} | {n} |");
            for scheme in [Scheme::Boundary, Scheme::MinLabel, Scheme::Gather] {
                let (t, voids, r) = time(&points, n, scheme, rounds.max(1));
                let _ = write!(row, " {:.2} ms ({voids}, {r}) |", 1e3 * t);
            }
            let _ = writeln!(s, "{row}");
        }
    }
    s
}
