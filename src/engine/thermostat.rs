//! Thermostats for molecular dynamics: the translational velocities of a group of particles
//! held at a temperature T₀ (docs/theory.md §11).
//!
//! * `Rescale`: every `every` steps, v ← λv with λ = √(T₀/T).
//! * `Berendsen` (1984): every step, λ = √(1 + Δt/τ (T₀/T − 1)).
//! * `Langevin` (Schneider & Stoll 1978): friction γ = 1/τ and a random force, integrated
//!   exactly over each step (an Ornstein–Uhlenbeck step after the velocity-Verlet step);
//!   the noise is keyed by (seed, global id, step, component), so it does not depend on the
//!   layout.
//! * `NoseHoover` (Nosé 1984, Hoover 1985): one thermostat variable ξ of mass
//!   Q = dof·k_B·T₀·τ², integrated by the Trotter splitting of Martyna et al. (1996) with
//!   chain length 1 (LAMMPS's `fix nvt`): a half step of ξ around each end of the velocity
//!   Verlet step. It conserves H = KE + PE + dof·k_B·T₀·η + ½Qξ², η = ∫ξ dt.
//!
//! The group's kinetic energy is a sum over every procCube: the step hands in `sum`, which
//! adds its slice element-wise over the team (a procCube alone: nothing to add). Membership is
//! by global id, so it follows particles through shuffles.

use crate::engine::particles::Particles;
use crate::engine::random::normal_at_step;
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};

/// A thermostat's kind, its parameters and (Nosé–Hoover) its state.
#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    /// λ = √(T₀/T) every `every` steps.
    Rescale { every: u64 },
    /// λ = √(1 + Δt/τ (T₀/T − 1)) every step.
    Berendsen { tau: f64 },
    /// Friction 1/τ and the matching random force; noise drawn from `seed`.
    Langevin { tau: f64, seed: u64 },
    /// Thermostat "velocity" ξ (1/time) and its integral η.
    NoseHoover { tau: f64, xi: f64, eta: f64 },
}

impl Kind {
    /// The deck's name of the kind.
    pub fn name(&self) -> &'static str {
        match self {
            Kind::Rescale { .. } => "rescale",
            Kind::Berendsen { .. } => "berendsen",
            Kind::Langevin { .. } => "langevin",
            Kind::NoseHoover { .. } => "nose-hoover",
        }
    }
}

/// A thermostat on a group of particles.
#[derive(Clone, Debug, PartialEq)]
pub struct Thermostat {
    pub kind: Kind,
    /// Target temperature T₀, in the deck's temperature unit.
    pub temperature: f64,
    /// Boltzmann's constant in the deck's units.
    pub kb: f64,
    /// Membership by global id; `None`: every particle.
    pub member: Option<Vec<bool>>,
    /// Translational degrees of freedom of the group, over all procCubes.
    pub dof: f64,
    /// Energy the thermostat has taken out of the particles since the start (rescale,
    /// Berendsen, Langevin): total energy plus this is conserved. Nosé–Hoover's is computed
    /// from ξ and η instead ([`Thermostat::reservoir`]).
    pub removed: f64,
}

/// What a checkpoint keeps of a thermostat: its kind's name and its state values.
#[derive(Clone, Debug, PartialEq)]
pub struct Saved {
    pub kind: String,
    pub values: Vec<f64>,
}

impl Thermostat {
    /// Whether owned particle `i` of `p` is in the group.
    fn holds<M: Model>(&self, p: &Particles<M>, i: usize) -> bool {
        self.member.as_ref().is_none_or(|m| m[p.gid[i] as usize])
    }

    /// Σ ½ m v² over the translational velocities of the group's owned particles.
    fn local_kinetic<M: Model>(&self, p: &Particles<M>) -> f64 {
        let n = second_order::<M>();
        let mut e = 0.0;
        for i in (0..p.n_owned).filter(|&i| self.holds(p, i)) {
            let a = p.alter[i].as_slice();
            let inv = p.inv_inertia[i].as_slice();
            for k in 0..3 {
                e += 0.5 * a[n + k] * a[n + k] / inv[k];
            }
        }
        e
    }

