//! Forward dynamics by the articulated-body algorithm (Featherstone's ABA, in its hybrid
//! form for prescribed joints) on symbolic expressions: the O(n) alternative to forming M
//! and factoring it, which costs O(n²) operations to form and O(n³) to factor.
//!
//! Everything is written in each body's own frame about its joint point, as the rest of the
//! derivation is, with spatial vectors split into (angular, linear) parts: a motion
//! (ω̇, a) of the joint point, a force (n, f) with its moment about the joint point.
//!
//! The accelerations are split as a = a⁰ + δa, a⁰ the velocity-product part the forward
//! recursion already gives (`alpha`, `accel`, with gravity as an upward acceleration of the
//! ground added), so that δa obeys a recursion without bias terms: δa_i = X_i δa_parent +
//! S_i q̈_i (S_i the joint's axis, angular for a revolute joint, linear for a prismatic
//! one). With p_i the body's own load at δa = 0 (its inertial loads at q̈ = 0 and its
//! weight), the backward sweep (tip to root) forms
//!
//! ```text
//! I^A_i = I_i + Σ_c X_cᵀ I^a_c X_c        p^A_i = p_i + Σ_c X_cᵀ p^a_c
//! free joint:   U = I^A S, D = Sᵀ U, u = τ − Sᵀ p^A,
//!               I^a = I^A − U Uᵀ / D,  p^a = p^A + U u / D
//! driven joint: U = I^A S, I^a = I^A,  p^a = p^A + U q̈_d
//! ```
//!
//! and the forward sweep (root to tip) δa' = X δa_parent, q̈ = (u − Uᵀ δa') / D (free),
//! δa = δa' + S q̈. τ is the generalised load of the joint's spring, damper and applied load
//! (−Q's part of them); a driven joint's load, what its drive supplies, is
//! Sᵀ (I^A δa + p^A) + Q's part, the row of M q̈ + F + Q.
//!
//! Constraints enter through a second, cheaper function, the response: the same sweeps
//! with every velocity, weight, load and prescribed acceleration zero and a generalised force
//! τ given at run time, giving M_ff⁻¹ τ (f: the free coordinates) and the driven rows
//! M_df M_ff⁻¹ τ. It reads U, 1/D and the joint transforms from the first function's
//! outputs (the "factors"); the runtime calls it once per constraint row to form
//! J M⁻¹ Jᵀ (docs/method.md §14).
//!
//! Joint specialisation comes from the expression graph: S is a constant axis, so a
//! revolute joint about z reads one column of I^A; rotations about a coordinate axis have
//! four non-trivial entries; a planar chain's out-of-plane terms are structural zeros.

use crate::dynamics::{Inertia, body_inertia, children, force_to_parent, spring_damper_load};
use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Symbols, V3, minus_gravity, vec3};
use crate::model::{JointKind, Model};

/// The articulated-body terms of a model.
#[derive(Debug, Clone, Default)]
pub struct ArticulatedTerms {
    /// (coordinate, variable): the prescribed q̈ of every driven coordinate, an input.
    pub driven: Vec<(usize, Id)>,
    /// The generalised force the response applies, one variable per coordinate (those of
    /// driven coordinates unused).
    pub tau: Vec<Id>,
    /// (coordinate, q̈): every free coordinate's acceleration without constraint forces.
    pub accelerations: Vec<(usize, Id)>,
    /// (coordinate, load): every driven coordinate's row of M q̈ + F + Q at those
    /// accelerations.
    pub drive_loads: Vec<(usize, Id)>,
    /// (coordinate, q̈): the response M_ff⁻¹ τ on the free coordinates.
    pub response: Vec<(usize, Id)>,
    /// (coordinate, load): the response's driven rows, M_df M_ff⁻¹ τ.
    pub response_loads: Vec<(usize, Id)>,
    /// The variables of a vector x, one per coordinate, and M(q) x: the mass matrix's
    /// product by the same recursions (O(n) operations), so that a model on this route can
    /// give M column by column without emitting its n² entries.
    pub mass_x: Vec<Id>,
    /// M(q) x, one entry per coordinate.
    pub mass_product: Vec<Id>,
    /// A model with one constraint row solves it within the sweeps (docs/method.md §14.6):
    /// that row of J, one variable per coordinate, given at run time (empty for other
    /// models).
    pub row: Vec<Id>,
    /// 1 when the row is given and solved, 0 when not (q̈ then without its force): a variable.
    pub row_weight: Option<Id>,
    /// (λ, J_f M_ff⁻¹ J_fᵀ) of the row.
    pub row_solution: Option<(Id, Id)>,
    /// The row's c as the sweeps compute it (a contact's from their accelerations,
    /// `contact_row_bias`): the same value as the constraint's own.
    pub row_bias: Option<Id>,
    /// (coordinate, q̈): every free coordinate's acceleration with the row's force.
    pub solved_accelerations: Vec<(usize, Id)>,
    /// (coordinate, load): every driven coordinate's row of M q̈ + F + Q + Jᵀ λ.
    pub solved_drive_loads: Vec<(usize, Id)>,
}

