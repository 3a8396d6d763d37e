//! `pdq plot`: one column against another, from one or more runs' `history.csv` (or any CSV
//! with a header, such as `final_positions.csv`), as a PNG: lines (the cyclic bar with and
//! without contact) or points (the channel's velocity profile, docs/examples.md).

use super::plot::{xy, Mark, Series};
use std::path::{Path, PathBuf};

/// A history file's columns by name.
pub struct Columns {
    pub names: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Columns {
    pub fn read(path: &Path) -> Result<Columns, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("reading {}: {e}", path.display()))?;
        let mut lines = text.lines();
        let names: Vec<String> = lines
            .next()
            .ok_or_else(|| format!("{}: empty file", path.display()))?
            .split(',')
            .map(str::to_string)
            .collect();
        let mut rows = Vec::new();
        for (k, line) in lines.enumerate() {
            let row: Vec<f64> = line
                .split(',')
                .map(|v| v.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|e| format!("{}:{}: {e}", path.display(), k + 2))?;
            if row.len() != names.len() {
                return Err(format!(
                    "{}:{}: {} values for {} columns",
                    path.display(),
                    k + 2,
                    row.len(),
                    names.len()
                ));
            }
            rows.push(row);
        }
        Ok(Columns { names, rows })
    }

    /// The column called `name`, scaled by `factor`; the error lists the columns there are.
    pub fn column(&self, name: &str, factor: f64, path: &Path) -> Result<Vec<f64>, String> {
        let k = self.names.iter().position(|n| n == name).ok_or_else(|| {
            format!(
                "{} has no column '{name}' (it has {})",
                path.display(),
                self.names.join(", ")
            )
        })?;
        Ok(self.rows.iter().map(|r| factor * r[k]).collect())
    }
}

/// What `pdq plot` draws.
pub struct CurvePlot {
    pub files: Vec<PathBuf>,
    pub x: String,
    pub y: String,
    /// Factors on x and y (units of the axes' labels).
    pub scale: [f64; 2],
    /// One name per file in the legend (default: the file's directory).
    pub labels: Vec<String>,
    pub title: String,
    pub output: PathBuf,
    /// Draw each row as a point instead of joining rows by lines.
    pub points: bool,
}

/// Draws `y` against `x` from every file, one line each.
pub fn plot_curves(p: &CurvePlot) -> Result<(), String> {
    if p.files.is_empty() {
        return Err("pdq plot: give at least one history.csv".into());
    }
    if !p.labels.is_empty() && p.labels.len() != p.files.len() {
        return Err(format!(
            "pdq plot: {} labels for {} files",
            p.labels.len(),
            p.files.len()
        ));
    }
    let mut curves = Vec::new();
    for (k, f) in p.files.iter().enumerate() {
        let c = Columns::read(f)?;
        let (x, y) = (
            c.column(&p.x, p.scale[0], f)?,
            c.column(&p.y, p.scale[1], f)?,
        );
        let label = p.labels.get(k).cloned().unwrap_or_else(|| {
            f.parent()
                .and_then(|d| d.file_name())
                .map_or_else(|| f.display().to_string(), |d| d.to_string_lossy().into())
        });
        curves.push((label, x.into_iter().zip(y).collect::<Vec<_>>()));
    }
    let series: Vec<Series> = curves
        .iter()
        .map(|(name, points)| Series {
            name,
            points,
            mark: if p.points { Mark::Points } else { Mark::Line },
        })
        .collect();
    xy(&p.output, &p.title, &p.x, &p.y, &series)
}
