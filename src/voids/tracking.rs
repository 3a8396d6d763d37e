//! Clusters followed from one analysis to the next by voxel overlap (Hemani et al. 2014): a
//! cluster that shares voxels with one cluster of the last analysis continues it (and keeps
//! its id); one that shares none nucleated; one that shares voxels with several is their
//! coalescence; several that share voxels with one are its split; a cluster of the last
//! analysis that shares none with any closed. Voxels are matched by their place on the run's
//! voxel lattice ([`VoxelGrid::offset`]), so grids of different extents compare.
//!
//! [`VoxelGrid::offset`]: super::VoxelGrid::offset

use super::{Labelled, Region};
use crate::parallel::comm::{Team, Transport};
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// What happened to a cluster between two analyses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    Nucleated,
    Grew,
    Shrank,
    Coalesced,
    Split,
    Closed,
    /// The first analysis after a restart: the clusters found, under new ids.
    Resumed,
}

impl EventKind {
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Nucleated => "nucleated",
            EventKind::Grew => "grew",
            EventKind::Shrank => "shrank",
            EventKind::Coalesced => "coalesced",
            EventKind::Split => "split",
            EventKind::Closed => "closed",
            EventKind::Resumed => "resumed",
        }
    }
}

/// One event: the cluster's id after it (for `Closed`, the id that ended), the ids it came
/// from, and its volume after it (for `Closed`, before).
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    pub kind: EventKind,
    pub id: u32,
    pub parents: Vec<u32>,
    pub volume: f64,
}

/// The last analysis, as each procCube and the root keep it.
pub struct Tracker {
    /// This procCube's labelled voxels of the last analysis, by lattice place, with their ids.
    previous: HashMap<[i64; 3], u32>,
    /// On the root: the last analysis's ids and volumes.
    last: BTreeMap<u32, f64>,
    /// The next id to give.
    next: u32,
    /// No analysis yet: nothing to match against.
    first: bool,
    /// The first analysis continues a run from a restart.
    resumed: bool,
}

impl Tracker {
    /// A tracker whose ids start at `next` (after a restart: past the ids used before).
    pub fn new(next: u32, resumed: bool) -> Tracker {
        Tracker {
            previous: HashMap::new(),
            last: BTreeMap::new(),
            next: next.max(1),
            first: true,
            resumed,
        }
    }

    /// Matches this analysis's clusters with the last's; the events on the root (empty
    /// elsewhere) and every cluster's id, by label, on every worker. Every worker must call
    /// it (a gather and a broadcast).
    pub fn follow<T: Transport>(
        &mut self,
        team: &mut Team<T>,
        region: &Region,
        found: &Labelled,
    ) -> (Vec<Event>, Vec<u32>) {
        let offset = region.grid.offset;
        let place = |v: usize| {
            let c = region.coords(v);
            [0, 1, 2].map(|a| c[a] as i64 + offset[a])
        };
        let mut overlap: HashMap<(u32, u32), u64> = HashMap::new();
        for (v, &l) in found.labels.iter().enumerate() {
            if l > 0 {
                if let Some(&id) = self.previous.get(&place(v)) {
                    *overlap.entry((l, id)).or_default() += 1;
                }
            }
        }
        let mut mine: Vec<[u64; 3]> = overlap
            .iter()
            .map(|(&(l, id), &n)| [l as u64, id as u64, n])
            .collect();
        mine.sort_unstable();
        let gathered = team.gather(bytemuck::cast_slice(&mine));
        let mut events = Vec::new();
        let mut ids_bytes = Vec::new();
        if let Some(all) = gathered {
            // Current label → the ids of the last analysis it overlaps.
            let mut parents: BTreeMap<u32, BTreeSet<u32>> = BTreeMap::new();
            for bytes in &all {
                for r in bytes.chunks_exact(24) {
                    let r: [u64; 3] = bytemuck::pod_read_unaligned(r);
                    parents.entry(r[0] as u32).or_default().insert(r[1] as u32);
                }
            }
            let ids = self.match_clusters(&found.clusters, &parents, &mut events);
            ids_bytes = bytemuck::cast_slice(&ids).to_vec();
        }
        team.broadcast(&mut ids_bytes);
        let ids: Vec<u32> = ids_bytes
            .chunks_exact(4)
            .map(|b| u32::from_ne_bytes(b.try_into().unwrap()))
            .collect();
        self.previous = found
            .labels
            .iter()
            .enumerate()
            .filter(|(_, &l)| l > 0)
            .map(|(v, &l)| (place(v), ids[l as usize - 1]))
            .collect();
        self.first = false;
        (events, ids)
    }

    /// On the root: the ids of the current clusters and the events, from the overlaps.
    fn match_clusters(
        &mut self,
        clusters: &[super::Cluster],
        parents: &BTreeMap<u32, BTreeSet<u32>>,
        events: &mut Vec<Event>,
    ) -> Vec<u32> {
        let none = BTreeSet::new();
        let mut children: HashMap<u32, u32> = HashMap::new();
        for set in parents.values() {
            for &p in set {
                *children.entry(p).or_default() += 1;
            }
        }
        let mut ids = Vec::with_capacity(clusters.len());
        for c in clusters {
            let from = parents.get(&c.label).unwrap_or(&none);
            let mut event = |kind, id, parents: Vec<u32>| {
                events.push(Event {
                    kind,
                    id,
                    parents,
                    volume: c.volume,
                })
            };
            let id = match from.len() {
                0 => {
                    let id = self.fresh();
                    // The clusters of a run's first analysis were there from the start.
                    let kind = if self.first && self.resumed {
                        EventKind::Resumed
                    } else {
                        EventKind::Nucleated
                    };
                    event(kind, id, Vec::new());
                    id
                }
                1 => {
                    let p = *from.iter().next().unwrap();
                    if children[&p] > 1 {
                        let id = self.fresh();
                        event(EventKind::Split, id, vec![p]);
                        id
                    } else {
                        let before = self.last.get(&p).copied().unwrap_or(0.0);
                        if c.volume > before {
                            event(EventKind::Grew, p, vec![p]);
                        } else if c.volume < before {
                            event(EventKind::Shrank, p, vec![p]);
                        }
                        p
                    }
                }
                _ => {
                    let id = self.fresh();
                    event(EventKind::Coalesced, id, from.iter().copied().collect());
                    id
                }
            };
            ids.push(id);
        }
        for (&p, &volume) in &self.last {
            if !children.contains_key(&p) {
                events.push(Event {
                    kind: EventKind::Closed,
                    id: p,
                    parents: Vec::new(),
                    volume,
                });
            }
        }
        self.last = ids
            .iter()
            .zip(clusters)
            .map(|(&id, c)| (id, c.volume))
            .collect();
        ids
    }

    fn fresh(&mut self) -> u32 {
        self.next += 1;
        self.next - 1
    }
}
