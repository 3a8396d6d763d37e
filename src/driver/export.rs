//! `pdq lammps-data`: a deck's initial state as a LAMMPS data file, so that LAMMPS starts from
//! PDQ's positions and velocities (`output::lammps_data`).

use crate::input::deck::Scene;
use crate::input::setup;
use crate::model::attributes::Attributes;
use crate::model::{Model, ModelVisitor};
use crate::output::lammps_data::{Atom, LammpsData};

/// The deck's particles after setup (lattice, `[velocity]`), one LAMMPS type per material.
pub fn lammps_data(scene: &Scene) -> Result<LammpsData, String> {
    struct Visit<'a>(&'a Scene);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<LammpsData, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let scene = self.0;
            if M::BONDED {
                return Err(format!(
                    "{}: model '{}' has bonds, which a LAMMPS data file of atom style atomic cannot carry; export a bondless deck (model \"point\")",
                    scene.file,
                    M::NAME
                ));
            }
            let setup = setup::build(model, scene).map_err(|e| e.to_string())?;
            let p = &setup.sim.particles;
            let mut masses = vec![f64::NAN; scene.materials.len()];
            let mut atoms = Vec::with_capacity(p.n_owned);
            for i in 0..p.n_owned {
                let kind = p.material[i] as usize;
                let mass = 1.0 / p.inv_inertia[i].as_slice()[0];
                if masses[kind].is_nan() {
                    masses[kind] = mass;
                } else if (mass - masses[kind]).abs() > 1e-12 * mass.abs() {
                    return Err(format!(
                        "{}: material '{}' has particles of mass {} and {}; a LAMMPS data file of atom style atomic takes one mass per type",
                        scene.file, scene.materials[kind].name, masses[kind], mass
                    ));
                }
                let v = p.velocity(i);
                atoms.push(Atom {
                    id: p.gid[i] as u64 + 1,
                    kind: kind + 1,
                    position: p.pos(i),
                    velocity: [v[0], v[1], v[2]],
                });
            }
            atoms.sort_by_key(|a| a.id);
            // A material no particle has still gets a type, with a mass LAMMPS accepts.
            for m in &mut masses {
                if m.is_nan() {
                    *m = 1.0;
                }
            }
            let d = &setup.domain;
            let mut bounds = [[0.0; 2]; 3];
            for (a, b) in bounds.iter_mut().enumerate() {
                *b = if d.periodic[a] {
                    [d.grid.origin[a], d.grid.origin[a] + d.period[a]]
                } else {
                    let along = atoms.iter().map(|t| t.position[a]);
                    let lo = along.clone().fold(f64::INFINITY, f64::min);
                    let hi = along.fold(f64::NEG_INFINITY, f64::max);
                    [lo - 0.5 * scene.spacing, hi + 0.5 * scene.spacing]
                };
            }
            let periodic: String = (0..3)
                .map(|a| if d.periodic[a] { "p " } else { "f " })
                .collect();
            Ok(LammpsData {
                comment: format!(
                    "PDQ {} from {} (units {}; boundary {})",
                    env!("CARGO_PKG_VERSION"),
                    scene.file,
                    scene.units.name(),
                    periodic.trim_end()
                ),
                bounds,
                masses,
                atoms,
            })
        }
    }
    setup::with_model(scene, Visit(scene)).map_err(|e| e.to_string())?
}