impl ArticulatedTerms {
    /// Every expression the terms hold (the inputs, variables, left out).
    pub(crate) fn roots_mut(&mut self) -> impl Iterator<Item = &mut Id> {
        let pairs = self
            .accelerations
            .iter_mut()
            .chain(&mut self.drive_loads)
            .chain(&mut self.response)
            .chain(&mut self.response_loads)
            .chain(&mut self.solved_accelerations)
            .chain(&mut self.solved_drive_loads)
            .map(|(_, id)| id);
        let solution = self.row_solution.iter_mut().flat_map(|(l, d)| [l, d]);
        let bias = self.row_bias.iter_mut();
        pairs
            .chain(&mut self.mass_product)
            .chain(solution)
            .chain(bias)
    }
}

/// A spatial force: moment about the frame's origin, force.
#[derive(Debug, Clone, Copy)]
struct Force {
    n: V3,
    f: V3,
}

/// A spatial acceleration: angular, and linear of the frame's origin.
#[derive(Debug, Clone, Copy)]
struct Motion {
    w: V3,
    v: V3,
}

/// A symmetric 6×6 articulated inertia [[A, B], [Bᵀ, C]] acting on (ω̇, a) to give (n, f):
/// A and C symmetric (both triangles hold the same ids), B general.
#[derive(Debug, Clone, Copy)]
struct Articulated {
    a: [V3; 3],
    b: [V3; 3],
    c: [V3; 3],
}

/// What the backward sweep keeps of a joint for the forward sweep.
#[derive(Debug, Clone, Copy)]
struct Joint {
    /// I^A S.
    u: Force,
    /// 1 / D (free joints).
    d_inverse: Option<Id>,
    /// u = τ − Sᵀ p^A (free joints) or q̈_d (driven ones).
    rate: Id,
    /// p^A.
    bias: Force,
}

