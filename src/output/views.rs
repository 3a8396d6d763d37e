//! The pictures of a body's particles (`picture.png`, the validation and analysis pictures):
//! a side view (along +y, the x–z plane) above an oblique 3D view from the front, left and
//! above, each particle a square of its lattice spacing, the nearest particle showing at each
//! pixel, as in the thesis's figures.
//!
//! Pictures are rasterized with a depth per pixel rather than painted far to near, so that
//! each procCube draws its own particles ([`raster`]) into the frame of the whole body (its
//! [`extent`], a min-reduction) and the root composites the pieces ([`composite`]: the
//! nearest wins, equal depths the larger id) without gathering the scene. The result does not
//! depend on the layout beyond the round-off in the positions.

use super::plot::{damage_colour, draw_colour_bar, register_font};
use plotters::prelude::*;
use std::path::Path;

const WIDTH: u32 = 1200;
const HEIGHT: u32 = 960;
/// Rows of the title, above the views.
const TITLE_ROWS: u32 = 40;
/// Rows of the side view; the oblique view has the rest.
const SIDE_ROWS: u32 = 330;
/// Pixels left free around a view's body.
const MARGIN: f64 = 30.0;

/// Screen right, screen up, and depth (away from the viewer) of a view.
type Basis = ([f64; 3], [f64; 3], [f64; 3]);

/// The two views: basis, first pixel row and rows of each.
fn views() -> [(Basis, u32, u32); 2] {
    // Side: screen right = +x, up = +z, depth = +y (the y = min face is nearest).
    let side = ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
    // Oblique: the camera looks along v from the front (−y), left (−x) and above (+z).
    let (az, el) = (30f64.to_radians(), 22f64.to_radians());
    let v = [az.sin() * el.cos(), az.cos() * el.cos(), -el.sin()];
    let right = normalise(cross(v, [0.0, 0.0, 1.0]));
    let up = cross(right, v);
    let below = TITLE_ROWS + SIDE_ROWS;
    [
        (side, TITLE_ROWS, SIDE_ROWS),
        ((right, up, v), below, HEIGHT - below),
    ]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalise(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|c| c / l)
}

fn dot(a: [f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The extent of particles at `points` on each view's screen, as values whose minimum over
/// several sets is the extent of their union: per view, min right, −max right, min up, −max
/// up (+∞ for no particles).
pub fn extent(points: &[[f64; 3]]) -> [f64; 8] {
    let mut e = [f64::INFINITY; 8];
    for (v, (basis, _, _)) in views().iter().enumerate() {
        for p in points {
            let (x, y) = (dot(basis.0, p), dot(basis.1, p));
            if x.is_finite() && y.is_finite() {
                e[4 * v] = e[4 * v].min(x);
                e[4 * v + 1] = e[4 * v + 1].min(-x);
                e[4 * v + 2] = e[4 * v + 2].min(y);
                e[4 * v + 3] = e[4 * v + 3].min(-y);
            }
        }
    }
    e
}

/// One covered pixel of a picture: where (row-major in the whole image), how deep, whose
/// particle, in what colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pixel {
    pub at: u32,
    pub depth: f64,
    pub id: u32,
    pub rgb: [u8; 3],
}

impl Pixel {
    const NONE: Pixel = Pixel {
        at: u32::MAX,
        depth: f64::INFINITY,
        id: 0,
        rgb: [255; 3],
    };

    /// Whether this pixel hides `other`: nearer, or as near with the larger id.
    fn hides(&self, other: &Pixel) -> bool {
        self.depth < other.depth || (self.depth == other.depth && self.id > other.id)
    }

    /// Bytes for a gather: at, id, rgb, and the depth's bits.
    pub fn to_bytes(pixels: &[Pixel]) -> Vec<u8> {
        let mut b = Vec::with_capacity(pixels.len() * 19);
        for p in pixels {
            b.extend_from_slice(&p.at.to_le_bytes());
            b.extend_from_slice(&p.id.to_le_bytes());
            b.extend_from_slice(&p.rgb);
            b.extend_from_slice(&p.depth.to_le_bytes());
        }
        b
    }

    /// Pixels from [`Pixel::to_bytes`].
    pub fn from_bytes(b: &[u8]) -> impl Iterator<Item = Pixel> + '_ {
        b.chunks_exact(19).map(|c| {
            let word = |k: usize| u32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            let mut depth = [0; 8];
            depth.copy_from_slice(&c[11..19]);
            Pixel {
                at: word(0),
                id: word(4),
                rgb: [c[8], c[9], c[10]],
                depth: f64::from_le_bytes(depth),
            }
        })
    }
}

