//! Ctrl-C during `simulate`: the first one asks the running simulation to stop at its next
//! output sample, so that its partial CSV is completed and closed and the command exits with
//! 130 (128 + SIGINT, as a shell reports an interrupted command); a second one ends the
//! process at once.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Whether an interrupt was requested since [`Interrupt::install`].
#[derive(Debug, Clone)]
pub struct Interrupt(Arc<AtomicBool>);

/// The exit code of an interrupted command.
pub const EXIT_CODE: u8 = 130;

impl Interrupt {
    /// Installs the handler. Where signals cannot be handled, Ctrl-C keeps its default
    /// effect (the process ends; the partial CSV then holds the rows flushed so far).
    pub fn install() -> Self {
        let flag = Arc::new(AtomicBool::new(false));
        // Registered first, so it sees the flag as the previous Ctrl-C left it: set means
        // this is the second one.
        let _ = signal_hook::flag::register_conditional_shutdown(
            signal_hook::consts::SIGINT,
            i32::from(EXIT_CODE),
            Arc::clone(&flag),
        );
        let _ = signal_hook::flag::register(signal_hook::consts::SIGINT, Arc::clone(&flag));
        Interrupt(flag)
    }

    /// True once Ctrl-C has been pressed.
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}
