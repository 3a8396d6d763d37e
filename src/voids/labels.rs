//! Clusters of marked voxels labelled over procCubes, without gathering the grid.
//!
//! Each procCube holds the voxels whose centres lie in its cells (its [`Region`]). The
//! labelling runs in three steps, the same for threads and MPI ranks:
//!
//! 1. Union-find inside the region: local components, each named by its smallest global voxel
//!    index.
//! 2. One voxel layer of halo from each neighbouring procCube, staged along x, then y, then z
//!    like the ghost messages, so that edge and corner neighbours arrive too; a marked voxel
//!    next to a marked halo voxel ties the two components.
//! 3. The ties are resolved into each cluster's smallest global voxel index, by one of three
//!    [`Scheme`]s. That name does not depend on the layout, and clusters are numbered 1, 2, …
//!    in its order, so labels are the same on any number of procCubes.
//!
//! Each procCube then measures its part of every cluster (voxels, faces, extent, bond sums),
//! and the root adds the parts by cluster.

use super::region::Region;
use super::union_find::UnionFind;
use super::{Cluster, Connectivity, VoxelGrid};
use crate::parallel::comm::{Solo, Team, Transport};
use std::collections::{BTreeMap, HashMap};

/// A halo voxel that is not marked, or that no procCube sent.
const NONE: u64 = u64::MAX;
/// Tags of the halo messages (a check; messages are matched by order).
const HALO_TAG: u32 = 40;

/// How the components' ties across procCube faces are resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    /// The ties (only components that touch a face) are gathered on the root, joined there
    /// by union-find and the renamed components sent back (Harrison et al. 2011): one
    /// gather and one broadcast whatever the clusters' shapes.
    Boundary,
    /// Each component takes the smallest name across its ties, and the halos are exchanged
    /// again until no name changes anywhere (LAMMPS's `compute cluster/atom`): the rounds
    /// grow with the number of procCubes a cluster crosses.
    MinLabel,
    /// The whole grid's marks are gathered on the root, labelled there, and each procCube's
    /// labels sent back.
    Gather,
}

impl Scheme {
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Boundary => "boundary",
            Scheme::MinLabel => "min-label",
            Scheme::Gather => "gather",
        }
    }
}

/// What a labelling gives each procCube.
#[derive(Clone, Debug, Default)]
pub struct Labelled {
    /// Per voxel of the region: its cluster's label, or 0 (not marked, or the outside).
    pub labels: Vec<u32>,
    /// The clusters, on the root (empty elsewhere), in label order.
    pub clusters: Vec<Cluster>,
    /// Marked voxels connected to the grid's margin (voids: the outside), on the root.
    pub outside: u64,
    /// Halo exchanges the merge took.
    pub rounds: u32,
}

/// Labels the clusters of `marked` voxels (one flag per voxel of the region) on every
/// procCube; `values` (per voxel, or empty) are summed per cluster into its bonds and
/// opening. With a bounded axis, the cluster holding voxel (0, 0, 0) of the margin is the
/// outside and left out. Every worker must call it (it exchanges).
pub fn label<T: Transport>(
    team: &mut Team<T>,
    region: &Region,
    marked: &[bool],
    values: &[[f64; 2]],
    connectivity: Connectivity,
    scheme: Scheme,
) -> Labelled {
    assert_eq!(
        marked.len(),
        region.len(),
        "one mark per voxel of the region"
    );
    if scheme == Scheme::Gather {
        return gathered(team, region, marked, values, connectivity);
    }
    let parts = Parts::find(region, marked, connectivity);
    let mut ext = parts.extended(region);
    halo(team, region, &mut ext);
    let ties = parts.ties(region, &ext, connectivity);
    let (names, rounds) = match scheme {
        Scheme::MinLabel => parts.min_label(team, region, &mut ext, &ties),
        _ => (parts.boundary_merge(team, &ext, &ties), 1),
    };
    let mut labelled = parts.measure(team, region, &ext, &names, values);
    labelled.rounds = rounds;
    labelled
}

/// One procCube's components.
struct Parts {
    /// Per voxel of the region: its component, or `u32::MAX` if not marked.
    comp: Vec<u32>,
    /// Each component's smallest global voxel index.
    name: Vec<u64>,
}

