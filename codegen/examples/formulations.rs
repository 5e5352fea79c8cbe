//! The two forward-dynamics formulations side by side (issue 30), outside the test suite (it
//! compiles and times code):
//!
//! ```text
//! cargo run --release -p camchain-codegen --example formulations -- OUTDIR [--native] [N ...]
//! ```
//!
//! `--native` builds the measured crates for this machine's processor (`-C
//! target-cpu=native`, as `scripts/bench/pinocchio` builds Pinocchio with `-march=native`).
//!
//! For the chains of `tests/common/chain.rs` (the spatial chain with its tip on a cam, and
//! the planar chain with its tip on a cam) with N bodies (default 4, 8, 16, 32, 64), it
//! generates each model twice, the dense route and the articulated-body sweeps asked for,
//! builds one throwaway crate per model holding both (release, one shared target directory,
//! the runtime built first and excluded), and times in one run, interleaved batch by batch:
//!
//! - `derivative_at`, the constrained reduced right-hand side f(t, y) (Newton on the
//!   dependent coordinate, velocities, accelerations, λ), at the integrated vectors of 8
//!   states 1 ms apart along the model's run taken in turn (so every call computes its sines
//!   and cosines): what an integrator calls, given t and y as Pinocchio's `aba` is given q,
//!   v and τ;
//! - `derivative` at the same states, each written into a `State` first (t, q, q̇ copied):
//!   the right-hand side as a caller holding q and q̇ gets it, which also rebuilds y from
//!   them (the figure of the sessions before `derivative_at` existed);
//! - the unconstrained forward dynamics, on the same chain without its contact (the
//!   mechanism Pinocchio's `aba` is timed on), generated again on both routes, at 8 states of
//!   its own run: `position_terms` + `articulated_terms` (articulated), `position_terms` +
//!   `velocity_terms` and an LDLᵀ solve of M q̈ = −(F + Q) (dense).
//!
//! Medians of 31 batches (each ≥ 2 ms of the thread's CPU time, which leaves out the time
//! it was preempted, as `scripts/bench/pinocchio` does) in ns per call. Also the operation counts and the
//! choice `Formulation::Auto` makes. Results: `OUTDIR/formulations.md` and `.csv`.

#[path = "support/cargo.rs"]
mod cargo;
#[path = "../tests/common/chain.rs"]
mod chain;

use cargo::{cargo_build, new_crate};

use camchain_codegen::{EmitOptions, Formulation};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

