//! Unit tests of `input/geometry.rs` (kept apart so the module reads on its own).
use super::*;

fn run(s: f64, ops: &[Op], bars: &[Bar]) -> Result<Cloud, GeometryError> {
    build(&Lattice::regular(s, [0.0; 3]), ops, bars)
}
fn add(shape: Shape, material: u16) -> Op {
    Op::Add { shape, material }
}
fn bx(min: Vec3, max: Vec3) -> Shape {
    Shape::Box { min, max }
}
fn cube(a: f64, b: f64) -> Shape {
    bx([a; 3], [b; 3])
}
fn prism(axis: usize, polygon: Vec<[f64; 2]>) -> Shape {
    Shape::Prism {
        axis,
        polygon,
        from: 1.0,
        to: 6.0,
    }
}
fn cyl(base: Vec3, axis: Vec3, length: f64, radius: f64) -> Shape {
    Shape::Cylinder {
        base,
        axis,
        length,
        radius,
    }
}
fn x_bar(from: Vec3, length: f64, area: f64, spacing: f64) -> Bar {
    Bar::along(from, [1.0, 0.0, 0.0], length, area, spacing, 9)
}

#[test]
fn jitter_moves_sites_within_bound_and_repeats_with_its_seed() {
    let ops = [add(bx([0.0; 3], [10.0, 10.0, 10.0]), 0)];
    let lattice = |seed| Lattice {
        jitter: 0.2,
        seed,
        ..Lattice::regular(1.0, [0.0; 3])
    };
    let regular = run(1.0, &ops, &[]).unwrap();
    let a = build(&lattice(1), &ops, &[]).unwrap();
    let b = build(&lattice(1), &ops, &[]).unwrap();
    let c = build(&lattice(2), &ops, &[]).unwrap();
    assert_eq!(a.position, b.position);
    assert_ne!(a.position, c.position);
    let mut largest: f64 = 0.0;
    for (p, q) in a.position.iter().zip(&regular.position) {
        for e in 0..3 {
            largest = largest.max((p[e] - q[e]).abs());
        }
    }
    // 3000 draws from U(−0.2, 0.2): the largest is within 1 % of the bound.
    assert!(largest <= 0.2 && largest > 0.19, "largest offset {largest}");
    let err = build(
        &Lattice {
            jitter: 0.5,
            ..lattice(1)
        },
        &ops,
        &[],
    )
    .unwrap_err();
    assert!(err.to_string().contains("jitter"), "{err}");
}

#[test]
fn box_300k_exact_and_ordered() {
    let c = run(1.0, &[add(bx([0.0; 3], [200.0, 50.0, 30.0]), 7)], &[]).unwrap();
    assert_eq!(c.len(), 300_000);
    assert!(c.volume.iter().chain(&c.spacing).all(|&v| v == 1.0));
    assert!(c.material.iter().all(|&m| m == 7));
    let at = |n: usize| c.position[n];
    assert_eq!(
        [at(0), at(1), at(200)],
        [[0.5; 3], [1.5, 0.5, 0.5], [0.5, 1.5, 0.5]]
    );
    assert_eq!(
        [at(10_000), at(299_999)],
        [[0.5, 0.5, 1.5], [199.5, 49.5, 29.5]]
    );
}

#[test]
fn box_minus_box() {
    let c = run(
        1.0,
        &[
            add(cube(0.0, 10.0), 1),
            Op::Subtract {
                shape: cube(3.0, 7.0),
            },
        ],
        &[],
    );
    assert_eq!(c.unwrap().len(), 1000 - 64);
}

#[test]
fn cylinder_along_x_matches_brute_force() {
    let c = run(
        1.0,
        &[add(cyl([0.0; 3], [2.0, 0.0, 0.0], 12.0, 3.0), 1)],
        &[],
    )
    .unwrap();
    let h = |n: i32| n as f64 + 0.5;
    let brute = (-20..20)
        .flat_map(|i| (-20..20).flat_map(move |j| (-20..20).map(move |k| (h(i), h(j), h(k)))))
        .filter(|&(x, y, z)| (0.0..=12.0).contains(&x) && y * y + z * z <= 9.0)
        .count();
    assert_eq!((c.len(), brute), (12 * 32, 12 * 32));
}

