//! A family of generated chains for the scaling study (issue 4 §4): N bodies in series,
//! joint kinds and axes cycling through revolute z, revolute y, prismatic along a skew axis
//! and revolute about (1, 1, 0), so consecutive axes are not all parallel; off-axis centres
//! of mass, diagonal inertias, a spring-damper in every joint, gravity along −z, and a cam
//! contact at the tip in a tilted plane.

/// The RON text of the N-body chain.
pub fn chain_ron(n: usize) -> String {
    spatial_chain(n, true)
}

/// The chain of [`chain_ron`] without its marker and contact: the unconstrained mechanism
/// that Pinocchio's `aba` is timed on (`scripts/bench/pinocchio`).
#[allow(dead_code)] // used by the formulations example, not by every test binary
pub fn free_chain_ron(n: usize) -> String {
    spatial_chain(n, false)
}

fn spatial_chain(n: usize, contact: bool) -> String {
    let mut bodies = String::new();
    for i in 0..n {
        let (kind, axis) = match i % 4 {
            0 => ("Revolute", "(0.0, 0.0, 1.0)"),
            1 => ("Revolute", "(0.0, 1.0, 0.0)"),
            2 => ("Prismatic", "(0.8, 0.6, 0.0)"),
            _ => ("Revolute", "(1.0, 1.0, 0.0)"),
        };
        let parent = if i == 0 {
            "ground".to_string()
        } else {
            format!("b{}", i - 1)
        };
        let anchor = if i == 0 {
            "(0.0, 0.0, 0.5)"
        } else {
            "(0.2, 0.0, 0.0)"
        };
        let mass = 1.0 + 0.1 * (i % 3) as f64;
        bodies.push_str(&format!(
            "        (name: \"b{i}\", parent: \"{parent}\", mass: {mass:?}, com: (0.1, 0.01, -0.005), \
             inertia: Diagonal(0.002, 0.003, 0.004), joint: (kind: {kind}, axis: {axis}, \
             anchor: {anchor}, coordinate: \"q{i}\", spring: (stiffness: 10.0, damping: 0.5, rest: 0.0))),\n"
        ));
    }
    let tip = if contact {
        format!(
            "    markers: [(name: \"tip\", body: \"b{last}\", position: (0.2, 0.0, 0.0))],\n    \
             contacts: [(marker: \"tip\", profile: \"0.1*x.sin() - 0.05*x*x\", frame: (origin: \
             (0.0, 0.0, 0.0), x_axis: (1.0, 0.0, 0.0), y_axis: (0.0, 0.6, 0.8)))],\n",
            last = n - 1
        )
    } else {
        String::new()
    };
    format!(
        "(\n    name: \"chain{n}\",\n    description: \"Scaling study: {n}-body chain.\",\n    \
         gravity: (0.0, 0.0, -9.81),\n    bodies: [\n{bodies}    ],\n{tip}    \
         simulation: (t_end: 1.0, dt_out: 0.01),\n)\n"
    )
}

/// The RON text of an N-body planar pendulum chain: every joint revolute about z, links of
/// 0.2 m with the centre of mass at mid-length, a spring-damper in every joint, gravity
/// along −y, no contact. Its absolute joint angles are sums through every joint below, so
/// its expressions are as deep as the chain is long.
#[allow(dead_code)] // used by the test suite, not by the scaling example
pub fn planar_chain_ron(n: usize) -> String {
    let mut bodies = String::new();
    for i in 0..n {
        let parent = if i == 0 {
            "ground".to_string()
        } else {
            format!("b{}", i - 1)
        };
        let anchor = if i == 0 {
            "(0.0, 0.0, 0.0)"
        } else {
            "(0.2, 0.0, 0.0)"
        };
        bodies.push_str(&format!(
            "        (name: \"b{i}\", parent: \"{parent}\", mass: 1.0, com: (0.1, 0.0, 0.0), \
             inertia: Izz(0.003), joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), \
             anchor: {anchor}, coordinate: \"q{i}\", spring: (stiffness: 10.0, damping: 0.5, \
             rest: 0.0))),\n"
        ));
    }
    format!(
        "(\n    name: \"planar{n}\",\n    description: \"A planar chain of {n} bodies.\",\n    \
         gravity: (0.0, -9.81, 0.0),\n    bodies: [\n{bodies}    ],\n    \
         simulation: (t_end: 1.0, dt_out: 0.01),\n)\n"
    )
}

/// The planar chain of [`planar_chain_ron`] with its tip on a cam: a knife edge at the far
/// end of the last link on the profile y = 0.05 sin x − 0.1 in the ground's plane (the
/// planar counterpart of [`chain_ron`]'s contact).
#[allow(dead_code)] // used by the formulations example, not by every test binary
pub fn planar_contact_ron(n: usize) -> String {
    let plain = planar_chain_ron(n);
    let tip = format!(
        "    markers: [(name: \"tip\", body: \"b{last}\", position: (0.2, 0.0, 0.0))],\n    \
         contacts: [(marker: \"tip\", profile: \"0.05*x.sin() - 0.1\")],\n    simulation:",
        last = n - 1
    );
    plain
        .replacen(
            &format!("name: \"planar{n}\""),
            &format!("name: \"planar_contact{n}\""),
            1,
        )
        .replacen("    simulation:", &tip, 1)
}
