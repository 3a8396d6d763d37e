//! The MPI transport: one worker per MPI rank, so that a run can span machines.
//!
//! Only point-to-point messages are used, so that everything above [`Transport`] (the exchange
//! plan, the reductions of [`crate::parallel::comm::Team`]) is the same code that the threads run, and a
//! run on MPI ranks gives the same numbers as one on threads.

use std::os::raw::c_int;
use std::sync::OnceLock;
use std::thread::ThreadId;

use mpi::attribute::{AttributeKey, CommAttribute};
use mpi::environment::{Threading, Universe};
use mpi::point_to_point::{Destination, Source};
use mpi::topology::{AnyCommunicator, Communicator, SimpleCommunicator};
use mpi::traits::Equivalence;

use crate::parallel::comm::Transport;

/// Variables that launchers set in the processes they start: Open MPI's mpirun (`OMPI_*`, and
/// `PMIX_RANK` from its PMIx server), and the PMI of MPICH's hydra and of Slurm's srun.
const LAUNCHER_VARIABLES: [&str; 4] = ["OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"];

/// Whether this process was started by an MPI launcher, so that a caller can start MPI only
/// then: a plain start needs no MPI, and Open MPI's singleton start forks a helper daemon.
///
/// The answer is fixed at the first call, which [`Mpi::init`] makes before starting MPI: a
/// singleton start sets `PMIX_RANK` in this process, and would turn the answer to `true`.
pub fn launched_by_mpirun() -> bool {
    static LAUNCHED: OnceLock<bool> = OnceLock::new();
    *LAUNCHED.get_or_init(|| {
        LAUNCHER_VARIABLES
            .iter()
            .any(|v| std::env::var_os(v).is_some())
    })
}

/// The MPI ranks of one run.
pub struct Mpi {
    world: SimpleCommunicator,
    /// Owned here so that MPI is finalized when the transport is dropped, after its last message;
    /// `None` when a [`Job`] owns it ([`Mpi::job`]).
    _universe: Option<Universe>,
    /// MPI tags are only guaranteed up to 32767, and the collective tags of `Team` are larger,
    /// so tags travel modulo this span (`MPI_TAG_UB + 1`, 2^31 with Open MPI: exact in practice).
    tag_span: u32,
    /// The thread that started MPI, when MPI only allows calls from that thread.
    home: Option<ThreadId>,
}

// SAFETY: the communicator is `MPI_COMM_WORLD`, a handle valid in every thread until `MPI_Finalize`;
// `Mpi` is not `Sync` and `exchange` takes `&mut self`, so calls are serialized, which is all that
// `MPI_THREAD_SERIALIZED` asks; where MPI gives less, `exchange` checks that it runs on `home`.
unsafe impl Send for Mpi {}

impl Mpi {
    /// Starts MPI; `None` if it was started before in this process (it can be started only once,
    /// and that start's `Mpi` owns it). Without a launcher this is a run of one rank.
    pub fn init() -> Option<Mpi> {
        // Serialized, not Single: the transport may be moved to a worker thread (test harnesses
        // run each test on its own thread), and MPI ties Single and Funneled to the main thread.
        launched_by_mpirun();
        let (universe, provided) = mpi::initialize_with_threading(Threading::Serialized)?;
        let world = universe.world();
        let tag_ub = world.get_attr::<TagUb>().map_or(32767, |t| t.0).max(32767);
        Some(Mpi {
            world,
            _universe: Some(universe),
            tag_span: tag_ub as u32 + 1,
            home: (provided < Threading::Serialized).then(|| std::thread::current().id()),
        })
    }

    /// Starts MPI for a run ([`Mpi::init`]): the transport, and the [`Job`] that ends MPI once
    /// the run's result is known.
    pub fn job() -> Option<(Job, Mpi)> {
        let mut mpi = Mpi::init()?;
        let universe = mpi._universe.take();
        Some((
            Job {
                universe,
                rank: mpi.rank(),
                size: mpi.size(),
            },
            mpi,
        ))
    }

    fn rank_in_world(&self, worker: usize) -> mpi::Rank {
        match mpi::Rank::try_from(worker) {
            Ok(r) if worker < self.size() => r,
            _ => panic!("worker {worker} of {}", self.size()),
        }
    }
}