const SIZES: [usize; 5] = [4, 8, 16, 32, 64];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first() else {
        eprintln!("usage: formulations OUTDIR [--native] [N ...]");
        return ExitCode::from(2);
    };
    let mut sizes = Vec::new();
    let native = args[1..].iter().any(|a| a == "--native");
    for a in args[1..].iter().filter(|a| *a != "--native") {
        match a.parse::<usize>() {
            Ok(n) if n >= 1 => sizes.push(n),
            _ => {
                eprintln!("error: `{a}` is not a number of bodies (an integer ≥ 1)");
                return ExitCode::from(2);
            }
        }
    }
    if sizes.is_empty() {
        sizes = SIZES.to_vec();
    }
    match run(Path::new(out), &sizes, native) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(out: &Path, sizes: &[usize], native: bool) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let out = out.canonicalize().map_err(|e| e.to_string())?;
    let runtime = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../runtime")
        .canonicalize()
        .map_err(|e| e.to_string())?;
    // Builds for the native processor have a target directory of their own.
    let target = out.join(if native { "target-native" } else { "target" });
    let warm = write_crate(&out, "warm", &[], &runtime)?;
    cargo_build(&warm, &target, native)?;
    let mut md = String::from(
        "| family | N | auto chooses | dense ops (velocity_terms) | articulated ops (terms + response per row) | rhs dense [ns] | rhs articulated [ns] | dense / articulated | rhs from a state, dense [ns] | … articulated [ns] | unconstrained ops (articulated) | unconstrained dense [ns] | unconstrained articulated [ns] |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut csv = String::from(
        "family,n,auto,dense_ops,articulated_ops,response_ops,rhs_dense_ns,rhs_articulated_ns,state_rhs_dense_ns,state_rhs_articulated_ns,free_ops,free_dense_ns,free_articulated_ns\n",
    );
    for &n in sizes {
        for (family, text, free_text) in [
            ("spatial", chain::chain_ron(n), chain::free_chain_ron(n)),
            (
                "planar",
                chain::planar_contact_ron(n),
                chain::planar_chain_ron(n),
            ),
        ] {
            let name = format!("{family}{n}");
            // The model file written out, parsed, and a function generating it on a route.
            let model_of = |file: PathBuf, text: &str| -> Result<_, String> {
                std::fs::write(&file, text).map_err(|e| e.to_string())?;
                let model = camchain_codegen::schema::parse_model(text, &file)
                    .map_err(|e| e.to_string())?;
                Ok(move |formulation| {
                    let options = EmitOptions {
                        runtime_path: "::camchain_runtime".to_string(),
                        formulation,
                        // Native builds have FMA (as `camchain_build::Config` finds it).
                        fused_multiply_add: native,
                        ..Default::default()
                    };
                    let path = file.display().to_string();
                    camchain_codegen::emit::generate_with(&model, &path, &options)
                })
            };
            let generate = model_of(out.join(format!("{name}.ron")), &text)?;
            let generate_free = model_of(out.join(format!("{name}_free.ron")), &free_text)?;
            let ops = |g: &camchain_codegen::Generated, f: &str| {
                g.op_counts
                    .iter()
                    .find(|(name, _)| name == f)
                    .map_or(0, |(_, c)| c.total())
            };
            let dense = generate(Formulation::Dense)?;
            let articulated = generate(Formulation::Articulated)?;
            let auto = generate(Formulation::Auto)?;
            let chosen = if ops(&auto, "articulated_terms") > 0 {
                "articulated"
            } else {
                "dense"
            };
            let (free_dense, free_articulated) = (
                generate_free(Formulation::Dense)?,
                generate_free(Formulation::Articulated)?,
            );
            let dir = write_crate(
                &out,
                &name,
                &[
                    ("dense", &dense.code),
                    ("articulated", &articulated.code),
                    ("free_dense", &free_dense.code),
                    ("free_articulated", &free_articulated.code),
                ],
                &runtime,
            )?;
            cargo_build(&dir, &target, native)?;
            let exe = target.join("release").join(format!("formulations_{name}"));
            let output = Command::new(&exe)
                .output()
                .map_err(|e| format!("{}: {e}", exe.display()))?;
            if !output.status.success() {
                return Err(format!(
                    "{name}: {}",
                    String::from_utf8_lossy(&output.stderr)
                ));
            }
            let v: Vec<f64> = String::from_utf8_lossy(&output.stdout)
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            let [sd, sa, fd, fa, rd, ra] = v[..] else {
                return Err(format!("{name}: unexpected output {v:?}"));
            };
            let (d_ops, a_ops, r_ops) = (
                ops(&dense, "velocity_terms"),
                ops(&articulated, "articulated_terms"),
                ops(&articulated, "articulated_response"),
            );
            let free_ops = ops(&free_articulated, "articulated_terms");
            // A chain's one contact row is solved within the sweeps: no response is called.
            let route_ops = if articulated.code.contains("fn articulated_rows") {
                format!("{a_ops} (row within)")
            } else {
                format!("{a_ops} + {r_ops}")
            };
            let _ = writeln!(
                md,
                "| {family} | {n} | {chosen} | {d_ops} | {route_ops} | {rd:.0} | {ra:.0} | {:.2}× | {sd:.0} | {sa:.0} | {free_ops} | {fd:.0} | {fa:.0} |",
                rd / ra
            );
            let _ = writeln!(
                csv,
                "{family},{n},{chosen},{d_ops},{a_ops},{r_ops},{rd:.1},{ra:.1},{sd:.1},{sa:.1},{free_ops},{fd:.1},{fa:.1}"
            );
            eprintln!("{name}: done");
        }
    }
    std::fs::write(out.join("formulations.md"), &md).map_err(|e| e.to_string())?;
    std::fs::write(out.join("formulations.csv"), &csv).map_err(|e| e.to_string())?;
    print!("{md}");
    Ok(())
}