/// Derives the articulated-body terms of `model` on its kinematics; with `row_bias`, the c of
/// the model's one constraint row, that row solved within the sweeps as well
/// (docs/method.md §14.6).
pub fn articulated(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
    row_bias: Option<Id>,
) -> ArticulatedTerms {
    let n = model.n();
    // Nodes the other terms already hold keep their names (the dense code is unchanged).
    let first_new = g.len();
    let name = |g: &mut Graph, id: Id, label: String| {
        if id.index() >= first_new {
            g.label(id, label);
        }
    };
    let names: Vec<&str> = model
        .bodies
        .iter()
        .map(|b| b.joint.coordinate.as_str())
        .collect();
    let driven: Vec<(usize, Id)> = (0..n)
        .filter(|&i| model.bodies[i].joint.prescribed.is_some())
        .map(|i| (i, g.var(&format!("__qdd_{}", names[i]))))
        .collect();
    let tau: Vec<Id> = (0..n)
        .map(|i| g.var(&format!("__tau_{}", names[i])))
        .collect();
    let prescribed = |i: usize| driven.iter().find(|d| d.0 == i).map(|d| d.1);
    let accelerations = accelerations_with_gravity(g, model, s, kin);
    // The main sweeps.
    let mut inertia: Vec<Option<Articulated>> = vec![None; n];
    let mut loads: Vec<Option<Force>> = vec![None; n];
    let mut joints: Vec<Option<Joint>> = vec![None; n];
    let kids = children(model);
    for i in (0..n).rev() {
        if g.exhausted() {
            break;
        }
        g.set_section(format!(
            "{}: articulated inertia and bias force (joint {})",
            model.bodies[i].name, names[i]
        ));
        let body = body_inertia(g, model, s, i);
        let mut big = rigid(g, &body);
        let mut bias = own_loads(g, &kin[i], accelerations[i], &body);
        for &c in &kids[i] {
            if let (Some(ic), Some(pc)) = (inertia[c].take(), loads[c].take()) {
                let moved = inertia_to_parent(g, &kin[c], &ic);
                big = add(g, &big, &moved);
                let (n_p, f_p) = force_to_parent(g, &kin[c], pc.n, pc.f);
                bias = Force {
                    n: vec3::add(g, bias.n, n_p),
                    f: vec3::add(g, bias.f, f_p),
                };
            }
        }
        let kind = model.bodies[i].joint.kind;
        let axis = kin[i].axis;
        let u = column(g, &big, kind, axis);
        let (joint, reduced, passed) = match prescribed(i) {
            Some(qdd) => {
                let pushed = Force {
                    n: vec3::scale(g, qdd, u.n),
                    f: vec3::scale(g, qdd, u.f),
                };
                let passed = add_force(g, bias, pushed);
                let joint = Joint {
                    u,
                    d_inverse: None,
                    rate: qdd,
                    bias,
                };
                (joint, big, passed)
            }
            None => {
                let d = project(g, kind, axis, u);
                name(g, d, format!("articulated_d_{}", names[i]));
                let one = g.one();
                let d_inverse = g.div(one, d);
                let load = passive_load(g, model, s, i);
                let sp = project(g, kind, axis, bias);
                let tau_i = g.neg(load);
                let rate = g.sub(tau_i, sp);
                let w = per_unit_rate(g, d_inverse, u, kind, model.bodies[i].joint.axis);
                let mut reduced = subtract_outer(g, &big, u, w);
                clear_joint_direction(g, &mut reduced, kind, model.bodies[i].joint.axis);
                let pushed = scale_force(g, rate, w);
                let passed = add_force(g, bias, pushed);
                let joint = Joint {
                    u,
                    d_inverse: Some(d_inverse),
                    rate,
                    bias,
                };
                (joint, reduced, passed)
            }
        };
        joints[i] = Some(joint);
        inertia[i] = Some(reduced);
        loads[i] = Some(passed);
    }
    let mut out = ArticulatedTerms {
        driven: driven.clone(),
        tau: tau.clone(),
        ..Default::default()
    };
    // Forward sweep of the main solve.
    let main_section = |i: usize| {
        format!(
            "{}: acceleration of joint {} (forward sweep)",
            model.bodies[i].name, names[i]
        )
    };
    forward_of(
        g,
        model,
        kin,
        &joints,
        main_section,
        |g, i, joint, qdd, after| match joint.d_inverse {
            Some(_) => {
                name(g, qdd, format!("qdd_{}", names[i]));
                out.accelerations.push((i, qdd));
            }
            None => {
                let load = drive_load(g, model, s, kin, (i, joint), after);
                name(g, load, format!("drive_load_{}", names[i]));
                out.drive_loads.push((i, load));
            }
        },
    );
    // The response: the same sweeps with τ and nothing else.
    let section = "response to a generalised force";
    let (rates, passing) = backward_of(g, model, kin, &joints, &tau, section);
    let response_joints: Vec<Option<Joint>> = (0..n)
        .map(|i| {
            let joint = joints[i]?;
            let zero = g.zero();
            Some(Joint {
                rate: rates[i].unwrap_or(zero),
                bias: passing[i]?,
                ..joint
            })
        })
        .collect();
    let response_section =
        |i: usize| format!("{}: {section} (forward sweep)", model.bodies[i].name);
    forward_of(
        g,
        model,
        kin,
        &response_joints,
        response_section,
        |g, i, joint, qdd, after| match joint.d_inverse {
            Some(_) => out.response.push((i, qdd)),
            None => {
                let rows = transmitted(g, model, kin, i, joint, after);
                out.response_loads.push((i, rows));
            }
        },
    );
    if let Some(c) = row_bias {
        out.row_bias = Some(c);
        row::solve_within(g, model, s, kin, &joints, c, &mut out);
    }
    (out.mass_x, out.mass_product) = mass_product(g, model, s, kin, &names);
    out
}

