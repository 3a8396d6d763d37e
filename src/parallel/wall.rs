//! Ghost messages of the wall method: the five staged messages forward, and the same path in
//! reverse for forces and partial sums (thesis 3.6 and 3.9).
//!
//! What travels is the model's declared records, whole: `Alter` forward (positions first, so a
//! periodic image only shifts the first three values), `State` partials back and finished
//! states forward, `Force` back. Backward messages retrace the forward ones stage by stage in
//! reverse order, so a force on a ghost that came by two hops (a south-east corner, say) goes
//! home by the same two hops and is summed on arrival at each.

use crate::engine::particles::Particles;
use crate::engine::simulation::Exchange;
use crate::model::attributes::{add_assign, Attributes};
use crate::model::Model;
use crate::parallel::comm::Transport;
use crate::parallel::decomposition::Stage;
use bytemuck::Pod;

/// Bytes and messages one procCube has sent, for the message-trimming measurements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traffic {
    pub bytes: u64,
    pub messages: u64,
}

pub struct WallExchange {
    stages: Vec<Stage>,
    transport: Box<dyn Transport>,
    out: Vec<u8>,
    inp: Vec<u8>,
    pub traffic: Traffic,
}

/// Tags: forward stages 0..5, backward 8..13.
const BACK: u32 = 8;

impl WallExchange {
    pub fn new(stages: Vec<Stage>, transport: Box<dyn Transport>) -> Self {
        WallExchange {
            stages,
            transport,
            out: Vec::new(),
            inp: Vec::new(),
            traffic: Traffic::default(),
        }
    }

    /// Owned values to their ghost copies, stage by stage; `shift` adds each stage's periodic
    /// offset to the first three values of every record it brings.
    pub fn forward<T: Pod>(&mut self, data: &mut [T], shift: bool) {
        let size = std::mem::size_of::<T>();
        if size == 0 {
            return;
        }
        for (s, st) in self.stages.iter().enumerate() {
            self.out.clear();
            self.out.reserve(st.send.len() * size);
            for &i in &st.send {
                self.out
                    .extend_from_slice(bytemuck::bytes_of(&data[i as usize]));
            }
            if st.to.is_some() {
                self.traffic.bytes += self.out.len() as u64;
                self.traffic.messages += 1;
            }
            self.transport
                .exchange(s as u32, st.to, &self.out, st.from, &mut self.inp);
            if st.from.is_none() {
                continue;
            }
            assert_eq!(
                self.inp.len(),
                st.recv.len() * size,
                "ghost message of stage {s} has the wrong size"
            );
            // Received ghosts are one contiguous run of the store: one copy.
            let ghosts = &mut data[st.recv.clone()];
            bytemuck::cast_slice_mut::<T, u8>(ghosts).copy_from_slice(&self.inp);
            if shift && st.shift != [0.0; 3] {
                for v in ghosts.iter_mut() {
                    let f: &mut [f64] = bytemuck::cast_slice_mut(std::slice::from_mut(v));
                    for (x, d) in f.iter_mut().zip(st.shift) {
                        *x += d;
                    }
                }
            }
        }
    }

    /// Ghost values back to their owners along the forward path in reverse, summed with `add`.
    pub fn reverse<T: Pod>(&mut self, data: &mut [T], add: impl Fn(&mut T, &T)) {
        let size = std::mem::size_of::<T>();
        if size == 0 {
            return;
        }
        for (s, st) in self.stages.iter().enumerate().rev() {
            self.out.clear();
            if st.from.is_some() {
                self.out
                    .extend_from_slice(bytemuck::cast_slice(&data[st.recv.clone()]));
                self.traffic.bytes += self.out.len() as u64;
                self.traffic.messages += 1;
            }
            self.transport
                .exchange(BACK + s as u32, st.from, &self.out, st.to, &mut self.inp);
            if st.to.is_none() {
                continue;
            }
            assert_eq!(
                self.inp.len(),
                st.send.len() * size,
                "returning message of stage {s} has the wrong size"
            );
            for (k, &i) in st.send.iter().enumerate() {
                let v: T = bytemuck::pod_read_unaligned(&self.inp[k * size..(k + 1) * size]);
                add(&mut data[i as usize], &v);
            }
        }
    }

    /// A new plan over the same transport (after a shuffle).
    pub fn set_stages(&mut self, stages: Vec<Stage>) {
        self.stages = stages;
    }

    /// New periodic offsets of the stages, in order (a box that changed size).
    pub fn set_shifts(&mut self, shifts: impl Iterator<Item = [f64; 3]>) {
        for (st, s) in self.stages.iter_mut().zip(shifts) {
            st.shift = s;
        }
    }

    pub fn stages(&self) -> &[Stage] {
        &self.stages
    }

    /// The byte mover underneath, for reductions and gathers.
    pub fn transport(&mut self) -> &mut dyn Transport {
        &mut *self.transport
    }
}

impl<M: Model> Exchange<M> for WallExchange {
    fn forward(&mut self, p: &mut Particles<M>) {
        WallExchange::forward(self, &mut p.alter, true);
    }
    fn reverse_state(&mut self, p: &mut Particles<M>) {
        if <M::State as Attributes>::LEN > 0 {
            self.reverse(&mut p.state, add_assign);
        }
    }
    fn forward_state(&mut self, p: &mut Particles<M>) {
        if <M::State as Attributes>::LEN > 0 {
            WallExchange::forward(self, &mut p.state, false);
        }
    }
    fn reverse_force(&mut self, p: &mut Particles<M>) {
        self.reverse(&mut p.force, add_assign);
    }
}
