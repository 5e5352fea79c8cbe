use super::*;
use crate::dynamics::{
    ContactGeometry, ContactKinematics, CoordinateInfo, Energy, InitialGuess, IntegratorKind,
    JointKind, ModelInfo,
};
use crate::partition::Workspace;
use nalgebra::{DMatrix, DVector};

const G: f64 = 9.81;

fn settings(
    integrator: IntegratorKind,
    t_end: f64,
    dt_out: f64,
    dt: f64,
    rtol: f64,
) -> SimSettings {
    SimSettings {
        t_end,
        dt_out,
        integrator,
        dt,
        rtol,
        atol: rtol * 1e-2,
    }
}

fn coordinate(name: &str, kind: JointKind, driven: bool) -> CoordinateInfo {
    CoordinateInfo {
        name: name.to_string(),
        kind,
        driven,
    }
}

/// A knife edge at `point` on a ground cam y = f(x) with f′ = `slope`, f″ = `second`.
fn on_ground_cam(point: [f64; 2], slope: f64, second: f64) -> ContactGeometry {
    let stretch = (1.0 + slope * slope).sqrt();
    ContactGeometry {
        position: [point[0], point[1], 0.0],
        x: point[0],
        y: point[1],
        follower: [point[0], point[1], 0.0],
        normal: [-slope / stretch, 1.0 / stretch, 0.0],
        force_scale: stretch,
        parameter: point[0],
        curvature: second / stretch.powi(3),
        ..ContactGeometry::default()
    }
}

fn model_info(
    name: &str,
    coordinates: Vec<CoordinateInfo>,
    contacts: usize,
    initial: InitialGuess,
) -> ModelInfo {
    ModelInfo {
        name: name.to_string(),
        description: String::new(),
        coordinates,
        contacts: (0..contacts)
            .map(|k| crate::ContactInfo::knife(&format!("tip{k}")))
            .collect(),
        loops: Vec::new(),
        spatial: false,
        initial,
        defaults: settings(IntegratorKind::Dopri5, 1.0, 0.1, 1e-3, 1e-9),
        restitution: None,
        parameters: Vec::new(),
    }
}

// ------------------------------------------------------------------------------------
// A bead of mass m on a wire y = f(x) in the vertical plane: coordinates (x, y), both
// prismatic; M = m I, F = 0, Q = (c ẋ, m g + c ẏ); h = y − f(x), J = (−f', 1),
// c = −f'' ẋ².

#[derive(Debug, Clone, Copy)]
enum Curve {
    /// y = a x².
    Parabola(f64),
    /// y = √(r² − x²): the upper half of a circle of radius r.
    UpperCircle(f64),
    /// y = 1 − x².
    Cap,
    /// y = atan x: Newton on x diverges from |x| ≳ 1.39.
    Arctan,
}

impl Curve {
    /// (f, f', f'') at x.
    fn eval(self, x: f64) -> (f64, f64, f64) {
        match self {
            Curve::Parabola(a) => (a * x * x, 2.0 * a * x, 2.0 * a),
            Curve::UpperCircle(r) => {
                let y = (r * r - x * x).sqrt();
                (y, -x / y, -r * r / (y * y * y))
            }
            Curve::Cap => (1.0 - x * x, -2.0 * x, -2.0),
            Curve::Arctan => {
                let stretch = 1.0 + x * x;
                (x.atan(), 1.0 / stretch, -2.0 * x / (stretch * stretch))
            }
        }
    }
}

struct Bead {
    info: ModelInfo,
    mass: f64,
    gravity: f64,
    damping: f64,
    curve: Curve,
    /// y is driven: 0 until t = 0.5, then 2 (out of reach of the cap y = 1 − x²).
    lifted: bool,
}

impl Bead {
    fn new(curve: Curve, x0: f64, xd0: f64) -> Self {
        let (y0, _, _) = curve.eval(x0);
        let initial = InitialGuess {
            q: vec![x0, y0 + 0.05],
            qd: vec![xd0, 0.0],
            hold: vec![true, false],
            given_q: vec![true; 2],
            given_qd: vec![true; 2],
        };
        let coordinates = vec![
            coordinate("x", JointKind::Prismatic, false),
            coordinate("y", JointKind::Prismatic, false),
        ];
        let info = model_info("bead", coordinates, 1, initial);
        Self {
            info,
            mass: 2.0,
            gravity: G,
            damping: 0.0,
            curve,
            lifted: false,
        }
    }

    fn lifted(x0: f64) -> Self {
        let mut bead = Self::new(Curve::Cap, x0, 0.0);
        bead.lifted = true;
        bead.info.coordinates[1].driven = true;
        bead.info.initial.hold = vec![false, false];
        bead
    }
}

