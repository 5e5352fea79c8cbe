//! M, F and Q of eq. (13) on symbolic expressions, each by the recursion that suits it.
//!
//! - M by composite inertias (the composite-rigid-body form of the backward recursion): the
//!   spatial inertia of every subtree about its joint point, in the subtree root's frame, is
//!   summed from the tip; M_ii is the joint axis projection of the subtree's momentum for a
//!   unit joint rate, and moving that momentum down to each ancestor's joint gives M_ji.
//! - F by the backward recursion of the inertial loads at q̈ = 0 (10)–(12): for body i, in its
//!   own frame, about its joint point,
//!
//!   ```text
//!   F_i = m_i a_i + α_i × h_i + ω_i × (ω_i × h_i) + Σ_c R_c F_c
//!   N_i = I_i α_i + ω_i × I_i ω_i + h_i × a_i + Σ_c (R_c N_c + r_c × R_c F_c)
//!   ```
//!
//!   with h_i = m_i c_i and I_i the inertia about the joint point (so no centre-of-mass
//!   acceleration is formed), projected on the joint axis.
//! - Q: the gravity loads of a subtree are its mass times −g, so their moment about joint i is
//!   (h_i + Σ_c M_c r_c) × (−g_i) + Σ_c R_c N_c, with −g carried into each body frame by the
//!   forward recursion; plus the joint's spring-damper.

use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Symbols, V3};
use crate::kinematics::{point_position, point_velocity, vec3};
use crate::model::{Body, Field, JointKind, Model};

/// M, F and Q of eq. (13) as expressions.
#[derive(Debug, Clone)]
pub struct DynamicsTerms {
    /// M(q), row-major rows.
    pub mass: Vec<Vec<Id>>,
    /// F(q, q̇).
    pub inertial: Vec<Id>,
    /// Q(q, q̇): gravity, springs and dampers.
    pub applied: Vec<Id>,
}

/// Derives M, F and Q.
pub fn backward(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
) -> DynamicsTerms {
    let mass = mass_matrix(g, model, s, kin);
    let inertial = inertial_forces(g, model, s, kin);
    let gravity = gravity_forces(g, model, s, kin);
    let applied = gravity
        .iter()
        .enumerate()
        .map(|(i, &grav)| {
            let spring = spring_damper_load(g, model, s, i);
            let passive = g.add(grav, spring);
            match joint_load(g, model, s, i) {
                Some(load) => g.sub(passive, load),
                None => passive,
            }
        })
        .collect();
    DynamicsTerms {
        mass,
        inertial,
        applied,
    }
}

/// Spatial inertia about a frame origin, in that frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Inertia {
    /// Mass.
    pub(crate) mass: Id,
    /// First moment h = Σ m c.
    pub(crate) first: V3,
    /// Inertia tensor about the origin (symmetric).
    pub(crate) tensor: [V3; 3],
}

/// Numeric mass, first moment and inertia about the joint point of one body.
fn body_constants(body: &Body) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let (m, c) = (body.mass, body.com);
    let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let mut tensor = body.inertia;
    for (a, row) in tensor.iter_mut().enumerate() {
        for (b, cell) in row.iter_mut().enumerate() {
            let delta = if a == b { cc } else { 0.0 };
            *cell += m * (delta - c[a] * c[b]);
        }
    }
    (m, c.map(|x| m * x), tensor)
}

/// The fields of body i's mass, centre of mass and inertia tensor.
fn inertia_fields(i: usize) -> impl Iterator<Item = Field> {
    let com = (0..3).map(move |k| Field::Com(i, k));
    let tensor = (0..9).map(move |e| Field::Inertia(i, e / 3, e % 3));
    std::iter::once(Field::Mass(i)).chain(com).chain(tensor)
}

/// Body i's mass, first moment and inertia about its joint point: constants computed here
/// when none of its fields is read at run time, otherwise expressions of the parameters
/// (the same formulas in the graph).
pub(crate) fn body_inertia(g: &mut Graph, model: &Model, s: &Symbols, i: usize) -> Inertia {
    let body = &model.bodies[i];
    if Symbols::any_runtime(model, inertia_fields(i)) {
        return body_inertia_symbolic(g, model, s, i);
    }
    let (m, h, tensor) = body_constants(body);
    Inertia {
        mass: g.constant(m),
        first: vec3::constant(g, h),
        tensor: [
            vec3::constant(g, tensor[0]),
            vec3::constant(g, tensor[1]),
            vec3::constant(g, tensor[2]),
        ],
    }
}

