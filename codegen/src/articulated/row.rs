//! One constraint row solved within the sweeps (docs/method.md §14.6), for a model whose
//! constraints are one row (a single cam contact): instead of the runtime calling the
//! response and forming J M⁻¹ Jᵀ from it, the main function takes that row of J and
//! returns q̈ with the row's force, in one forward sweep.
//!
//! The forward sweep is linear in its inputs, the free joints' rates r and the driven
//! joints' q̈_d, and the backward sweep of a generalised force τ (the response's) is its
//! adjoint: with ũ and p̃ from that sweep for τ = J (ũ_i = J_i − S_iᵀ p̃_i, p̃_i the bias
//! joint i receives from its children),
//!
//! ```text
//! J_f q̈_f = Σ_free ũ_i r_i / D_i − Σ_driven S_dᵀ p̃_d q̈_d
//! ```
//!
//! whatever r and q̈_d are. So, u the main sweep's rates, J q̈⁰ + c and the Delassus
//! number J_f M_ff⁻¹ J_fᵀ (the first with r = u, the second with r = ũ and q̈_d = 0) come
//! out of the backward sweeps alone:
//!
//! ```text
//! λ = (c + Σ_free ũ_i u_i / D_i + Σ_driven (J_d − S_dᵀ p̃_d) q̈_d) / Σ_free ũ_i² / D_i
//! q̈ = forward sweep with r = u − λ ũ,   τ_d = transmitted(p^A − λ p̃) + passive + λ J_d
//! ```
//!
//! which is (14) with J q̈ + c = 0 (8): q̈ = q̈⁰ − λ M_ff⁻¹ J_fᵀ. The response's forward
//! sweep, the run-time products with J and the combination are no longer done. A weight w
//! (1 when the row is given, 0 when not) makes λ = w · num / (den + 1 − w): without the
//! row (a contact the runtime does not solve) the same code gives q̈⁰, as ũ and λ are 0.

use super::{ArticulatedTerms, Joint, backward_of, drive_load, forward_of, project};
use super::{accelerations_with_gravity, add_force, scale_force};
use crate::contact::contact_terms;
use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Symbols, minus_gravity, vec3};
use crate::model::Model;

/// Adds the solved row's terms to `out`: `joints` are the main sweep's, `bias` the row's c.
pub(super) fn solve_within(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
    joints: &[Option<Joint>],
    bias: Id,
    out: &mut ArticulatedTerms,
) {
    let n = joints.len();
    let row: Vec<Id> = (model.bodies.iter())
        .map(|b| g.var(&format!("__row_{}", b.joint.coordinate)))
        .collect();
    let weight = g.var("__row_weight");
    let (rates, passing) = backward_of(g, model, kin, joints, &row, "the solved row's J");
    g.set_section("the solved row's multiplier".to_string());
    let (mut numerator, mut delassus) = (bias, g.zero());
    for i in 0..n {
        let (Some(joint), Some(p)) = (joints[i], passing[i]) else {
            break;
        };
        match (joint.d_inverse, rates[i]) {
            (Some(d_inverse), Some(r)) => {
                g.label(r, format!("row_rate_{}", model.bodies[i].joint.coordinate));
                let scaled = g.mul(r, d_inverse);
                let a = g.mul(scaled, joint.rate);
                numerator = g.add(numerator, a);
                let b = g.mul(scaled, r);
                delassus = g.add(delassus, b);
            }
            _ => {
                let sp = project(g, model.bodies[i].joint.kind, kin[i].axis, p);
                let coefficient = g.sub(row[i], sp);
                let a = g.mul(coefficient, joint.rate);
                numerator = g.add(numerator, a);
            }
        }
    }
    let one = g.one();
    let unsolved = g.sub(one, weight);
    let divisor = g.add(delassus, unsolved);
    let weighted = g.mul(weight, numerator);
    let lambda = g.div(weighted, divisor);
    g.label(lambda, "row_lambda".to_string());
    g.label(delassus, "row_delassus".to_string());
    let combined: Vec<Option<Joint>> = (0..n)
        .map(|i| {
            let joint = joints[i]?;
            Some(match rates[i] {
                Some(r) => {
                    let lr = g.mul(lambda, r);
                    let rate = g.sub(joint.rate, lr);
                    Joint { rate, ..joint }
                }
                None => {
                    let minus = g.neg(lambda);
                    let pushed = scale_force(g, minus, passing[i]?);
                    let bias = add_force(g, joint.bias, pushed);
                    Joint { bias, ..joint }
                }
            })
        })
        .collect();
    let section = |i: usize| {
        format!(
            "{}: acceleration of joint {} with the row's force",
            model.bodies[i].name, model.bodies[i].joint.coordinate
        )
    };
    forward_of(
        g,
        model,
        kin,
        &combined,
        section,
        |g, i, joint, qdd, after| match joint.d_inverse {
            Some(_) => out.solved_accelerations.push((i, qdd)),
            None => {
                let load = drive_load(g, model, s, kin, (i, joint), after);
                let pushed = g.mul(lambda, row[i]);
                out.solved_drive_loads.push((i, g.add(load, pushed)));
            }
        },
    );
    out.row = row;
    out.row_weight = Some(weight);
    out.row_solution = Some((lambda, delassus));
}

/// The c of a model's one contact row as the sweeps take it: the follower body's
/// velocity-product acceleration, which the contact reads on long paths, written as
/// a⁰ − R_bᵀ(−g) from the sweeps' a⁰ ([`accelerations_with_gravity`]), so that the sweeps
/// need no recursion of the plain acceleration besides a⁰'s (R_b, the body's absolute
/// rotation, is the position level's). The same c as the contact's own to rounding; the
/// other bodies' kinematics, and any contact that reads no acceleration, are unchanged.
pub(crate) fn contact_row_bias(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
) -> Option<Id> {
    let [contact] = model.contacts.as_slice() else {
        return None;
    };
    let body = model.markers.get(contact.marker)?.body;
    let a0 = *accelerations_with_gravity(g, model, s, kin).get(body)?;
    let minus_g = minus_gravity(g, model, s);
    let mut swept = kin.to_vec();
    let own = &mut swept[body];
    let gravity = own.rotation.apply_transpose(g, minus_g);
    own.accel = vec3::sub(g, a0, gravity);
    contact_terms(g, model, &swept, s).first().map(|c| c.bias)
}