/// The pixels that particles at `points` (with their `ids` and colour `values` in 0..1)
/// cover, the nearest at each, in the frame of a body of extent `extent` drawn with squares of
/// `spacing`. An error if the body has no extent to draw.
pub fn raster(
    points: &[[f64; 3]],
    ids: &[u32],
    values: &[f64],
    spacing: f64,
    extent: &[f64; 8],
) -> Result<Vec<Pixel>, String> {
    let mut image = vec![Pixel::NONE; (WIDTH * HEIGHT) as usize];
    let half = 0.5 * spacing;
    let w = WIDTH as f64;
    for (v, (basis, top, rows)) in views().iter().enumerate() {
        let e = &extent[4 * v..4 * v + 4];
        let (x0, x1, y0, y1) = (e[0], -e[1], e[2], -e[3]);
        let h = *rows as f64;
        let scale = ((w - 2.0 * MARGIN) / (x1 - x0 + 2.0 * half))
            .min((h - 2.0 * MARGIN) / (y1 - y0 + 2.0 * half));
        if !(scale.is_finite() && scale > 0.0) {
            return Err("the body has no extent to draw".into());
        }
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let px = |x: f64, y: f64| {
            (
                (0.5 * w + (x - cx) * scale).round() as i64,
                (0.5 * h - (y - cy) * scale).round() as i64,
            )
        };
        // Half a pixel more than the particle's cube, so that rounding leaves no gaps.
        let r = (half * scale + 0.5) / scale;
        for (k, p) in points.iter().enumerate() {
            let (x, y, depth) = (dot(basis.0, p), dot(basis.1, p), dot(basis.2, p));
            if !(x.is_finite() && y.is_finite()) {
                continue;
            }
            let (a, b) = (px(x - r, y + r), px(x + r, y - r));
            let b = (b.0.max(a.0 + 1), b.1.max(a.1 + 1));
            let c = damage_colour(values[k]);
            let mine = Pixel {
                at: 0,
                depth,
                id: ids[k],
                rgb: [c.0, c.1, c.2],
            };
            for row in a.1.max(0)..b.1.min(*rows as i64) {
                for col in a.0.max(0)..b.0.min(WIDTH as i64) {
                    let at = (*top as i64 + row) as u32 * WIDTH + col as u32;
                    let slot = &mut image[at as usize];
                    if mine.hides(slot) {
                        *slot = Pixel { at, ..mine };
                    }
                }
            }
        }
    }
    Ok(image.into_iter().filter(|p| p.at != u32::MAX).collect())
}

/// The pieces' pixels as one picture, the nearest at each pixel.
pub fn composite(pieces: impl IntoIterator<Item = Pixel>) -> Vec<Pixel> {
    let mut image = vec![Pixel::NONE; (WIDTH * HEIGHT) as usize];
    for p in pieces {
        let slot = &mut image[p.at as usize];
        if p.hides(slot) {
            *slot = p;
        }
    }
    image
}

/// Writes the composited `image` to `path` (PNG, 1200 × 960) with its `title`, the views'
/// labels and a colour bar whose ends say `scale`.
pub fn draw(path: &Path, title: &str, image: &[Pixel], scale: &[String; 2]) -> Result<(), String> {
    register_font();
    let err = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    let root = BitMapBackend::new(path, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    for p in image.iter().filter(|p| p.at != u32::MAX) {
        let (x, y) = ((p.at % WIDTH) as i32, (p.at / WIDTH) as i32);
        root.draw_pixel((x, y), &RGBColor(p.rgb[0], p.rgb[1], p.rgb[2]))
            .map_err(|e| err(&e))?;
    }
    let text = |s: &str, at: (i32, i32), size: u32| {
        root.draw(&Text::new(
            s.to_string(),
            at,
            ("sans-serif", size).into_font(),
        ))
        .map_err(|e| err(&e))
    };
    text(title, (14, 10), 20)?;
    let [(_, side, _), (_, oblique, _)] = views();
    text("side view (x right, z up)", (14, side as i32 + 6), 16)?;
    text(
        "3D view from the front, left and above",
        (14, oblique as i32 + 6),
        16,
    )?;
    let (_, lower) = root.split_vertically(oblique);
    draw_colour_bar(&lower, scale).map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