/// [`body_inertia`] with parameters: m, h = m c, I_O = I_G + m (|c|² δ − c cᵀ).
fn body_inertia_symbolic(g: &mut Graph, model: &Model, s: &Symbols, i: usize) -> Inertia {
    let body = &model.bodies[i];
    let mass = s.field(g, model, Field::Mass(i), body.mass);
    let c = s.field3(g, model, |k| Field::Com(i, k), body.com);
    let cc = vec3::dot(g, c, c);
    let mut tensor = [[g.zero(); 3]; 3];
    for (a, row) in tensor.iter_mut().enumerate() {
        for (b, cell) in row.iter_mut().enumerate() {
            let own = s.field(g, model, Field::Inertia(i, a, b), body.inertia[a][b]);
            let cacb = g.mul(c[a], c[b]);
            let shift = if a == b { g.sub(cc, cacb) } else { g.neg(cacb) };
            let m_shift = g.mul(mass, shift);
            *cell = g.add(own, m_shift);
        }
    }
    Inertia {
        mass,
        first: vec3::scale(g, mass, c),
        tensor,
    }
}

/// Names a composite inertia's mass, first moment and tensor after `name`.
fn label_inertia(g: &mut Graph, c: &Inertia, name: &str) {
    g.label(c.mass, format!("mass_{name}"));
    vec3::label(g, c.first, &format!("first_moment_{name}"));
    let axes = ["x", "y", "z"];
    for (a, row) in c.tensor.iter().enumerate() {
        for (b, &entry) in row.iter().enumerate().skip(a) {
            g.label(entry, format!("inertia_{name}_{}{}", axes[a], axes[b]));
        }
    }
}

/// A child's composite inertia seen from its parent's frame and joint point.
fn to_parent(g: &mut Graph, child: &BodyKinematics, c: &Inertia) -> Inertia {
    let h = child.relative.apply(g, c.first);
    let rotated = rotate_tensor(g, child, &c.tensor);
    let r = child.offset;
    let mr = vec3::scale(g, c.mass, r);
    let first = vec3::add(g, h, mr);
    // I' = R I Rᵀ + δ r·(h' + h̃) − (r h'ᵀ + h̃ rᵀ), h̃ = R h, h' = h̃ + m r.
    let both = vec3::add(g, first, h);
    let diag = vec3::dot(g, r, both);
    let mut tensor = rotated;
    for a in 0..3 {
        for b in a..3 {
            let t1 = g.mul(r[a], first[b]);
            let t2 = g.mul(h[a], r[b]);
            let off = g.add(t1, t2);
            let mut e = g.sub(rotated[a][b], off);
            if a == b {
                e = g.add(e, diag);
            }
            tensor[a][b] = e;
            tensor[b][a] = e;
        }
    }
    Inertia {
        mass: c.mass,
        first,
        tensor,
    }
}

/// R I Rᵀ for the child's joint rotation (upper triangle computed, mirrored).
pub(crate) fn rotate_tensor(g: &mut Graph, child: &BodyKinematics, t: &[V3; 3]) -> [V3; 3] {
    if child.relative == crate::kinematics::Rotation::Identity {
        return *t;
    }
    let r = child.relative.matrix(g);
    // (R I)_{aj} = row_a(R)·column_j(I); (R I Rᵀ)_{ab} = row_a(R I)·row_b(R).
    let ri: Vec<V3> = (0..3)
        .map(|a| {
            let cols: V3 = [0, 1, 2].map(|j| {
                let col = [t[0][j], t[1][j], t[2][j]];
                vec3::dot(g, r[a], col)
            });
            cols
        })
        .collect();
    let mut out = *t;
    for a in 0..3 {
        for b in a..3 {
            let e = vec3::dot(g, ri[a], r[b]);
            out[a][b] = e;
            out[b][a] = e;
        }
    }
    out
}

