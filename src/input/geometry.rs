//! Reference particle cloud of a scene: shapes filled on a simple-cubic, face-centred or
//! body-centred cubic lattice, plus bars.
//!
//! Overlap and boundary rules (user-visible, keep the docs in sync):
//! - Simple cubic: sites sit at cell centres (`origin + spacing·(i + ½)`), so a face on a
//!   lattice plane never touches a site and a box `[0, L]` holds exactly `L / spacing` sites per
//!   axis.
//! - fcc and bcc: sites sit at `origin + a·(i + b)` for the basis offsets b (fcc (0,0,0),
//!   (½,½,0), (½,0,½), (0,½,½); bcc (0,0,0), (½,½,½)), as in LAMMPS, so they lie on the lattice
//!   planes. A box fills them half-open, `min <= p < max` per axis, like LAMMPS's
//!   `create_atoms` in a block: a box of n whole cells holds n³·basis sites, and such boxes
//!   tile, side by side and across a periodic boundary. Other shapes stay closed.
//! - Box, Cylinder, Sphere and Prism are closed (a point on the surface is inside); Slab is
//!   half-open `from <= p < to`. `build` widens every test by `1e-9·spacing` (Slab: shifts both
//!   ends down by it) so a site lying on a face up to rounding gets the same answer however its
//!   coordinate rounded.
//! - Ops run in order on a map of filled sites: Add (re)fills with its material (later wins),
//!   Subtract empties; a later Add refills subtracted sites.
//! - Bars come last; a filled site closer than ¼ of the lattice spacing to a bar particle is
//!   removed because it would coincide with that particle.

use std::collections::BTreeMap;
use std::fmt;

pub type Vec3 = [f64; 3];

const AXES: [&str; 3] = ["x", "y", "z"];

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn normalize(a: Vec3) -> Vec3 {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}
fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Box {
        min: Vec3,
        max: Vec3,
    },
    /// Axis from `base` along `axis` (any direction, normalized internally) for `length`.
    Cylinder {
        base: Vec3,
        axis: Vec3,
        length: f64,
        radius: f64,
    },
    Sphere {
        center: Vec3,
        radius: f64,
    },
    /// Polygon in the plane normal to coordinate axis `axis` (0=x,1=y,2=z), extruded from `from` to `to` along it.
    /// Vertices are (a, b) in the cyclic pair of the other axes: axis x -> (y, z), y -> (z, x), z -> (x, y). Either orientation; need not be convex (even-odd / crossing-number test).
    Prism {
        axis: usize,
        polygon: Vec<[f64; 2]>,
        from: f64,
        to: f64,
    },
    /// Half-open slab a <= p[axis] < b — handy for regions.
    Slab {
        axis: usize,
        from: f64,
        to: f64,
    },
}

/// Cyclic pair so that (u, v, axis) is right-handed and polygon orientation is stable per axis.
fn plane_axes(axis: usize) -> (usize, usize) {
    ((axis + 1) % 3, (axis + 2) % 3)
}

fn seg_dist2(q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (ex, ey) = (q[0] - a[0] - t * dx, q[1] - a[1] - t * dy);
    ex * ex + ey * ey
}

