//! Boundary conditions and loads on sets of particles, as functions of time.
//!
//! Kinematic conditions act on generalized degrees of freedom (0, 1, 2 = x, y, z translation;
//! a model with rotations adds 3, 4, 5; first-order DOFs such as temperature follow the
//! second-order ones): the DOF's force is taken out (and reported as the support's reaction:
//! for a temperature, the heat the support supplies) and its velocity is set so that the drift
//! lands exactly on the prescribed value; a first-order value is set directly. Loads add
//! forces (or heat) starting at a DOF.

use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};

/// The deck's name for the first first-order DOF (temperature); setup turns it into the
/// model's index (the number of second-order DOFs).
pub const TEMPERATURE: usize = usize::MAX;

/// How a prescribed value varies with time: a factor applied to the deck's value.
#[derive(Clone, Debug, PartialEq)]
pub enum History {
    Constant,
    /// From 0 at t = 0 to 1 at t = duration, then held.
    Ramp {
        duration: f64,
    },
    /// Piecewise linear through (time, factor) points with increasing times, held outside.
    Table(Vec<(f64, f64)>),
}

impl History {
    pub fn factor(&self, t: f64) -> f64 {
        match self {
            History::Constant => 1.0,
            History::Ramp { duration } => (t / duration).clamp(0.0, 1.0),
            History::Table(points) => {
                let (first, last) = (points[0], points[points.len() - 1]);
                if t <= first.0 {
                    return first.1;
                }
                if t >= last.0 {
                    return last.1;
                }
                let k = points.partition_point(|p| p.0 <= t);
                let (a, b) = (points[k - 1], points[k]);
                a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
            }
        }
    }

    /// ∫ factor dt from `a` to `b` (a ≤ b), exactly: the factor is linear between its knots,
    /// so the trapezoid rule over the pieces between them is exact.
    pub fn integral(&self, a: f64, b: f64) -> f64 {
        let knots: Vec<f64> = match self {
            History::Constant => Vec::new(),
            History::Ramp { duration } => vec![0.0, *duration],
            History::Table(points) => points.iter().map(|p| p.0).collect(),
        };
        let mut ts = vec![a];
        ts.extend(knots.into_iter().filter(|&t| t > a && t < b));
        ts.push(b);
        ts.windows(2)
            .map(|w| 0.5 * (w[1] - w[0]) * (self.factor(w[0]) + self.factor(w[1])))
            .sum()
    }

    /// Checks the description is usable; the message names what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        match self {
            History::Constant => Ok(()),
            History::Ramp { duration } => {
                if duration.is_finite() && *duration > 0.0 {
                    Ok(())
                } else {
                    Err(format!("ramp duration must be > 0 (got {duration})"))
                }
            }
            History::Table(points) => {
                if points.is_empty() {
                    return Err("history table is empty".into());
                }
                if points.iter().any(|p| !(p.0.is_finite() && p.1.is_finite())) {
                    return Err("history table entries must be finite numbers".into());
                }
                if points.windows(2).any(|w| w[1].0 <= w[0].0) {
                    return Err("history table times must increase".into());
                }
                Ok(())
            }
        }
    }
}

/// What a kinematic condition prescribes on its DOFs (`values` line up with `dofs`).
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    Fixed,
    Velocity(Vec<f64>),
    Displacement(Vec<f64>),
}

#[derive(Clone, Debug)]
pub struct Constraint {
    pub name: String,
    /// Store indices of owned particles.
    pub particles: Vec<u32>,
    pub dofs: Vec<usize>,
    pub motion: Motion,
    pub history: History,
    /// Force the support exerts on the body, per DOF, at the last force evaluation.
    pub reaction: Vec<f64>,
}

impl Constraint {
    pub fn new(
        name: &str,
        particles: Vec<u32>,
        dofs: Vec<usize>,
        motion: Motion,
        history: History,
    ) -> Self {
        let n = dofs.len();
        Constraint {
            name: name.to_string(),
            particles,
            dofs,
            motion,
            history,
            reaction: vec![0.0; n],
        }
    }

    /// Removes the DOFs' forces, keeping their sum (negated) as the reaction.
    pub fn take_forces<M: Model>(&mut self, p: &mut Particles<M>) {
        self.reaction.iter_mut().for_each(|r| *r = 0.0);
        for &i in &self.particles {
            let f = p.force[i as usize].as_mut_slice();
            for (r, &d) in self.reaction.iter_mut().zip(&self.dofs) {
                *r -= f[d];
                f[d] = 0.0;
            }
        }
    }

    /// A first-order DOF's prescribed value at `t` (temperatures are absolute), if any.
    fn first_order_value(&self, k: usize, t: f64) -> Option<f64> {
        match &self.motion {
            Motion::Displacement(u) => Some(u[k] * self.history.factor(t)),
            _ => None,
        }
    }