/// The backward sweep of a generalised force `tau` alone (every velocity, weight, load and
/// prescribed acceleration zero) on the factors of `joints`: each free joint's rate
/// u = τ − Sᵀ p and each joint's p before its own (the bias its driven rows read).
fn backward_of(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    joints: &[Option<Joint>],
    tau: &[Id],
    section: &str,
) -> (Vec<Option<Id>>, Vec<Option<Force>>) {
    let n = joints.len();
    let kids = children(model);
    let mut passed: Vec<Option<Force>> = vec![None; n];
    let mut rates: Vec<Option<Id>> = vec![None; n];
    let mut before: Vec<Option<Force>> = vec![None; n];
    for i in (0..n).rev() {
        let Some(joint) = joints[i] else { break };
        g.set_section(format!(
            "{}: {section} (backward sweep)",
            model.bodies[i].name
        ));
        let zero = vec3::zero(g);
        let mut bias = Force { n: zero, f: zero };
        for &c in &kids[i] {
            if let Some(pc) = passed[c].take() {
                let (n_p, f_p) = force_to_parent(g, &kin[c], pc.n, pc.f);
                bias = add_force(g, bias, Force { n: n_p, f: f_p });
            }
        }
        let kind = model.bodies[i].joint.kind;
        passed[i] = Some(match joint.d_inverse {
            Some(d_inverse) => {
                let sp = project(g, kind, kin[i].axis, bias);
                let rate = g.sub(tau[i], sp);
                let w = per_unit_rate(g, d_inverse, joint.u, kind, model.bodies[i].joint.axis);
                let pushed = scale_force(g, rate, w);
                rates[i] = Some(rate);
                add_force(g, bias, pushed)
            }
            None => bias,
        });
        before[i] = Some(bias);
    }
    (rates, before)
}

/// The forward sweep (root to tip) on `joints`' rates, factors and driven accelerations:
/// `visit(g, i, joint, q̈_i, δa_i)` for every joint in turn, in the section `section(i)`.
fn forward_of(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    joints: &[Option<Joint>],
    section: impl Fn(usize) -> String,
    mut visit: impl FnMut(&mut Graph, usize, &Joint, Id, Motion),
) {
    let mut motion: Vec<Option<Motion>> = vec![None; joints.len()];
    for (i, joint) in joints.iter().enumerate() {
        let Some(joint) = joint else { break };
        g.set_section(section(i));
        let before = incoming(g, model, kin, &motion, i);
        let (qdd, after) = joint_acceleration(g, model, kin, i, joint, before);
        visit(g, i, joint, qdd, after);
        motion[i] = Some(after);
    }
}

/// M(q) x by the recursions without velocities, weights or loads: the accelerations of the
/// joint rates x forward (A1), each body's inertial load I δa, summed from the tip and
/// projected on its joint.
fn mass_product(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
    names: &[&str],
) -> (Vec<Id>, Vec<Id>) {
    let n = model.n();
    let x: Vec<Id> = names.iter().map(|c| g.var(&format!("__x_{c}"))).collect();
    let mut motion: Vec<Option<Motion>> = vec![None; n];
    for i in 0..n {
        if g.exhausted() {
            break;
        }
        g.set_section(format!(
            "{}: acceleration for M x (forward sweep)",
            model.bodies[i].name
        ));
        let before = incoming(g, model, kin, &motion, i);
        motion[i] = Some(with_joint_rate(g, model, kin, i, before, x[i]));
    }
    let kids = children(model);
    let mut loads: Vec<Option<Force>> = vec![None; n];
    let mut product = vec![g.zero(); n];
    for i in (0..n).rev() {
        let Some(a) = motion[i] else { continue };
        g.set_section(format!(
            "{}: inertial load for M x (backward sweep)",
            model.bodies[i].name
        ));
        let body = body_inertia(g, model, s, i);
        let rigid = rigid(g, &body);
        let mut load = apply(g, &rigid, a);
        for &c in &kids[i] {
            if let Some(lc) = loads[c].take() {
                let (n_p, f_p) = force_to_parent(g, &kin[c], lc.n, lc.f);
                load = add_force(g, load, Force { n: n_p, f: f_p });
            }
        }
        product[i] = project(g, model.bodies[i].joint.kind, kin[i].axis, load);
        loads[i] = Some(load);
    }
    (x, product)
}