/// Even-odd rule, made closed by treating points within `tol` of an edge as inside.
fn in_polygon(poly: &[[f64; 2]], q: [f64; 2], tol: f64) -> bool {
    let mut inside = false;
    for (n, &a) in poly.iter().enumerate() {
        let b = poly[(n + 1) % poly.len()];
        if seg_dist2(q, a, b) <= tol * tol {
            return true;
        }
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if q[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

fn polygon_area(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

impl Shape {
    /// Exact test (no tolerance); see the module doc for which boundaries are inside.
    pub fn contains(&self, p: Vec3) -> bool {
        self.contains_tol(p, 0.0)
    }

    /// How `build` fills lattice sites: boxes half-open (`min <= p < max`) on fcc and bcc
    /// lattices, whose sites lie on the planes box faces are usually put on; otherwise
    /// `contains_tol`.
    fn fills(&self, p: Vec3, tol: f64, half_open: bool) -> bool {
        match self {
            Shape::Box { min, max } if half_open => {
                (0..3).all(|e| p[e] >= min[e] - tol && p[e] < max[e] - tol)
            }
            _ => self.contains_tol(p, tol),
        }
    }

    fn contains_tol(&self, p: Vec3, tol: f64) -> bool {
        match self {
            Shape::Box { min, max } => (0..3).all(|e| p[e] >= min[e] - tol && p[e] <= max[e] + tol),
            Shape::Cylinder {
                base,
                axis,
                length,
                radius,
            } => {
                let d = sub(p, *base);
                let t = dot(d, normalize(*axis));
                let r = radius + tol;
                t >= -tol && t <= length + tol && dot(d, d) - t * t <= r * r
            }
            Shape::Sphere { center, radius } => {
                let d = sub(p, *center);
                dot(d, d) <= (radius + tol) * (radius + tol)
            }
            Shape::Prism {
                axis,
                polygon,
                from,
                to,
            } => {
                let (u, v) = plane_axes(*axis);
                *axis < 3
                    && p[*axis] >= from - tol
                    && p[*axis] <= to + tol
                    && in_polygon(polygon, [p[u], p[v]], tol)
            }
            Shape::Slab { axis, from, to } => {
                *axis < 3 && p[*axis] >= from - tol && p[*axis] < to - tol
            }
        }
    }

    /// Axis-aligned bounding box (may be infinite for Slab in the free axes).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let inf = f64::INFINITY;
        match self {
            Shape::Box { min, max } => (*min, *max),
            Shape::Cylinder {
                base,
                axis,
                length,
                radius,
            } => {
                let a = normalize(*axis);
                let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
                for e in 0..3 {
                    let end = base[e] + length * a[e];
                    let r = radius * (1.0 - a[e] * a[e]).max(0.0).sqrt();
                    lo[e] = base[e].min(end) - r;
                    hi[e] = base[e].max(end) + r;
                }
                (lo, hi)
            }
            Shape::Sphere { center, radius } => (
                [center[0] - radius, center[1] - radius, center[2] - radius],
                [center[0] + radius, center[1] + radius, center[2] + radius],
            ),
            Shape::Prism {
                axis,
                polygon,
                from,
                to,
            } if *axis < 3 => {
                let (u, v) = plane_axes(*axis);
                let (mut lo, mut hi) = ([inf; 3], [-inf; 3]);
                for q in polygon {
                    lo[u] = lo[u].min(q[0]);
                    hi[u] = hi[u].max(q[0]);
                    lo[v] = lo[v].min(q[1]);
                    hi[v] = hi[v].max(q[1]);
                }
                lo[*axis] = *from;
                hi[*axis] = *to;
                (lo, hi)
            }
            Shape::Slab { axis, from, to } if *axis < 3 => {
                let (mut lo, mut hi) = ([-inf; 3], [inf; 3]);
                lo[*axis] = *from;
                hi[*axis] = *to;
                (lo, hi)
            }
            _ => ([-inf; 3], [inf; 3]),
        }
    }

    /// Checks the shape is well formed: finite numbers, min < max, radius > 0, length > 0, polygon >= 3 vertices with nonzero area, axis < 3, from < to. Error text says what is wrong, e.g. "cylinder radius must be > 0 (got -1)".
    pub fn validate(&self) -> Result<(), String> {
        let kind = self.kind();
        let pos = |what: &str, x: f64| (x > 0.0, format!("{kind} {what} must be > 0 (got {x})"));
        let axis_ok = |a: usize| (a < 3, format!("{kind} axis must be 0, 1 or 2 (got {a})"));
        let range = |f: f64, t: f64| (f < t, format!("{kind} from must be < to (got {f} >= {t})"));
        let (numbers, checks): (Vec<f64>, Vec<(bool, String)>) = match self {
            Shape::Box { min, max } => {
                let order = |e: usize| (min[e], max[e], AXES[e]);
                let msg = |(a, b, x)| format!("box min must be < max in {x} (got {a} >= {b})");
                let checks = (0..3).map(|e| (min[e] < max[e], msg(order(e))));
                ([*min, *max].concat(), checks.collect())
            }
            Shape::Cylinder {
                base,
                axis,
                length,
                radius,
            } => {
                let dir = (
                    dot(*axis, *axis) > 0.0,
                    "cylinder axis must be nonzero".into(),
                );
                let numbers = [&base[..], axis, &[*length, *radius]].concat();
                (
                    numbers,
                    vec![dir, pos("length", *length), pos("radius", *radius)],
                )
            }
            Shape::Sphere { center, radius } => (
                [&center[..], &[*radius]].concat(),
                vec![pos("radius", *radius)],
            ),
            Shape::Prism {
                axis,
                polygon,
                from,
                to,
            } => {
                let ((lo, hi), (u, v)) = (self.bounds(), plane_axes(*axis));
                let scale = (hi[u] - lo[u]).max(hi[v] - lo[v]);
                let area = polygon_area(polygon).abs() > 1e-12 * scale * scale;
                let n = polygon.len();
                let count = format!("prism polygon needs at least 3 vertices (got {n})");
                let checks = vec![
                    axis_ok(*axis),
                    range(*from, *to),
                    (n >= 3, count),
                    (area, "prism polygon has zero area".into()),
                ];
                ([&polygon.concat()[..], &[*from, *to]].concat(), checks)
            }
            Shape::Slab { axis, from, to } => {
                (vec![*from, *to], vec![axis_ok(*axis), range(*from, *to)])
            }
        };
        if !all_finite(&numbers) {
            return Err(format!("{kind} has a non-finite number: {self:?}"));
        }
        checks
            .into_iter()
            .find(|c| !c.0)
            .map_or(Ok(()), |c| Err(c.1))
    }

    fn kind(&self) -> &'static str {
        match self {
            Shape::Box { .. } => "box",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Sphere { .. } => "sphere",
            Shape::Prism { .. } => "prism",
            Shape::Slab { .. } => "slab",
        }
    }
}

/// The cubic lattices a scene can be filled on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LatticeKind {
    /// One site per cell, at its centre.
    #[default]
    Sc,
    /// Face-centred cubic: four sites per cell, nearest neighbours a/√2 apart (12 of them).
    Fcc,
    /// Body-centred cubic: two sites per cell, nearest neighbours a√3/2 apart (8 of them).
    Bcc,
}

impl LatticeKind {
    /// The deck's word for it.
    pub fn name(&self) -> &'static str {
        match self {
            LatticeKind::Sc => "sc",
            LatticeKind::Fcc => "fcc",
            LatticeKind::Bcc => "bcc",
        }
    }

    /// Sites per cubic cell.
    pub fn basis(&self) -> usize {
        match self {
            LatticeKind::Sc => 1,
            LatticeKind::Fcc => 4,
            LatticeKind::Bcc => 2,
        }
    }

    /// The cubic cell side a of `density` sites per unit volume: a³ = basis / density.
    pub fn cell_side(&self, density: f64) -> f64 {
        (self.basis() as f64 / density).cbrt()
    }

    /// Whether a key is a site. fcc and bcc keys count half cells (the basis offsets are
    /// halves): fcc sites are the keys with an even sum, bcc those with three even or three odd
    /// indices.
    fn admits(&self, key: &Key) -> bool {
        match self {
            LatticeKind::Sc => true,
            LatticeKind::Fcc => (key[0] + key[1] + key[2]).rem_euclid(2) == 0,
            LatticeKind::Bcc => {
                key[0].rem_euclid(2) == key[1].rem_euclid(2)
                    && key[1].rem_euclid(2) == key[2].rem_euclid(2)
            }
        }
    }
}

