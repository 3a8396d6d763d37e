//! LAMMPS data files (`read_data`, atom style `atomic`): a scene's atoms with their types,
//! positions and velocities, so that LAMMPS starts from exactly PDQ's state (the peer
//! comparison of the LJ melt, docs/examples.md).

use std::fmt::Write as _;

/// One atom: LAMMPS id (from 1), type (from 1), position and velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atom {
    pub id: u64,
    pub kind: usize,
    pub position: [f64; 3],
    pub velocity: [f64; 3],
}

/// What a data file holds.
#[derive(Clone, Debug, PartialEq)]
pub struct LammpsData {
    /// The first line: LAMMPS skips it; it says where the file came from.
    pub comment: String,
    /// Low and high bound along x, y, z.
    pub bounds: [[f64; 2]; 3],
    /// Mass of each type, type 1 first.
    pub masses: Vec<f64>,
    pub atoms: Vec<Atom>,
}

impl LammpsData {
    /// The file's text. Numbers are written with 17 significant digits, so that LAMMPS reads
    /// back the same doubles.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{}\n", self.comment.replace('\n', " "));
        let _ = writeln!(s, "{} atoms", self.atoms.len());
        let _ = writeln!(s, "{} atom types\n", self.masses.len());
        for (a, name) in ["x", "y", "z"].iter().enumerate() {
            let [lo, hi] = self.bounds[a];
            let _ = writeln!(s, "{lo:.16e} {hi:.16e} {name}lo {name}hi");
        }
        s.push_str("\nMasses\n\n");
        for (t, m) in self.masses.iter().enumerate() {
            let _ = writeln!(s, "{} {m:.16e}", t + 1);
        }
        s.push_str("\nAtoms # atomic\n\n");
        for a in &self.atoms {
            let [x, y, z] = a.position;
            let _ = writeln!(s, "{} {} {x:.16e} {y:.16e} {z:.16e} 0 0 0", a.id, a.kind);
        }
        s.push_str("\nVelocities\n\n");
        for a in &self.atoms {
            let [x, y, z] = a.velocity;
            let _ = writeln!(s, "{} {x:.16e} {y:.16e} {z:.16e}", a.id);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_text_has_lammps_sections_and_exact_numbers() {
        let d = LammpsData {
            comment: "test".into(),
            bounds: [[0.0, 1.5], [0.0, 2.0], [-1.0, 1.0]],
            masses: vec![1.0],
            atoms: vec![Atom {
                id: 1,
                kind: 1,
                position: [0.1, 0.2, 1.0 / 3.0],
                velocity: [-0.5, 0.0, 2.0],
            }],
        };
        let t = d.text();
        assert!(t.contains("1 atoms\n1 atom types\n"));
        assert!(t.contains("-1.0000000000000000e0 1.0000000000000000e0 zlo zhi"));
        assert!(t.contains("\nAtoms # atomic\n\n1 1 "));
        let line = t.lines().find(|l| l.ends_with(" 0 0 0")).unwrap();
        let z: f64 = line.split(' ').nth(4).unwrap().parse().unwrap();
        assert_eq!(z, 1.0 / 3.0);
        assert!(t.contains("\nVelocities\n\n1 -5.0000000000000000e-1 "));
    }
}