/// I a: the load of an inertia for an acceleration (n = A ω̇ + B a, f = Bᵀ ω̇ + C a).
fn apply(g: &mut Graph, i: &Articulated, a: Motion) -> Force {
    let aw = mat_vec(g, &i.a, a.w);
    let bv = mat_vec(g, &i.b, a.v);
    let bt = transpose(&i.b);
    let btw = mat_vec(g, &bt, a.w);
    let cv = mat_vec(g, &i.c, a.v);
    Force {
        n: vec3::add(g, aw, bv),
        f: vec3::add(g, btw, cv),
    }
}

/// The parent's δa seen at body i's joint point, in body i's frame (zero at the ground):
/// ω̇ = Rᵀ ω̇_p, a = Rᵀ (a_p + ω̇_p × r).
fn incoming(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    motion: &[Option<Motion>],
    i: usize,
) -> Motion {
    let zero = vec3::zero(g);
    let Some(parent) = model.bodies[i].parent.and_then(|p| motion[p]) else {
        return Motion { w: zero, v: zero };
    };
    let k = &kin[i];
    let lever = vec3::cross(g, parent.w, k.offset);
    let at_joint = vec3::add(g, parent.v, lever);
    Motion {
        w: k.relative.apply_transpose(g, parent.w),
        v: k.relative.apply_transpose(g, at_joint),
    }
}

/// q̈ of joint i (free: (u − Uᵀ δa') / D; driven: its prescribed value) and body i's δa.
fn joint_acceleration(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    i: usize,
    joint: &Joint,
    before: Motion,
) -> (Id, Motion) {
    let qdd = match joint.d_inverse {
        Some(d_inverse) => {
            let un = vec3::dot(g, joint.u.n, before.w);
            let uf = vec3::dot(g, joint.u.f, before.v);
            let ua = g.add(un, uf);
            let free = g.sub(joint.rate, ua);
            g.mul(d_inverse, free)
        }
        None => joint.rate,
    };
    (qdd, with_joint_rate(g, model, kin, i, before, qdd))
}

/// δa = δa′ + S q̈: the joint's rate along its axis, angular or linear.
fn with_joint_rate(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    i: usize,
    before: Motion,
    qdd: Id,
) -> Motion {
    let step = vec3::scale(g, qdd, kin[i].axis);
    match model.bodies[i].joint.kind {
        JointKind::Revolute => Motion {
            w: vec3::add(g, before.w, step),
            v: before.v,
        },
        JointKind::Prismatic => Motion {
            w: before.w,
            v: vec3::add(g, before.v, step),
        },
    }
}

/// Sᵀ (I^A δa + p^A) of a driven joint, written Uᵀ δa + Sᵀ p^A (I^A is symmetric).
fn transmitted(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    i: usize,
    joint: &Joint,
    after: Motion,
) -> Id {
    let un = vec3::dot(g, joint.u.n, after.w);
    let uf = vec3::dot(g, joint.u.f, after.v);
    let ua = g.add(un, uf);
    let sp = project(g, model.bodies[i].joint.kind, kin[i].axis, joint.bias);
    g.add(ua, sp)
}

/// A driven joint's row of M q̈ + F + Q: [`transmitted`] plus its spring, damper and load.
fn drive_load(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
    (i, joint): (usize, &Joint),
    after: Motion,
) -> Id {
    let rows = transmitted(g, model, kin, i, joint, after);
    let passive = passive_load(g, model, s, i);
    g.add(rows, passive)
}

/// Q's part from joint i's spring, damper and applied load: k (q − rest) + c q̇ − τ.
fn passive_load(g: &mut Graph, model: &Model, s: &Symbols, i: usize) -> Id {
    let spring = spring_damper_load(g, model, s, i);
    match crate::dynamics::joint_load(g, model, s, i) {
        Some(load) => g.sub(spring, load),
        None => spring,
    }
}

/// The body's rigid inertia as a 6×6: A = I_O, B = [h]×, C = m·1.
fn rigid(g: &mut Graph, body: &Inertia) -> Articulated {
    let z = g.zero();
    let h = body.first;
    let (nx, ny, nz) = (g.neg(h[0]), g.neg(h[1]), g.neg(h[2]));
    let m = body.mass;
    Articulated {
        a: body.tensor,
        b: [[z, nz, h[1]], [h[2], z, nx], [ny, h[0], z]],
        c: [[m, z, z], [z, m, z], [z, z, m]],
    }
}