impl Dynamics for Bead {
    fn info(&self) -> &ModelInfo {
        &self.info
    }
    fn mass_matrix(&self, _q: &[f64], m: &mut [f64]) {
        m.copy_from_slice(&[self.mass, 0.0, 0.0, self.mass]);
    }
    fn inertial_forces(&self, _q: &[f64], _qd: &[f64], f: &mut [f64]) {
        f.fill(0.0);
    }
    fn applied_forces(&self, _t: f64, _q: &[f64], qd: &[f64], out: &mut [f64]) {
        out[0] = self.damping * qd[0];
        out[1] = self.mass * self.gravity + self.damping * qd[1];
    }
    fn constraint(&self, q: &[f64], h: &mut [f64]) {
        h[0] = q[1] - self.curve.eval(q[0]).0;
    }
    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
        j[0] = -self.curve.eval(q[0]).1;
        j[1] = 1.0;
    }
    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
        c[0] = -self.curve.eval(q[0]).2 * qd[0] * qd[0];
    }
    fn contact_geometry(&self, q: &[f64], _qd: &[f64], out: &mut [ContactGeometry]) {
        let (_, slope, curvature) = self.curve.eval(q[0]);
        out[0] = on_ground_cam([q[0], q[1]], slope, curvature);
    }
    fn contact_kinematics_into(
        &self,
        q: &[f64],
        _qd: &[f64],
        _k: usize,
        out: &mut ContactKinematics,
    ) {
        let mut geometry = [ContactGeometry::default()];
        self.contact_geometry(q, _qd, &mut geometry);
        *out = ContactKinematics {
            geometry: geometry[0],
            x: q[0],
            y: q[1],
            j1: vec![1.0, 0.0],
            j2: vec![0.0, 1.0],
            conv1: 0.0,
            conv2: 0.0,
            ..ContactKinematics::new(2)
        };
    }
    fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        if self.lifted {
            q[1] = if t > 0.5 { 2.0 } else { 0.0 };
            qd[1] = 0.0;
            qdd[1] = 0.0;
        }
    }
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        let kinetic = 0.5 * self.mass * (qd[0] * qd[0] + qd[1] * qd[1]);
        Energy {
            kinetic,
            gravity: self.mass * self.gravity * q[1],
            spring: 0.0,
        }
    }
    fn damper_power(&self, qd: &[f64]) -> f64 {
        self.damping * (qd[0] * qd[0] + qd[1] * qd[1])
    }
}

// ------------------------------------------------------------------------------------
// A two-link arm of point masses on a slider: coordinates (s, θ1, θ2); the base moves
// along `axis` (s), link 1 has absolute angle θ1, link 2 relative angle θ2. Point masses
// m0 at the base, m1 at the elbow, m2 at the tip. M = Σ m_k J_kᵀ J_k,
// F = Σ m_k J_kᵀ (J̇_k q̇), Q = Σ m_k g J_k,yᵀ + (0, 0, k θ2 + c θ̇2). Optional contact of
// the tip with the cam y = Σ c_i x^i; optional drive s(t) = A sin(ω t).

const L1: f64 = 0.6;
const L2: f64 = 0.5;
const MASSES: [f64; 3] = [1.0, 0.8, 0.5];

struct Arm {
    info: ModelInfo,
    axis: [f64; 2],
    gravity: f64,
    stiffness: f64,
    damping: f64,
    cam: Option<[f64; 4]>,
    drive: Option<(f64, f64)>,
}

/// Positions, Jacobians (2×3) and convective accelerations J̇ q̇ of the three masses.
struct Points {
    position: [[f64; 2]; 3],
    jacobian: [[[f64; 3]; 2]; 3],
    convective: [[f64; 2]; 3],
}

impl Arm {
    fn new(cam: bool, drive: bool) -> Self {
        let coordinates = vec![
            coordinate("s", JointKind::Prismatic, drive),
            coordinate("th1", JointKind::Revolute, false),
            coordinate("th2", JointKind::Revolute, false),
        ];
        let initial = InitialGuess {
            q: vec![0.0, -std::f64::consts::FRAC_PI_2 + 0.3, 0.4],
            qd: vec![0.3, 0.5, 0.0],
            hold: vec![true, true, false],
            given_q: vec![true; 3],
            given_qd: vec![true; 3],
        };
        let info = model_info("arm", coordinates, usize::from(cam), initial);
        Self {
            info,
            axis: [1.0, 0.0],
            gravity: G,
            stiffness: 0.0,
            damping: 0.0,
            cam: cam.then_some([-0.9, 0.0, 0.3, 0.0]),
            drive: drive.then_some((0.2, 2.0)),
        }
    }

