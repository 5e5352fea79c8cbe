//! Checks model files the way the build does and prints the first problem of each:
//! `cargo run -p camchain-codegen --example check_model -- models/*.ron`.

use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut status = ExitCode::SUCCESS;
    for arg in std::env::args().skip(1) {
        let path = Path::new(&arg);
        match camchain_codegen::generate_file(path, path) {
            Ok(g) => {
                println!("{arg}: ok, model `{}`", g.name);
                for (name, count) in &g.op_counts {
                    println!("  {name:<24} {count}");
                }
            }
            Err(e) => {
                eprintln!("error: {e}");
                status = ExitCode::FAILURE;
            }
        }
    }
    status
}