/// a⁰ = accel − g of every body, own frame: the kinematics' recursion started from −g at
/// the ground rather than from zero, so that gravity rides on the acceleration instead of
/// being rotated into each body beside it (the kinematics keep −g apart for the dense
/// route's F and Q). Those rotations and the sums accel + (−g) were about 2 % of the
/// 16-body chain's sweeps.
pub(crate) fn accelerations_with_gravity(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
) -> Vec<V3> {
    let ground = minus_gravity(g, model, s);
    let mut out: Vec<V3> = Vec::with_capacity(kin.len());
    for (k, body) in kin.iter().zip(&model.bodies) {
        g.set_section(format!(
            "{}: acceleration with gravity (joint {})",
            body.name, body.joint.coordinate
        ));
        let parent = body.parent.map_or(ground, |p| out[p]);
        let at_joint = k.carried.at_joint(g, parent);
        let a0 = k.carried.in_body(g, &k.relative, at_joint);
        vec3::label(g, a0, &format!("acc_g_{}", body.name));
        out.push(a0);
    }
    out
}

/// The body's own loads at δa = 0 about its joint point, own frame: with a⁰ = accel − g
/// ([`accelerations_with_gravity`]), f = m a⁰ + α × h + ω × (ω × h),
/// n = I α + ω × I ω + h × a⁰.
fn own_loads(g: &mut Graph, k: &BodyKinematics, a0: V3, body: &Inertia) -> Force {
    let ma = vec3::scale(g, body.mass, a0);
    let a_h = vec3::cross(g, k.alpha, body.first);
    let w_w_h = vec3::omega_omega(g, k.omega, body.first);
    let rest = vec3::add(g, a_h, w_w_h);
    let f = vec3::add(g, ma, rest);
    let i_a = crate::dynamics::mat_vec(g, &body.tensor, k.alpha);
    let i_w = crate::dynamics::mat_vec(g, &body.tensor, k.omega);
    let gyro = vec3::cross(g, k.omega, i_w);
    let h_a = vec3::cross(g, body.first, a0);
    let m = vec3::add(g, i_a, gyro);
    Force {
        n: vec3::add(g, m, h_a),
        f,
    }
}

/// I S: the column of the joint's axis (angular for a revolute joint, linear for a prismatic
/// one).
fn column(g: &mut Graph, i: &Articulated, kind: JointKind, axis: V3) -> Force {
    match kind {
        JointKind::Revolute => {
            let bt = transpose(&i.b);
            Force {
                n: mat_vec(g, &i.a, axis),
                f: mat_vec(g, &bt, axis),
            }
        }
        JointKind::Prismatic => Force {
            n: mat_vec(g, &i.b, axis),
            f: mat_vec(g, &i.c, axis),
        },
    }
}

/// Sᵀ f.
fn project(g: &mut Graph, kind: JointKind, axis: V3, f: Force) -> Id {
    match kind {
        JointKind::Revolute => vec3::dot(g, axis, f.n),
        JointKind::Prismatic => vec3::dot(g, axis, f.f),
    }
}

/// W = U / D. Along a joint axis that is a coordinate axis ±e_k, D = ±U_k, so W_k is ±1
/// exactly: written so, the code never forms D · (1 / D).
fn per_unit_rate(g: &mut Graph, d_inverse: Id, u: Force, kind: JointKind, axis: [f64; 3]) -> Force {
    let mut w = scale_force(g, d_inverse, u);
    let k = (0..3)
        .find(|&k| axis[k].abs() == 1.0 && axis[(k + 1) % 3] == 0.0 && axis[(k + 2) % 3] == 0.0);
    if let Some(k) = k {
        let unit = g.constant(axis[k]);
        match kind {
            JointKind::Revolute => w.n[k] = unit,
            JointKind::Prismatic => w.f[k] = unit,
        }
    }
    w
}

/// I − U Wᵀ (W = U / D), symmetric: only the upper triangles of A and C are computed.
fn subtract_outer(g: &mut Graph, i: &Articulated, u: Force, w: Force) -> Articulated {
    let mut out = *i;
    for r in 0..3 {
        for c in 0..3 {
            if c >= r {
                let p = g.mul(u.n[r], w.n[c]);
                out.a[r][c] = g.sub(i.a[r][c], p);
                out.a[c][r] = out.a[r][c];
                let p = g.mul(u.f[r], w.f[c]);
                out.c[r][c] = g.sub(i.c[r][c], p);
                out.c[c][r] = out.c[r][c];
            }
            let p = g.mul(u.n[r], w.f[c]);
            out.b[r][c] = g.sub(i.b[r][c], p);
        }
    }
    out
}