    fn with_spring_damper(mut self, stiffness: f64, damping: f64) -> Self {
        self.stiffness = stiffness;
        self.damping = damping;
        self
    }

    fn points(&self, q: &[f64], qd: &[f64]) -> Points {
        let [ax, ay] = self.axis;
        let (a1, a12) = (q[1], q[1] + q[2]);
        let (w1, w12) = (qd[1], qd[1] + qd[2]);
        let base = [q[0] * ax, q[0] * ay];
        let elbow = [base[0] + L1 * a1.cos(), base[1] + L1 * a1.sin()];
        let tip = [elbow[0] + L2 * a12.cos(), elbow[1] + L2 * a12.sin()];
        let elbow_conv = [-L1 * a1.cos() * w1 * w1, -L1 * a1.sin() * w1 * w1];
        let tip_conv = [
            elbow_conv[0] - L2 * a12.cos() * w12 * w12,
            elbow_conv[1] - L2 * a12.sin() * w12 * w12,
        ];
        let (s1, c1, s12, c12) = (L1 * a1.sin(), L1 * a1.cos(), L2 * a12.sin(), L2 * a12.cos());
        Points {
            position: [base, elbow, tip],
            jacobian: [
                [[ax, 0.0, 0.0], [ay, 0.0, 0.0]],
                [[ax, -s1, 0.0], [ay, c1, 0.0]],
                [[ax, -s1 - s12, -s12], [ay, c1 + c12, c12]],
            ],
            convective: [[0.0, 0.0], elbow_conv, tip_conv],
        }
    }

    /// (f3, f3', f3'') of the cam at x.
    fn cam_at(&self, x: f64) -> (f64, f64, f64) {
        let c = self.cam.unwrap_or_default();
        let f = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
        let slope = c[1] + x * (2.0 * c[2] + 3.0 * x * c[3]);
        (f, slope, 2.0 * c[2] + 6.0 * x * c[3])
    }
}

fn row_dot(row: &[f64; 3], x: &[f64]) -> f64 {
    row.iter().zip(x).map(|(a, b)| a * b).sum()
}

impl Dynamics for Arm {
    fn info(&self) -> &ModelInfo {
        &self.info
    }
    fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {
        let p = self.points(q, &[0.0; 3]);
        m.fill(0.0);
        for (k, mass) in MASSES.iter().enumerate() {
            for row in &p.jacobian[k] {
                for i in 0..3 {
                    for j in 0..3 {
                        m[i * 3 + j] += mass * row[i] * row[j];
                    }
                }
            }
        }
    }
    fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {
        let p = self.points(q, qd);
        f.fill(0.0);
        for (k, mass) in MASSES.iter().enumerate() {
            for (row, conv) in p.jacobian[k].iter().zip(p.convective[k]) {
                for i in 0..3 {
                    f[i] += mass * row[i] * conv;
                }
            }
        }
    }
    fn applied_forces(&self, _t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let p = self.points(q, qd);
        for (i, o) in out.iter_mut().enumerate() {
            *o = (0..3)
                .map(|k| MASSES[k] * self.gravity * p.jacobian[k][1][i])
                .sum();
        }
        out[2] += self.stiffness * q[2] + self.damping * qd[2];
    }
    fn constraint(&self, q: &[f64], h: &mut [f64]) {
        if let Some(h) = h.first_mut() {
            let tip = self.points(q, &[0.0; 3]).position[2];
            *h = tip[1] - self.cam_at(tip[0]).0;
        }
    }
    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
        if self.cam.is_some() {
            let p = self.points(q, &[0.0; 3]);
            let slope = self.cam_at(p.position[2][0]).1;
            let [j1, j2] = p.jacobian[2];
            for i in 0..3 {
                j[i] = j2[i] - slope * j1[i];
            }
        }
    }
    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
        if let Some(c) = c.first_mut() {
            let p = self.points(q, qd);
            let (_, slope, curvature) = self.cam_at(p.position[2][0]);
            let [conv1, conv2] = p.convective[2];
            let x_rate = row_dot(&p.jacobian[2][0], qd);
            *c = conv2 - slope * conv1 - curvature * x_rate * x_rate;
        }
    }
    fn contact_geometry(&self, q: &[f64], _qd: &[f64], out: &mut [ContactGeometry]) {
        if let Some(out) = out.first_mut() {
            let [x, y] = self.points(q, &[0.0; 3]).position[2];
            let (_, slope, curvature) = self.cam_at(x);
            *out = on_ground_cam([x, y], slope, curvature);
        }
    }
    fn contact_kinematics_into(
        &self,
        q: &[f64],
        qd: &[f64],
        _k: usize,
        out: &mut ContactKinematics,
    ) {
        let p = self.points(q, qd);
        let mut geometry = [ContactGeometry::default()];
        self.contact_geometry(q, qd, &mut geometry);
        *out = ContactKinematics {
            geometry: geometry[0],
            x: p.position[2][0],
            y: p.position[2][1],
            j1: p.jacobian[2][0].to_vec(),
            j2: p.jacobian[2][1].to_vec(),
            conv1: p.convective[2][0],
            conv2: p.convective[2][1],
            ..ContactKinematics::new(q.len())
        };
    }
    fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        if let Some((amplitude, omega)) = self.drive {
            q[0] = amplitude * (omega * t).sin();
            qd[0] = amplitude * omega * (omega * t).cos();
            qdd[0] = -amplitude * omega * omega * (omega * t).sin();
        }
    }
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        let p = self.points(q, qd);
        let mut energy = Energy {
            spring: 0.5 * self.stiffness * q[2] * q[2],
            ..Energy::default()
        };
        for (k, mass) in MASSES.iter().enumerate() {
            let [vx, vy] = p.jacobian[k].map(|row| row_dot(&row, qd));
            energy.kinetic += 0.5 * mass * (vx * vx + vy * vy);
            energy.gravity += mass * self.gravity * p.position[k][1];
        }
        energy
    }
    fn damper_power(&self, qd: &[f64]) -> f64 {
        self.damping * qd[2] * qd[2]
    }
}

