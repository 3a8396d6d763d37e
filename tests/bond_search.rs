//! Property test: for random particle clouds and horizons, the bond list holds every pair
//! within the horizon exactly once.

use pdq::engine::bonds::BondList;
use proptest::prelude::*;
use std::collections::BTreeSet;

fn brute_force(x: &[[f64; 3]], h: f64) -> BTreeSet<(u32, u32)> {
    let mut s = BTreeSet::new();
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            let d: f64 = (0..3).map(|k| (x[j][k] - x[i][k]).powi(2)).sum();
            if d <= h * h {
                s.insert((i as u32, j as u32));
            }
        }
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn every_pair_within_the_horizon_exactly_once(
        pts in prop::collection::vec((0.0f64..10.0, 0.0f64..10.0, 0.0f64..4.0), 2..250),
        h in 0.3f64..4.0,
    ) {
        let x: Vec<[f64; 3]> = pts.iter().map(|&(a, b, c)| [a, b, c]).collect();
        let bonds = BondList::<()>::find(&x, x.len(), h, 1.0, true);
        let mut seen = BTreeSet::new();
        for (i, j, b) in bonds.iter() {
            let key = (i.min(j) as u32, i.max(j) as u32);
            prop_assert!(i != j);
            prop_assert!(seen.insert(key), "pair {:?} stored twice", key);
            prop_assert!(bonds.geom[b].beta > 0.0 && bonds.geom[b].beta <= 1.0);
        }
        prop_assert_eq!(seen, brute_force(&x, h));
        // Initial bond counts agree with the pairs.
        let total: u32 = bonds.initial.iter().sum();
        prop_assert_eq!(total as usize, 2 * bonds.len());
    }
}

/// Lattices whose extent is a whole number of horizons, at spacings not exact in binary: the
/// cells must not lose pairs at exactly the horizon, and ghosts (particles past `n_owned`) are
/// bonded to owned particles only.
#[test]
fn lattice_pairs_at_exactly_the_horizon_are_found() {
    for (h, origin, n) in [
        (1.0 / 3.0, 0.0, 31usize),
        (0.02, 0.013, 91),
        (0.001, 0.0, 40),
    ] {
        let x: Vec<[f64; 3]> = (0..n).map(|i| [origin + i as f64 * h, 0.0, 0.0]).collect();
        let horizon = 3.0 * h;
        let bonds = BondList::<()>::find(&x, x.len(), horizon, h, true);
        assert_eq!(
            bonds.len(),
            3 * n - 6,
            "spacing {h}: every pair up to 3 apart"
        );
        let n_owned = n / 2;
        let ghosts = BondList::<()>::find(&x, n_owned, horizon, h, true);
        for (i, j, _) in ghosts.iter() {
            assert!(i < n_owned, "a ghost owns a bond");
            assert!(j < n_owned || i + 3 >= n_owned, "bond {i}-{j} too far");
        }
        // Owned-owned pairs plus owned-ghost pairs.
        let expect = (3 * n_owned - 6) + 6;
        assert_eq!(ghosts.len(), expect, "spacing {h}");
    }
}
