//! Generates the N-four-bars that `gen.py` wrote.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    camchain_build::compile_models(&[
        "models/nbar10.ron",
        "models/nbar20.ron",
        "models/nbar40.ron",
        "models/nbar80.ron",
    ])?;
    Ok(())
}