fn add_inertia(g: &mut Graph, a: &Inertia, b: &Inertia) -> Inertia {
    let mut tensor = a.tensor;
    for (i, j) in [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)] {
        let e = g.add(a.tensor[i][j], b.tensor[i][j]);
        tensor[i][j] = e;
        tensor[j][i] = e;
    }
    Inertia {
        mass: g.add(a.mass, b.mass),
        first: vec3::add(g, a.first, b.first),
        tensor,
    }
}

pub(crate) fn mat_vec(g: &mut Graph, m: &[V3; 3], v: V3) -> V3 {
    [
        vec3::dot(g, m[0], v),
        vec3::dot(g, m[1], v),
        vec3::dot(g, m[2], v),
    ]
}

/// The children of every body.
pub(crate) fn children(model: &Model) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new(); model.n()];
    for (i, b) in model.bodies.iter().enumerate() {
        if let Some(p) = b.parent {
            out[p].push(i);
        }
    }
    out
}

/// A spatial force (moment about the frame origin, force), moved from a child's frame to its
/// parent's: f' = R f, n' = R n + r × f'.
pub(crate) fn force_to_parent(g: &mut Graph, child: &BodyKinematics, n: V3, f: V3) -> (V3, V3) {
    let f = child.relative.apply(g, f);
    let n = child.relative.apply(g, n);
    let r_f = vec3::cross(g, child.offset, f);
    (vec3::add(g, n, r_f), f)
}

/// The generalised component of a spatial force on joint i.
fn project(g: &mut Graph, model: &Model, kin: &[BodyKinematics], i: usize, n: V3, f: V3) -> Id {
    match model.bodies[i].joint.kind {
        JointKind::Revolute => vec3::dot(g, kin[i].axis, n),
        JointKind::Prismatic => vec3::dot(g, kin[i].axis, f),
    }
}

/// M by composite inertias.
fn mass_matrix(g: &mut Graph, model: &Model, s: &Symbols, kin: &[BodyKinematics]) -> Vec<Vec<Id>> {
    let n = model.n();
    let kids = children(model);
    let mut composite: Vec<Option<Inertia>> = vec![None; n];
    let mut mass = vec![vec![g.zero(); n]; n];
    for i in (0..n).rev() {
        if g.exhausted() {
            // The model is refused (its graph outgrew the node limit): M has N² terms, and
            // the rest of them would only take time.
            break;
        }
        g.set_section(format!(
            "{}: composite inertia and column {} of M",
            model.bodies[i].name, model.bodies[i].joint.coordinate
        ));
        let mut c = body_inertia(g, model, s, i);
        for &k in &kids[i] {
            if let Some(child) = composite[k] {
                let moved = to_parent(g, &kin[k], &child);
                label_inertia(g, &moved, &format!("{}_in_parent", model.bodies[k].name));
                c = add_inertia(g, &c, &moved);
            }
        }
        // Momentum of the subtree for a unit rate of joint i, about the joint point.
        let u = kin[i].axis;
        let (mut nn, mut ff) = match model.bodies[i].joint.kind {
            JointKind::Revolute => (mat_vec(g, &c.tensor, u), vec3::cross(g, u, c.first)),
            JointKind::Prismatic => (vec3::cross(g, c.first, u), vec3::scale(g, c.mass, u)),
        };
        label_inertia(g, &c, &model.bodies[i].name);
        mass[i][i] = project(g, model, kin, i, nn, ff);
        let coordinate = |j: usize| &model.bodies[j].joint.coordinate;
        g.label(mass[i][i], format!("m_{}_{}", coordinate(i), coordinate(i)));
        let mut k = i;
        while let Some(p) = model.bodies[k].parent {
            (nn, ff) = force_to_parent(g, &kin[k], nn, ff);
            vec3::label(
                g,
                nn,
                &format!("momentum_moment_{}_{}", coordinate(i), coordinate(p)),
            );
            vec3::label(
                g,
                ff,
                &format!("momentum_{}_{}", coordinate(i), coordinate(p)),
            );
            let e = project(g, model, kin, p, nn, ff);
            g.label(e, format!("m_{}_{}", coordinate(p), coordinate(i)));
            mass[p][i] = e;
            mass[i][p] = e;
            k = p;
        }
        composite[i] = Some(c);
    }
    mass
}

