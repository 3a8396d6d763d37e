//! Sums over a whole bond list outside the step's bond loops (`forces.rs`): the bonds'
//! contributions to fixed data at setup, and the stored elastic energy for the history.

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::model::attributes::add_assign;
use crate::model::Model;

/// The bonds' contributions to fixed data (see [`Model::bond_fixed`]), summed on both ends of
/// every bond, broken or not: one value per particle of the store, ghosts included.
pub fn bond_fixed_sums<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
) -> Vec<M::Fixed> {
    let mut sums = vec![M::Fixed::default(); p.len()];
    if !M::FIXED_FROM_BONDS {
        return sums;
    }
    for (i, j, b) in bonds.iter() {
        let law = model.law(p.material[i], p.material[j]);
        let (fi, fj) = model.bond_fixed(&law, &p.side(i), &p.side(j), &bonds.geom[b]);
        add_assign(&mut sums[i], &fi);
        add_assign(&mut sums[j], &fj);
    }
    sums
}

/// Adds the bond sums to the fixed data of a store that holds whole families (one procCube
/// and no ghosts); procCubes sum across faces in [`crate::parallel::Cube::start`].
pub fn add_bond_fixed<M: Model>(model: &M, p: &mut Particles<M>, bonds: &BondList<M::Bond>) {
    if !M::FIXED_FROM_BONDS {
        return;
    }
    let sums = bond_fixed_sums(model, p, bonds);
    for (f, s) in p.fixed.iter_mut().zip(&sums) {
        add_assign(f, s);
    }
}

/// Elastic energy stored in the intact bonds and in the owned particles.
pub fn strain_energy<M: Model>(model: &M, p: &Particles<M>, bonds: &BondList<M::Bond>) -> f64 {
    let mut e = 0.0;
    for i in 0..p.n_owned {
        e += model.particle_energy(p.material[i], p.volume[i], &p.fixed[i], &p.state[i]);
    }
    // Four running sums (bond k into sum k mod 4, in bond order, added pairwise at the end):
    // one sum was a chain of dependent additions, and this pass at every history row took a
    // sixth of a cracking run. The order is fixed, so the sum is the same run after run.
    let mut sums = [0.0; 4];
    let (offsets, partners) = (bonds.offsets(), bonds.partners());
    for (i, w) in offsets.windows(2).enumerate() {
        let side_i = p.side(i);
        for b in w[0] as usize..w[1] as usize {
            if bonds.broken[b] {
                continue;
            }
            let j = partners[b] as usize;
            let law = model.law(p.material[i], p.material[j]);
            let geom = &bonds.geom[b];
            sums[b % 4] += model.energy(&law, &side_i, &p.side(j), geom, &bonds.history[b]);
        }
    }
    e + ((sums[0] + sums[1]) + (sums[2] + sums[3]))
}
