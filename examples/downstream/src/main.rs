//! A user's program: assembles the finger follower of `models/follower.ron` on its track,
//! advances it 1 s and prints where the tip is and how hard the track pushes on it; then
//! runs it again over a higher bump (a run-time parameter of the model file) and prints the
//! summary a design study keeps; last, lets the tip leave the track (one-sided contact, a
//! method of the `Simulate` trait that `camchain::prelude` brings into scope).

use camchain::prelude::*;

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
    // The same model over a 40 mm bump: no rebuild, the value checked as the build checks
    // the file (a bump above its declared maximum of 50 mm would be an error naming the file).
    let higher = follower::Model::with(&[("bump", 0.04)])?;
    let run = higher.simulate_metrics(higher.assemble()?, &higher.default_settings())?;
    println!(
        "over a 40 mm bump: normal force {:.6} … {:.6} N, lift-off {:?}",
        run.min_normal_force, run.max_normal_force, run.first_lift_off
    );
    // One-sided contact: the tip may leave the track and land again (restitution 0.5).
    let settings = SimSettings {
        integrator: IntegratorKind::Dopri5,
        ..higher.default_settings()
    };
    let free = higher.simulate_unilateral(higher.assemble()?, &settings, 0.5)?;
    let lift_offs = free
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::LiftOff))
        .count();
    let plural = if lift_offs == 1 { "" } else { "s" };
    println!("one-sided contact over a 40 mm bump: {lift_offs} lift-off{plural}");
    Ok(())
}
