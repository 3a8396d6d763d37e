//! The scene's particles without the whole cloud: a site is filled by the last entry whose shape
//! fills it (an `Add` with its material, a `Subtract` empties it), unless a bar particle sits
//! within ¼ of a spacing — the overlap rules of [`super::build`], decided site by site. Global
//! ids come from counting the filled sites of every lattice row (z, y slowest; x fastest), so a
//! procCube fills only its own cells and still numbers its particles as `build` does: lattice
//! sites in (z, y, x) order, then bar particles in bar order. Memory is one counter per row and
//! one entry per bar particle, never one per site.

use super::{all_finite, dot, scene_err, sub, Bar, GeometryError, Key, Keys, Lattice, Op, Vec3};
use super::{sites, NOT_A_BAR};
use std::collections::HashSet;

/// One particle of the scene: its global id, reference position, volume, material and bar.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Site {
    pub gid: u32,
    pub position: Vec3,
    pub volume: f64,
    pub material: u16,
    pub bar: u32,
}

/// A bar particle: position, volume, material.
#[derive(Clone, Copy, Debug)]
struct BarParticle {
    position: Vec3,
    volume: f64,
    material: u16,
}

/// The scene's lattice sites and bar particles, enumerable region by region.
pub struct SceneSites {
    lattice: Lattice,
    keys: Keys,
    ops: Vec<Op>,
    bar_particles: Vec<(BarParticle, u32)>,
    /// Lattice sites displaced by a bar particle.
    removed: HashSet<Key>,
    /// Inclusive key ranges (x, y, z) holding every site an `Add` can fill.
    range: [(i64, i64); 3],
    /// Filled sites before each row (k, j), row-major with j fastest; one more at the end.
    row_start: Vec<u64>,
    /// Bounding box of every particle's position (jitter included).
    pub lo: Vec3,
    pub hi: Vec3,
}

impl SceneSites {
    /// Checks the scene as `build` does and counts its sites row by row.
    pub fn new(lattice: &Lattice, ops: &[Op], bars: &[Bar]) -> Result<Self, GeometryError> {
        let keys = check_lattice(lattice)?;
        let range = add_range(&keys, ops)?;
        let mut sites = SceneSites {
            lattice: *lattice,
            keys,
            ops: ops.to_vec(),
            bar_particles: Vec::new(),
            removed: HashSet::new(),
            range,
            row_start: Vec::new(),
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
        };
        sites.place_bars(bars)?;
        sites.count_rows()?;
        Ok(sites)
    }

