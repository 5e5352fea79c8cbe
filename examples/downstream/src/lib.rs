//! The user's model as an FMU's library (FMI 3.0 Co-Simulation): `cargo build --lib` builds
//! `libdownstream.so`, and `camchain fmu --library target/debug/libdownstream.so` packs it with
//! the `modelDescription.xml` it describes itself (docs/fmu.md, "From your crate").

mod follower {
    camchain::include_model!("follower");
}

camchain::fmu::export!(follower::boxed);
