//! PNG plots: measured points against a reference curve, and pictures of a body's particles
//! (a side and a 3D view) coloured by damage, material, speed or height. The font is
//! DejaVu Sans compiled in, so no system fonts are needed.

use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// How a series is drawn.
pub enum Mark {
    /// Small filled circles (PDQ's particles or measurements).
    Points,
    /// A line (the reference formula).
    Line,
}

pub struct Series<'a> {
    pub name: &'a str,
    pub points: &'a [(f64, f64)],
    pub mark: Mark,
}

pub(crate) fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // DejaVu Sans is a valid font: registration cannot fail on it.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Writes an x–y plot of `series` to `path` (PNG, 900 × 560).
pub fn xy(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), String> {
    register_font();
    let err = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    let all = series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        if x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 > x1 {
        return Err(format!("plot {}: nothing to draw", path.display()));
    }
    let pad = |a: f64, b: f64| {
        let d = (b - a).abs().max(1e-300) * 0.05;
        (a - d, b + d)
    };
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|e| err(&e))?;
    let colours = [BLUE, RED, BLACK, GREEN];
    for (k, s) in series.iter().enumerate() {
        let colour = colours[k % colours.len()];
        match s.mark {
            Mark::Points => chart
                .draw_series(s.points.iter().map(|&p| Circle::new(p, 2, colour.filled())))
                .map_err(|e| err(&e))?
                .label(s.name)
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled())),
            Mark::Line => chart
                .draw_series(LineSeries::new(
                    s.points.iter().copied(),
                    colour.stroke_width(2),
                ))
                .map_err(|e| err(&e))?
                .label(s.name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                }),
        };
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// The particles of one frame, for [`particle_views`].
pub struct Body<'a> {
    /// Reference positions.
    pub x0: &'a [[f64; 3]],
    pub displacement: &'a [[f64; 3]],
    /// What each particle is coloured by, scaled to 0..1 (damage as it is).
    pub value: &'a [f64],
    /// Lattice spacing: each particle is drawn as a square of this size.
    pub spacing: f64,
    /// The words at the two ends of the colour bar (value 0 and 1).
    pub scale: [String; 2],
}

/// The colour bar's ends for damage.
pub fn damage_scale() -> [String; 2] {
    ["damage 0".into(), "1".into()]
}

/// 0 (blue) through yellow to 1 (dark red): for damage the thesis's figures' reading, cracks
/// standing out against an intact body.
pub(crate) fn damage_colour(d: f64) -> RGBColor {
    let stops: [(f64, [f64; 3]); 5] = [
        (0.0, [40.0, 70.0, 160.0]),
        (0.15, [70.0, 160.0, 200.0]),
        (0.35, [250.0, 220.0, 60.0]),
        (0.6, [235.0, 110.0, 30.0]),
        (1.0, [140.0, 10.0, 10.0]),
    ];
    let d = if d.is_finite() {
        d.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let k = stops.iter().position(|s| s.0 >= d).unwrap_or(4).max(1);
    let ((a, ca), (b, cb)) = (stops[k - 1], stops[k]);
    let t = ((d - a) / (b - a)).clamp(0.0, 1.0);
    let c = |i: usize| (ca[i] + t * (cb[i] - ca[i])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// Writes the deformed body coloured by its values (damage, or what [`Body::scale`] names) to
/// `path` (PNG, 1200 × 960): a side view (along +y, the x–z plane) above an oblique 3D view
/// from the front, left and above ([`super::views`]). Displacements are drawn `magnify` times;
/// what shows is the body's visible surface, as in the thesis's figures.
pub fn particle_views(path: &Path, title: &str, body: &Body, magnify: f64) -> Result<(), String> {
    let n = body.x0.len();
    if n == 0 || body.displacement.len() != n || body.value.len() != n {
        return Err(format!("plot {}: no particles to draw", path.display()));
    }
    let deformed: Vec<[f64; 3]> = body
        .x0
        .iter()
        .zip(body.displacement)
        .map(|(x, u)| [0, 1, 2].map(|k| x[k] + magnify * u[k]))
        .collect();
    let ids: Vec<u32> = (0..n as u32).collect();
    let extent = super::views::extent(&deformed);
    let pixels = super::views::raster(&deformed, &ids, body.value, body.spacing, &extent)
        .map_err(|e| format!("plot {}: {e}", path.display()))?;
    super::views::draw(path, title, &super::views::composite(pixels), &body.scale)
}

pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// A horizontal colour scale in the lower right corner of `area`, `ends` written at its ends.
pub(crate) fn draw_colour_bar(
    area: &Area,
    ends: &[String; 2],
) -> Result<(), Box<dyn std::error::Error>> {
    let (w, h) = area.dim_in_pixel();
    let (x0, y0, len) = (w as i32 - 330, h as i32 - 40, 240);
    for k in 0..len {
        let d = k as f64 / (len - 1) as f64;
        area.draw(&Rectangle::new(
            [(x0 + k, y0), (x0 + k + 1, y0 + 14)],
            damage_colour(d).filled(),
        ))?;
    }
    let font = ("sans-serif", 14).into_font();
    // About 7 pixels a character at this size: the left end's words end at the bar.
    let left = x0 - 6 - 7 * ends[0].chars().count() as i32;
    area.draw(&Text::new(ends[0].clone(), (left.max(4), y0), font.clone()))?;
    area.draw(&Text::new(ends[1].clone(), (x0 + len + 6, y0), font))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixels(path: &Path) -> (u32, Vec<u8>) {
        let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        (info.width, buf)
    }

    /// Two particles one behind the other along y: the side view shows the near one (y = 0,
    /// intact), not the far one (broken), wherever they are painted; a third, alone, shows its
    /// damage colour.
    #[test]
    fn the_side_view_shows_the_near_face() {
        let path = std::env::temp_dir().join(format!("pdq-views-{}.png", std::process::id()));
        let x0 = [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [4.0, 0.0, 0.0]];
        let body = Body {
            x0: &x0,
            displacement: &[[0.0; 3]; 3],
            value: &[1.0, 0.0, 0.5],
            spacing: 1.0,
            scale: damage_scale(),
        };
        particle_views(&path, "test", &body, 1.0).unwrap();
        let (width, rgb) = pixels(&path);
        let count = |c: RGBColor| {
            rgb.chunks_exact(3)
                .take(width as usize * 370) // the title and the side view
                .filter(|p| p[0] == c.0 && p[1] == c.1 && p[2] == c.2)
                .count()
        };
        let (intact, broken, half) = (damage_colour(0.0), damage_colour(1.0), damage_colour(0.5));
        assert!(count(intact) > 1000, "the near particle is drawn");
        assert!(count(half) > 1000, "the lone particle is drawn");
        assert_eq!(count(broken), 0, "the far particle is hidden");
        let _ = std::fs::remove_file(path);
    }
}