/// A cubic lattice of cell side `spacing` (a). Simple cubic: sites at origin + spacing·(i + ½, j + ½, k + ½) for integers i, j, k, so a box [0, 200] with spacing 1 holds exactly 200 sites along that axis (site = centre of a cube of side `spacing`, volume spacing³) and box faces never cut through sites. fcc and bcc: sites at origin + spacing·(i + b) for each basis offset b, volume spacing³ / basis each (see the module doc for how a box fills them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    pub kind: LatticeKind,
    /// The cubic cell side a (for sc the distance between neighbours); horizons given as
    /// `m` spacings are m·a whatever the kind.
    pub spacing: f64,
    pub origin: Vec3,
    /// Each lattice site is moved by a random offset of up to `jitter × spacing` per axis
    /// (0: a regular lattice). Shapes select sites by their regular positions.
    pub jitter: f64,
    /// Seed of the offsets: the same seed gives the same scene, whatever the layout.
    pub seed: u64,
}

impl Lattice {
    pub fn regular(spacing: f64, origin: Vec3) -> Self {
        Lattice {
            kind: LatticeKind::Sc,
            spacing,
            origin,
            jitter: 0.0,
            seed: 0,
        }
    }

    /// The volume of each lattice particle: a³ / basis.
    pub fn site_volume(&self) -> f64 {
        let s = self.spacing;
        s * s * s / self.kind.basis() as f64
    }