    /// Sets velocities for the drift from `t` to `t + dt`, so positions land on the target,
    /// and first-order values to their targets at `t + dt`.
    pub fn set_drift_velocity<M: Model>(&self, p: &mut Particles<M>, t: f64, dt: f64) {
        let n = second_order::<M>();
        // A velocity's mean over the step moves the support as far as its history does, also
        // over a step that spans a corner of the history (a static start's one long step).
        let mean_factor = self.history.integral(t, t + dt) / dt;
        for &i in &self.particles {
            let i = i as usize;
            let x0 = p.x0[i];
            let a = p.alter[i].as_mut_slice();
            for (k, &d) in self.dofs.iter().enumerate() {
                if d >= n {
                    if let Some(v) = self.first_order_value(k, t + dt) {
                        a[n + d] = v;
                    }
                    continue;
                }
                a[n + d] = match &self.motion {
                    Motion::Fixed => 0.0,
                    Motion::Velocity(v) => v[k] * mean_factor,
                    Motion::Displacement(u) => {
                        let reference = if d < 3 { x0[d] } else { 0.0 };
                        (reference + u[k] * self.history.factor(t + dt) - a[d]) / dt
                    }
                };
            }
        }
    }

    /// Sets the velocities reported at time `t` (end of a step of length `dt`).
    pub fn set_velocity<M: Model>(&self, p: &mut Particles<M>, t: f64, dt: f64) {
        let n = second_order::<M>();
        for &i in &self.particles {
            let a = p.alter[i as usize].as_mut_slice();
            for (k, &d) in self.dofs.iter().enumerate() {
                if d >= n {
                    if let Some(v) = self.first_order_value(k, t) {
                        a[n + d] = v;
                    }
                    continue;
                }
                a[n + d] = match &self.motion {
                    Motion::Fixed => 0.0,
                    Motion::Velocity(v) => v[k] * self.history.factor(t),
                    Motion::Displacement(u) => {
                        u[k] * (self.history.factor(t) - self.history.factor(t - dt)) / dt
                    }
                };
            }
        }
    }
}

/// External generalized forces `vector · weight_i · factor(t)` on particle i, on the DOFs
/// from `dof` on (0 for forces on x, y, z; the temperature DOF for heat, with one value).
#[derive(Clone, Debug)]
pub struct Load {
    pub name: String,
    pub particles: Vec<u32>,
    pub weight: Vec<f64>,
    pub vector: [f64; 3],
    pub dof: usize,
    pub history: History,
}

impl Load {
    pub fn apply<M: Model>(&self, p: &mut Particles<M>, t: f64) {
        let f = self.history.factor(t);
        let v = [self.vector[0] * f, self.vector[1] * f, self.vector[2] * f];
        let len = 3.min(<M::Force as Attributes>::LEN - self.dof);
        for (&i, &w) in self.particles.iter().zip(&self.weight) {
            let force = &mut p.force[i as usize].as_mut_slice()[self.dof..];
            for k in 0..len {
                force[k] += v[k] * w;
            }
        }
    }

    /// Total applied force at time `t`, as a vector.
    pub fn total(&self, t: f64) -> [f64; 3] {
        let s: f64 = self.weight.iter().sum::<f64>() * self.history.factor(t);
        [self.vector[0] * s, self.vector[1] * s, self.vector[2] * s]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histories() {
        assert_eq!(History::Constant.factor(7.0), 1.0);
        let r = History::Ramp { duration: 2.0 };
        assert_eq!(r.factor(1.0), 0.5);
        assert_eq!(r.factor(3.0), 1.0);
        let t = History::Table(vec![(0.0, 0.0), (1.0, 2.0), (3.0, -2.0)]);
        assert_eq!(t.factor(0.5), 1.0);
        assert_eq!(t.factor(2.0), 0.0);
        assert_eq!(t.factor(9.0), -2.0);
        // Integrals across corners: the ramp is ½ over its 2 s, then 1 per second.
        assert_eq!(r.integral(0.0, 3.0), 2.0);
        assert_eq!(r.integral(1.0, 2.0), 0.75);
        assert_eq!(History::Constant.integral(1.0, 4.0), 3.0);
        // 1 (0 to 1) + 0 (1 to 3) − 2 × 2 (held after 3).
        assert_eq!(t.integral(0.0, 5.0), -3.0);
        assert_eq!(t.integral(-1.0, 0.5), 0.25);
        assert!(History::Table(vec![(1.0, 0.0), (1.0, 1.0)])
            .validate()
            .is_err());
        assert!(History::Ramp { duration: 0.0 }.validate().is_err());
    }
}
