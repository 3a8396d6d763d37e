//! The particle store of one procCube: owned particles first, then ghosts, in one set of arrays.
//!
//! The engine keeps what every model needs (global id, reference position, volume, material);
//! the model's declared records (`Alter`, `Fixed`, `State`, `Force`) sit beside them, one
//! contiguous array each, so the force loop streams only what the model reads.

use crate::model::attributes::Attributes;
use crate::model::{second_order, Model, Side};

pub struct Particles<M: Model> {
    /// Particles `0..n_owned` are integrated here; the rest are ghosts (copies of neighbours').
    pub n_owned: usize,
    pub gid: Vec<u32>,
    pub x0: Vec<[f64; 3]>,
    pub volume: Vec<f64>,
    pub material: Vec<u16>,
    pub fixed: Vec<M::Fixed>,
    pub alter: Vec<M::Alter>,
    pub state: Vec<M::State>,
    pub force: Vec<M::Force>,
    /// 1 / inertia of each generalized degree of freedom.
    pub inv_inertia: Vec<M::Force>,
}

impl<M: Model> Particles<M> {
    /// Owned particles at rest in their reference positions, in the given order.
    pub fn new(
        model: &M,
        gid: Vec<u32>,
        x0: Vec<[f64; 3]>,
        volume: Vec<f64>,
        material: Vec<u16>,
    ) -> Self {
        let n = gid.len();
        let n2 = second_order::<M>();
        assert!(
            <M::Alter as Attributes>::LEN >= 2 * n2 + M::FIRST_ORDER && n2 >= 3,
            "model '{}': Alter must hold coordinates, velocities, then first-order values (see Model docs)",
            M::NAME
        );
        let fixed: Vec<M::Fixed> = (0..n)
            .map(|i| model.fixed(material[i], volume[i]))
            .collect();
        let alter = x0
            .iter()
            .map(|x| {
                let mut a = M::Alter::default();
                a.as_mut_slice()[..3].copy_from_slice(x);
                model.at_rest(&mut a);
                a
            })
            .collect();
        let inv_inertia = (0..n)
            .map(|i| {
                let mut m = model.inertia(material[i], volume[i], &fixed[i]);
                for v in m.as_mut_slice() {
                    *v = 1.0 / *v;
                }
                m
            })
            .collect();
        Particles {
            n_owned: n,
            gid,
            x0,
            volume,
            material,
            fixed,
            alter,
            state: vec![M::State::default(); n],
            force: vec![M::Force::default(); n],
            inv_inertia,
        }
    }

    pub fn len(&self) -> usize {
        self.gid.len()
    }

    pub fn is_empty(&self) -> bool {
        self.gid.is_empty()
    }

    #[inline(always)]
    pub fn side(&self, i: usize) -> Side<'_, M> {
        Side {
            x0: &self.x0[i],
            volume: self.volume[i],
            material: self.material[i],
            alter: &self.alter[i],
            fixed: &self.fixed[i],
            state: &self.state[i],
        }
    }

    /// Current position of particle `i`.
    #[inline]
    pub fn pos(&self, i: usize) -> [f64; 3] {
        let a = self.alter[i].as_slice();
        [a[0], a[1], a[2]]
    }

    /// Displacement of particle `i` from its reference position.
    #[inline]
    pub fn displacement(&self, i: usize) -> [f64; 3] {
        let p = self.pos(i);
        let x = self.x0[i];
        [p[0] - x[0], p[1] - x[1], p[2] - x[2]]
    }

    /// Generalized velocities of particle `i`.
    #[inline]
    pub fn velocity(&self, i: usize) -> &[f64] {
        let n = second_order::<M>();
        &self.alter[i].as_slice()[n..2 * n]
    }

    pub fn velocity_mut(&mut self, i: usize) -> &mut [f64] {
        let n = second_order::<M>();
        &mut self.alter[i].as_mut_slice()[n..2 * n]
    }

    /// Kinetic energy of the owned particles, over every second-order degree of freedom.
    pub fn kinetic_energy(&self) -> f64 {
        let n = second_order::<M>();
        let mut e = 0.0;
        for i in 0..self.n_owned {
            let a = self.alter[i].as_slice();
            let inv = self.inv_inertia[i].as_slice();
            for k in 0..n {
                e += 0.5 * a[n + k] * a[n + k] / inv[k];
            }
        }
        e
    }

    /// Total linear momentum of the owned particles.
    pub fn momentum(&self) -> [f64; 3] {
        let n = second_order::<M>();
        let mut p = [0.0; 3];
        for i in 0..self.n_owned {
            let a = self.alter[i].as_slice();
            let inv = self.inv_inertia[i].as_slice();
            for k in 0..3 {
                p[k] += a[n + k] / inv[k];
            }
        }
        p
    }

    /// Bytes held per particle (for memory estimates).
    pub fn bytes_per_particle() -> usize {
        4 + 24
            + 8
            + 2
            + std::mem::size_of::<M::Fixed>()
            + std::mem::size_of::<M::Alter>()
            + std::mem::size_of::<M::State>()
            + 2 * std::mem::size_of::<M::Force>()
    }
}
