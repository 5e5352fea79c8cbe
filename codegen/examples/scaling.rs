//! The scaling study of issue 4 §4, outside the test suite (it compiles and times code):
//!
//! ```text
//! cargo run --release -p camchain-codegen --example scaling -- OUTDIR [--build]
//! ```
//!
//! For the chain family of `tests/common/chain.rs` with N = 2, 4, 8, 16, 32, 64 bodies it
//! writes `OUTDIR/chainN.ron`, generates each (timing the generation), and reports the
//! operations per function and the generated source size. With `--build` it also writes a
//! throwaway crate per N under `OUTDIR/crates/` depending on camchain-runtime by path (one
//! shared target dir, the runtime built first and excluded from the figures), times
//! `cargo build --release` of each, and runs it: the median time per evaluation of
//! `equations` and `constraint_terms`. Results: `OUTDIR/scaling.md` (markdown table) and
//! `OUTDIR/scaling.csv`.

#[path = "support/cargo.rs"]
mod cargo;
#[path = "../tests/common/chain.rs"]
mod chain;

use cargo::{cargo_build, new_crate};

use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

const SIZES: [usize; 6] = [2, 4, 8, 16, 32, 64];
const FUNCTIONS: [&str; 5] = [
    "mass_matrix",
    "inertial_forces",
    "applied_forces",
    "equations",
    "constraint_terms",
];

struct Row {
    n: usize,
    ops: Vec<usize>,
    bytes: usize,
    generate_s: f64,
    build_s: Option<f64>,
    eval_ns: Option<(f64, f64)>,
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.iter().find(|a| !a.starts_with("--")) else {
        eprintln!("usage: scaling OUTDIR [--build]");
        return ExitCode::from(2);
    };
    let build = args.iter().any(|a| a == "--build");
    match run(Path::new(out), build) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(out: &Path, build: bool) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let out = out.canonicalize().map_err(|e| e.to_string())?;
    let runtime = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../runtime")
        .canonicalize()
        .map_err(|e| e.to_string())?;
    let target = out.join("target");
    if build {
        // Build the runtime once, so that its build is not in any N's figure.
        let warm = write_crate(&out, 0, "", &runtime)?;
        cargo_build(&warm, &target, false)?;
    }
    let mut rows = Vec::new();
    for n in SIZES {
        let text = chain::chain_ron(n);
        let file = out.join(format!("chain{n}.ron"));
        std::fs::write(&file, &text).map_err(|e| e.to_string())?;
        let start = Instant::now();
        let model =
            camchain_codegen::schema::parse_model(&text, &file).map_err(|e| e.to_string())?;
        // The measuring crate depends on camchain-runtime alone, not on the facade.
        let options = camchain_codegen::EmitOptions {
            runtime_path: "::camchain_runtime".to_string(),
            ..Default::default()
        };
        let generated =
            camchain_codegen::emit::generate_with(&model, &file.display().to_string(), &options)?;
        let generate_s = start.elapsed().as_secs_f64();
        let ops = FUNCTIONS
            .iter()
            .map(|f| {
                generated
                    .op_counts
                    .iter()
                    .find(|(name, _)| name == f)
                    .map_or(0, |(_, c)| c.total())
            })
            .collect();
        let mut row = Row {
            n,
            ops,
            bytes: generated.code.len(),
            generate_s,
            build_s: None,
            eval_ns: None,
        };
        if build {
            let dir = write_crate(&out, n, &generated.code, &runtime)?;
            let start = Instant::now();
            cargo_build(&dir, &target, false)?;
            row.build_s = Some(start.elapsed().as_secs_f64());
            let exe = target.join("release").join(format!("scaling_chain{n}"));
            let output = Command::new(&exe)
                .output()
                .map_err(|e| format!("{}: {e}", exe.display()))?;
            let text = String::from_utf8_lossy(&output.stdout);
            let v: Vec<f64> = text
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            if v.len() == 2 {
                row.eval_ns = Some((v[0], v[1]));
            }
        }
        eprintln!("N = {n}: done");
        rows.push(row);
    }
    let (md, csv) = report(&rows);
    std::fs::write(out.join("scaling.md"), &md).map_err(|e| e.to_string())?;
    std::fs::write(out.join("scaling.csv"), &csv).map_err(|e| e.to_string())?;
    print!("{md}");
    Ok(())
}

