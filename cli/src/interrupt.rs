//! Ctrl-C (SIGINT) and SIGTERM (what a batch scheduler sends at a job's time limit) during
//! `simulate` and `sweep`: the first one asks the running simulations to stop at their next
//! step (the runtime reads the flag after every step, so within a step's time, far below a
//! second), the partial outputs are completed and closed, and the command exits with 130
//! (128 + SIGINT) or 143 (128 + SIGTERM), as a shell reports a command killed by that
//! signal; a second signal of either kind ends the process at once with the same code.

use crate::CliError;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Whether an interrupt was requested since [`Interrupt::install`], and by which signal.
#[derive(Debug, Clone)]
pub struct Interrupt {
    /// Set by either signal.
    any: Arc<AtomicBool>,
    /// Set by SIGTERM.
    term: Arc<AtomicBool>,
}

/// The exit code of a command interrupted by Ctrl-C (128 + SIGINT).
pub const EXIT_CODE: u8 = 130;

/// The exit code of a command stopped by SIGTERM (128 + SIGTERM).
pub const TERM_EXIT_CODE: u8 = 143;

impl Interrupt {
    /// Installs the handlers. Where signals cannot be handled, they keep their default
    /// effect (the process ends; a partial CSV then holds the rows flushed so far).
    pub fn install() -> Self {
        let any = Arc::new(AtomicBool::new(false));
        let term = Arc::new(AtomicBool::new(false));
        // Registered first, so they see the flag as the previous signal left it: set means
        // this is the second one.
        for (signal, code) in [
            (signal_hook::consts::SIGINT, EXIT_CODE),
            (signal_hook::consts::SIGTERM, TERM_EXIT_CODE),
        ] {
            let _ = signal_hook::flag::register_conditional_shutdown(
                signal,
                i32::from(code),
                Arc::clone(&any),
            );
        }
        let _ = signal_hook::flag::register(signal_hook::consts::SIGTERM, Arc::clone(&term));
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            let _ = signal_hook::flag::register(signal, Arc::clone(&any));
        }
        Interrupt { any, term }
    }

    /// True once Ctrl-C or SIGTERM has arrived.
    pub fn requested(&self) -> bool {
        self.any.load(Ordering::Relaxed)
    }

    /// The flag the simulations read after every step (`camchain_runtime::Cancel`).
    pub fn flag(&self) -> &AtomicBool {
        &self.any
    }

    /// "Ctrl-C" or "SIGTERM", for the message that says where the run stopped.
    pub fn signal_name(&self) -> &'static str {
        if self.term.load(Ordering::Relaxed) {
            "SIGTERM"
        } else {
            "Ctrl-C"
        }
    }

    /// The command's error once interrupted: exit code 130 after Ctrl-C, 143 after SIGTERM.
    pub fn error(&self) -> CliError {
        CliError::Interrupted {
            code: if self.term.load(Ordering::Relaxed) {
                TERM_EXIT_CODE
            } else {
                EXIT_CODE
            },
        }
    }
}
