//! The byte movers under the wall method: threads in one process, or MPI ranks.
//!
//! Everything above this module (the exchange plan, ghost packing, reductions for output) is
//! the same for both transports; a [`Transport`] only moves bytes between workers. Both
//! implementations deliver the messages from one sender to one receiver in the order they were
//! sent, and every worker calls the same sequence of operations, so a message is identified by
//! its sender and its place in that sequence (the tag is a check, not a selector).

use std::sync::mpsc::{channel, Receiver, Sender};

/// Moves bytes between the workers of one run (one procCube each).
pub trait Transport: Send {
    /// This worker's number, 0-based.
    fn rank(&self) -> usize;
    /// Number of workers.
    fn size(&self) -> usize;
    /// Sends `send` to `to` (if any) and receives the next message from `from` (if any) into
    /// `recv`, replacing its contents. Two workers may send to each other in the same call
    /// without deadlock, and a worker may send to itself.
    fn exchange(
        &mut self,
        tag: u32,
        to: Option<usize>,
        send: &[u8],
        from: Option<usize>,
        recv: &mut Vec<u8>,
    );
}

impl<T: Transport + ?Sized> Transport for &mut T {
    fn rank(&self) -> usize {
        (**self).rank()
    }
    fn size(&self) -> usize {
        (**self).size()
    }
    fn exchange(
        &mut self,
        tag: u32,
        to: Option<usize>,
        send: &[u8],
        from: Option<usize>,
        recv: &mut Vec<u8>,
    ) {
        (**self).exchange(tag, to, send, from, recv)
    }
}

/// One worker alone: only messages to itself.
pub struct Solo {
    queue: std::collections::VecDeque<(u32, Vec<u8>)>,
}

impl Solo {
    pub fn new() -> Solo {
        Solo {
            queue: Default::default(),
        }
    }
}

impl Default for Solo {
    fn default() -> Self {
        Solo::new()
    }
}

impl Transport for Solo {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn exchange(
        &mut self,
        tag: u32,
        to: Option<usize>,
        send: &[u8],
        from: Option<usize>,
        recv: &mut Vec<u8>,
    ) {
        if let Some(t) = to {
            assert_eq!(t, 0, "worker 0 of 1 sends to worker {t}");
            self.queue.push_back((tag, send.to_vec()));
        }
        if let Some(f) = from {
            assert_eq!(f, 0, "worker 0 of 1 receives from worker {f}");
            let (t, msg) = self
                .queue
                .pop_front()
                .expect("a worker alone waits for a message it never sent");
            assert_eq!(t, tag, "message order broken (tag {t}, expected {tag})");
            *recv = msg;
        }
    }
}

/// Workers on threads of one process: one channel per ordered pair of workers, and a return
/// channel that hands each buffer back to its sender so that steady stepping allocates nothing.
pub struct Threads {
    rank: usize,
    size: usize,
    to: Vec<Sender<(u32, Vec<u8>)>>,
    from: Vec<Receiver<(u32, Vec<u8>)>>,
    /// Buffers this worker has finished reading, going back to whoever sent them.
    give_back: Vec<Sender<Vec<u8>>>,
    /// Buffers coming back from the workers this worker sent to.
    returned: Vec<Receiver<Vec<u8>>>,
    /// How long to spin for a message before parking: only when every worker has a core, as a
    /// spinning thread would otherwise take the core from the one it waits for.
    spin: std::time::Duration,
}

impl Threads {
    /// Transports for `n` workers, to be moved one to each thread.
    pub fn team(n: usize) -> Vec<Threads> {
        // data[s][r]: sender s → receiver r; back[s][r]: buffers from r back to s.
        let mut data_tx: Vec<Vec<Option<Sender<_>>>> = vec![];
        let mut data_rx: Vec<Vec<Option<Receiver<_>>>> = vec![];
        let mut back_tx: Vec<Vec<Option<Sender<_>>>> = vec![];
        let mut back_rx: Vec<Vec<Option<Receiver<_>>>> = vec![];
        for _ in 0..n {
            let (mut dt, mut dr, mut bt, mut br) = (vec![], vec![], vec![], vec![]);
            for _ in 0..n {
                let (a, b) = channel();
                dt.push(Some(a));
                dr.push(Some(b));
                let (c, d) = channel();
                bt.push(Some(c));
                br.push(Some(d));
            }
            data_tx.push(dt);
            data_rx.push(dr);
            back_tx.push(bt);
            back_rx.push(br);
        }
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        let spin = if n <= cores {
            std::time::Duration::from_micros(200)
        } else {
            std::time::Duration::ZERO
        };
        (0..n)
            .map(|me| Threads {
                spin,
                rank: me,
                size: n,
                to: (0..n).map(|r| data_tx[me][r].take().unwrap()).collect(),
                from: (0..n).map(|s| data_rx[s][me].take().unwrap()).collect(),
                give_back: (0..n).map(|s| back_tx[s][me].take().unwrap()).collect(),
                returned: (0..n).map(|r| back_rx[me][r].take().unwrap()).collect(),
            })
            .collect()
    }
}