#[test]
fn oblique_cylinder_inside() {
    let (base, axis, len, r, s) = ([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], 10.0, 2.5, 0.5);
    let c = run(s, &[add(cyl(base, axis, len, r), 1)], &[]).unwrap();
    for p in &c.position {
        let (d, a) = (sub(*p, base), normalize(axis));
        let t = dot(d, a);
        assert!((-1e-9..=len + 1e-9).contains(&t) && dot(d, d) - t * t <= r * r + 1e-9);
    }
    let expected = std::f64::consts::PI * r * r * len / (s * s * s);
    assert!(
        (c.len() as f64 - expected).abs() < 0.05 * expected,
        "{}",
        c.len()
    );
}

#[test]
fn prism_square_equals_box_on_every_axis() {
    let poly = vec![[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]];
    let boxes = [
        [1.0, 0.0, 0.0, 6.0, 4.0, 3.0],
        [0.0, 1.0, 0.0, 3.0, 6.0, 4.0],
    ];
    let boxes = [boxes[0], boxes[1], [0.0, 0.0, 1.0, 4.0, 3.0, 6.0]];
    for (axis, b) in boxes.into_iter().enumerate() {
        let p = run(0.5, &[add(prism(axis, poly.clone()), 1)], &[]).unwrap();
        let b = run(
            0.5,
            &[add(bx([b[0], b[1], b[2]], [b[3], b[4], b[5]]), 1)],
            &[],
        );
        assert_eq!((p.len(), &p), (480, &b.unwrap()), "axis {axis}");
    }
}

#[test]
fn prism_l_shape_and_orientation() {
    let mut poly = vec![
        [0.0, 0.0],
        [6.0, 0.0],
        [6.0, 2.0],
        [2.0, 2.0],
        [2.0, 5.0],
        [0.0, 5.0],
    ];
    let ccw = run(1.0, &[add(prism(2, poly.clone()), 1)], &[]).unwrap();
    assert_eq!(ccw.len(), (12 + 6) * 5);
    assert!(!ccw.position.iter().any(|p| p[0] > 2.0 && p[1] > 2.0));
    poly.reverse();
    assert_eq!(run(1.0, &[add(prism(2, poly), 1)], &[]).unwrap(), ccw);
}

#[test]
fn later_add_wins_and_subtract_then_add_restores() {
    let c = run(1.0, &[add(cube(0.0, 10.0), 1), add(cube(2.0, 4.0), 2)], &[]).unwrap();
    assert_eq!(
        (c.len(), c.material.iter().filter(|&&m| m == 2).count()),
        (1000, 8)
    );
    let plain = run(1.0, &[add(cube(0.0, 10.0), 1)], &[]).unwrap();
    let hole = Op::Subtract {
        shape: cube(2.0, 5.0),
    };
    let ops = [add(cube(0.0, 10.0), 1), hole, add(cube(2.0, 5.0), 1)];
    assert_eq!(run(1.0, &ops, &[]).unwrap(), plain);
}

#[test]
fn slab_is_half_open_and_only_subtracts() {
    let slab = Shape::Slab {
        axis: 2,
        from: 0.0,
        to: 2.5,
    };
    assert!(slab.contains([9.0, 9.0, 0.0]) && !slab.contains([9.0, 9.0, 2.5]));
    let ops = [
        add(cube(0.0, 10.0), 1),
        Op::Subtract {
            shape: slab.clone(),
        },
    ];
    assert_eq!(run(0.5, &ops, &[]).unwrap().len(), 8000 - 400 * 5);
    let e = run(1.0, &[add(slab, 1)], &[]).unwrap_err();
    assert!(e.message.contains("slab is unbounded"), "{e}");
}

#[test]
fn bar_particles() {
    let bar = Bar::along([1.0, 2.0, 3.0], [0.0, 0.0, 2.0], 10.0, 0.2, 0.5, 3);
    let c = run(1.0, &[], &[bar]).unwrap();
    assert_eq!(c.len(), 20);
    for (k, p) in c.position.iter().enumerate() {
        assert_eq!(*p, [1.0, 2.0, 3.0 + 0.5 * (k as f64 + 0.5)]);
    }
    assert!(c.volume.iter().all(|&v| (v - 0.1).abs() < 1e-15));
    assert!(c.material.iter().all(|&m| m == 3) && c.spacing.iter().all(|&d| d == 0.5));
    let close = |a: Vec3, b: Vec3| (0..3).all(|e| (a[e] - b[e]).abs() < 1e-12);
    let angled = |az, el| Bar::at_angle([0.0; 3], az, el, 2.0, 1.0, 1.0, 0).to;
    assert!(close(angled(0.0, 90.0), [0.0, 0.0, 2.0]));
    assert!(close(angled(90.0, 0.0), [0.0, 2.0, 0.0]));
    assert!(close(angled(180.0, 0.0), [-2.0, 0.0, 0.0]));
}