/// A crate `scaling_chainN` whose main times the generated functions.
fn write_crate(out: &Path, n: usize, code: &str, runtime: &Path) -> Result<PathBuf, String> {
    let dir = new_crate(
        out,
        &format!("chain{n}"),
        &format!("scaling_chain{n}"),
        runtime,
    )?;
    let main = if code.is_empty() {
        "fn main() {}\n".to_string()
    } else {
        std::fs::write(dir.join("src/model.rs"), code).map_err(|e| e.to_string())?;
        format!(
            "#[allow(dead_code)]\nmod model;\nuse camchain_runtime::Dynamics;\nuse std::hint::black_box;\n\
             fn time(mut f: impl FnMut()) -> f64 {{\n    let mut samples = Vec::new();\n    \
             for _ in 0..7 {{\n        let reps = 2000;\n        let t = std::time::Instant::now();\n        \
             for _ in 0..reps {{ f(); }}\n        samples.push(t.elapsed().as_secs_f64() * 1e9 / reps as f64);\n    }}\n    \
             samples.sort_by(f64::total_cmp);\n    samples[3]\n}}\n\
             fn main() {{\n    let n = {n};\n    let m = model::Model;\n    \
             let q: Vec<f64> = (0..n).map(|i| 0.1 + 0.01 * i as f64).collect();\n    \
             let qd: Vec<f64> = (0..n).map(|i| 0.2 - 0.01 * i as f64).collect();\n    \
             let (mut mm, mut f, mut a) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);\n    \
             let (mut j, mut c) = (vec![0.0; n], vec![0.0; 1]);\n    \
             let te = time(|| m.equations(0.0, black_box(&q), black_box(&qd), &mut mm, &mut f, &mut a));\n    \
             let tc = time(|| m.constraint_terms(black_box(&q), black_box(&qd), &mut j, &mut c));\n    \
             black_box((&mm, &f, &a, &j, &c));\n    println!(\"{{te}} {{tc}}\");\n}}\n"
        )
    };
    std::fs::write(dir.join("src/main.rs"), main).map_err(|e| e.to_string())?;
    Ok(dir)
}

fn report(rows: &[Row]) -> (String, String) {
    let mut md = String::from(
        "| N | M | F | Q | equations | constraint_terms | code [bytes] | generation [s] | build [s] | equations [ns] | constraint_terms [ns] |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "n,mass_matrix,inertial_forces,applied_forces,equations,constraint_terms,code_bytes,generate_s,build_s,equations_ns,constraint_terms_ns\n",
    );
    let opt = |v: Option<f64>, p: usize| v.map_or("–".to_string(), |x| format!("{x:.p$}"));
    for r in rows {
        let (te, tc) = (r.eval_ns.map(|e| e.0), r.eval_ns.map(|e| e.1));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {:.3} | {} | {} | {} |",
            r.n,
            r.ops[0],
            r.ops[1],
            r.ops[2],
            r.ops[3],
            r.ops[4],
            r.bytes,
            r.generate_s,
            opt(r.build_s, 1),
            opt(te, 0),
            opt(tc, 0)
        );
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{}",
            r.n,
            r.ops[0],
            r.ops[1],
            r.ops[2],
            r.ops[3],
            r.ops[4],
            r.bytes,
            r.generate_s,
            opt(r.build_s, 3),
            opt(te, 1),
            opt(tc, 1)
        );
    }
    (md, csv)
}
