//! Backward recursion (tip → ground) of joint loads on symbolic expressions, eqs. (10)–(13).
//!
//! For body i, in its own frame, the force and the moment about its joint point carried by
//! joint i are the inertial minus applied loads of i plus those carried by its children:
//!
//! ```text
//! F_i = m_i a_Gi + Σ_c R_c F_c
//! N_i = I_i α_i + ω_i × I_i ω_i + c_i × m_i a_Gi + Σ_c (R_c N_c + r_c × R_c F_c)
//! ```
//!
//! (gravity is already inside a_Gi through the ground's acceleration −g). Projecting N_i (a
//! revolute joint) or F_i (a prismatic joint) on the joint axis gives one [`Lin`] form per
//! joint whose q̈ coefficients are the row of M, whose velocity remainder is F, and whose
//! gravity remainder, plus the joint's spring-damper, is Q (13).

use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, L3, Lin, Symbols};
use crate::kinematics::{lin3, point_accel, point_position, point_velocity, vec3};
use crate::model::{JointKind, Model};

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

/// Joint load of one body: force and moment about its joint point, body frame.
struct Load {
    force: L3,
    moment: L3,
}

/// Runs the backward recursion over all bodies and collects M, F, Q.
pub fn backward(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    kin: &[BodyKinematics],
) -> DynamicsTerms {
    let n = model.n();
    let mut loads: Vec<Option<Load>> = (0..n).map(|_| None).collect();
    let mut forms: Vec<Option<Lin>> = vec![None; n];
    for i in (0..n).rev() {
        g.set_section(format!(
            "{}: inertial loads and joint {} load (backward recursion)",
            model.bodies[i].name, model.bodies[i].joint.coordinate
        ));
        let mut load = body_load(g, model, i, &kin[i]);
        for c in (i + 1..n).filter(|&c| model.bodies[c].parent == Some(i)) {
            if let Some(child) = loads[c].take() {
                load = add_child_load(g, &kin[c], load, &child);
            }
        }
        // Generalised force of joint i: the carried load projected on the joint axis.
        let carried = match model.bodies[i].joint.kind {
            JointKind::Revolute => &load.moment,
            JointKind::Prismatic => &load.force,
        };
        forms[i] = Some(lin3::dot_v(g, kin[i].axis, carried));
        loads[i] = Some(load);
    }
    let forms: Vec<Lin> = forms.into_iter().flatten().collect();
    collect_terms(g, model, s, &forms)
}

/// Inertial minus applied loads of body i alone (10, 11).
fn body_load(g: &mut Graph, model: &Model, i: usize, k: &BodyKinematics) -> Load {
    let body = &model.bodies[i];
    let mass = g.constant(body.mass);
    let a_com = point_accel(g, k, body.com);
    let force = lin3::scale(g, mass, &a_com);
    let i_alpha = lin3::mat_mul(g, &body.inertia, &k.alpha);
    let i_omega = vec3::mat_mul(g, &body.inertia, k.omega);
    let gyro = vec3::cross(g, k.omega, i_omega);
    let com = vec3::constant(g, body.com);
    let c_f = lin3::v_cross(g, com, &force);
    let moment = lin3::add_vel(g, &i_alpha, gyro);
    let moment = lin3::add(g, &moment, &c_f);
    Load { force, moment }
}

/// Adds a child's joint load, moved to the parent's joint point (12).
fn add_child_load(g: &mut Graph, child: &BodyKinematics, load: Load, c: &Load) -> Load {
    let f = child.relative.apply_lin(g, &c.force);
    let m = child.relative.apply_lin(g, &c.moment);
    let r_f = lin3::v_cross(g, child.offset, &f);
    let force = lin3::add(g, &load.force, &f);
    let moment = lin3::add(g, &load.moment, &m);
    let moment = lin3::add(g, &moment, &r_f);
    Load { force, moment }
}

/// Splits the joint forms into M, F and Q (adding springs and dampers to Q).
fn collect_terms(g: &mut Graph, model: &Model, s: &Symbols, forms: &[Lin]) -> DynamicsTerms {
    let n = model.n();
    let mut mass = vec![vec![g.zero(); n]; n];
    for (i, form) in forms.iter().enumerate() {
        for (j, &entry) in form.qdd.iter().enumerate().skip(i) {
            // M is symmetric; the recursion yields both triangles, the upper one is used.
            mass[i][j] = entry;
            mass[j][i] = entry;
        }
    }
    let inertial = forms.iter().map(|f| f.vel).collect();
    let applied = forms
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let spring = spring_damper_load(g, model, s, i);
            g.add(f.grav, spring)
        })
        .collect();
    DynamicsTerms {
        mass,
        inertial,
        applied,
    }
}

/// k (q − rest) + c q̇ of joint i (the sign of Q in M q̈ + F + Q = 0).
fn spring_damper_load(g: &mut Graph, model: &Model, s: &Symbols, i: usize) -> Id {
    let Some(sd) = model.bodies[i].joint.spring else {
        return g.zero();
    };
    let rest = g.constant(sd.rest);
    let stretch = g.sub(s.q[i], rest);
    let k = g.constant(sd.stiffness);
    let c = g.constant(sd.damping);
    let ks = g.mul(k, stretch);
    let cv = g.mul(c, s.qd[i]);
    g.add(ks, cv)
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
}

/// Derives the energy expressions.
pub fn energy(g: &mut Graph, model: &Model, s: &Symbols, kin: &[BodyKinematics]) -> EnergyTerms {
    g.set_section("energy");
    let half = g.constant(0.5);
    let mut kinetic = Vec::new();
    let mut gravity = Vec::new();
    let mut spring = Vec::new();
    let mut damper = Vec::new();
    let gvec = vec3::constant(g, model.gravity);
    for (i, body) in model.bodies.iter().enumerate() {
        let m = g.constant(body.mass);
        let v = point_velocity(g, &kin[i], body.com);
        let vv = vec3::dot(g, v, v);
        let i_w = vec3::mat_mul(g, &body.inertia, kin[i].omega);
        let w_i_w = vec3::dot(g, kin[i].omega, i_w);
        let m_vv = g.mul(m, vv);
        let both = g.add(m_vv, w_i_w);
        kinetic.push(g.mul(half, both));
        let p = point_position(g, &kin[i], body.com);
        let gp = vec3::dot(g, gvec, p);
        let mgp = g.mul(m, gp);
        gravity.push(g.neg(mgp));
        if let Some(sd) = body.joint.spring {
            let rest = g.constant(sd.rest);
            let stretch = g.sub(s.q[i], rest);
            let sq = g.powi(stretch, 2);
            let k = g.constant(0.5 * sd.stiffness);
            spring.push(g.mul(k, sq));
            let c = g.constant(sd.damping);
            let v2 = g.powi(s.qd[i], 2);
            damper.push(g.mul(c, v2));
        }
    }
    EnergyTerms {
        kinetic: g.sum(kinetic),
        gravity: g.sum(gravity),
        spring: g.sum(spring),
        damper_power: g.sum(damper),
    }
}
