//! Property test: for random particle clouds and horizons, the bond list holds every pair
//! within the horizon exactly once.

use pdq::bonds::BondList;
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