    /// The group's kinetic energy over all procCubes.
    fn kinetic<M: Model>(&self, p: &Particles<M>, sum: &mut dyn FnMut(&mut [f64])) -> f64 {
        let mut v = [self.local_kinetic(p)];
        sum(&mut v);
        v[0]
    }

    /// Multiplies the group's translational velocities by `s`.
    fn scale<M: Model>(&self, p: &mut Particles<M>, s: f64) {
        let n = second_order::<M>();
        for i in 0..p.n_owned {
            if self.holds(p, i) {
                for v in &mut p.alter[i].as_mut_slice()[n..n + 3] {
                    *v *= s;
                }
            }
        }
    }

    /// Temperature of kinetic energy `ke` spread over the group's DOFs.
    pub fn temperature_of(&self, ke: f64) -> f64 {
        2.0 * ke / (self.dof * self.kb)
    }

    /// Nosé–Hoover's mass Q = dof·k_B·T₀·τ².
    fn mass(&self, tau: f64) -> f64 {
        self.dof * self.kb * self.temperature * tau * tau
    }

    /// The energy the thermostat holds: for Nosé–Hoover dof·k_B·T₀·η + ½Qξ², for the others
    /// what it has removed. Kinetic plus potential energy plus this is what the thermostatted
    /// dynamics conserves (Nosé–Hoover exactly up to the integrator's error, the others as the
    /// bookkeeping of what they took).
    pub fn reservoir(&self) -> f64 {
        match self.kind {
            Kind::NoseHoover { tau, xi, eta } => {
                self.dof * self.kb * self.temperature * eta + 0.5 * self.mass(tau) * xi * xi
            }
            _ => self.removed,
        }
    }

    /// Before the step's first kick: Nosé–Hoover's first half step (the others act at the
    /// end of the step).
    pub fn begin_step<M: Model>(
        &mut self,
        p: &mut Particles<M>,
        dt: f64,
        sum: &mut dyn FnMut(&mut [f64]),
    ) {
        if matches!(self.kind, Kind::NoseHoover { .. }) {
            self.nose_hoover_half(p, dt, sum);
        }
    }

    /// After the step's last kick (`step` is the step just taken).
    pub fn end_step<M: Model>(
        &mut self,
        p: &mut Particles<M>,
        dt: f64,
        step: u64,
        sum: &mut dyn FnMut(&mut [f64]),
    ) {
        match self.kind {
            Kind::Rescale { every } => {
                if step.is_multiple_of(every) {
                    let ke = self.kinetic(p, sum);
                    let l2 = self.temperature / self.temperature_of(ke);
                    self.rescale(p, ke, l2);
                }
            }
            Kind::Berendsen { tau } => {
                let ke = self.kinetic(p, sum);
                let t = self.temperature_of(ke);
                // A step longer than τ could ask for λ² < 0; the deck refuses τ < Δt.
                let l2 = 1.0 + dt / tau * (self.temperature / t - 1.0);
                self.rescale(p, ke, l2);
            }
            Kind::Langevin { tau, seed } => self.langevin(p, dt, tau, seed, step, sum),
            Kind::NoseHoover { .. } => self.nose_hoover_half(p, dt, sum),
        }
    }

    /// v ← λv for the group of kinetic energy `ke`, and the energy it took counted. A group at
    /// rest has no temperature to scale from (λ² is not finite): it is left alone.
    fn rescale<M: Model>(&mut self, p: &mut Particles<M>, ke: f64, lambda2: f64) {
        if ke <= 0.0 {
            return;
        }
        let l2 = lambda2.max(0.0);
        self.scale(p, l2.sqrt());
        self.removed += ke * (1.0 - l2);
    }

