use super::*;

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

fn inside(c: [f64; 3], r: f64) -> impl Fn([f64; 3]) -> bool {
    move |s| (0..3).map(|a| (s[a] - c[a]).powi(2)).sum::<f64>() < r * r
}

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
    let points = block([40, 20, 20], |s| {
        holes.iter().any(|&(c, r)| inside(c, r)(s))
    });
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
    let a = inside([8.0, 8.0, 8.0], 3.0);
    let b = inside([20.0, 8.0, 8.0], 3.0);
    let slot =
        |s: [f64; 3]| s[0] > 8.0 && s[0] < 20.0 && s[1] == 8.0 && (7.0..=9.0).contains(&s[2]);
    let points = block([28, 16, 16], |s| a(s) || b(s) || slot(s));
    assert_eq!(voids_of(&points, Connectivity::Face).voids.len(), 1);
    let apart = block([28, 16, 16], |s| a(s) || b(s));
    assert_eq!(voids_of(&apart, Connectivity::Face).voids.len(), 2);
}

#[test]
fn a_hole_open_to_the_outside_is_not_a_void() {
    let hole = inside([10.0, 8.0, 8.0], 3.0);
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
    let points = block([22, 12, 12], |s| {
        holes.iter().any(|&(c, r)| inside(c, r)(s))
    });
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