/// A body's inertial loads about its joint point, own frame, waiting to be moved to the
/// parent: the force is kept as m·a plus the rest, so that the parent receives m·a from the
/// kinematics' parent-frame acceleration instead of rotating it there and back.
struct Loads {
    moment: V3,
    /// The force minus the body's own m·a (own frame).
    force_rest: V3,
    mass: Id,
}

/// F: inertial loads at q̈ = 0, summed from the tip.
fn inertial_forces(g: &mut Graph, model: &Model, s: &Symbols, kin: &[BodyKinematics]) -> Vec<Id> {
    let n = model.n();
    let kids = children(model);
    let mut loads: Vec<Option<Loads>> = (0..n).map(|_| None).collect();
    let mut out = vec![g.zero(); n];
    for i in (0..n).rev() {
        g.set_section(format!(
            "{}: inertial loads and joint {} load (backward recursion)",
            model.bodies[i].name, model.bodies[i].joint.coordinate
        ));
        let k = &kin[i];
        let b = body_inertia(g, model, s, i);
        // Own loads about the joint point (no centre-of-mass acceleration needed).
        let name = &model.bodies[i].name;
        let a_h = vec3::cross(g, k.alpha, b.first);
        vec3::label(g, a_h, &format!("tangential_force_{name}"));
        let w_w_h = vec3::omega_omega(g, k.omega, b.first);
        vec3::label(g, w_w_h, &format!("centripetal_force_{name}"));
        let w_dot_h = vec3::dot(g, k.omega, b.first);
        g.label(w_dot_h, format!("omega_dot_first_moment_{name}"));
        let mut force_rest = vec3::add(g, a_h, w_w_h);
        let i_a = mat_vec(g, &b.tensor, k.alpha);
        vec3::label(g, i_a, &format!("inertia_alpha_{name}"));
        let i_w = mat_vec(g, &b.tensor, k.omega);
        vec3::label(g, i_w, &format!("angular_momentum_{name}"));
        let gyro = vec3::cross(g, k.omega, i_w);
        vec3::label(g, gyro, &format!("gyroscopic_{name}"));
        let h_a = vec3::cross(g, b.first, k.accel);
        vec3::label(g, h_a, &format!("moment_of_acc_{name}"));
        let m = vec3::add(g, i_a, gyro);
        let mut moment = vec3::add(g, m, h_a);
        for &c in &kids[i] {
            if let Some(child) = loads[c].take() {
                let (nc, fc) = child_loads_to_parent(g, &kin[c], &child);
                let child_name = &model.bodies[c].name;
                vec3::label(g, nc, &format!("moment_{child_name}_in_parent"));
                vec3::label(g, fc, &format!("force_{child_name}_in_parent"));
                moment = vec3::add(g, moment, nc);
                force_rest = vec3::add(g, force_rest, fc);
            }
        }
        vec3::label(g, moment, &format!("moment_{name}"));
        vec3::label(g, force_rest, &format!("force_{name}_rest"));
        out[i] = match model.bodies[i].joint.kind {
            JointKind::Revolute => vec3::dot(g, k.axis, moment),
            JointKind::Prismatic => {
                let ma = vec3::scale(g, b.mass, k.accel);
                let force = vec3::add(g, ma, force_rest);
                vec3::dot(g, k.axis, force)
            }
        };
        g.label(out[i], format!("f_{}", model.bodies[i].joint.coordinate));
        loads[i] = Some(Loads {
            moment,
            force_rest,
            mass: b.mass,
        });
    }
    out
}

/// A child's loads in its parent's frame, about the parent's origin: f' = m a' + R f_rest
/// (a' the child's acceleration already in the parent's frame), n' = R n + r × f'.
fn child_loads_to_parent(g: &mut Graph, child: &BodyKinematics, l: &Loads) -> (V3, V3) {
    let ma = vec3::scale(g, l.mass, child.accel_in_parent);
    let rest = child.relative.apply(g, l.force_rest);
    let f = vec3::add(g, ma, rest);
    let n = child.relative.apply(g, l.moment);
    let r_f = vec3::cross(g, child.offset, f);
    (vec3::add(g, n, r_f), f)
}