    /// The Ornstein–Uhlenbeck step of the friction 1/τ and its random force, exact over Δt:
    /// v ← c·v + √((1 − c²) k_B T₀ / m)·ξ with c = e^(−Δt/τ). To first order in Δt/τ it is
    /// Δt times the friction −mv/τ and the random force √(2 m k_B T₀ /(τ Δt))·ξ.
    fn langevin<M: Model>(
        &mut self,
        p: &mut Particles<M>,
        dt: f64,
        tau: f64,
        seed: u64,
        step: u64,
        sum: &mut dyn FnMut(&mut [f64]),
    ) {
        let n = second_order::<M>();
        let c = (-dt / tau).exp();
        let spread = ((1.0 - c * c) * self.kb * self.temperature).sqrt();
        let mut gained = 0.0;
        for i in 0..p.n_owned {
            if !self.holds(p, i) {
                continue;
            }
            let gid = p.gid[i];
            let inv: [f64; 3] = std::array::from_fn(|k| p.inv_inertia[i].as_slice()[k]);
            let v = &mut p.alter[i].as_mut_slice()[n..n + 3];
            for k in 0..3 {
                let old = v[k];
                v[k] = c * old + spread * inv[k].sqrt() * normal_at_step(seed, gid, step, k);
                gained += 0.5 * (v[k] * v[k] - old * old) / inv[k];
            }
        }
        // One reduction a step keeps the tally the same on every restart of a layout.
        let mut g = [gained];
        sum(&mut g);
        self.removed -= g[0];
    }

    /// Half a step (Δt/2) of Nosé–Hoover's thermostat: ξ a quarter step, the velocities
    /// scaled by e^(−ξΔt/2) (η moves with them), ξ another quarter step with the scaled
    /// kinetic energy (Martyna et al. 1996, chain length 1).
    fn nose_hoover_half<M: Model>(
        &mut self,
        p: &mut Particles<M>,
        dt: f64,
        sum: &mut dyn FnMut(&mut [f64]),
    ) {
        let ke = self.kinetic(p, sum);
        let Kind::NoseHoover {
            tau,
            mut xi,
            mut eta,
        } = self.kind
        else {
            return;
        };
        let q = self.mass(tau);
        let target = self.dof * self.kb * self.temperature;
        let h = 0.5 * dt;
        xi += 0.5 * h * (2.0 * ke - target) / q;
        let s = (-xi * h).exp();
        eta += xi * h;
        xi += 0.5 * h * (2.0 * ke * s * s - target) / q;
        self.scale(p, s);
        self.kind = Kind::NoseHoover { tau, xi, eta };
    }

    /// The state a restart needs: Nosé–Hoover's ξ and η, the others' tally of removed energy.
    pub fn save(&self) -> Saved {
        let values = match self.kind {
            Kind::NoseHoover { xi, eta, .. } => vec![xi, eta],
            _ => vec![self.removed],
        };
        Saved {
            kind: self.kind.name().to_string(),
            values,
        }
    }

    /// Takes up a saved state of the same kind; another kind's (or none: a checkpoint of a run
    /// without this thermostat) leaves it at its start. Returns whether it was taken up.
    pub fn restore(&mut self, saved: &Saved) -> bool {
        if saved.kind != self.kind.name() {
            return false;
        }
        match (&mut self.kind, saved.values.as_slice()) {
            (Kind::NoseHoover { xi, eta, .. }, &[x, e]) => {
                (*xi, *eta) = (x, e);
                true
            }
            (Kind::NoseHoover { .. }, _) => false,
            (_, &[r]) => {
                self.removed = r;
                true
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn state_round_trips_only_into_its_own_kind() {
        let mut nh = Thermostat {
            kind: Kind::NoseHoover {
                tau: 0.5,
                xi: 0.25,
                eta: -1.5,
            },
            temperature: 1.0,
            kb: 1.0,
            member: None,
            dof: 10.0,
            removed: 0.0,
        };
        let saved = nh.save();
        let mut fresh = nh.clone();
        fresh.kind = Kind::NoseHoover {
            tau: 0.5,
            xi: 0.0,
            eta: 0.0,
        };
        assert!(fresh.restore(&saved));
        assert_eq!(fresh, nh);
        // H's reservoir: dof·k_B·T₀·η + ½Qξ², Q = dof·k_B·T₀·τ².
        assert_eq!(nh.reservoir(), 10.0 * -1.5 + 0.5 * 2.5 * 0.0625);
        let mut b = nh.clone();
        b.kind = Kind::Berendsen { tau: 1.0 };
        assert!(!b.restore(&saved));
        b.removed = 3.0;
        nh.kind = Kind::Rescale { every: 1 };
        assert!(!nh.restore(&b.save()));
    }
}