impl Transport for Threads {
    fn rank(&self) -> usize {
        self.rank
    }
    fn size(&self) -> usize {
        self.size
    }
    fn exchange(
        &mut self,
        tag: u32,
        to: Option<usize>,
        send: &[u8],
        from: Option<usize>,
        recv: &mut Vec<u8>,
    ) {
        if let Some(t) = to {
            let mut buf = self.returned[t].try_recv().unwrap_or_default();
            buf.clear();
            buf.extend_from_slice(send);
            // A closed channel means the receiver's thread has already failed; its panic is
            // the one to report, so this side stops quietly.
            if self.to[t].send((tag, buf)).is_err() {
                panic!(
                    "worker {t} stopped before receiving from worker {}",
                    self.rank
                );
            }
        }
        if let Some(f) = from {
            // Neighbours finish their steps within microseconds of each other: spinning briefly
            // avoids parking the thread and paying the wake-up on almost every message.
            let mut got = None;
            let start = std::time::Instant::now();
            while start.elapsed() < self.spin {
                match self.from[f].try_recv() {
                    Ok(m) => {
                        got = Some(m);
                        break;
                    }
                    Err(std::sync::mpsc::TryRecvError::Empty) => std::hint::spin_loop(),
                    Err(std::sync::mpsc::TryRecvError::Disconnected) => break,
                }
            }
            let (t, msg) = match got.map(Ok).unwrap_or_else(|| self.from[f].recv()) {
                Ok(m) => m,
                Err(_) => panic!("worker {f} stopped before sending to worker {}", self.rank),
            };
            assert_eq!(
                t, tag,
                "message order broken between workers {f} and {} (tag {t}, expected {tag})",
                self.rank
            );
            let old = std::mem::replace(recv, msg);
            let _ = self.give_back[f].send(old);
        }
    }
}

/// Reductions and gathers for output, built on point-to-point messages so that both transports
/// share them. Sums are taken in rank order, so they are the same run after run.
pub struct Team<T: Transport> {
    pub transport: T,
    buf: Vec<u8>,
    tag: u32,
}

/// Tags of collective messages start here; exchange stages use small tags.
const COLLECTIVE_TAG: u32 = 1 << 20;

impl<T: Transport> Team<T> {
    pub fn new(transport: T) -> Self {
        Team {
            transport,
            buf: Vec::new(),
            tag: COLLECTIVE_TAG,
        }
    }

    pub fn rank(&self) -> usize {
        self.transport.rank()
    }

    pub fn size(&self) -> usize {
        self.transport.size()
    }

    pub fn is_root(&self) -> bool {
        self.rank() == 0
    }

    fn next_tag(&mut self) -> u32 {
        self.tag = self.tag.wrapping_add(1).max(COLLECTIVE_TAG);
        self.tag
    }

    /// Every worker's bytes, in rank order, on the root; `None` elsewhere.
    pub fn gather(&mut self, mine: &[u8]) -> Option<Vec<Vec<u8>>> {
        let tag = self.next_tag();
        if self.is_root() {
            let mut all = vec![mine.to_vec()];
            for r in 1..self.size() {
                self.transport
                    .exchange(tag, None, &[], Some(r), &mut self.buf);
                all.push(std::mem::take(&mut self.buf));
            }
            Some(all)
        } else {
            self.transport
                .exchange(tag, Some(0), mine, None, &mut self.buf);
            None
        }
    }

    /// The root's bytes on every worker.
    pub fn broadcast(&mut self, bytes: &mut Vec<u8>) {
        let tag = self.next_tag();
        if self.is_root() {
            for r in 1..self.size() {
                self.transport
                    .exchange(tag, Some(r), bytes, None, &mut self.buf);
            }
        } else {
            self.transport.exchange(tag, None, &[], Some(0), bytes);
        }
    }