/// Neighbour offsets for a connectivity; `back` keeps those towards smaller indices.
fn offsets(connectivity: Connectivity, back: bool) -> Vec<[i64; 3]> {
    let mut v = Vec::new();
    for dz in -1i64..=1 {
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                let touching = dx.abs() + dy.abs() + dz.abs();
                let wanted = match connectivity {
                    Connectivity::Face => touching == 1,
                    Connectivity::All => touching >= 1,
                };
                if wanted && (!back || (dz, dy, dx) < (0, 0, 0)) {
                    v.push([dx, dy, dz]);
                }
            }
        }
    }
    v
}

impl Parts {
    /// Union-find over the region's marked voxels.
    fn find(region: &Region, marked: &[bool], connectivity: Connectivity) -> Parts {
        let d = region.dims();
        let back = offsets(connectivity, true);
        let mut sets = UnionFind::new(region.len());
        for z in 0..d[2] {
            for y in 0..d[1] {
                for x in 0..d[0] {
                    let v = (z * d[1] + y) * d[0] + x;
                    if !marked[v] {
                        continue;
                    }
                    for o in &back {
                        let (a, b, c) = (x as i64 + o[0], y as i64 + o[1], z as i64 + o[2]);
                        if a < 0 || b < 0 || c < 0 || a >= d[0] as i64 || b >= d[1] as i64 {
                            continue;
                        }
                        let u = (c as usize * d[1] + b as usize) * d[0] + a as usize;
                        if marked[u] {
                            sets.join(u, v);
                        }
                    }
                }
            }
        }
        // A set's root is its smallest member, met first: components in order of their roots,
        // which is the order of their smallest global indices too.
        let mut comp = vec![u32::MAX; region.len()];
        let mut name = Vec::new();
        for v in 0..region.len() {
            if !marked[v] {
                continue;
            }
            let r = sets.root(v);
            if r == v {
                comp[v] = name.len() as u32;
                name.push(region.grid.index(region.coords(v)) as u64);
            } else {
                comp[v] = comp[r];
            }
        }
        Parts { comp, name }
    }

    /// The region with one layer of halo on every side, holding each marked voxel's
    /// component name and `NONE` elsewhere.
    fn extended(&self, region: &Region) -> Vec<u64> {
        let d = region.dims();
        let e = d.map(|n| n + 2);
        let mut ext = vec![NONE; e.iter().product()];
        for (v, &c) in self.comp.iter().enumerate() {
            if c != u32::MAX {
                ext[ext_index(e, local_xyz(d, v), [1, 1, 1])] = self.name[c as usize];
            }
        }
        ext
    }

    /// (component, halo voxel) for every marked voxel next to a halo voxel.
    fn ties(&self, region: &Region, ext: &[u64], connectivity: Connectivity) -> Vec<(u32, usize)> {
        let d = region.dims();
        let e = d.map(|n| n + 2);
        let all = offsets(connectivity, false);
        let mut ties = Vec::new();
        for (v, &c) in self.comp.iter().enumerate() {
            let xyz = local_xyz(d, v);
            if c == u32::MAX || (0..3).all(|a| xyz[a] > 0 && xyz[a] + 1 < d[a]) {
                continue;
            }
            for o in &all {
                // Extended coordinates of the neighbour: local + 1 + offset.
                let n = [0, 1, 2].map(|a| (xyz[a] as i64 + 1 + o[a]) as usize);
                if (0..3).any(|a| n[a] == 0 || n[a] == e[a] - 1) {
                    let h = ext_index(e, n, [0, 0, 0]);
                    if ext[h] != NONE {
                        ties.push((c, h));
                    }
                }
            }
        }
        ties
    }