    /// The offset of site `key`: uniform in [−jitter·spacing, jitter·spacing) per axis, a
    /// function of the seed and the site's integer index only (SplitMix64).
    fn offset(&self, key: &Key) -> Vec3 {
        if self.jitter == 0.0 {
            return [0.0; 3];
        }
        let mut h = self.seed ^ 0x9E37_79B9_7F4A_7C15;
        for k in key {
            h = crate::engine::random::splitmix64(h ^ (*k as u64));
        }
        [0, 1, 2].map(|e| {
            let u = (crate::engine::random::splitmix64(h.wrapping_add(e as u64)) >> 11) as f64
                / (1u64 << 53) as f64;
            (2.0 * u - 1.0) * self.jitter * self.spacing
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Op {
    /// Fill every lattice site inside the shape with `material`; a site already filled takes the new material (later entries win).
    Add { shape: Shape, material: u16 },
    /// Remove every filled lattice site inside the shape (sites added by later Add entries come back).
    Subtract { shape: Shape },
}

/// A line of particles from `from` to `to`: n = max(1, round(len / spacing)) particles at from + (k + ½)·(to − from)/n, each of volume area·len/n.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    pub from: Vec3,
    pub to: Vec3,
    pub area: f64,
    pub spacing: f64,
    pub material: u16,
}

impl Bar {
    /// A bar starting at `from` in direction `dir` (normalized internally) for `length`.
    /// A zero `dir` yields non-finite end points, which `build` reports.
    pub fn along(
        from: Vec3,
        dir: Vec3,
        length: f64,
        area: f64,
        spacing: f64,
        material: u16,
    ) -> Bar {
        let d = normalize(dir);
        let to = [0, 1, 2].map(|e| from[e] + length * d[e]);
        Bar {
            from,
            to,
            area,
            spacing,
            material,
        }
    }

    /// Direction from two angles in degrees: `azimuth` measured in the x–y plane from +x toward +y, `elevation` from that plane toward +z.
    pub fn at_angle(
        from: Vec3,
        azimuth_deg: f64,
        elevation_deg: f64,
        length: f64,
        area: f64,
        spacing: f64,
        material: u16,
    ) -> Bar {
        let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let dir = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
        Bar::along(from, dir, length, area, spacing, material)
    }

    fn validate(&self) -> Result<(), String> {
        if !all_finite(&[self.from.as_slice(), self.to.as_slice()].concat()) {
            return Err(format!(
                "bar end points must be finite (got {:?} to {:?})",
                self.from, self.to
            ));
        }
        for (what, x) in [("area", self.area), ("spacing", self.spacing)] {
            if !(x.is_finite() && x > 0.0) {
                return Err(format!("bar {what} must be finite and > 0 (got {x})"));
            }
        }
        if self.from == self.to {
            return Err("bar has zero length (from == to)".into());
        }
        Ok(())
    }

    pub fn length(&self) -> f64 {
        let d = sub(self.to, self.from);
        dot(d, d).sqrt()
    }

    fn count(&self) -> f64 {
        (self.length() / self.spacing).round().max(1.0)
    }
}

/// The reference particle cloud, in a deterministic order: lattice particles first in (z, y, x) lexicographic order of their site index (x fastest), then bar particles in bar order. Global id = index.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Cloud {
    pub position: Vec<Vec3>,
    pub volume: Vec<f64>,
    pub material: Vec<u16>,
    /// Lattice spacing (or bar particle spacing) of each particle; for bar particles the
    /// realised spacing len/n. Reported for inspection: the engine's partial-volume factor uses
    /// the lattice spacing for every bond, bar bonds included.
    pub spacing: Vec<f64>,
    /// Index of the bar each particle belongs to, [`NOT_A_BAR`] for lattice particles.
    pub bar: Vec<u32>,
}

/// The bar index of a lattice particle.
pub const NOT_A_BAR: u32 = u32::MAX;

impl Cloud {
    pub fn len(&self) -> usize {
        self.position.len()
    }
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}

/// `message` is the complete user-facing text; `entry`/`bar` let callers point at the deck line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GeometryError {
    /// Index into ops (Some) or None for the whole scene.
    pub entry: Option<usize>,
    pub bar: Option<usize>,
    /// The scene came out empty: nothing was added, or every site was subtracted.
    pub empty: bool,
    pub message: String,
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for GeometryError {}

fn scene_err(message: String) -> GeometryError {
    GeometryError {
        message,
        ..Default::default()
    }
}

/// Site keys are [k, j, i] so BTreeMap order is the documented (z, y, x) order, x fastest.
type Key = [i64; 3];

/// How keys place a lattice's sites: keys count whole cells on the simple-cubic lattice (sites
/// at their centres) and half cells on fcc and bcc (sites on the planes), where `admits` picks
/// the sites.
struct Keys {
    origin: Vec3,
    /// Distance between keys, and the sites' offset from the keys in those steps.
    step: f64,
    shift: f64,
    /// Shapes select sites within this of their surface.
    tol: f64,
    /// fcc and bcc boxes leave out the sites on their upper faces.
    half_open: bool,
}

impl Keys {
    fn of(lattice: &Lattice) -> Keys {
        let s = lattice.spacing;
        let (step, shift) = match lattice.kind {
            LatticeKind::Sc => (s, 0.5),
            LatticeKind::Fcc | LatticeKind::Bcc => (0.5 * s, 0.0),
        };
        Keys {
            origin: lattice.origin,
            step,
            shift,
            tol: 1e-9 * s,
            half_open: lattice.kind != LatticeKind::Sc,
        }
    }

    fn site(&self, key: &Key) -> Vec3 {
        [0, 1, 2].map(|e| self.origin[e] + self.step * (key[2 - e] as f64 + self.shift))
    }

    /// Index ranges (padded by one) of the sites covering [lo, hi]; inside tests trim them.
    fn around(&self, lo: Vec3, hi: Vec3) -> [(f64, f64); 3] {
        let idx = |x: f64, e: usize| (x - self.origin[e]) / self.step - self.shift;
        [0, 1, 2].map(|e| (idx(lo[e], e).floor() - 1.0, idx(hi[e], e).ceil() + 1.0))
    }
}

/// Keys of all sites in inclusive index ranges given per axis (x, y, z).
fn sites(r: [(f64, f64); 3]) -> impl Iterator<Item = Key> {
    let r = r.map(|(a, b)| a as i64..=b as i64);
    let (rx, ry) = (r[0].clone(), r[1].clone());
    r[2].clone().flat_map(move |k| {
        let rx = rx.clone();
        ry.clone()
            .flat_map(move |j| rx.clone().map(move |i| [k, j, i]))
    })
}

/// Applies `ops` in order on the lattice, then adds the bars; see the module doc for the
/// overlap rules. Each Add visits only the sites in its shape's bounding box; bar/site overlap
/// is found by indexing the lattice around each bar particle, O(M log N) rather than O(N·M).
pub fn build(lattice: &Lattice, ops: &[Op], bars: &[Bar]) -> Result<Cloud, GeometryError> {
    let keys = scene_sites::check_lattice(lattice)?;
    let (s, tol, half_open, kind) = (lattice.spacing, keys.tol, keys.half_open, lattice.kind);
    let site = |key: &Key| keys.site(key);
    let range = |lo: Vec3, hi: Vec3| keys.around(lo, hi);
    let sites = |r| sites(r).filter(move |key| kind.admits(key));
    let mut filled: BTreeMap<Key, u16> = BTreeMap::new();
    for (n, op) in ops.iter().enumerate() {
        let (Op::Add { shape, .. } | Op::Subtract { shape }) = op;
        let kind = shape.kind();
        let err = |m: &str| GeometryError {
            entry: Some(n),
            message: format!("geometry entry {n} ({kind}){m}"),
            ..Default::default()
        };
        shape.validate().map_err(|m| err(&format!(": {m}")))?;
        let Op::Add { material, .. } = op else {
            filled.retain(|key, _| !shape.fills(site(key), tol, half_open));
            continue;
        };
        let (lo, hi) = shape.bounds();
        if !all_finite(&[lo, hi].concat()) {
            return Err(err(&format!(
                " cannot be added: {kind} is unbounded; use it in regions or Subtract only"
            )));
        }
        let r = range(lo, hi);
        if r.iter().map(|(a, b)| b - a + 1.0).product::<f64>() > u32::MAX as f64 {
            return Err(err(" spans more than u32::MAX lattice sites"));
        }
        let mut selected = 0usize;
        for key in sites(r).filter(|key| shape.fills(site(key), tol, half_open)) {
            filled.insert(key, *material);
            selected += 1;
        }
        if selected == 0 {
            return Err(err(
                " selects no lattice site: it is smaller than the spacing or outside",
            ));
        }
    }

    let mut total = filled.len() as f64;
    for (b, bar) in bars.iter().enumerate() {
        let message = |m| format!("bar {b}: {m}");
        let err = |m| GeometryError {
            bar: Some(b),
            message: message(m),
            ..Default::default()
        };
        bar.validate().map_err(err)?;
        total += bar.count();
    }
    if total > u32::MAX as f64 {
        return Err(scene_err(format!(
            "the scene has {total} particles, over u32::MAX"
        )));
    }
    let mut bar_particles = Vec::new();
    let rm = 0.25 * s;
    for (b, bar) in bars.iter().enumerate() {
        let n = bar.count();
        let (step, ds) = (sub(bar.to, bar.from).map(|d| d / n), bar.length() / n);
        for k in 0..n as usize {
            let p = [0, 1, 2].map(|e| bar.from[e] + (k as f64 + 0.5) * step[e]);
            for key in sites(range(p.map(|x| x - rm), p.map(|x| x + rm))) {
                let d = sub(site(&key), p);
                if dot(d, d) < rm * rm {
                    filled.remove(&key);
                }
            }
            bar_particles.push((p, bar.area * ds, bar.material, ds, b as u32));
        }
    }

    let mut cloud = Cloud::default();
    let lattice_particles = filled.iter().map(|(key, &m)| {
        let (p, d) = (site(key), lattice.offset(key));
        (
            [p[0] + d[0], p[1] + d[1], p[2] + d[2]],
            lattice.site_volume(),
            m,
            s,
            NOT_A_BAR,
        )
    });
    for (p, volume, material, spacing, bar) in lattice_particles.chain(bar_particles) {
        cloud.bar.push(bar);
        cloud.position.push(p);
        cloud.volume.push(volume);
        cloud.material.push(material);
        cloud.spacing.push(spacing);
    }
    if cloud.is_empty() {
        let m = "the scene has no particles: nothing was added, or every site was subtracted";
        return Err(GeometryError {
            empty: true,
            ..scene_err(m.into())
        });
    }
    Ok(cloud)
}

#[path = "geometry_count.rs"]
mod count;
pub use count::{count_particles, neighbours_within};
#[path = "geometry_sites.rs"]
mod scene_sites;
pub use scene_sites::{SceneSites, Site};

#[cfg(test)]
#[path = "geometry_tests.rs"]
mod tests;
