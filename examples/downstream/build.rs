// Compiles models/follower.ron into `$OUT_DIR/camchain/follower.rs`; a bad model stops the
// build with `models/follower.ron:line:column: field: message`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    camchain_build::compile_models(&["models/follower.ron"])?;
    Ok(())
}