    /// Particles of the scene: lattice sites then bar particles.
    pub fn len(&self) -> usize {
        self.lattice_count() as usize + self.bar_particles.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn lattice_count(&self) -> u64 {
        *self.row_start.last().unwrap_or(&0)
    }

    /// Bars after the ops, as in `build`: validated, counted, and the lattice sites within ¼
    /// spacing of each bar particle marked removed.
    fn place_bars(&mut self, bars: &[Bar]) -> Result<(), GeometryError> {
        let rm = 0.25 * self.lattice.spacing;
        for (b, bar) in bars.iter().enumerate() {
            bar.validate().map_err(|m| GeometryError {
                bar: Some(b),
                message: format!("bar {b}: {m}"),
                ..Default::default()
            })?;
            let n = bar.count();
            let (step, ds) = (sub(bar.to, bar.from).map(|d| d / n), bar.length() / n);
            for k in 0..n as usize {
                let p = [0, 1, 2].map(|e| bar.from[e] + (k as f64 + 0.5) * step[e]);
                let r = self.keys.around(p.map(|x| x - rm), p.map(|x| x + rm));
                for key in sites(r).filter(|key| self.lattice.kind.admits(key)) {
                    let d = sub(self.keys.site(&key), p);
                    if dot(d, d) < rm * rm {
                        self.removed.insert(key);
                    }
                }
                let particle = BarParticle {
                    position: p,
                    volume: bar.area * ds,
                    material: bar.material,
                };
                self.grow_box(p);
                self.bar_particles.push((particle, b as u32));
            }
        }
        Ok(())
    }

    fn grow_box(&mut self, p: Vec3) {
        self.lo = [0, 1, 2].map(|e| self.lo[e].min(p[e]));
        self.hi = [0, 1, 2].map(|e| self.hi[e].max(p[e]));
    }

    /// The material of the lattice site `key`, if it is filled.
    fn material(&self, key: &Key) -> Option<u16> {
        if !self.lattice.kind.admits(key) {
            return None;
        }
        let p = self.keys.site(key);
        let (tol, half_open) = (self.keys.tol, self.keys.half_open);
        let last = self.ops.iter().rev().find(|op| {
            let (Op::Add { shape, .. } | Op::Subtract { shape }) = op;
            shape.fills(p, tol, half_open)
        })?;
        match last {
            Op::Add { material, .. } if !self.removed.contains(key) => Some(*material),
            _ => None,
        }
    }

    /// A filled lattice site's particle position (its jitter included).
    fn position(&self, key: &Key) -> Vec3 {
        let (p, d) = (self.keys.site(key), self.lattice.offset(key));
        [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
    }

    fn rows(&self) -> impl Iterator<Item = (i64, i64)> {
        let [_, (j0, j1), (k0, k1)] = self.range;
        (k0..=k1).flat_map(move |k| (j0..=j1).map(move |j| (k, j)))
    }

    /// Counts the filled sites of every row, grows the bounding box, and checks what `build`
    /// checks of the result: every `Add` selects a site, the scene is not empty and its ids fit.
    fn count_rows(&mut self) -> Result<(), GeometryError> {
        let (i0, i1) = self.range[0];
        let mut row_start = vec![0u64];
        let mut total = 0u64;
        let rows: Vec<(i64, i64)> = self.rows().collect();
        for (k, j) in rows {
            for i in i0..=i1 {
                let key = [k, j, i];
                if self.material(&key).is_some() {
                    total += 1;
                    self.grow_box(self.position(&key));
                }
            }
            row_start.push(total);
        }
        self.row_start = row_start;
        self.check_adds()?;
        let n = total as f64 + self.bar_particles.len() as f64;
        if n > u32::MAX as f64 {
            return Err(scene_err(format!(
                "the scene has {n} particles, over u32::MAX"
            )));
        }
        if n == 0.0 {
            let m = "the scene has no particles: nothing was added, or every site was subtracted";
            return Err(GeometryError {
                empty: true,
                ..scene_err(m.into())
            });
        }
        Ok(())
    }

    /// `build`'s check that each `Add` fills at least one site when it is applied.
    fn check_adds(&self) -> Result<(), GeometryError> {
        let (tol, half_open, kind) = (self.keys.tol, self.keys.half_open, self.lattice.kind);
        for (n, op) in self.ops.iter().enumerate() {
            let Op::Add { shape, .. } = op else { continue };
            let (lo, hi) = shape.bounds();
            let r = self.keys.around(lo, hi);
            let any = sites(r)
                .filter(|key| kind.admits(key))
                .any(|key| shape.fills(self.keys.site(&key), tol, half_open));
            if !any {
                return Err(GeometryError {
                    entry: Some(n),
                    message: format!(
                        "geometry entry {n} ({}) selects no lattice site: it is smaller than the spacing or outside",
                        shape.kind()
                    ),
                    ..Default::default()
                });
            }
        }
        Ok(())
    }

    /// Every particle `keep` accepts by position, with its global id; lattice rows are skipped
    /// when `row_may_hold(y, z)` (the row's y and z, jitter aside) says none of theirs can be.
    pub fn select(
        &self,
        row_may_hold: impl Fn(f64, f64) -> bool,
        keep: impl Fn(&Vec3) -> bool,
    ) -> Vec<Site> {
        let (i0, i1) = self.range[0];
        let volume = self.lattice.site_volume();
        let mut out = Vec::new();
        for (r, (k, j)) in self.rows().enumerate() {
            let y = self.keys.site(&[k, j, i0]);
            if self.row_start[r] == self.row_start[r + 1] || !row_may_hold(y[1], y[2]) {
                continue;
            }
            let mut gid = self.row_start[r];
            for i in i0..=i1 {
                let key = [k, j, i];
                let Some(material) = self.material(&key) else {
                    continue;
                };
                let position = self.position(&key);
                if keep(&position) {
                    out.push(Site {
                        gid: gid as u32,
                        position,
                        volume,
                        material,
                        bar: NOT_A_BAR,
                    });
                }
                gid += 1;
            }
        }
        let first_bar = self.lattice_count();
        for (n, (b, bar)) in self.bar_particles.iter().enumerate() {
            if keep(&b.position) {
                out.push(Site {
                    gid: (first_bar + n as u64) as u32,
                    position: b.position,
                    volume: b.volume,
                    material: b.material,
                    bar: *bar,
                });
            }
        }
        out
    }

    /// Every particle's position, in id order, to `visit` (the census of cells).
    pub fn for_each_position(&self, mut visit: impl FnMut(&Vec3)) {
        self.for_each(|s| visit(&s.position));
    }

    /// Every particle, in id order, to `visit`.
    pub fn for_each(&self, mut visit: impl FnMut(Site)) {
        let (i0, i1) = self.range[0];
        let volume = self.lattice.site_volume();
        let mut gid = 0u32;
        for (k, j) in self.rows() {
            for i in i0..=i1 {
                let key = [k, j, i];
                if let Some(material) = self.material(&key) {
                    let position = self.position(&key);
                    let bar = NOT_A_BAR;
                    visit(Site {
                        gid,
                        position,
                        volume,
                        material,
                        bar,
                    });
                    gid += 1;
                }
            }
        }
        for (b, bar) in &self.bar_particles {
            let (position, volume, material, bar) = (b.position, b.volume, b.material, *bar);
            visit(Site {
                gid,
                position,
                volume,
                material,
                bar,
            });
            gid += 1;
        }
    }

    /// The largest distance a particle lies from its lattice site (the jitter), per axis.
    pub fn jitter(&self) -> f64 {
        self.lattice.jitter * self.lattice.spacing
    }
}

/// `build`'s checks of the lattice; its keys.
pub(super) fn check_lattice(lattice: &Lattice) -> Result<Keys, GeometryError> {
    let (s, o) = (lattice.spacing, lattice.origin);
    if !(s.is_finite() && s > 0.0 && all_finite(&o)) {
        return Err(scene_err(format!(
            "lattice spacing must be finite and > 0, origin finite (got spacing {s}, origin {o:?})"
        )));
    }
    if !(0.0..0.5).contains(&lattice.jitter) {
        return Err(scene_err(format!(
            "lattice jitter must be in [0, 0.5) spacings (got {})",
            lattice.jitter
        )));
    }
    Ok(Keys::of(lattice))
}

/// `build`'s checks of each entry; the key ranges covering every `Add`.
fn add_range(keys: &Keys, ops: &[Op]) -> Result<[(i64, i64); 3], GeometryError> {
    let mut range = [(i64::MAX, i64::MIN); 3];
    for (n, op) in ops.iter().enumerate() {
        let (Op::Add { shape, .. } | Op::Subtract { shape }) = op;
        let kind = shape.kind();
        let err = |m: &str| GeometryError {
            entry: Some(n),
            message: format!("geometry entry {n} ({kind}){m}"),
            ..Default::default()
        };
        shape.validate().map_err(|m| err(&format!(": {m}")))?;
        let Op::Add { .. } = op else { continue };
        let (lo, hi) = shape.bounds();
        if !all_finite(&[lo, hi].concat()) {
            return Err(err(&format!(
                " cannot be added: {kind} is unbounded; use it in regions or Subtract only"
            )));
        }
        let r = keys.around(lo, hi);
        if r.iter().map(|(a, b)| b - a + 1.0).product::<f64>() > u32::MAX as f64 {
            return Err(err(" spans more than u32::MAX lattice sites"));
        }
        for e in 0..3 {
            range[e].0 = range[e].0.min(r[e].0 as i64);
            range[e].1 = range[e].1.max(r[e].1 as i64);
        }
    }
    if range[0].0 > range[0].1 {
        // No `Add`: an empty lattice (bars only, or nothing).
        range = [(0, -1); 3];
    }
    Ok(range)
}
