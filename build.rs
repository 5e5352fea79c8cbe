//! Compiles the built-in models (`models/*.ron`) through `camchain-build`, the same API a
//! user's build script calls, and, with the `random-models` feature, the random models
//! of the property tests (`tests/random_models/*.ron`) and the contact test models
//! (`tests/contact_models/*.ron`), not user-facing.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    camchain_build::Config::new()
        // The command line draws the mechanism and runs `--numeric` from the model text.
        .embed_model_source(true)
        .include_file("models.rs")
        .compile_models(&["models"])?;
    // Set by cargo when the `random-models` feature is on (this package's own tests).
    if std::env::var_os("CARGO_FEATURE_RANDOM_MODELS").is_some() {
        let out = std::path::PathBuf::from(std::env::var("OUT_DIR")?).join("random_models");
        // The articulated-body sweeps: tests/suite/random_compiled.rs compares them with the
        // numeric reference and runs them against the reference's simulations. Written with
        // `mul_add`, as a build for a processor with FMA writes them, so that this text is
        // checked on every machine (without FMA enabled, `mul_add` calls the C library's
        // exact `fma`: the same values, slower).
        camchain_build::Config::new()
            .out_dir(out)
            .formulation(camchain_build::Formulation::Articulated)
            .fused_multiply_add(true)
            .include_file("random_models.rs")
            .compile_models(&["tests/random_models"])?;
        // The contact kinds the built-in models do not use (tests/suite/contacts_compiled.rs).
        let contacts = std::path::PathBuf::from(std::env::var("OUT_DIR")?).join("contact_models");
        camchain_build::Config::new()
            .out_dir(contacts)
            .include_file("contact_models.rs")
            .compile_models(&["tests/contact_models"])?;
    }
    // Set by cargo when the `parameter-modes` feature is on (this package's own tests): the
    // built-in models again with every parameter folded and with every parameter read at
    // run time (compared by tests/suite/parameters.rs), and the test models of parameter checks.
    if std::env::var_os("CARGO_FEATURE_PARAMETER_MODES").is_some() {
        let out = std::path::PathBuf::from(std::env::var("OUT_DIR")?);
        // Every built-in model but n_four_bar, paper_surface, paper_convex_text and
        // driven_convex. n_four_bar's 81 links are forty copies of four_bar's (compared in
        // both modes), one parameter (gravity) is all it reads at run time, and its two extra
        // copies were 1.4 MB of the 8.8 MB this crate's tests compile. paper_surface is
        // paper_concave's chain (compared in both modes) on a turret, its surface contact that
        // of paraboloid_orbit (compared in both modes); its two copies were 187 kB, the
        // largest of the spatial cams'. paper_convex_text and driven_convex are paper_convex
        // and driven_concave (compared in both modes) with other values of the same
        // parameters, so the same code in each mode; their copies were 320 kB.
        let mut files: Vec<std::path::PathBuf> = std::fs::read_dir("models")?
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .filter(|path| path.extension().is_some_and(|e| e == "ron"))
            .filter(|path| {
                path.file_stem().is_some_and(|s| {
                    ![
                        "n_four_bar",
                        "paper_surface",
                        "paper_convex_text",
                        "driven_convex",
                    ]
                    .iter()
                    .any(|skipped| s == *skipped)
                })
            })
            .collect();
        files.sort();
        // The second copy also gets the articulated-body sweeps, checked against the folded
        // copy's dense M, F and Q (tests/common/articulated.rs) and taking that route in
        // every run of it.
        for (dir, mode, formulation) in [
            (
                "folded",
                camchain_build::ParameterMode::FoldAll,
                camchain_build::Formulation::Auto,
            ),
            (
                "all_at_run_time",
                camchain_build::ParameterMode::AllAtRunTime,
                camchain_build::Formulation::Articulated,
            ),
        ] {
            // Entry points as calls of the fused pair: the comparison reads values, not the
            // standalone expressions (the built-in models' own copies test those), and the
            // two copies compile in less time.
            camchain_build::Config::new()
                .out_dir(out.join(dir))
                .parameters(mode)
                .formulation(formulation)
                .entry_points(camchain_build::EntryPoints::ViaFusedPair)
                .include_file("models.rs")
                .compile_models(&files)?;
        }
        camchain_build::Config::new()
            .out_dir(out.join("parameter_models"))
            .include_file("models.rs")
            .compile_models(&["tests/parameter_models"])?;
    }
    Ok(())
}
