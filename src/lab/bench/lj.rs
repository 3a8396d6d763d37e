//! `pdq bench --scene lj`: LAMMPS's LJ melt (`bench/in.lj`, `inputs/lj_melt.toml`) at n fcc
//! cells per edge (4n³ atoms; n = 20 is the standard 32,000), against LAMMPS `lj/cut` on the
//! same scene (`shared/bench/lammps_lj.in`).

/// The example deck, run as users run it; the bench only resizes the box.
const LJ_MELT: &str = include_str!("../../../inputs/lj_melt.toml");

/// The LAMMPS input of the LJ peer (`shared/bench/lammps_lj.in`): bench/in.lj, which rebuilds
/// its neighbour lists every 20 steps without checking.
pub(super) const LAMMPS_LJ: &str = "units lj\natom_style atomic\nlattice fcc 0.8442\nregion box block 0 ${n} 0 ${n} 0 ${n}\ncreate_box 1 box\ncreate_atoms 1 box\nmass 1 1.0\nvelocity all create 1.44 87287 loop geom\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0 2.5\nneighbor 0.3 bin\nneigh_modify delay 0 every 20 check no\nfix 1 all nve\nthermo 50\nrun ${steps}\n";

/// The LJ melt with n fcc cells per edge. The box ends a quarter cell short of n cells, so
/// that the sites of the far faces (the next period's first) are left out whatever rounding.
pub(super) fn lj_deck(n: usize) -> Result<String, String> {
    if n < 4 {
        return Err(format!(
            "the LJ scene needs at least 4 fcc cells per edge (three cells of cutoff + skin across the period), got --n {n}"
        ));
    }
    let a = (4.0f64 / 0.8442).cbrt();
    let max = (n as f64 - 0.25) * a;
    let old = "max = [33.5, 33.5, 33.5]";
    if !LJ_MELT.contains(old) {
        return Err(format!(
            "inputs/lj_melt.toml no longer has '{old}' for the bench to resize"
        ));
    }
    Ok(LJ_MELT.replace(old, &format!("max = [{max}, {max}, {max}]")))
}
