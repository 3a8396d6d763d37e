//! The largest clusters' voxels, gathered on the root for a picture of where they are.

use super::{Labelled, Region};
use crate::parallel::comm::{f64s, Team, Transport};

/// How many clusters a picture shows.
pub const SHOWN: usize = 5;

/// The centres of the voxels of the `k` largest clusters of `found` (most voxels first, ties
/// by label), each with its place in that order (0: the largest), on the root; `None`
/// elsewhere. Every worker must call it (it broadcasts and gathers).
pub fn largest<T: Transport>(
    team: &mut Team<T>,
    region: &Region,
    found: &Labelled,
    k: usize,
) -> Option<Vec<([f64; 3], usize)>> {
    let mut chosen: Vec<u8> = Vec::new();
    if team.is_root() {
        let mut by_size: Vec<(u64, u32)> =
            found.clusters.iter().map(|c| (c.voxels, c.label)).collect();
        by_size.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        for (_, label) in by_size.into_iter().take(k) {
            chosen.extend_from_slice(&label.to_le_bytes());
        }
    }
    team.broadcast(&mut chosen);
    let labels: Vec<u32> = chosen
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    // Each voxel as (x, y, z, place).
    let mut mine: Vec<f64> = Vec::new();
    for (v, l) in found.labels.iter().enumerate() {
        if let Some(place) = labels.iter().position(|c| c == l).filter(|_| *l != 0) {
            let c = region.coords(v).map(|x| x as f64);
            mine.extend(region.grid.centre(c));
            mine.push(place as f64);
        }
    }
    let all = team.gather(bytemuck::cast_slice(&mine))?;
    let voxels = all
        .iter()
        .flat_map(|b| {
            f64s(b)
                .chunks_exact(4)
                .map(|r| ([r[0], r[1], r[2]], r[3] as usize))
                .collect::<Vec<_>>()
        })
        .collect();
    Some(voxels)
}