    /// Resolves the ties on the root: every component's cluster name.
    fn boundary_merge<T: Transport>(
        &self,
        team: &mut Team<T>,
        ext: &[u64],
        ties: &[(u32, usize)],
    ) -> Vec<u64> {
        let mut pairs: Vec<[u64; 2]> = ties
            .iter()
            .map(|&(c, h)| [self.name[c as usize], ext[h]])
            .filter(|p| p[0] != p[1])
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let gathered = team.gather(bytemuck::cast_slice(&pairs));
        let mut renamed: Vec<u8> = Vec::new();
        if let Some(all) = gathered {
            let mut index: HashMap<u64, usize> = HashMap::new();
            let mut names: Vec<u64> = Vec::new();
            let mut edges = Vec::new();
            for bytes in &all {
                for p in bytes.chunks_exact(16) {
                    let ends = [0, 8].map(|k| u64::from_ne_bytes(p[k..k + 8].try_into().unwrap()));
                    let [a, b] = ends.map(|n| {
                        *index.entry(n).or_insert_with(|| {
                            names.push(n);
                            names.len() - 1
                        })
                    });
                    edges.push((a, b));
                }
            }
            let mut sets = UnionFind::new(names.len());
            for &(a, b) in &edges {
                sets.join(a, b);
            }
            // The smallest name of each set.
            let mut least: Vec<u64> = vec![NONE; names.len()];
            for (k, &n) in names.iter().enumerate() {
                let r = sets.root(k);
                least[r] = least[r].min(n);
            }
            let mut map: Vec<[u64; 2]> = (0..names.len())
                .map(|k| [names[k], least[sets.root(k)]])
                .filter(|m| m[0] != m[1])
                .collect();
            map.sort_unstable();
            renamed = bytemuck::cast_slice(&map).to_vec();
        }
        team.broadcast(&mut renamed);
        let map: HashMap<u64, u64> = renamed
            .chunks_exact(16)
            .map(|p| {
                let [a, b] = [0, 8].map(|k| u64::from_ne_bytes(p[k..k + 8].try_into().unwrap()));
                (a, b)
            })
            .collect();
        self.name.iter().map(|n| *map.get(n).unwrap_or(n)).collect()
    }

    /// Resolves the ties by exchanging the smallest name seen until none changes; returns
    /// the names and the halo exchanges taken.
    fn min_label<T: Transport>(
        &self,
        team: &mut Team<T>,
        region: &Region,
        ext: &mut [u64],
        ties: &[(u32, usize)],
    ) -> (Vec<u64>, u32) {
        let d = region.dims();
        let e = d.map(|n| n + 2);
        let mut names = self.name.clone();
        let mut rounds = 1;
        loop {
            let mut changed = false;
            for &(c, h) in ties {
                if ext[h] < names[c as usize] {
                    names[c as usize] = ext[h];
                    changed = true;
                }
            }
            if team.max(if changed { 1.0 } else { 0.0 }) == 0.0 {
                return (names, rounds);
            }
            // The boundary layers carry the new names.
            for (v, &c) in self.comp.iter().enumerate() {
                let xyz = local_xyz(d, v);
                if c != u32::MAX && (0..3).any(|a| xyz[a] == 0 || xyz[a] + 1 == d[a]) {
                    ext[ext_index(e, xyz, [1, 1, 1])] = names[c as usize];
                }
            }
            halo(team, region, ext);
            rounds += 1;
        }
    }

    /// Each component's part of its cluster, added by cluster on the root; the labels sent
    /// back to every procCube.
    fn measure<T: Transport>(
        &self,
        team: &mut Team<T>,
        region: &Region,
        ext: &[u64],
        names: &[u64],
        values: &[[f64; 2]],
    ) -> Labelled {
        let d = region.dims();
        let e = d.map(|n| n + 2);
        let mut parts: Vec<Part> = names.iter().map(|&n| Part::new(n)).collect();
        for (v, &c) in self.comp.iter().enumerate() {
            if c == u32::MAX {
                continue;
            }
            let xyz = local_xyz(d, v);
            let g = region.coords(v);
            let p = &mut parts[c as usize];
            p.voxels += 1;
            for a in 0..3 {
                p.sum[a] += g[a] as u64;
                p.first[a] = p.first[a].min(g[a] as u64);
                p.last[a] = p.last[a].max(g[a] as u64);
                for s in [-1i64, 1] {
                    let mut n = xyz.map(|x| x as i64 + 1);
                    n[a] += s;
                    let n = n.map(|x| x as usize);
                    if ext[ext_index(e, n, [0, 0, 0])] == NONE {
                        p.faces[a] += 1;
                    }
                }
            }
            if let Some(x) = values.get(v) {
                p.values[0] += x[0];
                p.values[1] += x[1];
            }
        }
        let gathered = team.gather(bytemuck::cast_slice(&parts));
        let mut order: Vec<u8> = Vec::new();
        let mut labelled = Labelled::default();
        if let Some(all) = gathered {
            let mut clusters: BTreeMap<u64, Part> = BTreeMap::new();
            for bytes in &all {
                for b in bytes.chunks_exact(std::mem::size_of::<Part>()) {
                    let p: Part = bytemuck::pod_read_unaligned(b);
                    clusters
                        .entry(p.name)
                        .and_modify(|q| q.add(&p))
                        .or_insert(p);
                }
            }
            if region.grid.has_outside() {
                if let Some(o) = clusters.remove(&0) {
                    labelled.outside = o.voxels;
                }
            }
            let names: Vec<u64> = clusters.keys().copied().collect();
            order = bytemuck::cast_slice(&names).to_vec();
            labelled.clusters = clusters
                .values()
                .enumerate()
                .map(|(k, p)| p.cluster(k as u32 + 1, &region.grid))
                .collect();
        }
        team.broadcast(&mut order);
        let sorted: Vec<u64> = order
            .chunks_exact(8)
            .map(|b| u64::from_ne_bytes(b.try_into().unwrap()))
            .collect();
        labelled.labels = self
            .comp
            .iter()
            .map(|&c| {
                if c == u32::MAX {
                    return 0;
                }
                match sorted.binary_search(&names[c as usize]) {
                    Ok(k) => k as u32 + 1,
                    Err(_) => 0,
                }
            })
            .collect();
        labelled
    }
}

