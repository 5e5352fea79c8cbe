//! `camchain`: the command line. `cargo run --release` simulates the paper's two cams,
//! prints a summary of each run and writes CSV and figures to `out/`; see `camchain --help`
//! and the README.

fn main() -> std::process::ExitCode {
    camchain_cli::main()
}