/// I^a S = 0 (I^a = I^A − U Uᵀ / D with U = I^A S, D = Sᵀ U): along a joint axis that is a
/// coordinate axis, the row and column of I^a for that coordinate are exactly zero. Written
/// as zeros, so the expressions never form D · (1 / D).
fn clear_joint_direction(g: &mut Graph, i: &mut Articulated, kind: JointKind, axis: [f64; 3]) {
    let Some(k) = (0..3)
        .find(|&k| axis[k].abs() == 1.0 && axis[(k + 1) % 3] == 0.0 && axis[(k + 2) % 3] == 0.0)
    else {
        return;
    };
    let zero = g.zero();
    for j in 0..3 {
        match kind {
            JointKind::Revolute => {
                i.a[k][j] = zero;
                i.a[j][k] = zero;
                i.b[k][j] = zero;
            }
            JointKind::Prismatic => {
                i.c[k][j] = zero;
                i.c[j][k] = zero;
                i.b[j][k] = zero;
            }
        }
    }
}

/// Xᵀ I X: a child's articulated inertia in its parent's frame about the parent's origin.
/// Rotated, A' = R A Rᵀ, B' = R B Rᵀ, C' = R C Rᵀ; then moved by r (the child's joint point
/// in the parent's frame): C_p = C', B_p = B' + r̃ C', A_p = A' + r̃ B'ᵀ − B_p r̃.
fn inertia_to_parent(g: &mut Graph, child: &BodyKinematics, i: &Articulated) -> Articulated {
    let a = rotation::rotate(g, child, &i.a, true);
    let b = rotation::rotate(g, child, &i.b, false);
    let c = rotation::rotate(g, child, &i.c, true);
    let r = child.offset;
    // r̃ M, column by column: r × M[:, j].
    let cross_columns = |g: &mut Graph, m: &[V3; 3]| -> [V3; 3] {
        let cols: Vec<V3> = (0..3)
            .map(|j| vec3::cross(g, r, [m[0][j], m[1][j], m[2][j]]))
            .collect();
        transpose(&[cols[0], cols[1], cols[2]])
    };
    let rc = cross_columns(g, &c);
    let mut bp = b;
    for row in 0..3 {
        for col in 0..3 {
            bp[row][col] = g.add(b[row][col], rc[row][col]);
        }
    }
    // r̃ B'ᵀ: column j is r × (row j of B').
    let rbt = cross_columns(g, &transpose(&b));
    // B_p r̃: row i is (row i of B_p) × r.
    let bpr: Vec<V3> = (0..3).map(|row| vec3::cross(g, bp[row], r)).collect();
    let mut ap = a;
    for row in 0..3 {
        for col in row..3 {
            let e = g.add(a[row][col], rbt[row][col]);
            let e = g.sub(e, bpr[row][col]);
            ap[row][col] = e;
            ap[col][row] = e;
        }
    }
    Articulated { a: ap, b: bp, c }
}

fn add(g: &mut Graph, x: &Articulated, y: &Articulated) -> Articulated {
    let mut out = *x;
    for r in 0..3 {
        for c in 0..3 {
            out.b[r][c] = g.add(x.b[r][c], y.b[r][c]);
            if c >= r {
                out.a[r][c] = g.add(x.a[r][c], y.a[r][c]);
                out.a[c][r] = out.a[r][c];
                out.c[r][c] = g.add(x.c[r][c], y.c[r][c]);
                out.c[c][r] = out.c[r][c];
            }
        }
    }
    out
}

fn add_force(g: &mut Graph, x: Force, y: Force) -> Force {
    Force {
        n: vec3::add(g, x.n, y.n),
        f: vec3::add(g, x.f, y.f),
    }
}

fn scale_force(g: &mut Graph, s: Id, x: Force) -> Force {
    Force {
        n: vec3::scale(g, s, x.n),
        f: vec3::scale(g, s, x.f),
    }
}

fn transpose(m: &[V3; 3]) -> [V3; 3] {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

fn mat_vec(g: &mut Graph, m: &[V3; 3], v: V3) -> V3 {
    crate::dynamics::mat_vec(g, m, v)
}

mod rotation;
mod row;
pub(crate) use row::contact_row_bias;
#[cfg(test)]
mod tests;
