//! Voids and cracks on voxels over procCubes (issue 24): the same labels and clusters on 1, 2,
//! 4 and 8 procCubes and with each merge scheme as on one grid, periodic grids, and the
//! tracking events. The runs through decks (threads and MPI) are in `tests/inputs.rs` and
//! `tests/mpi_runs.rs`.

use pdq::parallel::comm::{Team, Threads};
use pdq::voids::tracking::{EventKind, Tracker};
use pdq::voids::{
    deposit, find_voids, label, Cluster, Connectivity, Extent, Labelled, Region, Scheme, VoidMap,
    VoxelGrid, OCCUPIED, OUTSIDE,
};

/// Sites of a cubic lattice of spacing 1 filling [0, n) along each axis, less those `removed`.
fn block(n: [usize; 3], removed: impl Fn([f64; 3]) -> bool) -> Vec<[f64; 3]> {
    let mut p = Vec::new();
    for z in 0..n[2] {
        for y in 0..n[1] {
            for x in 0..n[0] {
                let s = [x as f64, y as f64, z as f64];
                if !removed(s) {
                    p.push(s);
                }
            }
        }
    }
    p
}

fn ball(c: [f64; 3], r: f64) -> impl Fn([f64; 3]) -> bool {
    move |s| (0..3).map(|a| (s[a] - c[a]).powi(2)).sum::<f64>() < r * r
}

