//! PNG plots of validation results: measured points against a reference curve. The font is
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

fn register_font() {
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