/// A crate `formulations_NAME` holding the modules `modules` and timing them.
fn write_crate(
    out: &Path,
    name: &str,
    modules: &[(&str, &str)],
    runtime: &Path,
) -> Result<PathBuf, String> {
    let dir = new_crate(out, name, &format!("formulations_{name}"), runtime)?;
    let mut main = String::new();
    for (module, code) in modules {
        std::fs::write(dir.join(format!("src/{module}.rs")), code).map_err(|e| e.to_string())?;
        let _ = writeln!(main, "#[allow(dead_code, clippy::all)]\nmod {module};");
    }
    if modules.is_empty() {
        main.push_str("fn main() {}\n");
    } else {
        main.push_str(TIMING);
    }
    std::fs::write(dir.join("src/main.rs"), main).map_err(|e| e.to_string())?;
    Ok(dir)
}

/// The measuring program: both modules' models, the same states, batches interleaved.
const TIMING: &str = r#"
use camchain_runtime::{Dynamics, Simulate, State, VelocityTerms, ArticulatedTerms, SolvedRow};
use std::hint::black_box;

fn states(model: &dyn Simulate) -> Vec<State> {
    let mut state = model.assemble(0.0).expect("assembles");
    let mut out = Vec::new();
    for _ in 0..8 {
        model.step(&mut state, 1e-3).expect("steps");
        out.push(state.clone());
    }
    out
}

#[repr(C)]
struct Timespec {
    seconds: i64,
    nanoseconds: i64,
}

unsafe extern "C" {
    fn clock_gettime(clock: i32, time: *mut Timespec) -> i32;
}

/// This thread's CPU time (s): leaves out the time the thread was preempted, as the
/// Pinocchio benchmark's CPU figures do (scripts/bench/pinocchio).
fn thread_time() -> f64 {
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut t = Timespec { seconds: 0, nanoseconds: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer.
    unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.seconds as f64 + t.nanoseconds as f64 * 1e-9
}

fn batch(f: &mut dyn FnMut()) -> f64 {
    let mut reps = 1;
    loop {
        let t = thread_time();
        for _ in 0..reps {
            f();
        }
        let s = thread_time() - t;
        if s >= 2e-3 {
            return s * 1e9 / reps as f64;
        }
        reps *= 2;
    }
}

fn rhs<'a>(model: &'a dyn Simulate, states: &'a [State]) -> impl FnMut() + 'a {
    let mut current = states[0].clone();
    let mut dy = vec![0.0; current.integrated_len()];
    let mut k = 0;
    move || {
        let next = &states[k % states.len()];
        k += 1;
        current.t = next.t;
        current.q.copy_from_slice(&next.q);
        current.qd.copy_from_slice(&next.qd);
        model.derivative(&mut current, &mut dy).expect("a consistent state");
        black_box(&dy);
    }
}

/// The same right-hand side on y (`derivative_at`), the states' integrated vectors taken
/// in turn: what an integrator calls at its stages, given t and y as Pinocchio's `aba` is
/// given q, v and τ.
fn rhs_at<'a>(model: &'a dyn Simulate, states: &'a [State]) -> impl FnMut() + 'a {
    let mut current = states[0].clone();
    let ys: Vec<(f64, Vec<f64>)> = states
        .iter()
        .map(|s| {
            assert_eq!(s.dependent(), current.dependent(), "one partition throughout");
            (s.t, s.integrated())
        })
        .collect();
    let mut dy = vec![0.0; current.integrated_len()];
    let mut k = 0;
    move || {
        let (t, y) = &ys[k % ys.len()];
        k += 1;
        model.derivative_at(&mut current, *t, y, &mut dy).expect("a consistent state");
        black_box(&dy);
    }
}

/// Unconstrained forward dynamics, dense: the fused pair and an LDLᵀ solve of M.
fn free_dense<'a>(model: &'a dyn Dynamics, states: &'a [State]) -> impl FnMut() + 'a {
    let info = model.info();
    let (n, m) = (info.n(), info.n_constraints());
    let (mut h, mut j, mut cache) = (vec![0.0; m], vec![0.0; m * n], vec![0.0; model.cache_len()]);
    let (mut mass, mut f, mut a, mut c) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n], vec![0.0; m]);
    let mut x = vec![0.0; n];
    let mut k = 0;
    move || {
        let s = &states[k % states.len()];
        k += 1;
        model.position_terms(&s.q, &mut h, &mut j, &mut cache);
        let out = VelocityTerms { mass: &mut mass, inertial: &mut f, applied: &mut a, bias: &mut c };
        model.velocity_terms(s.t, &s.q, &s.qd, &cache, out);
        // L D Lᵀ in place (lower triangle), then the solve.
        for col in 0..n {
            let mut d = mass[col * n + col];
            for p in 0..col {
                let l = mass[col * n + p];
                d -= l * l * mass[p * n + p];
            }
            mass[col * n + col] = d;
            for r in col + 1..n {
                let mut v = mass[r * n + col];
                for p in 0..col {
                    v -= mass[r * n + p] * mass[col * n + p] * mass[p * n + p];
                }
                mass[r * n + col] = v / d;
            }
        }
        for i in 0..n {
            let mut v = -(f[i] + a[i]);
            for p in 0..i {
                v -= mass[i * n + p] * x[p];
            }
            x[i] = v;
        }
        for i in 0..n {
            x[i] /= mass[i * n + i];
        }
        for i in (0..n).rev() {
            let mut v = x[i];
            for p in i + 1..n {
                v -= mass[p * n + i] * x[p];
            }
            x[i] = v;
        }
        black_box(&x);
    }
}

