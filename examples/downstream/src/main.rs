//! A user's program: assembles the finger follower of `models/follower.ron` on its track,
//! advances it 1 s and prints where the tip is and how hard the track pushes on it.

mod follower {
    camchain::include_model!("follower");
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = follower::Model::default();
    let mut state = model.assemble()?;
    model.step(&mut state, 1.0)?;
    let sample = model.sample(&state)?;
    let tip = &sample.contacts[0];
    println!("t = {:.3} s", sample.t);
    println!(
        "tip at x = {:.6} m, y = {:.6} m",
        tip.position[0], tip.position[1]
    );
    println!("normal force {:.6} N", sample.normal_force[0]);
    println!("constraint residual h = {:.2e} m", sample.h[0]);
    Ok(())
}