    /// Sends `out[r]` to each worker r; returns what every worker sent here, in rank order
    /// (this worker's own included). One message to and from every other worker, in rounds
    /// around the ring, so no two workers wait on each other.
    pub fn all_to_all(&mut self, mut out: Vec<Vec<u8>>) -> Vec<Vec<u8>> {
        let (n, me) = (self.size(), self.rank());
        assert_eq!(out.len(), n, "one message per worker");
        let tag = self.next_tag();
        let mut got = vec![Vec::new(); n];
        got[me] = std::mem::take(&mut out[me]);
        for k in 1..n {
            let (to, from) = ((me + k) % n, (me + n - k) % n);
            self.transport
                .exchange(tag, Some(to), &out[to], Some(from), &mut got[from]);
        }
        got
    }

    /// The root's `parts[r]` on each worker r (`parts` is read on the root only).
    pub fn scatter(&mut self, mut parts: Vec<Vec<u8>>) -> Vec<u8> {
        assert!(
            !self.is_root() || parts.len() == self.size(),
            "one part per worker"
        );
        let tag = self.next_tag();
        if self.is_root() {
            for (r, part) in parts.iter().enumerate().skip(1) {
                self.transport
                    .exchange(tag, Some(r), part, None, &mut self.buf);
            }
            std::mem::take(&mut parts[0])
        } else {
            let mut got = Vec::new();
            self.transport.exchange(tag, None, &[], Some(0), &mut got);
            got
        }
    }

    /// Element-wise reduction of `values` over all workers (in rank order), known everywhere.
    pub fn reduce(&mut self, values: &mut [f64], op: Reduce) {
        let gathered = self.gather(bytemuck::cast_slice(values));
        let mut out = Vec::new();
        if let Some(all) = gathered {
            let mut acc: Vec<f64> = f64s(&all[0]);
            for b in &all[1..] {
                let v: Vec<f64> = f64s(b);
                for (a, x) in acc.iter_mut().zip(&v) {
                    *a = match op {
                        Reduce::Sum => *a + x,
                        Reduce::Max => a.max(*x),
                        Reduce::Min => a.min(*x),
                    };
                }
            }
            out = bytemuck::cast_slice(&acc).to_vec();
        }
        self.broadcast(&mut out);
        values.copy_from_slice(&f64s(&out));
    }

    pub fn sum(&mut self, v: f64) -> f64 {
        let mut a = [v];
        self.reduce(&mut a, Reduce::Sum);
        a[0]
    }

    pub fn max(&mut self, v: f64) -> f64 {
        let mut a = [v];
        self.reduce(&mut a, Reduce::Max);
        a[0]
    }
}

/// Bytes back to numbers (a received buffer need not be aligned for `f64`).
pub fn f64s(bytes: &[u8]) -> Vec<f64> {
    bytes
        .chunks_exact(8)
        .map(|c| f64::from_ne_bytes(c.try_into().unwrap()))
        .collect()
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reduce {
    Sum,
    Max,
    Min,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threads_exchange_and_reduce() {
        let team = Threads::team(3);
        let results: Vec<(Vec<u8>, f64, f64)> = std::thread::scope(|s| {
            let handles: Vec<_> = team
                .into_iter()
                .map(|t| {
                    s.spawn(move || {
                        let mut team = Team::new(t);
                        let me = team.rank();
                        let n = team.size();
                        // A ring: everyone sends east and receives from the west at once.
                        let mut got = Vec::new();
                        for round in 0..3 {
                            team.transport.exchange(
                                round,
                                Some((me + 1) % n),
                                &[me as u8, round as u8],
                                Some((me + n - 1) % n),
                                &mut got,
                            );
                        }
                        let sum = team.sum(me as f64 + 0.5);
                        let max = team.max(me as f64);
                        (got, sum, max)
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (me, (got, sum, max)) in results.iter().enumerate() {
            assert_eq!(got, &vec![((me + 2) % 3) as u8, 2]);
            assert_eq!(*sum, 0.5 + 1.5 + 2.5);
            assert_eq!(*max, 2.0);
        }
    }

    #[test]
    fn solo_sends_to_itself() {
        let mut t = Solo::new();
        let mut got = Vec::new();
        t.exchange(7, Some(0), &[1, 2, 3], Some(0), &mut got);
        assert_eq!(got, vec![1, 2, 3]);
    }
}
