//! SIGTERM and SIGINT end a run cleanly: the current step finishes, a checkpoint is written,
//! and `pdq run` exits with [`EXIT_INTERRUPTED`] and says how to resume. Cluster schedulers
//! send SIGTERM some time before they kill a job at its wall-time limit. A second SIGINT
//! (Ctrl-C twice) ends the process at once.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// The exit code of a run stopped by a signal after writing its checkpoint (EX_TEMPFAIL from
/// sysexits.h: "try again later").
pub const EXIT_INTERRUPTED: u8 = 75;

static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// Installs the handlers (once per process; later calls do nothing).
pub fn install() -> Result<(), String> {
    if FLAG.get().is_some() {
        return Ok(());
    }
    let flag = Arc::new(AtomicBool::new(false));
    let register = || -> std::io::Result<()> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        // The second SIGINT exits at once (130 = 128 + SIGINT); registered before the flag
        // so that it sees the flag set by the first.
        signal_hook::flag::register_conditional_shutdown(SIGINT, 130, flag.clone())?;
        signal_hook::flag::register(SIGINT, flag.clone())?;
        signal_hook::flag::register(SIGTERM, flag.clone())?;
        Ok(())
    };
    register().map_err(|e| format!("cannot install the SIGTERM/SIGINT handlers: {e}"))?;
    let _ = FLAG.set(flag);
    Ok(())
}

/// True once SIGTERM or SIGINT has arrived (never, if the handlers are not installed).
pub fn requested() -> bool {
    FLAG.get().is_some_and(|f| f.load(Ordering::Relaxed))
}