/// Labels `points` on procCubes cut at `walls` (on threads), the points dealt out to the
/// workers in turn, so that most are deposited on another procCube's voxels. Returns each
/// voxel's label over the whole grid and the root's clusters and rounds.
fn labelled_on(
    grid: &VoxelGrid,
    walls: &[Vec<f64>; 3],
    points: &[[f64; 3]],
    connectivity: Connectivity,
    scheme: Scheme,
) -> (Vec<u32>, Vec<Cluster>, u32) {
    let n: usize = walls.iter().map(|w| w.len() + 1).product();
    let results: Vec<(Region, Labelled)> = std::thread::scope(|s| {
        let handles: Vec<_> = Threads::team(n)
            .into_iter()
            .map(|t| {
                s.spawn(move || {
                    let mut team = Team::new(t);
                    let rank = team.rank();
                    let region = Region::new(grid.clone(), walls.clone(), rank).unwrap();
                    let mine: Vec<[f64; 3]> =
                        points.iter().skip(rank).step_by(n).copied().collect();
                    let (occupied, _) = deposit(&mut team, &region, &mine, None);
                    let empty: Vec<bool> = occupied.iter().map(|o| !o).collect();
                    let found = label(&mut team, &region, &empty, &[], connectivity, scheme);
                    (region, found)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut labels = vec![u32::MAX; grid.len()];
    for (region, found) in &results {
        for (v, &l) in found.labels.iter().enumerate() {
            let g = grid.index(region.coords(v));
            assert_eq!(labels[g], u32::MAX, "voxel {g} held twice");
            labels[g] = l;
        }
    }
    assert!(
        labels.iter().all(|&l| l != u32::MAX),
        "a voxel nobody holds"
    );
    let root = &results[0].1;
    (labels, root.clusters.clone(), root.rounds)
}

const LAYOUTS: [[&[f64]; 3]; 6] = [
    [&[], &[], &[]],
    [&[19.7], &[], &[]],
    [&[19.7], &[9.2], &[]],
    [&[12.0, 27.5], &[], &[]],
    [&[10.3], &[6.0], &[11.1]],
    [&[7.6, 16.2, 31.0], &[], &[]],
];

fn walls(w: [&[f64]; 3]) -> [Vec<f64>; 3] {
    w.map(|x| x.to_vec())
}

#[test]
fn holes_give_the_same_voids_on_every_layout_and_scheme() {
    let holes = [
        ([8.0, 9.5, 9.5], 4.0),
        ([20.0, 9.0, 10.0], 3.0),
        ([30.5, 10.0, 9.0], 2.5),
    ];
    // A slot joins a fourth and fifth hole across the wall at x = 19.7.
    let joined = |s: [f64; 3]| {
        ball([16.0, 4.0, 14.0], 1.6)(s)
            || ball([24.0, 4.0, 14.0], 1.6)(s)
            || (s[0] > 16.0 && s[0] < 24.0 && s[1] == 4.0 && s[2] == 14.0)
    };
    let points = block([40, 20, 20], |s| {
        holes.iter().any(|&(c, r)| ball(c, r)(s)) || joined(s)
    });
    let grid = VoxelGrid::around(&points, 1.0).unwrap();
    for connectivity in [Connectivity::Face, Connectivity::All] {
        let one = find_voids(&grid, &grid.occupancy(&points), connectivity);
        assert_eq!(one.voids.len(), 4, "{:?}", one.voids);
        let expected: Vec<u32> = one
            .labels
            .iter()
            .map(|&l| if l == u32::MAX { 0 } else { l })
            .collect();
        for layout in LAYOUTS {
            for scheme in [Scheme::Boundary, Scheme::MinLabel, Scheme::Gather] {
                let (labels, clusters, _) =
                    labelled_on(&grid, &walls(layout), &points, connectivity, scheme);
                let what = format!("{layout:?}, {scheme:?}, {connectivity:?}");
                assert!(labels == expected, "labels differ on {what}");
                assert_eq!(clusters, one.voids, "clusters differ on {what}");
            }
        }
    }
}

#[test]
fn the_min_label_scheme_takes_more_rounds_for_a_void_across_more_procubes() {
    // A tube along x through the whole block, closed at both ends.
    let tube = |s: [f64; 3]| s[0] >= 2.0 && s[0] <= 37.0 && s[1] == 10.0 && s[2] == 10.0;
    let points = block([40, 20, 20], tube);
    let grid = VoxelGrid::around(&points, 1.0).unwrap();
    let rounds = |w: [&[f64]; 3]| {
        let (_, clusters, rounds) = labelled_on(
            &grid,
            &walls(w),
            &points,
            Connectivity::Face,
            Scheme::MinLabel,
        );
        assert_eq!(clusters.len(), 1);
        assert_eq!(clusters[0].voxels, 36);
        rounds
    };
    let (one, two, four) = (rounds(LAYOUTS[0]), rounds(LAYOUTS[1]), rounds(LAYOUTS[5]));
    assert_eq!(one, 1);
    assert!(two > one && four > two, "rounds {one}, {two}, {four}");
}

#[test]
fn a_void_across_a_periodic_boundary_is_one_void() {
    // Periodic along x with period 30: a hole centred on the boundary wraps around.
    let points = block([30, 12, 12], |s| {
        ball([0.0, 6.0, 6.0], 3.0)(s) || ball([30.0, 6.0, 6.0], 3.0)(s)
    });
    let extent = [
        Extent::Periodic {
            origin: -0.5,
            period: 30.0,
        },
        Extent::Bounded { lo: 0.0, hi: 11.0 },
        Extent::Bounded { lo: 0.0, hi: 11.0 },
    ];
    let grid = VoxelGrid::spanning([0.0; 3], extent, [1.0; 3]).unwrap();
    assert_eq!(grid.dims, [30, 14, 14]);
    let removed = 30 * 12 * 12 - points.len();
    for w in [
        [&[][..], &[], &[]],
        [&[14.6][..], &[], &[]],
        [&[9.5, 19.5][..], &[], &[]],
    ] {
        let (_, clusters, _) = labelled_on(
            &grid,
            &walls(w),
            &points,
            Connectivity::Face,
            Scheme::Boundary,
        );
        assert_eq!(clusters.len(), 1, "{w:?}: {clusters:?}");
        assert_eq!(clusters[0].voxels as usize, removed);
    }
}

#[test]
fn a_fully_periodic_grid_has_no_outside() {
    let points = block([16, 16, 16], ball([8.0, 8.0, 8.0], 3.0));
    let extent = [Extent::Periodic {
        origin: -0.5,
        period: 16.0,
    }; 3];
    let grid = VoxelGrid::spanning([0.0; 3], extent, [1.0; 3]).unwrap();
    assert!(!grid.has_outside());
    let (_, clusters, _) = labelled_on(
        &grid,
        &walls([&[7.9], &[8.1], &[]]),
        &points,
        Connectivity::Face,
        Scheme::Boundary,
    );
    assert_eq!(clusters.len(), 1);
    assert_eq!(clusters[0].voxels as usize, 16 * 16 * 16 - points.len());
}

#[test]
fn values_are_summed_per_cluster_on_any_layout() {
    // Two sheets of "bond midpoints" with openings: each sheet is one cluster.
    let sheet = |x: f64| -> Vec<[f64; 3]> {
        let mut p = Vec::new();
        for z in 2..18 {
            for y in 2..10 {
                p.push([x, y as f64, z as f64]);
            }
        }
        p
    };
    let mut mids = sheet(8.0);
    mids.extend(sheet(25.0));
    let values: Vec<[f64; 2]> = mids.iter().map(|p| [0.01 * (p[1] + p[2]), 1.0]).collect();
    let body = block([40, 12, 20], |_| false);
    let grid = VoxelGrid::around(&body, 1.0).unwrap();
    for (k, layout) in LAYOUTS.into_iter().enumerate() {
        let alone = k % 2 == 1;
        let w = walls(layout);
        let n: usize = w.iter().map(|x| x.len() + 1).product();
        let roots: Vec<Labelled> = std::thread::scope(|s| {
            let handles: Vec<_> = Threads::team(n)
                .into_iter()
                .map(|t| {
                    let (w, mids, values, grid) = (&w, &mids, &values, &grid);
                    s.spawn(move || {
                        let mut team = Team::new(t);
                        let rank = team.rank();
                        let region = Region::new(grid.clone(), w.clone(), rank).unwrap();
                        // Dealt out in turn, or all on the root (the others deposit no
                        // value but must still read the values sent to them).
                        let mine: Vec<usize> = if alone {
                            if rank == 0 {
                                (0..mids.len()).collect()
                            } else {
                                Vec::new()
                            }
                        } else {
                            (rank..mids.len()).step_by(n).collect()
                        };
                        let pts: Vec<[f64; 3]> = mine.iter().map(|&k| mids[k]).collect();
                        let val: Vec<[f64; 2]> = mine.iter().map(|&k| values[k]).collect();
                        let (marked, sums) = deposit(&mut team, &region, &pts, Some(&val));
                        label(
                            &mut team,
                            &region,
                            &marked,
                            &sums,
                            Connectivity::All,
                            Scheme::Boundary,
                        )
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        let c = &roots[0].clusters;
        assert_eq!(c.len(), 2, "{layout:?}");
        for k in 0..2 {
            assert_eq!(c[k].bonds, 8 * 16);
            assert_eq!(c[k].voxels, 8 * 16);
            // Mean of 0.01 (y + z) over y in 2..10, z in 2..18: 0.01 (5.5 + 9.5).
            assert!((c[k].opening - 0.15).abs() < 1e-12, "{}", c[k].opening);
            // A one-voxel sheet of 8 × 16: its area, and its edges' faces (2 %).
            assert!((c[k].area - 128.0).abs() < 0.02 * 128.0, "{}", c[k].area);
            assert_eq!(c[k].first, [[9, 3, 3], [26, 3, 3]][k]);
            assert_eq!(c[k].last, [[9, 10, 18], [26, 10, 18]][k]);
        }
    }
}

#[test]
fn an_oblique_sheet_has_its_area() {
    // A staircase sheet x + y = 20 (normal (1, 1, 0)/√2), 2 voxels thick along x.
    let mut mids = Vec::new();
    for z in 0..10 {
        for y in 0..16 {
            for t in 0..2 {
                mids.push([(20 - y + t) as f64, y as f64, z as f64]);
            }
        }
    }
    let body = block([30, 20, 12], |_| false);
    let grid = VoxelGrid::around(&body, 1.0).unwrap();
    let marked = grid.occupancy(&mids);
    let region = Region::whole(grid.clone());
    let mut team = Team::new(pdq::parallel::comm::Solo::new());
    let found = label(
        &mut team,
        &region,
        &marked,
        &[],
        Connectivity::All,
        Scheme::Boundary,
    );
    assert_eq!(found.clusters.len(), 1);
    // 16 steps of √2 by 10: 226.3; the edges of the sheet add to the face counts.
    let area = 16.0 * 2f64.sqrt() * 10.0;
    let a = found.clusters[0].area;
    assert!((a - area).abs() / area < 0.12, "{a} vs {area}");
}

/// Voids of `points` on one grid of the run's voxel lattice (anchored at the origin).
fn analyse(
    points: &[[f64; 3]],
    tracker: &mut Tracker,
) -> (Labelled, Vec<pdq::voids::tracking::Event>) {
    let extent = [Extent::Bounded { lo: 0.0, hi: 39.0 }; 3];
    let grid = VoxelGrid::spanning([0.0; 3], extent, [1.0; 3]).unwrap();
    let region = Region::whole(grid.clone());
    let mut team = Team::new(pdq::parallel::comm::Solo::new());
    let (occupied, _) = deposit(&mut team, &region, points, None);
    let empty: Vec<bool> = occupied.iter().map(|o| !o).collect();
    let found = label(
        &mut team,
        &region,
        &empty,
        &[],
        Connectivity::Face,
        Scheme::Boundary,
    );
    let (events, _) = tracker.follow(&mut team, &region, &found);
    (found, events)
}

#[test]
fn two_voids_growing_into_one_are_one_coalescence_with_both_parents() {
    let mut tracker = Tracker::new(1, false);
    let at = |r: f64, third: bool| {
        block([40, 40, 40], |s| {
            ball([13.0, 20.0, 20.0], r)(s)
                || ball([27.0, 20.0, 20.0], r)(s)
                || (third && ball([20.0, 8.0, 30.0], 2.0)(s))
        })
    };
    let (first, events) = analyse(&at(3.0, false), &mut tracker);
    assert_eq!(first.clusters.len(), 2);
    let kinds: Vec<_> = events.iter().map(|e| (e.kind, e.id)).collect();
    assert_eq!(
        kinds,
        [(EventKind::Nucleated, 1), (EventKind::Nucleated, 2)]
    );
    // Both grow; a third nucleates.
    let (_, events) = analyse(&at(5.0, true), &mut tracker);
    let kinds: Vec<_> = events.iter().map(|e| (e.kind, e.id)).collect();
    assert_eq!(
        kinds,
        [
            (EventKind::Grew, 1),
            (EventKind::Grew, 2),
            (EventKind::Nucleated, 3)
        ]
    );
    // They touch: one void, one coalescence with parents 1 and 2; the third closes.
    let (merged, events) = analyse(&at(7.5, false), &mut tracker);
    assert_eq!(merged.clusters.len(), 1);
    assert_eq!(events.len(), 2, "{events:?}");
    assert_eq!(events[0].kind, EventKind::Coalesced);
    assert_eq!(events[0].parents, [1, 2]);
    assert_eq!(events[0].id, 4);
    assert_eq!(events[0].volume, merged.clusters[0].volume);
    assert_eq!((events[1].kind, events[1].id), (EventKind::Closed, 3));
    // And split again.
    let (_, events) = analyse(&at(5.0, false), &mut tracker);
    let kinds: Vec<_> = events
        .iter()
        .map(|e| (e.kind, e.id, e.parents.clone()))
        .collect();
    assert_eq!(
        kinds,
        [
            (EventKind::Split, 5, vec![4]),
            (EventKind::Split, 6, vec![4])
        ]
    );
}

/// Runs deck `text` on `procs` procCubes (threads) into a fresh directory.
fn run_deck(text: &str, name: &str, procs: [usize; 3]) -> std::path::PathBuf {
    use pdq::driver::run::{run, RunOptions};
    use pdq::parallel::decomposition::Procs;
    let scene = pdq::input::deck::parse(text, &format!("{name}.toml"), name).unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-voids-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            threads: Some(procs.iter().product()),
            procs: Some(Procs::Given(procs)),
            ..Default::default()
        },
    )
    .unwrap();
    dir
}

/// The rows of a CSV as numbers (by header name), for the rows of `step`.
fn rows(path: &std::path::Path, step: u64) -> Vec<std::collections::HashMap<String, f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(|v| v.parse::<f64>().unwrap_or(f64::NAN)))
                .collect::<std::collections::HashMap<_, _>>()
        })
        .filter(|r| r["step"] == step as f64)
        .collect()
}

/// The holes deck (`tests/decks/holes.toml`): three voids, the hole cut open through the top
/// face is not one, the two holes joined by a slot are one; the same table on 1, 2 and 4
/// procCubes and with every merge scheme.
#[test]
fn a_block_with_holes_has_its_voids_on_every_layout() {
    let deck = std::fs::read_to_string("tests/decks/holes.toml").unwrap();
    let one = run_deck(&deck, "holes1", [1, 1, 1]);
    let table = std::fs::read_to_string(one.join("voids_clusters.csv")).unwrap();
    let voids = rows(&one.join("voids_clusters.csv"), 0);
    assert_eq!(voids.len(), 3, "{table}");
    // Sites sit at voxel centres, and a voxel is empty when its site is inside the sphere: a
    // hole of radius R holds every voxel whose centre is within R, so its volume lies between
    // the spheres of radius R ∓ (√3/2) h (h = 1 mm).
    let ball = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * (r * 1e-3).powi(3);
    let h = 3f64.sqrt() / 2.0;
    let near = |v: &std::collections::HashMap<String, f64>, c: [f64; 3]| {
        (v["x"] - c[0] * 1e-3).abs() < 1e-3
            && (v["y"] - c[1] * 1e-3).abs() < 1e-3
            && (v["z"] - c[2] * 1e-3).abs() < 1e-3
    };
    for (c, r) in [([6.0, 10.0, 10.0], 3.5), ([15.0, 5.5, 6.0], 2.5)] {
        let v = voids
            .iter()
            .find(|v| near(v, c))
            .expect("a void at each hole");
        let vol = v["volume"];
        assert!(
            vol >= ball(r - h) && vol <= ball(r + h),
            "hole of radius {r} mm: {vol:e} m³ outside [{:e}, {:e}]",
            ball(r - h),
            ball(r + h)
        );
    }
    // The joined pair: both holes and the slot (9 × 2 × 2 sites less those inside the holes).
    let joined = voids.iter().find(|v| near(v, [18.5, 14.0, 14.0])).unwrap();
    assert!(joined["volume"] > 2.0 * ball(2.0 - h) + 20e-9, "{table}");
    let summary = rows(&one.join("voids.csv"), 1);
    assert_eq!(summary[0]["count"], 3.0);
    // Afterwards from the frames (`pdq voids DIR`): the same table.
    let framed = run_deck(
        &deck.replace("picture = \"none\"", "picture = \"none\"\nframes_every = 1"),
        "holes_frames",
        [1, 1, 1],
    );
    let ask = pdq::driver::post::PostVoids {
        voxel: 1e-3,
        connectivity: Connectivity::Face,
        name: "post".into(),
        labels: true,
    };
    let post = pdq::driver::post::voids_from_frames(&framed, &ask).unwrap();
    assert_eq!((post.frames, post.voids), (2, 3));
    let again = std::fs::read_to_string(framed.join("post_clusters.csv")).unwrap();
    assert!(again == table, "afterwards:\n{again}\nin situ:\n{table}");
    assert!(framed.join("post_voxels.xdmf").exists());
    // Where the largest are, in situ and afterwards.
    for picture in ["voids_largest.png", "post_largest.png"] {
        let bytes = std::fs::read(framed.join("pictures").join(picture)).unwrap();
        assert!(
            bytes.starts_with(b"\x89PNG") && bytes.len() > 5_000,
            "{picture}"
        );
    }
    std::fs::remove_dir_all(framed).unwrap();
    for (name, procs, scheme) in [
        ("holes2", [2, 1, 1], "boundary"),
        ("holes4", [2, 2, 1], "boundary"),
        ("holes4z", [1, 2, 2], "boundary"),
        ("holes4m", [2, 2, 1], "min-label"),
        ("holes4g", [1, 2, 2], "gather"),
    ] {
        let text = deck.replace(
            "kind = \"voids\"",
            &format!("kind = \"voids\"\nscheme = \"{scheme}\""),
        );
        let dir = run_deck(&text, name, procs);
        let other = std::fs::read_to_string(dir.join("voids_clusters.csv")).unwrap();
        assert!(
            other == table,
            "{name}: {procs:?} {scheme} differs:\n{other}\n{table}"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }
    std::fs::remove_dir_all(one).unwrap();
}

/// The quick example (a notched block pulled apart) with its crack analysis: after the run one
/// crack spans the section at the notch, the same on two procCubes.
#[test]
fn a_notched_bar_has_one_crack_spanning_its_section() {
    // The example deck analyses its cracks every 250 steps.
    let text = std::fs::read_to_string("inputs/pmb_block.toml").unwrap();
    assert!(text.contains("kind = \"cracks\""));
    let mut tables = Vec::new();
    for (name, procs) in [("notch1", [1, 1, 1]), ("notch2", [2, 1, 1])] {
        let dir = run_deck(&text, name, procs);
        let cracks = rows(&dir.join("cracks_clusters.csv"), 2000);
        // The body is 40 × 10 × 10 mm with the notch at x = 20 mm.
        let spanning: Vec<_> = cracks
            .iter()
            .filter(|c| {
                c["min_y"] <= 1e-3 && c["max_y"] >= 9e-3 && c["min_z"] <= 1e-3 && c["max_z"] >= 9e-3
            })
            .collect();
        assert_eq!(spanning.len(), 1, "{name}: {cracks:?}");
        let c = spanning[0];
        assert!(c["min_x"] < 20e-3 && c["max_x"] > 20e-3, "{c:?}");
        // Its area: about the 10 × 10 mm section; the crack's roughness and the edges of a
        // slab of midpoints a few voxels thick add to it.
        assert!(c["area"] > 90e-6 && c["area"] < 160e-6, "{c:?}");
        assert!(c["opening"] > 0.0);
        let events = std::fs::read_to_string(dir.join("cracks_events.csv")).unwrap();
        assert!(events.contains("nucleated"), "{events}");
        // Voxels and bonds by id (openings are sums in a layout's order: round-off apart).
        let t = std::fs::read_to_string(dir.join("cracks_clusters.csv")).unwrap();
        let keep: Vec<String> = t
            .lines()
            .map(|l| {
                l.split(',')
                    .take(4)
                    .chain(l.split(',').skip(17).take(1))
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect();
        tables.push(keep);
        std::fs::remove_dir_all(dir).unwrap();
    }
    assert_eq!(tables[0], tables[1]);
}

#[test]
fn bad_analyses_are_refused_with_their_line() {
    let deck = std::fs::read_to_string("tests/decks/holes.toml").unwrap();
    let err = |from: &str, to: &str| {
        let text = deck.replace(from, to);
        pdq::input::deck::parse(&text, "holes.toml", "holes")
            .unwrap_err()
            .to_string()
    };
    let e = err("kind = \"voids\"", "kind = \"pores\"");
    assert!(
        e.contains("holes.toml:") && e.contains("'pores' is not known"),
        "{e}"
    );
    let e = err("every = 1", "every = 0");
    assert!(e.contains("every = 0"), "{e}");
    let e = err(
        "kind = \"voids\"",
        "kind = \"voids\"\nconnectivity = \"edge\"",
    );
    assert!(e.contains("connectivity 'edge'"), "{e}");
    let e = err("kind = \"voids\"", "kind = \"voids\"\nscheme = \"fast\"");
    assert!(e.contains("scheme 'fast'"), "{e}");
    let e = err("kind = \"voids\"", "kind = \"voids\"\nvoxel = \"-1 mm\"");
    assert!(e.contains("voxel must be a length > 0"), "{e}");
    let e = err(
        "every = 1\n",
        "every = 1\n[[analysis]]\nkind = \"voids\"\nevery = 5\n",
    );
    assert!(e.contains("'voids' is used twice"), "{e}");
    // Voids may run beside shuffles; cracks may not (a shuffle drops broken bonds).
    let shuffled = deck.replace("[output]", "[parallel]\nshuffle_every = 10\n[output]");
    assert!(pdq::input::deck::parse(&shuffled, "holes.toml", "holes").is_ok());
    let cracks = shuffled.replace("kind = \"voids\"", "kind = \"cracks\"");
    let e = pdq::input::deck::parse(&cracks, "holes.toml", "holes")
        .unwrap_err()
        .to_string();
    assert!(e.contains("holes.toml:") && e.contains("shuffle"), "{e}");
}

// One grid (`find_voids`): the labelling on one procCube.

fn voids_of(points: &[[f64; 3]], connectivity: Connectivity) -> VoidMap {
    let grid = VoxelGrid::around(points, 1.0).unwrap();
    find_voids(&grid, &grid.occupancy(points), connectivity)
}

#[test]
fn an_intact_block_has_no_void() {
    let m = voids_of(&block([12, 7, 5], |_| false), Connectivity::Face);
    assert!(m.voids.is_empty());
    assert_eq!(m.porosity(), 0.0);
    // One voxel per site, a margin of one voxel all round.
    assert_eq!(m.grid.dims, [14, 9, 7]);
    assert_eq!(
        m.labels.iter().filter(|&&l| l == OCCUPIED).count(),
        12 * 7 * 5
    );
}

#[test]
fn three_spherical_holes_are_three_voids_of_their_volumes() {
    let holes = [
        ([8.0, 9.5, 9.5], 4.0),
        ([20.0, 9.0, 10.0], 3.0),
        ([30.5, 10.0, 9.0], 2.5),
    ];
    let points = block([40, 20, 20], |s| holes.iter().any(|&(c, r)| ball(c, r)(s)));
    let m = voids_of(&points, Connectivity::Face);
    assert_eq!(m.voids.len(), 3, "{:?}", m.voids);
    // Each empty voxel is a removed site at its centre: the void holds every voxel whose
    // centre is inside the sphere, so it lies between the spheres of radius R ∓ √3/2.
    let h = 3f64.sqrt() / 2.0;
    let ball = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    for &(c, r) in &holes {
        // Voids are numbered by their first voxel (z slowest): find this hole's by its centre.
        let v = m
            .voids
            .iter()
            .find(|v| (0..3).all(|a| (v.centroid[a] - c[a]).abs() < r))
            .unwrap_or_else(|| panic!("no void around {c:?}: {:?}", m.voids));
        assert!(
            v.volume >= ball(r - h) && v.volume <= ball(r + h),
            "hole of radius {r}: void volume {} outside [{}, {}]",
            v.volume,
            ball(r - h),
            ball(r + h)
        );
        let off = (0..3)
            .map(|a| (v.centroid[a] - c[a]).abs())
            .fold(0.0, f64::max);
        assert!(
            off < 0.5,
            "centroid {:?} against the centre {c:?}",
            v.centroid
        );
        let error = (v.equivalent_radius - r).abs();
        assert!(
            error < h,
            "equivalent radius {} for {r}",
            v.equivalent_radius
        );
        // The staircase surface: between the sphere's area and twice it.
        let area = 4.0 * std::f64::consts::PI * r * r;
        assert!(
            v.surface > area && v.surface < 2.0 * area,
            "{} vs {area}",
            v.surface
        );
    }
    let removed = 40 * 20 * 20 - points.len();
    let total: u64 = m.voids.iter().map(|v| v.voxels).sum();
    assert_eq!(total as usize, removed);
    assert!((m.porosity() - removed as f64 / 16000.0).abs() < 1e-15);
}

#[test]
fn two_holes_joined_by_a_slot_are_one_void() {
    let a = ball([8.0, 8.0, 8.0], 3.0);
    let b = ball([20.0, 8.0, 8.0], 3.0);
    let slot =
        |s: [f64; 3]| s[0] > 8.0 && s[0] < 20.0 && s[1] == 8.0 && (7.0..=9.0).contains(&s[2]);
    let points = block([28, 16, 16], |s| a(s) || b(s) || slot(s));
    assert_eq!(voids_of(&points, Connectivity::Face).voids.len(), 1);
    let apart = block([28, 16, 16], |s| a(s) || b(s));
    assert_eq!(voids_of(&apart, Connectivity::Face).voids.len(), 2);
}

#[test]
fn a_hole_open_to_the_outside_is_not_a_void() {
    let hole = ball([10.0, 8.0, 8.0], 3.0);
    // A channel from the hole up through the top face.
    let channel = |s: [f64; 3]| s[0] == 10.0 && s[1] == 8.0 && s[2] >= 8.0;
    let points = block([20, 16, 16], |s| hole(s) || channel(s));
    let m = voids_of(&points, Connectivity::Face);
    assert!(m.voids.is_empty(), "{:?}", m.voids);
    let grid = &m.grid;
    let centre = grid.voxel_of(&[10.0, 8.0, 8.0]).unwrap();
    assert_eq!(m.labels[centre], OUTSIDE);
}

#[test]
fn holes_touching_at_a_corner_join_only_with_26_connectivity() {
    let a = |s: [f64; 3]| s == [5.0, 5.0, 5.0] || s == [4.0, 5.0, 5.0];
    let b = |s: [f64; 3]| s == [6.0, 6.0, 6.0] || s == [7.0, 6.0, 6.0];
    let points = block([12, 12, 12], |s| a(s) || b(s));
    assert_eq!(voids_of(&points, Connectivity::Face).voids.len(), 2);
    let all = voids_of(&points, Connectivity::All);
    assert_eq!(all.voids.len(), 1);
    assert_eq!(all.voids[0].voxels, 4);
}

#[test]
fn labels_do_not_depend_on_the_order_of_the_particles() {
    let holes = [([6.0, 6.0, 6.0], 2.5), ([15.0, 6.0, 6.0], 2.0)];
    let points = block([22, 12, 12], |s| holes.iter().any(|&(c, r)| ball(c, r)(s)));
    let mut reversed = points.clone();
    reversed.reverse();
    reversed.rotate_left(17);
    let (m, r) = (
        voids_of(&points, Connectivity::Face),
        voids_of(&reversed, Connectivity::Face),
    );
    assert_eq!(m.labels, r.labels);
    assert_eq!(m.voids, r.voids);
    // Labels follow the first voxel: the hole at smaller x is void 1.
    assert!(m.voids[0].centroid[0] < m.voids[1].centroid[0]);
}

#[test]
fn bad_grids_are_refused_with_a_reason() {
    let p = [[0.0; 3]];
    assert!(VoxelGrid::around(&p, 0.0).unwrap_err().contains("positive"));
    assert!(VoxelGrid::around(&[], 1.0)
        .unwrap_err()
        .contains("no particles"));
    let nan = [[0.0, f64::NAN, 0.0]];
    assert!(VoxelGrid::around(&nan, 1.0).unwrap_err().contains("finite"));
    let far = [[0.0; 3], [1e6, 1e6, 1e6]];
    assert!(VoxelGrid::around(&far, 1e-3)
        .unwrap_err()
        .contains("larger voxels"));
}