// ------------------------------------------------------------------------------------
// The independent route: the full system
//   [M    Jᵀ  −E_d] [q̈ ]   [−F − Q]
//   [J    0    0  ] [λ ] = [−c    ]
//   [E_dᵀ 0    0  ] [τ_d]  [q̈_d   ]
// solved by nalgebra's LU. Returns (q̈, λ, τ with zeros on free coordinates).

fn full_system<D: Dynamics>(
    model: &D,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let info = model.info();
    let (n, nc) = (info.n(), info.n_constraints());
    let driven: Vec<usize> = (0..n).filter(|&i| info.coordinates[i].driven).collect();
    let (mut m, mut f, mut applied) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    let (mut j, mut c) = (vec![0.0; nc * n], vec![0.0; nc]);
    let (mut qp, mut qdp, mut qdd_d) = (q.to_vec(), qd.to_vec(), vec![0.0; n]);
    model.prescribed(t, &mut qp, &mut qdp, &mut qdd_d);
    model.mass_matrix(q, &mut m);
    model.inertial_forces(q, qd, &mut f);
    model.applied_forces(t, q, qd, &mut applied);
    model.constraint_jacobian(q, &mut j);
    model.constraint_bias(q, qd, &mut c);
    let size = n + nc + driven.len();
    let mut system = DMatrix::zeros(size, size);
    let mut rhs = DVector::zeros(size);
    for i in 0..n {
        for k in 0..n {
            system[(i, k)] = m[i * n + k];
        }
        rhs[i] = -f[i] - applied[i];
        for k in 0..nc {
            system[(i, n + k)] = j[k * n + i];
            system[(n + k, i)] = j[k * n + i];
        }
    }
    for k in 0..nc {
        rhs[n + k] = -c[k];
    }
    for (e, &d) in driven.iter().enumerate() {
        system[(d, n + nc + e)] = -1.0;
        system[(n + nc + e, d)] = 1.0;
        rhs[n + nc + e] = qdd_d[d];
    }
    let x = system.lu().solve(&rhs).expect("the full system is regular");
    let mut tau = vec![0.0; n];
    for (e, &d) in driven.iter().enumerate() {
        tau[d] = x[n + nc + e];
    }
    (
        x.as_slice()[..n].to_vec(),
        x.as_slice()[n..n + nc].to_vec(),
        tau,
    )
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn run<D: Dynamics>(model: &D, settings: &SimSettings) -> Trajectory {
    let state = model.assemble(0.0).unwrap();
    model.simulate(state, settings).unwrap()
}

fn dopri(t_end: f64, rtol: f64) -> SimSettings {
    settings(IntegratorKind::Dopri5, t_end, 0.05, 1e-3, rtol)
}

fn rk4(t_end: f64, dt: f64) -> SimSettings {
    settings(IntegratorKind::Rk4, t_end, 0.05, dt, 1e-9)
}

fn arms() -> Vec<Arm> {
    vec![
        Arm::new(true, false),
        Arm::new(true, false).with_spring_damper(5.0, 0.3),
        Arm::new(true, true).with_spring_damper(5.0, 0.3),
        Arm::new(false, false),
        Arm::new(false, true),
    ]
}

#[test]
fn partitioned_accelerations_match_the_full_system() {
    // Both routes solve the same linear equations at the same state; the saddle-point
    // system is well conditioned here (entries of order 1, κ ≲ 10³), so they agree to
    // round-off: 1e-10 relative is ≥ 100 times the expected discrepancy.
    for arm in arms() {
        let trajectory = run(&arm, &dopri(1.0, 1e-9));
        for sample in &trajectory.samples {
            let (qdd, lambda, tau) = full_system(&arm, sample.t, &sample.q, &sample.qd);
            let scale = 1.0
                + qdd
                    .iter()
                    .chain(&lambda)
                    .chain(&tau)
                    .fold(0.0_f64, |m, x| m.max(x.abs()));
            assert!(
                max_difference(&sample.qdd, &qdd) < 1e-10 * scale,
                "t = {}",
                sample.t
            );
            assert!(
                max_difference(&sample.lambda, &lambda) < 1e-10 * scale,
                "t = {}",
                sample.t
            );
            assert!(
                max_difference(&sample.drive, &tau) < 1e-10 * scale,
                "t = {}",
                sample.t
            );
        }
    }
}

#[test]
fn constraint_holds_along_a_run() {
    // Every stored state went through Newton (15) to |h| ≤ 1e-12 and J q̇ = 0 (16) by a
    // direct solve; 1e-10 leaves a margin of 100 for h and for round-off in J q̇.
    for arm in arms().into_iter().filter(|arm| arm.cam.is_some()) {
        for settings in [dopri(2.0, 1e-8), rk4(2.0, 2e-3)] {
            let trajectory = run(&arm, &settings);
            assert_eq!(trajectory.samples.len(), 41);
            for sample in &trajectory.samples {
                assert!(
                    sample.h[0].abs() < 1e-10,
                    "h = {} at t = {}",
                    sample.h[0],
                    sample.t
                );
                let mut j = [0.0; 3];
                arm.constraint_jacobian(&sample.q, &mut j);
                let velocity = row_dot(&j, &sample.qd);
                assert!(
                    velocity.abs() < 1e-10,
                    "J q̇ = {velocity} at t = {}",
                    sample.t
                );
            }
        }
    }
}

/// max_t |E(t) − E(0) − W_drive(t) + D(t)|: zero for exact solutions.
fn energy_balance_error(trajectory: &Trajectory) -> f64 {
    let first = trajectory.samples[0].energy.total();
    trajectory
        .samples
        .iter()
        .map(|s| (s.energy.total() - first - s.driven_work + s.dissipated).abs())
        .fold(0.0, f64::max)
}

#[test]
fn energy_is_conserved_without_damping() {
    // Energies here are O(10) J. With rtol = 1e-10 the local error is ~1e-10 relative
    // per step; over ~500 steps the drift stays ≲ 1e-8 J (measured: bead 2.3e-9 J,
    // arms 1–2e-10 J). Bound: 1e-7 J, i.e. 1e-8 relative. The bead and the arm on the
    // cam also re-partition once on the way (see `repartition_…`), which must not
    // disturb the balance.
    let bead = Bead::new(Curve::Parabola(0.5), 1.0, 0.0);
    let trajectory = run(&bead, &dopri(5.0, 1e-10));
    assert!(
        energy_balance_error(&trajectory) < 1e-7,
        "bead: {}",
        energy_balance_error(&trajectory)
    );
    for arm in [Arm::new(true, false), Arm::new(false, false)] {
        let trajectory = run(&arm, &dopri(3.0, 1e-10));
        let error = energy_balance_error(&trajectory);
        assert!(
            error < 1e-7,
            "arm with {} contacts: {error}",
            arm.info.n_contacts()
        );
    }
}

#[test]
fn energy_balance_holds_with_drive_and_damper() {
    // E(t) − E(0) = W_drive − D, with W_drive and D integrated as quadratures of Σ τ_d q̇_d
    // and Σ c q̇² alongside the motion. The quadratures are not error-controlled but use
    // the same fifth-order stages; with rtol = 1e-10 the balance closes to 7e-11 J
    // (measured); bound 1e-8 J against energies of O(10) J and works of O(0.1–1) J.
    for arm in [Arm::new(true, true), Arm::new(false, true)] {
        let arm = arm.with_spring_damper(5.0, 0.3);
        let trajectory = run(&arm, &dopri(3.0, 1e-10));
        let last = trajectory.samples.last().unwrap();
        assert!(last.dissipated > 1e-3 && last.driven_work.abs() > 1e-3);
        let error = energy_balance_error(&trajectory);
        assert!(
            error < 1e-8,
            "arm with {} contacts: {error}",
            arm.info.n_contacts()
        );
    }
}

/// N = m (g cos θ + v² κ) for a bead on y = f(x): cos θ = 1/√(1 + f'²), signed curvature
/// κ = f''/(1 + f'²)^{3/2}, speed² v² = ẋ² + ẏ².
fn closed_form_normal_force(bead: &Bead, q: &[f64], qd: &[f64]) -> f64 {
    let (_, slope, second) = bead.curve.eval(q[0]);
    let stretch = (1.0 + slope * slope).sqrt();
    let speed2 = qd[0] * qd[0] + qd[1] * qd[1];
    bead.mass * (bead.gravity / stretch + speed2 * second / stretch.powi(3))
}

#[test]
fn normal_force_matches_the_closed_form() {
    // At the bottom of y = a x² with speed v: N = m (g + 2 a v²). The closed form and
    // the multiplier are evaluated at the same state, along the whole run too, so they
    // agree to round-off (measured 6e-16 relative); bound 1e-12 relative.
    let bead = Bead::new(Curve::Parabola(0.5), 0.0, 3.0);
    let state = bead.assemble(0.0).unwrap();
    let sample = bead.sample(&state).unwrap();
    let expected = bead.mass * (G + 2.0 * 0.5 * 9.0);
    assert!((sample.normal_force[0] - expected).abs() < 1e-12 * expected);
    let trajectory = bead.simulate(state, &dopri(3.0, 1e-9)).unwrap();
    for sample in &trajectory.samples {
        let expected = closed_form_normal_force(&bead, &sample.q, &sample.qd);
        assert!(
            (sample.normal_force[0] - expected).abs() < 1e-12 * expected,
            "t = {}",
            sample.t
        );
    }
}

/// A bead going over the top of a circle of radius 1: starts at x = 0.9 on the right
/// flank moving up-left at 4 m/s, passes the top (where J_x = −f' = 0) near t ≈ 0.3 s.
fn circle_bead() -> Bead {
    let slope = Curve::UpperCircle(1.0).eval(0.9).1;
    Bead::new(
        Curve::UpperCircle(1.0),
        0.9,
        -4.0 / (1.0 + slope * slope).sqrt(),
    )
}

#[test]
fn repartition_passes_a_vanishing_pivot_smoothly() {
    let bead = circle_bead();
    let t_end = 0.6;
    let settings = dopri(t_end, 1e-10);
    let automatic = bead.assemble(0.0).unwrap();
    assert_eq!(
        automatic.dependent(),
        &[0],
        "x has the larger |J_i| on the flank"
    );
    let mut imposed = automatic.clone();
    imposed.set_dependent(&[1]).unwrap();
    let first = bead.simulate(automatic, &settings).unwrap();
    let second = bead.simulate(imposed, &settings).unwrap();

    assert_eq!(first.stats.repartitions, 1);
    assert_eq!(second.stats.repartitions, 0);
    let (a, b) = (
        first.samples.last().unwrap(),
        second.samples.last().unwrap(),
    );
    assert_eq!(a.dependent[..], [1]);
    assert!(a.q[0] < -0.3, "the bead is past the top: x = {}", a.q[0]);
    // The runs integrate different coordinates (x, then y, against y throughout), so
    // they differ by the sum of their global errors: ~10·rtol each over ~100 steps
    // (measured difference 1.2e-9 on q and q̇). Bound 1e-8: ten times the measurement,
    // yet a mishandled switch (a lost FSAL restart, stale u) would show at 1e-4 or more.
    for (sa, sb) in first.samples.iter().zip(&second.samples) {
        assert!(max_difference(&sa.q, &sb.q) < 1e-8, "t = {}", sa.t);
        assert!(max_difference(&sa.qd, &sb.qd) < 1e-8, "t = {}", sa.t);
        assert!(sa.h[0].abs() < 1e-10);
    }
    assert!(energy_balance_error(&first) < 1e-7);
    let rk4_run = run(&bead, &rk4(t_end, 1e-3));
    assert_eq!(rk4_run.stats.repartitions, 1);
    // RK4 with h = 1e-3: global error ~ C h⁴ with C ~ 10² for these derivatives
    // (measured difference 5e-10); bound 1e-8.
    assert!(max_difference(&rk4_run.samples.last().unwrap().q, &b.q) < 1e-8);
}

#[test]
fn unreachable_cam_gives_newton_failed_with_time_and_state() {
    // y is lifted from 0 to 2 at t = 0.5; the cap y = 1 − x² never exceeds 1.
    let bead = Bead::lifted(0.8);
    let state = bead.assemble(0.0).unwrap();
    assert!(
        (state.q[0] - 1.0).abs() < 1e-12,
        "x solved onto the cap: {}",
        state.q[0]
    );
    for settings in [rk4(1.0, 0.01), dopri(1.0, 1e-8)] {
        let failure = bead.simulate(state.clone(), &settings).unwrap_err();
        let SimError::NewtonFailed {
            t,
            ref q,
            residual,
            iterations,
        } = failure.error
        else {
            panic!("expected NewtonFailed, got {}", failure.error);
        };
        assert!(t > 0.5 && t < 0.51, "t = {t}");
        assert_eq!(q[1], 2.0);
        assert!(q.iter().all(|x| x.is_finite()) && residual > 1e-3);
        assert!(iterations <= crate::partition::NEWTON_MAX_ITERATIONS);
        assert!(
            failure.to_string().contains("cannot reach the cam"),
            "{failure}"
        );
        // RK4 lands on the output time 0.5 where the point leaves the cap; Dopri5 steps
        // freely and its steps shrink onto that point: the last accepted state is kept
        // as the final sample, within round-off steps of 0.5.
        let last = failure.partial.samples.last().unwrap();
        assert!((last.t - 0.5).abs() < 1e-9, "last sample at {}", last.t);
        assert_eq!(failure.partial.samples.len(), 11);
    }
}

#[test]
fn assembly_falls_back_to_damped_newton() {
    // y held at 0, x solved from atan x = 0 starting at x = 2, where plain Newton
    // diverges (x ← x − (1 + x²) atan x overshoots to −3.5, then further out).
    let mut bead = Bead::new(Curve::Arctan, 2.0, 0.0);
    bead.info.initial.q = vec![2.0, 0.0];
    bead.info.initial.hold = vec![false, true];
    let mut ws = Workspace::new(2, 1, 0);
    ws.set_state(&[2.0, 0.0], &[0.0, 0.0]);
    assert!(ws.solve_positions(&bead, &[0], 0.0).is_err());
    let state = bead.assemble(0.0).unwrap();
    // Converged to |h| ≤ 1e-12 with |J_x| = 1 at the root: |x| ≤ ~1e-12.
    assert!(
        state.q[0].abs() < 1e-11 && state.q[1] == 0.0,
        "{:?}",
        state.q
    );
}

#[test]
fn non_finite_forces_are_reported_not_propagated() {
    let mut bead = Bead::new(Curve::Parabola(0.5), 0.5, 0.0);
    bead.gravity = f64::NAN;
    let state = bead.assemble(0.0).unwrap();
    let failure = bead.simulate(state, &dopri(1.0, 1e-8)).unwrap_err();
    assert!(
        matches!(
            failure.error,
            SimError::NonFinite {
                quantity: "q̈", ..
            }
        ),
        "{}",
        failure.error
    );
    assert!(failure.partial.samples.is_empty());
}

#[test]
fn chains_without_contact_are_plain_odes() {
    let arm = Arm::new(false, false);
    let state = arm.assemble(0.0).unwrap();
    assert!(state.dependent().is_empty());
    assert_eq!(state.independent(), &[0, 1, 2]);
    let trajectory = arm.simulate(state, &dopri(1.0, 1e-9)).unwrap();
    let sample = trajectory.samples.last().unwrap();
    assert!(sample.lambda.is_empty() && sample.h.is_empty() && sample.contacts.is_empty());
    assert_eq!(sample.drive, vec![0.0; 3]);
}

#[test]
fn integrators_agree() {
    // RK4 with h = 1e-3 (global error ~ C h⁴, measured difference 2e-12) against
    // Dopri5 with rtol = 1e-11: bound 1e-9, which an order or landing mistake in either
    // integrator (errors ~h³ = 1e-9·C or worse) would exceed.
    let arm = Arm::new(true, true).with_spring_damper(5.0, 0.3);
    let fine = run(&arm, &dopri(1.0, 1e-11));
    let fixed = run(&arm, &rk4(1.0, 1e-3));
    let (a, b) = (fine.samples.last().unwrap(), fixed.samples.last().unwrap());
    assert!(max_difference(&a.q, &b.q) < 1e-9, "{:?} vs {:?}", a.q, b.q);
    assert_eq!(fixed.stats.rhs_evaluations, 4 * fixed.stats.steps);
    assert_eq!(fixed.stats.steps, 1000);
}

#[test]
fn fixed_steps_stay_fixed_late_in_a_long_run() {
    // At t ≈ 1000 s each t + h rounds by up to ulp(1000)/2 ≈ 6e-14 s, which accumulates
    // over the 100 steps of an output interval to more than 1e-9·dt: the last step of
    // an interval must still land on the output time, not leave a sliver step.
    let arm = Arm::new(true, false);
    let state = arm.assemble(1000.0).unwrap();
    let mut settings = rk4(1010.0, 1e-3);
    settings.dt_out = 0.1;
    let trajectory = arm.simulate(state, &settings).unwrap();
    assert_eq!(trajectory.stats.steps, 10_000);
}

#[test]
fn observed_samples_are_the_trajectory() {
    let arm = Arm::new(true, true).with_spring_damper(5.0, 0.3);
    let settings = dopri(1.0, 1e-9);
    let mut seen = Vec::new();
    let state = arm.assemble(0.0).unwrap();
    let observed = arm
        .simulate_observed(state, &settings, &mut |s| {
            seen.push(s.clone());
            Observed::Continue(())
        })
        .unwrap();
    assert_eq!(seen, observed.samples);
    assert_eq!(observed, run(&arm, &settings));
}

#[test]
fn an_observer_that_breaks_stops_the_run_with_the_samples_so_far() {
    let arm = Arm::new(true, true).with_spring_damper(5.0, 0.3);
    for integrator in [IntegratorKind::Rk4, IntegratorKind::Dop853] {
        let settings = settings(integrator, 1.0, 0.1, 1e-3, 1e-9);
        let state = arm.assemble(0.0).unwrap();
        let mut count = 0;
        let failure = arm
            .simulate_observed(state, &settings, &mut |_| {
                count += 1;
                if count == 4 {
                    Observed::Break(())
                } else {
                    Observed::Continue(())
                }
            })
            .expect_err("stopped");
        // Samples at t = 0, 0.1, 0.2, 0.3: the fourth asked to stop.
        assert_eq!(
            failure.error,
            SimError::Interrupted {
                t: 0.30000000000000004
            }
        );
        let times: Vec<f64> = failure.partial.samples.iter().map(|s| s.t).collect();
        assert_eq!(times[..4], [0.0, 0.1, 0.2, 0.30000000000000004]);
        let whole = run(&arm, &settings);
        assert_eq!(failure.partial.samples[..4], whole.samples[..4]);
    }
}

#[test]
fn outputs_land_on_the_requested_times() {
    let arm = Arm::new(true, false);
    for integrator in [IntegratorKind::Rk4, IntegratorKind::Dopri5] {
        let settings = settings(integrator, 1.0, 0.3, 0.07, 1e-8);
        let trajectory = run(&arm, &settings);
        let times: Vec<f64> = trajectory.samples.iter().map(|s| s.t).collect();
        assert_eq!(times, vec![0.0, 0.3, 0.6, 0.3 * 3.0, 1.0]);
    }
    let mut state = arm.assemble(0.25).unwrap();
    let stats = arm.step(&mut state, 0.1).unwrap();
    assert_eq!(state.t, 0.25 + 0.1);
    assert!(stats.steps > 0 && stats.rhs_evaluations >= 6 * stats.steps);
    let stats = arm.step_with(&mut state, 0.05, &rk4(1.0, 0.02)).unwrap();
    assert_eq!(stats.steps, 3);
    assert_eq!(state.t, 0.25 + 0.1 + 0.05);
}

#[test]
fn a_modified_state_restarts_consistently() {
    // Changing an independent velocity between steps: the dependent velocity is
    // re-solved, so J q̇ = 0 and h = 0 hold after the next step.
    let arm = Arm::new(true, false);
    let mut state = arm.assemble(0.0).unwrap();
    arm.step(&mut state, 0.1).unwrap();
    let u = state.independent()[0];
    state.qd[u] += 0.5;
    arm.step(&mut state, 0.1).unwrap();
    let sample = arm.sample(&state).unwrap();
    let mut j = [0.0; 3];
    arm.constraint_jacobian(&state.q, &mut j);
    assert!(row_dot(&j, &state.qd).abs() < 1e-10 && sample.h[0].abs() < 1e-10);
}

#[test]
fn invalid_settings_are_rejected() {
    let arm = Arm::new(true, false);
    let state = arm.assemble(0.0).unwrap();
    let good = dopri(1.0, 1e-8);
    let cases = [
        SimSettings {
            dt: 0.0,
            ..good.clone()
        },
        SimSettings {
            dt_out: -1.0,
            ..good.clone()
        },
        SimSettings {
            t_end: -1.0,
            ..good.clone()
        },
        SimSettings {
            rtol: 0.0,
            ..good.clone()
        },
        SimSettings {
            atol: f64::NAN,
            ..good.clone()
        },
        SimSettings {
            t_end: f64::INFINITY,
            ..good.clone()
        },
    ];
    for settings in cases {
        let failure = arm.simulate(state.clone(), &settings).unwrap_err();
        assert!(
            matches!(failure.error, SimError::InvalidSettings { .. }),
            "{settings:?}"
        );
    }
    let mut state = state;
    assert!(matches!(
        arm.step(&mut state, -0.1),
        Err(SimError::InvalidSettings { .. })
    ));
    assert!(state.set_dependent(&[0, 1]).is_err());
}

mod streamed;
