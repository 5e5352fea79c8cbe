//! Tests of the reader on its own (the comparison with ron is in `differential.rs`).