/// Unconstrained forward dynamics, articulated: the position level and the sweeps.
fn free_articulated<'a>(model: &'a dyn Dynamics, states: &'a [State]) -> impl FnMut() + 'a {
    let info = model.info();
    let (n, m) = (info.n(), info.n_constraints());
    let (mut h, mut j, mut cache) = (vec![0.0; m], vec![0.0; m * n], vec![0.0; model.cache_len()]);
    let (mut qdd, mut drive, mut c) = (vec![0.0; n], vec![0.0; n], vec![0.0; m]);
    let mut k = 0;
    move || {
        let s = &states[k % states.len()];
        k += 1;
        model.position_terms(&s.q, &mut h, &mut j, &mut cache);
        // No factors: the runtime passes none when no row is solved (no response is called).
        let out = ArticulatedTerms { qdd: &mut qdd, drive: &mut drive, bias: &mut c, factors: &mut [], row: &[], solved: &mut SolvedRow::default() };
        model.articulated_terms(s.t, &s.q, &s.qd, &cache, out);
        black_box(&qdd);
    }
}

fn main() {
    let dense = dense::Model;
    let articulated = articulated::Model;
    let (unconstrained_dense, unconstrained) = (free_dense::Model, free_articulated::Model);
    let free_states = states(&unconstrained);
    let states = states(&articulated);
    let mut fns: Vec<Box<dyn FnMut()>> = vec![
        Box::new(rhs(&dense, &states)),
        Box::new(rhs(&articulated, &states)),
        Box::new(free_dense(&unconstrained_dense, &free_states)),
        Box::new(free_articulated(&unconstrained, &free_states)),
        Box::new(rhs_at(&dense, &states)),
        Box::new(rhs_at(&articulated, &states)),
    ];
    let mut samples = vec![Vec::new(); fns.len()];
    for _ in 0..31 {
        for (f, s) in fns.iter_mut().zip(samples.iter_mut()) {
            s.push(batch(f.as_mut()));
        }
    }
    for s in &mut samples {
        s.sort_by(f64::total_cmp);
        print!("{} ", s[s.len() / 2]);
    }
    println!();
}
"#;