/// One procCube's part of a cluster, as sent to the root.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
struct Part {
    name: u64,
    voxels: u64,
    sum: [u64; 3],
    faces: [u64; 3],
    first: [u64; 3],
    last: [u64; 3],
    values: [f64; 2],
}

impl Part {
    fn new(name: u64) -> Part {
        Part {
            name,
            voxels: 0,
            sum: [0; 3],
            faces: [0; 3],
            first: [u64::MAX; 3],
            last: [0; 3],
            values: [0.0; 2],
        }
    }

    fn add(&mut self, p: &Part) {
        self.voxels += p.voxels;
        for a in 0..3 {
            self.sum[a] += p.sum[a];
            self.faces[a] += p.faces[a];
            self.first[a] = self.first[a].min(p.first[a]);
            self.last[a] = self.last[a].max(p.last[a]);
        }
        self.values[0] += p.values[0];
        self.values[1] += p.values[1];
    }

    fn cluster(&self, label: u32, grid: &VoxelGrid) -> Cluster {
        let s = grid.size;
        let face_area = [s[1] * s[2], s[0] * s[2], s[0] * s[1]];
        let by_axis = [0, 1, 2].map(|a| self.faces[a] as f64 * face_area[a]);
        let volume = self.voxels as f64 * grid.voxel_volume();
        let bonds = self.values[1].round() as u64;
        Cluster {
            label,
            voxels: self.voxels,
            volume,
            surface: by_axis.iter().sum(),
            area: 0.5 * by_axis.iter().map(|x| x * x).sum::<f64>().sqrt(),
            centroid: grid.centre(self.sum.map(|x| x as f64 / self.voxels as f64)),
            equivalent_radius: (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt(),
            first: self.first.map(|x| x as usize),
            last: self.last.map(|x| x as usize),
            bonds,
            opening: if bonds > 0 {
                self.values[0] / self.values[1]
            } else {
                0.0
            },
        }
    }
}

fn local_xyz(d: [usize; 3], v: usize) -> [usize; 3] {
    [v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])]
}

/// Index into the extended box of dims `e` of coordinates `c` + `shift`.
fn ext_index(e: [usize; 3], c: [usize; 3], shift: [usize; 3]) -> usize {
    ((c[2] + shift[2]) * e[1] + c[1] + shift[1]) * e[0] + c[0] + shift[0]
}