/// The gravity part of Q: moments of the subtrees' weights about the joints.
fn gravity_forces(g: &mut Graph, model: &Model, s: &Symbols, kin: &[BodyKinematics]) -> Vec<Id> {
    let n = model.n();
    let kids = children(model);
    if model.gravity == [0.0; 3] && !Symbols::any_runtime(model, (0..3).map(Field::Gravity)) {
        return vec![g.zero(); n];
    }
    let subtree = subtree_masses(g, model, s);
    let mut moments: Vec<Option<V3>> = vec![None; n];
    let mut out = vec![g.zero(); n];
    for i in (0..n).rev() {
        g.set_section(format!(
            "{}: gravity load of the subtree on joint {}",
            model.bodies[i].name, model.bodies[i].joint.coordinate
        ));
        let k = &kin[i];
        let h = body_inertia(g, model, s, i).first;
        // First moment of the subtree's weights about the joint point, children at their
        // joint points: h_i + Σ_c M_c r_c.
        let mut arm = h;
        let mut moment = vec3::zero(g);
        for &c in &kids[i] {
            let mc = subtree[c];
            let mr = vec3::scale(g, mc, kin[c].offset);
            arm = vec3::add(g, arm, mr);
            if let Some(nc) = moments[c].take() {
                let nc = kin[c].relative.apply(g, nc);
                moment = vec3::add(g, moment, nc);
            }
        }
        let own = vec3::cross(g, arm, k.gravity);
        let moment = vec3::add(g, own, moment);
        let name = &model.bodies[i].name;
        vec3::label(g, arm, &format!("weight_arm_{name}"));
        vec3::label(g, moment, &format!("weight_moment_{name}"));
        out[i] = match model.bodies[i].joint.kind {
            JointKind::Revolute => vec3::dot(g, k.axis, moment),
            JointKind::Prismatic => {
                let m = subtree[i];
                let ug = vec3::dot(g, k.axis, k.gravity);
                g.mul(m, ug)
            }
        };
        g.label(
            out[i],
            format!("weight_{}", model.bodies[i].joint.coordinate),
        );
        moments[i] = Some(moment);
    }
    out
}

/// The mass of every body's subtree: constants summed here when no mass is read at run
/// time, otherwise sums in the graph.
fn subtree_masses(g: &mut Graph, model: &Model, s: &Symbols) -> Vec<Id> {
    let n = model.n();
    if !Symbols::any_runtime(model, (0..n).map(Field::Mass)) {
        let mut subtree = vec![0.0; n];
        for i in (0..n).rev() {
            subtree[i] += model.bodies[i].mass;
            if let Some(p) = model.bodies[i].parent {
                subtree[p] += subtree[i];
            }
        }
        return subtree.into_iter().map(|m| g.constant(m)).collect();
    }
    let mut subtree: Vec<Id> = (0..n)
        .map(|i| s.field(g, model, Field::Mass(i), model.bodies[i].mass))
        .collect();
    for i in (0..n).rev() {
        if let Some(p) = model.bodies[i].parent {
            subtree[p] = g.add(subtree[p], subtree[i]);
        }
    }
    subtree
}

/// k (q − rest) + c q̇ of joint i (the sign of Q in M q̈ + F + Q = 0).
pub(crate) fn spring_damper_load(g: &mut Graph, model: &Model, s: &Symbols, i: usize) -> Id {
    let Some(sd) = model.bodies[i].joint.spring else {
        return g.zero();
    };
    let rest = s.field(g, model, Field::Rest(i), sd.rest);
    let stretch = g.sub(s.q[i], rest);
    let k = s.field(g, model, Field::Stiffness(i), sd.stiffness);
    let c = s.field(g, model, Field::Damping(i), sd.damping);
    let ks = g.mul(k, stretch);
    let cv = g.mul(c, s.qd[i]);
    g.add(ks, cv)
}

