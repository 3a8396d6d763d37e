//! `[[geometry]]` and the shapes that select regions: boxes, cylinders, spheres, prisms and
//! slabs, added or subtracted in deck order.

use super::convert::{Converter, R};
use super::sections::{AxisSpec, ShapeSpec};
use super::spec::{Located, Region};
use crate::input::geometry::{Op, Shape};
use toml::Spanned;

impl Converter {
    /// The `[[geometry]]` entries in deck order, each with its line; `names` are the materials.
    pub(super) fn geometry(
        &self,
        entries: &[Spanned<ShapeSpec>],
        names: &[String],
    ) -> R<Vec<Located<Op>>> {
        let mut ops = Vec::new();
        for (k, g) in entries.iter().enumerate() {
            let line = self.line_of(g);
            let g = g.get_ref();
            let ctx = format!("geometry entry {k}");
            if g.ids.is_some() {
                return self.err(
                    line,
                    format!("{ctx}: 'ids' selects particles in regions, not in geometry"),
                );
            }
            let shape = self.shape(g, line, &ctx)?;
            let item = match g.op.as_deref().unwrap_or("add") {
                "add" => {
                    let Some(mat) = &g.material else {
                        return self.err(line, format!("{ctx}: an 'add' entry needs 'material'"));
                    };
                    Op::Add {
                        shape,
                        material: self.material_id(names, mat, line)?,
                    }
                }
                "subtract" => {
                    if g.material.is_some() {
                        return self
                            .err(line, format!("{ctx}: a 'subtract' entry takes no material"));
                    }
                    Op::Subtract { shape }
                }
                other => {
                    return self.err(
                        line,
                        format!("{ctx}: op must be \"add\" or \"subtract\", not \"{other}\""),
                    )
                }
            };
            ops.push(Located { item, line });
        }
        Ok(ops)
    }

    fn axis_index(&self, a: &Option<AxisSpec>, line: usize, ctx: &str) -> R<usize> {
        match a {
            Some(AxisSpec::Name(n)) => match n.as_str() {
                "x" => Ok(0),
                "y" => Ok(1),
                "z" => Ok(2),
                _ => self.err(line, format!("{ctx}: axis must be \"x\", \"y\" or \"z\" (got \"{n}\")")),
            },
            Some(AxisSpec::Direction(_)) => self.err(
                line,
                format!("{ctx}: this shape needs a coordinate axis \"x\", \"y\" or \"z\", not a direction"),
            ),
            None => self.err(line, format!("{ctx}: needs 'axis'")),
        }
    }

    fn shape(&self, g: &ShapeSpec, line: usize, ctx: &str) -> R<Shape> {
        let sys = self.sys;
        let Some(kind) = g.shape.as_deref() else {
            return self.err(
                line,
                format!("{ctx}: needs 'shape' (box, cylinder, sphere, prism or slab)"),
            );
        };
        let allowed: &[&str] = match kind {
            "box" => &["min", "max"],
            "cylinder" => &["base", "axis", "length", "radius"],
            "sphere" => &["center", "radius"],
            "prism" => &["axis", "polygon", "from", "to"],
            "slab" => &["axis", "from", "to"],
            other => {
                return self.err(
                    line,
                    format!(
                        "{ctx}: unknown shape '{other}' (box, cylinder, sphere, prism or slab)"
                    ),
                )
            }
        };
        let present = [
            ("min", g.min.is_some()),
            ("max", g.max.is_some()),
            ("base", g.base.is_some()),
            ("center", g.center.is_some()),
            ("axis", g.axis.is_some()),
            ("length", g.length.is_some()),
            ("radius", g.radius.is_some()),
            ("polygon", g.polygon.is_some()),
            ("from", g.from.is_some()),
            ("to", g.to.is_some()),
        ];
        for (key, is) in present {
            if is && !allowed.contains(&key) {
                return self.err(
                    line,
                    format!(
                        "{ctx}: a {kind} does not take '{key}' (it takes {})",
                        allowed.join(", ")
                    ),
                );
            }
            if !is && allowed.contains(&key) {
                return self.err(line, format!("{ctx}: a {kind} needs '{key}'"));
            }
        }
        let shape = match kind {
            "box" => Shape::Box {
                min: g.min.unwrap().value(sys),
                max: g.max.unwrap().value(sys),
            },
            "cylinder" => Shape::Cylinder {
                base: g.base.unwrap().value(sys),
                axis: match g.axis.clone().unwrap() {
                    AxisSpec::Direction(d) => d,
                    AxisSpec::Name(_) => {
                        let mut d = [0.0; 3];
                        d[self.axis_index(&g.axis, line, ctx)?] = 1.0;
                        d
                    }
                },
                length: g.length.unwrap().value(sys),
                radius: g.radius.unwrap().value(sys),
            },
            "sphere" => Shape::Sphere {
                center: g.center.unwrap().value(sys),
                radius: g.radius.unwrap().value(sys),
            },
            "prism" => Shape::Prism {
                axis: self.axis_index(&g.axis, line, ctx)?,
                polygon: g
                    .polygon
                    .as_ref()
                    .unwrap()
                    .iter()
                    .map(|[a, b]| [a.value(sys), b.value(sys)])
                    .collect(),
                from: g.from.unwrap().value(sys),
                to: g.to.unwrap().value(sys),
            },
            _ => Shape::Slab {
                axis: self.axis_index(&g.axis, line, ctx)?,
                from: g.from.unwrap().value(sys),
                to: g.to.unwrap().value(sys),
            },
        };
        shape
            .validate()
            .or_else(|e| self.err(line, format!("{ctx} ({kind}): {e}")))?;
        Ok(shape)
    }

    pub(super) fn region(&self, r: &ShapeSpec, line: usize, ctx: &str) -> R<Region> {
        let ctx = format!("{ctx}: region");
        if r.op.is_some() || r.material.is_some() {
            return self.err(
                line,
                format!("{ctx}: 'op' and 'material' belong to geometry entries"),
            );
        }
        if let Some(ids) = &r.ids {
            if r.shape.is_some() {
                return self.err(line, format!("{ctx}: give 'ids' or 'shape', not both"));
            }
            if ids.is_empty() {
                return self.err(line, format!("{ctx}: 'ids' is empty"));
            }
            return Ok(Region::Ids(ids.clone()));
        }
        if r.shape.as_deref() == Some("all") {
            let extra = [
                r.min.is_some(),
                r.max.is_some(),
                r.base.is_some(),
                r.center.is_some(),
                r.axis.is_some(),
                r.length.is_some(),
                r.radius.is_some(),
                r.polygon.is_some(),
                r.from.is_some(),
                r.to.is_some(),
            ];
            if extra.iter().any(|&e| e) {
                return self.err(line, format!("{ctx}: shape \"all\" takes no other key"));
            }
            return Ok(Region::All);
        }
        if r.shape.is_none() {
            return self.err(
                line,
                format!(
                    "{ctx}: needs 'shape' (box, cylinder, sphere, prism, slab or all) or 'ids'"
                ),
            );
        }
        Ok(Region::Shape(self.shape(r, line, &ctx)?))
    }
}
