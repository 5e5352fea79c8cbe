//! Parsing an expression keeps no memory once its result is dropped.
//!
//! The `syn`-based parser this crate had lexed through proc-macro2, whose span locations keep
//! a copy of every lexed text in a thread-local source map for the life of the thread: a
//! sweep on a model file, which parses the model again for every run, grew each worker by the
//! size of the model's expressions per run (and proc-macro2's 32-bit positions overflow after
//! 4 GiB). This test counts the bytes a thread holds across parses with a counting allocator.

use camchain_model::profile::parse_expression;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    /// Bytes allocated and not yet freed by this thread.
    static HELD: Cell<isize> = const { Cell::new(0) };
}

/// The system allocator, counting per thread.
struct Counting;

fn count(bytes: usize, sign: isize) {
    let bytes = isize::try_from(bytes).unwrap_or(isize::MAX);
    // `try_with`: nothing to count while the thread's locals are torn down.
    let _ = HELD.try_with(|held| held.set(held.get() + sign * bytes));
}

// SAFETY: every call is forwarded to `System` unchanged; the counting touches a
// constant-initialised thread-local `Cell`, which allocates nothing.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's guarantees for `layout` are System's.
        let pointer = unsafe { System.alloc(layout) };
        if !pointer.is_null() {
            count(layout.size(), 1);
        }
        pointer
    }

    unsafe fn dealloc(&self, pointer: *mut u8, layout: Layout) {
        // SAFETY: `pointer` was allocated by `alloc` above with `layout`.
        unsafe { System.dealloc(pointer, layout) };
        count(layout.size(), -1);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn held() -> isize {
    HELD.with(Cell::get)
}

#[test]
fn parsing_keeps_no_memory_per_expression() {
    let sources = [
        "0.12*(2.0*x).sin() + 0.05*(4.0*x).cos() - x.powi(3)/6.0 + (1.0 + x*x).sqrt()",
        "x + y",
        "x.powi(2.5)",
    ];
    let parse_all = || {
        for source in sources {
            drop(parse_expression(source, "x"));
        }
    };
    // Once, for anything allocated on first use.
    parse_all();
    let before = held();
    for _ in 0..1000 {
        parse_all();
    }
    let kept = held() - before;
    // 3000 parses of 100 bytes of text: the old parser kept over 100 kB (each text and its
    // line table). Nothing should remain; 1 kB of slack is less than a byte per parse, so
    // any memory kept per parse fails.
    assert!(kept < 1024, "{kept} bytes kept after 3000 parses");
}
