//! The MPI transport. `cargo test --features mpi` runs this as one rank (Open MPI's singleton
//! start); the same binary started by mpirun checks the messages between ranks:
//! `mpirun -np 4 target/release/deps/mpi_transport-HASH`.
#![cfg(feature = "mpi")]

use pdq::parallel::comm::{Team, Transport};
use pdq::parallel::comm_mpi::{launched_by_mpirun, Mpi};

/// Bytes that say who sent them and when, `len` of them.
fn pattern(sender: usize, round: u32, len: usize) -> Vec<u8> {
    (0..len)
        .map(|i| (i as u32 ^ round ^ (sender as u32 * 101)) as u8)
        .collect()
}

/// One test only: MPI starts once per process, and a failing rank aborts the whole process.
#[test]
fn mpi_transport() {
    let launched = launched_by_mpirun();
    let mpi = Mpi::init().expect("MPI started before this test");
    assert!(Mpi::init().is_none(), "MPI started twice");
    // Open MPI's singleton start sets PMIX_RANK; the answer must not change with it.
    assert_eq!(launched_by_mpirun(), launched);
    let mut team = Team::new(mpi);
    let (me, n) = (team.rank(), team.size());
    if !launched {
        assert_eq!((me, n), (0, 1));
    }
    let (east, west) = ((me + 1) % n, (me + n - 1) % n);

    // A ring, with a message far past MPI's eager limit (on which a blocking send would wait
    // for its receive forever), an empty one, and a tag past the 32767 that MPI guarantees.
    let mut got = Vec::new();
    for (round, len) in [
        (0u32, 3usize),
        (1, 4 << 20),
        (2, 0),
        (3, 5),
        (70_000, 7),
        (3, 1),
    ] {
        let msg = pattern(me, round, len);
        team.transport
            .exchange(round, Some(east), &msg, Some(west), &mut got);
        assert_eq!(got, pattern(west, round, len), "round {round} on rank {me}");
    }

    // Each to itself, large, then a send and a receive in separate calls.
    let big = pattern(me, 9, 3 << 20);
    team.transport
        .exchange(9, Some(me), &big, Some(me), &mut got);
    assert_eq!(got, big);
    team.transport
        .exchange(10, Some(me), b"later", None, &mut got);
    team.transport.exchange(10, None, &[], Some(me), &mut got);
    assert_eq!(got, b"later");

    let sum = team.sum(me as f64 + 0.5);
    assert_eq!(sum, (0..n).map(|r| r as f64 + 0.5).sum::<f64>());
    assert_eq!(team.max(me as f64), (n - 1) as f64);

    let gathered = team.gather(&vec![me as u8; me + 1]);
    if me == 0 {
        let expected: Vec<Vec<u8>> = (0..n).map(|r| vec![r as u8; r + 1]).collect();
        assert_eq!(gathered, Some(expected));
    } else {
        assert_eq!(gathered, None);
    }

    let mut bytes = if me == 0 {
        b"from the root".to_vec()
    } else {
        vec![]
    };
    team.broadcast(&mut bytes);
    assert_eq!(bytes, b"from the root");
}