/// The applied load τ(t, q, q̇) of joint i, if it has one: it enters Q as −τ (a torque in
/// the direction of the coordinate drives it forward).
pub fn joint_load(g: &mut Graph, model: &Model, s: &Symbols, i: usize) -> Option<Id> {
    let load = model.bodies[i].joint.load.as_ref()?;
    let expr = s.expression(model, Field::Load(i), &load.expr);
    // Parameter indices past the model's parameters are the coordinates, then their rates
    // (`JointLoad::expr`).
    let variables: Vec<Id> = s.params.iter().chain(&s.q).chain(&s.qd).copied().collect();
    let tau = crate::expr::scalar::scalar_to_expr(g, expr, s.t, &variables);
    g.label(tau, format!("load_{}", model.bodies[i].joint.coordinate));
    Some(tau)
}

/// Energy expressions: kinetic (from body velocities), gravity and spring potentials.
#[derive(Debug, Clone, Copy)]
pub struct EnergyTerms {
    /// ½ Σ (m v_G·v_G + ω·I ω).
    pub kinetic: Id,
    /// −Σ m g·p_G.
    pub gravity: Id,
    /// Σ ½ k (q − rest)².
    pub spring: Id,
    /// Σ c q̇², the power the dampers dissipate.
    pub damper_power: Id,
    /// Σ τ q̇, the power of the applied joint loads.
    pub load_power: Id,
}

/// Derives the energy expressions.
pub fn energy(g: &mut Graph, model: &Model, s: &Symbols, kin: &[BodyKinematics]) -> EnergyTerms {
    g.set_section("energy");
    let half = g.constant(0.5);
    let mut kinetic = Vec::new();
    let mut gravity = Vec::new();
    let mut spring = Vec::new();
    let mut damper = Vec::new();
    let mut load_power = Vec::new();
    let gvec = s.field3(g, model, Field::Gravity, model.gravity);
    for (i, body) in model.bodies.iter().enumerate() {
        let m = s.field(g, model, Field::Mass(i), body.mass);
        let com = s.field3(g, model, |k| Field::Com(i, k), body.com);
        let v = point_velocity(g, &kin[i], com);
        vec3::label(g, v, &format!("vel_com_{}", body.name));
        let vv = vec3::dot(g, v, v);
        let i_w = if Symbols::any_runtime(model, (0..9).map(|e| Field::Inertia(i, e / 3, e % 3))) {
            let rows =
                [0, 1, 2].map(|r| s.field3(g, model, |c| Field::Inertia(i, r, c), body.inertia[r]));
            [0, 1, 2].map(|r| vec3::dot(g, rows[r], kin[i].omega))
        } else {
            vec3::mat_mul(g, &body.inertia, kin[i].omega)
        };
        let w_i_w = vec3::dot(g, kin[i].omega, i_w);
        let m_vv = g.mul(m, vv);
        let both = g.add(m_vv, w_i_w);
        let own = g.mul(half, both);
        g.label(own, format!("kinetic_{}", body.name));
        kinetic.push(own);
        let p = point_position(g, &kin[i], com);
        vec3::label(g, p, &format!("pos_com_{}", body.name));
        let gp = vec3::dot(g, gvec, p);
        let mgp = g.mul(m, gp);
        gravity.push(g.neg(mgp));
        if let Some(sd) = body.joint.spring {
            let rest = s.field(g, model, Field::Rest(i), sd.rest);
            let stretch = g.sub(s.q[i], rest);
            let sq = g.powi(stretch, 2);
            let k = s.field_scaled(g, model, Field::Stiffness(i), sd.stiffness, 0.5);
            g.label(k, format!("half_stiffness_{}", body.joint.coordinate));
            spring.push(g.mul(k, sq));
            let c = s.field(g, model, Field::Damping(i), sd.damping);
            let v2 = g.powi(s.qd[i], 2);
            damper.push(g.mul(c, v2));
        }
        if let Some(tau) = joint_load(g, model, s, i) {
            load_power.push(g.mul(tau, s.qd[i]));
        }
    }
    EnergyTerms {
        kinetic: g.sum(kinetic),
        gravity: g.sum(gravity),
        spring: g.sum(spring),
        damper_power: g.sum(damper),
        load_power: g.sum(load_power),
    }
}