#[test]
fn bar_removes_only_coincident_sites() {
    let ops = [add(cube(0.0, 10.0), 1)];
    let c = run(1.0, &ops, &[x_bar([0.0, 5.5, 5.5], 10.0, 0.1, 1.0)]).unwrap();
    assert_eq!(c.len(), 1000 - 10 + 10);
    assert_eq!(c.material.iter().filter(|&&m| m == 9).count(), 10);
    assert!(c.position.contains(&[3.5, 4.5, 5.5]) && c.position.contains(&[3.5, 5.5, 6.5]));
    // A bar between site rows, or with particles between sites, removes nothing.
    let c = run(1.0, &ops, &[x_bar([0.0, 5.0, 5.0], 10.0, 0.1, 1.0)]).unwrap();
    assert_eq!(c.len(), 1010);
    let c = run(1.0, &ops, &[x_bar([0.5, 5.5, 5.5], 9.0, 0.1, 1.0)]).unwrap();
    assert_eq!(c.len(), 1009);
}

#[test]
fn errors() {
    let bad = cyl([0.0; 3], [1.0, 0.0, 0.0], 1.0, -1.0);
    assert_eq!(
        bad.validate().unwrap_err(),
        "cylinder radius must be > 0 (got -1)"
    );
    let e = run(1.0, &[add(cube(0.0, 9.0), 1), add(bad, 1)], &[]).unwrap_err();
    assert_eq!((e.entry, e.bar), (Some(1), None));
    let msg = "geometry entry 1 (cylinder): cylinder radius must be > 0 (got -1)";
    assert_eq!(e.to_string(), msg);
    let e = prism(2, vec![]).validate().unwrap_err();
    assert!(e.contains("at least 3 vertices"), "{e}");
    let e = prism(2, vec![[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
        .validate()
        .unwrap_err();
    assert!(e.contains("zero area"), "{e}");
    let ops = [
        add(cube(0.0, 9.0), 1),
        add(cube(0.0, 9.0), 1),
        add(cube(0.1, 0.2), 1),
    ];
    let msg =
        "geometry entry 2 (box) selects no lattice site: it is smaller than the spacing or outside";
    assert_eq!(run(1.0, &ops, &[]).unwrap_err().message, msg);
    let ops = [
        add(cube(0.0, 4.0), 1),
        Op::Subtract {
            shape: cube(-1.0, 5.0),
        },
    ];
    let e = run(1.0, &ops, &[]).unwrap_err();
    assert!(
        e.entry.is_none() && e.message.contains("no particles"),
        "{e}"
    );
    let e = run(0.0, &ops[..1], &[]).unwrap_err();
    assert!(e.entry.is_none() && e.message.contains("spacing"), "{e}");
    let bad = x_bar([0.0; 3], 1.0, 0.0, 1.0);
    let e = run(1.0, &ops[..1], &[bad.clone(), bad]).unwrap_err();
    assert_eq!((e.entry, e.bar), (None, Some(0)));
    assert!(e.message.contains("area"), "{e}");
    let e = run(1.0, &[add(cube(0.0, 1e9), 1)], &[]).unwrap_err();
    assert!(e.message.contains("u32::MAX"), "{e}");
}

fn cubic(kind: LatticeKind, a: f64) -> Lattice {
    Lattice {
        kind,
        ..Lattice::regular(a, [0.0; 3])
    }
}

#[test]
fn fcc_and_bcc_boxes_of_whole_cells_hold_basis_sites_per_cell() {
    // LAMMPS in.lj: `lattice fcc 0.8442`, `region box block 0 20 0 20 0 20` → 32,000 atoms.
    let a = LatticeKind::Fcc.cell_side(0.8442);
    assert!((a - 1.6796).abs() < 1e-4, "{a}");
    let fcc = cubic(LatticeKind::Fcc, a);
    let cloud = build(&fcc, &[add(cube(0.0, 20.0 * a), 0)], &[]).unwrap();
    assert_eq!(cloud.len(), 32_000);
    // Half-open: the max faces hold sites of the next cells, which are left out.
    let top = 20.0 * a * (1.0 - 1e-12);
    assert!(cloud.position.iter().all(|p| p.iter().all(|&x| x < top)));
    assert!(cloud.volume.iter().all(|&v| v == a * a * a / 4.0));
    let total: f64 = cloud.volume.iter().sum();
    assert!((total - (20.0 * a).powi(3)).abs() < 1e-9 * total);
    let bcc = cubic(LatticeKind::Bcc, 2.0);
    let cloud = build(&bcc, &[add(cube(0.0, 6.0), 0)], &[]).unwrap();
    assert_eq!(cloud.len(), 2 * 27);
    assert!(cloud.position.contains(&[1.0, 1.0, 1.0]) && cloud.position.contains(&[0.0; 3]));
    assert!(!cloud.position.contains(&[1.0, 0.0, 0.0]));
    // Two boxes side by side tile: no site twice, none lost.
    let halves = [
        add(bx([0.0; 3], [3.0 * a, 6.0 * a, 6.0 * a]), 0),
        add(bx([3.0 * a, 0.0, 0.0], [6.0 * a; 3]), 1),
    ];
    assert_eq!(build(&fcc, &halves, &[]).unwrap().len(), 4 * 216);
}

#[test]
fn fcc_sites_have_twelve_neighbours_and_bcc_eight() {
    for (kind, near, count) in [
        (LatticeKind::Fcc, 0.5f64.sqrt(), 12),
        (LatticeKind::Bcc, 0.75f64.sqrt(), 8),
        (LatticeKind::Sc, 1.0, 6),
    ] {
        let cloud = build(&cubic(kind, 1.0), &[add(cube(0.0, 5.0), 0)], &[]).unwrap();
        let centre = cloud
            .position
            .iter()
            .min_by(|p, q| {
                let d = |p: &Vec3| p.iter().map(|x| (x - 2.5).powi(2)).sum::<f64>();
                d(p).total_cmp(&d(q))
            })
            .unwrap();
        let mut d: Vec<f64> = cloud
            .position
            .iter()
            .map(|p| sub(*p, *centre))
            .map(|v| dot(v, v).sqrt())
            .filter(|&r| r > 0.0)
            .collect();
        d.sort_by(f64::total_cmp);
        assert!((d[0] - near).abs() < 1e-12, "{kind:?}: {}", d[0]);
        assert_eq!(
            d.iter().filter(|&&r| r < near + 1e-9).count(),
            count,
            "{kind:?}"
        );
    }
}

#[test]
fn simple_cubic_is_unchanged_by_the_lattice_kinds() {
    // Closed box on sc: a site on the max face (here 2.5) is still in.
    let cloud = run(1.0, &[add(bx([0.0; 3], [2.5, 2.0, 2.0]), 0)], &[]).unwrap();
    assert_eq!(cloud.len(), 3 * 2 * 2);
    assert_eq!(cloud.position[0], [0.5, 0.5, 0.5]);
    assert_eq!(cloud.volume[0], 1.0);
}

/// `SceneSites` numbers and places every particle as `build` does, region by region.
#[test]
fn scene_sites_match_build_site_for_site() {
    let ops = vec![
        add(bx([0.0; 3], [12.0, 6.0, 5.0]), 0),
        Op::Subtract {
            shape: cyl([6.0, 3.0, -1.0], [0.0, 0.0, 1.0], 7.0, 1.6),
        },
        add(cube(2.0, 4.0), 3),
        Op::Subtract {
            shape: Shape::Slab {
                axis: 0,
                from: 9.0,
                to: 10.0,
            },
        },
    ];
    let bars = [x_bar([0.0, 1.5, 1.5], 12.0, 0.2, 0.7)];
    for kind in [LatticeKind::Sc, LatticeKind::Fcc, LatticeKind::Bcc] {
        let lattice = Lattice {
            jitter: 0.1,
            seed: 7,
            ..cubic(kind, 1.0)
        };
        let cloud = build(&lattice, &ops, &bars).unwrap();
        let sites = SceneSites::new(&lattice, &ops, &bars).unwrap();
        assert_eq!(sites.len(), cloud.len(), "{kind:?}");
        // Two halves along x, as two procCubes would take them, make the whole.
        let mut all = sites.select(|_, _| true, |p| p[0] < 6.0);
        all.extend(sites.select(|_, _| true, |p| p[0] >= 6.0));
        all.sort_by_key(|s| s.gid);
        for (g, s) in all.iter().enumerate() {
            assert_eq!(s.gid as usize, g);
            assert_eq!(s.position, cloud.position[g], "{kind:?} particle {g}");
            assert_eq!(
                (s.volume, s.material, s.bar),
                (cloud.volume[g], cloud.material[g], cloud.bar[g])
            );
        }
        assert_eq!(all.len(), cloud.len());
    }
}