/// Fills the halo layers of `ext` from the neighbouring procCubes: along x, then y (with the
/// x halos), then z (with both), so that edge and corner halo voxels arrive as well. A face
/// without a neighbour keeps `NONE`.
fn halo<T: Transport>(team: &mut Team<T>, region: &Region, ext: &mut [u64]) {
    let d = region.dims();
    let e = d.map(|n| n + 2);
    let mut recv = Vec::new();
    for a in 0..3 {
        // Along the axes done before, the halo travels on; the later ones, only the region.
        let range = |b: usize| if b < a { 0..e[b] } else { 1..d[b] + 1 };
        let layer = |at: usize| -> Vec<usize> {
            let mut idx = Vec::new();
            let (r0, r1, r2) = (range(0), range(1), range(2));
            for z in if a == 2 { at..at + 1 } else { r2.clone() } {
                for y in if a == 1 { at..at + 1 } else { r1.clone() } {
                    for x in if a == 0 { at..at + 1 } else { r0.clone() } {
                        idx.push(ext_index(e, [x, y, z], [0, 0, 0]));
                    }
                }
            }
            idx
        };
        // Up: the top layer goes to the upper neighbour; the lower one's fills the bottom
        // halo. Down: the reverse.
        for (stage, (dir, send_at, fill_at)) in
            [(1i64, d[a], 0), (-1, 1, d[a] + 1)].into_iter().enumerate()
        {
            let send: Vec<u64> = layer(send_at).iter().map(|&i| ext[i]).collect();
            let (to, from) = (region.neighbour(a, dir), region.neighbour(a, -dir));
            team.transport.exchange(
                HALO_TAG + (2 * a + stage) as u32,
                to,
                bytemuck::cast_slice(&send),
                from,
                &mut recv,
            );
            if from.is_some() {
                for (&i, b) in layer(fill_at).iter().zip(recv.chunks_exact(8)) {
                    ext[i] = u64::from_ne_bytes(b.try_into().unwrap());
                }
            }
        }
    }
}

/// The gather scheme: the marks on the root, labelled there as one region, labels sent back.
fn gathered<T: Transport>(
    team: &mut Team<T>,
    region: &Region,
    marked: &[bool],
    values: &[[f64; 2]],
    connectivity: Connectivity,
) -> Labelled {
    // Each procCube's box, its marks, and the values of its marked voxels.
    let mut mine: Vec<u8> = Vec::new();
    for a in 0..3 {
        mine.extend_from_slice(&(region.lo[a] as u64).to_ne_bytes());
        mine.extend_from_slice(&(region.hi[a] as u64).to_ne_bytes());
    }
    mine.extend(marked.iter().map(|&m| m as u8));
    for (v, x) in values.iter().enumerate() {
        if marked[v] {
            mine.extend_from_slice(bytemuck::cast_slice(x));
        }
    }
    let gathered = team.gather(&mine);
    let mut labelled = Labelled::default();
    let mut parts: Vec<Vec<u8>> = vec![Vec::new(); team.size()];
    if let Some(all) = gathered {
        let whole = Region::whole(region.grid.clone());
        let mut marks = vec![false; whole.len()];
        let mut sums = vec![[0.0; 2]; if values.is_empty() { 0 } else { whole.len() }];
        let boxes: Vec<([usize; 3], [usize; 3])> = all.iter().map(|b| read_box(b)).collect();
        for (bytes, (lo, hi)) in all.iter().zip(&boxes) {
            let d = [0, 1, 2].map(|a| hi[a] - lo[a]);
            let n = d.iter().product::<usize>();
            let (flags, rest) = bytes[48..].split_at(n);
            let mut rest = rest.chunks_exact(16);
            for (v, &f) in flags.iter().enumerate() {
                let xyz = local_xyz(d, v);
                let g = whole.grid.index([0, 1, 2].map(|a| lo[a] + xyz[a]));
                marks[g] = f != 0;
                if f != 0 && !sums.is_empty() {
                    let x: [f64; 2] = bytemuck::pod_read_unaligned(rest.next().unwrap());
                    sums[g] = x;
                }
            }
        }
        let mut solo = Team::new(Solo::new());
        labelled = label(
            &mut solo,
            &whole,
            &marks,
            &sums,
            connectivity,
            Scheme::Boundary,
        );
        for (k, (lo, hi)) in boxes.iter().enumerate() {
            let mut out = Vec::new();
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        out.push(labelled.labels[whole.grid.index([x, y, z])]);
                    }
                }
            }
            parts[k] = bytemuck::cast_slice(&out).to_vec();
        }
    }
    let back = team.scatter(parts);
    labelled.labels = back
        .chunks_exact(4)
        .map(|b| u32::from_ne_bytes(b.try_into().unwrap()))
        .collect();
    labelled
}

fn read_box(bytes: &[u8]) -> ([usize; 3], [usize; 3]) {
    let n = |k: usize| u64::from_ne_bytes(bytes[8 * k..8 * k + 8].try_into().unwrap()) as usize;
    ([n(0), n(2), n(4)], [n(1), n(3), n(5)])
}