impl Drop for Mpi {
    fn drop(&mut self) {
        // A rank that panics would otherwise finalize MPI while unwinding, which waits for ranks
        // that are themselves waiting for its messages; aborting ends the whole job instead.
        if std::thread::panicking() {
            self.world.abort(1);
        }
    }
}

/// MPI for the length of one run, apart from the transport that the run's procCube owns.
///
/// A rank that meets an error the others do not (a file it cannot read, a setup that fails
/// on its procCube alone) would otherwise return while its neighbours wait for its next
/// message, and hang in `MPI_Finalize` while they hang in their receives. [`Job::end`]
/// instead prints the error with the rank's number and aborts the whole job, so that every
/// rank stops and `mpirun` names the rank that aborted.
pub struct Job {
    universe: Option<Universe>,
    rank: usize,
    size: usize,
}

impl Job {
    /// Ends MPI after a run: finalizes it on success (and on one rank); on an error with
    /// several ranks prints it, naming this rank, and aborts every rank (exit code 1).
    pub fn end<T>(mut self, result: Result<T, String>) -> Result<T, String> {
        match result {
            Err(e) if self.size > 1 => {
                eprintln!("error on rank {} of {}: {e}", self.rank, self.size);
                eprintln!("stopping every rank (MPI_Abort)");
                SimpleCommunicator::world().abort(1)
            }
            r => {
                drop(self.universe.take());
                r
            }
        }
    }
}

/// The testing aid `PDQ_TEST_FAIL_RANK=K`: rank K (alone) fails once its procCube is built,
/// as a rank meeting an error of its own would (tests/mpi_runs.rs); not for users.
pub fn injected_failure(rank: usize) -> Result<(), String> {
    match std::env::var("PDQ_TEST_FAIL_RANK")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        Some(k) if k == rank => Err(format!(
            "rank {rank} failed on purpose (PDQ_TEST_FAIL_RANK={k})"
        )),
        _ => Ok(()),
    }
}

/// `MPI_TAG_UB`, an attribute that MPI sets on `MPI_COMM_WORLD` (rsmpi has no accessor).
#[repr(C)]
#[derive(Clone)]
struct TagUb(c_int);

impl CommAttribute for TagUb {
    fn get_key() -> AttributeKey {
        // SAFETY: a predefined keyval, valid while MPI is initialized.
        unsafe { AttributeKey::new_unchecked(mpi::ffi::MPI_TAG_UB as c_int) }
    }
}

impl Transport for Mpi {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn exchange(
        &mut self,
        tag: u32,
        to: Option<usize>,
        send: &[u8],
        from: Option<usize>,
        recv: &mut Vec<u8>,
    ) {
        if let Some(home) = self.home {
            assert_eq!(
                home,
                std::thread::current().id(),
                "this MPI allows calls only from the thread that started it"
            );
        }
        let mpi_tag = (tag % self.tag_span) as mpi::Tag;
        // Ranks are checked before the send starts: a panic while it is pending aborts the
        // process without a message.
        let to = to.map(|t| self.rank_in_world(t));
        let from = from.map(|f| self.rank_in_world(f));
        let world = &self.world;
        let got_tag = mpi::request::scope(|scope| {
            // The send is immediate so that two ranks sending each other messages too large for
            // MPI to buffer both reach their receives, and so that a rank can send to itself.
            let sending = to.map(|t| {
                world
                    .process_at_rank(t)
                    .immediate_send_with_tag(scope, send, mpi_tag)
            });
            // Any tag: the message is the next one from `from` (MPI keeps order between two
            // ranks), as with the other transports, and a wrong tag then fails the check below
            // instead of leaving this rank waiting for a message that never comes.
            let got_tag = from.map(|f| {
                let (message, status) = world.process_at_rank(f).matched_probe();
                let len = status.count(u8::equivalent_datatype()) as usize;
                // Reuses the buffer's capacity: steady stepping allocates nothing.
                recv.clear();
                recv.resize(len, 0);
                message.matched_receive_into(&mut recv[..]);
                status.tag()
            });
            if let Some(s) = sending {
                s.wait_without_status();
            }
            got_tag
        });
        if let (Some(f), Some(t)) = (from, got_tag) {
            assert_eq!(
                t,
                mpi_tag,
                "message order broken between ranks {f} and {} (tag {t}, expected {mpi_tag})",
                self.world.rank()
            );
        }
    }
}
