//! Drives an FMU's master can set: the speed of every coordinate driven at a constant speed
//! (a camshaft turning at `omega*t`) becomes an input, and a model whose input was set
//! follows it instead of its own law.
//!
//! [`Driven`] is the model seen through its inputs: every [`Dynamics`] method is the model's
//! own, but for [`Dynamics::prescribed`] of a coordinate whose speed was set, which moves on
//! at that speed from where the drive was when it was set (the angle is continuous, the
//! speed steps, the acceleration is zero between changes). The runtime solves the dependent
//! coordinates and their velocities from the prescribed ones at every right-hand side, so a
//! speed step acts from the next step on.

use camchain_runtime::{
    ArticulatedTerms, ContactGeometry, ContactKinematics, Dynamics, Energy, Flank, ModelInfo,
    VelocityTerms,
};

/// The times at which a drive is sampled to tell whether its speed is constant: spread over
/// several seconds, none a round number a periodic law would repeat at.
const PROBES: [f64; 4] = [0.0, 0.371, 1.137, 3.929];

/// The coordinates driven at a constant speed, with that speed: those whose prescribed
/// acceleration is zero and whose speed is the same (to 1e-12) at every probe time.
pub fn constant_speed_drives(model: &dyn Dynamics) -> Vec<(usize, f64)> {
    let info = model.info();
    let n = info.n();
    let mut samples = Vec::new();
    for &t in &PROBES {
        let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        model.prescribed(t, &mut q, &mut qd, &mut qdd);
        samples.push((qd, qdd));
    }
    info.coordinates
        .iter()
        .enumerate()
        .filter(|(_, c)| c.driven)
        .filter_map(|(i, _)| {
            let speed = samples[0].0[i];
            let constant = samples.iter().all(|(qd, qdd)| {
                qdd[i] == 0.0
                    && speed.is_finite()
                    && (qd[i] - speed).abs() <= 1e-12 * speed.abs().max(1.0)
            });
            constant.then_some((i, speed))
        })
        .collect()
}

/// A drive whose speed was set: from `(t0, q0)` on at `speed`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Override {
    coordinate: usize,
    t0: f64,
    q0: f64,
    speed: f64,
}

/// The model with the speeds its master set (see the module documentation).
pub struct Driven {
    inner: Box<dyn Dynamics + Send + Sync>,
    overrides: Vec<Override>,
}

impl Driven {
    /// The model, following its own laws until a speed is set.
    pub fn new(inner: Box<dyn Dynamics + Send + Sync>) -> Self {
        Driven {
            inner,
            overrides: Vec::new(),
        }
    }

    /// From time `t` on, coordinate `coordinate` moves at `speed`, starting where its drive
    /// is at `t` (under the law it followed until then).
    pub fn set_speed(&mut self, coordinate: usize, speed: f64, t: f64) {
        let n = self.inner.info().n();
        let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        self.prescribed(t, &mut q, &mut qd, &mut qdd);
        let new = Override {
            coordinate,
            t0: t,
            q0: q.get(coordinate).copied().unwrap_or(0.0),
            speed,
        };
        match self
            .overrides
            .iter_mut()
            .find(|o| o.coordinate == coordinate)
        {
            Some(o) => *o = new,
            None => self.overrides.push(new),
        }
    }
}

impl Dynamics for Driven {
    fn info(&self) -> &ModelInfo {
        self.inner.info()
    }
    fn parameter_values(&self) -> &[f64] {
        self.inner.parameter_values()
    }
    fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {
        self.inner.mass_matrix(q, m);
    }
    fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {
        self.inner.inertial_forces(q, qd, f);
    }
    fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.inner.applied_forces(t, q, qd, out);
    }
    fn loop_points(&self, q: &[f64], out: &mut [[f64; 3]]) {
        self.inner.loop_points(q, out);
    }
    fn constraint(&self, q: &[f64], h: &mut [f64]) {
        self.inner.constraint(q, h);
    }
    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
        self.inner.constraint_jacobian(q, j);
    }
    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
        self.inner.constraint_bias(q, qd, c);
    }
    fn contact_geometry(&self, q: &[f64], qd: &[f64], out: &mut [ContactGeometry]) {
        self.inner.contact_geometry(q, qd, out);
    }
    fn contact_kinematics_into(
        &self,
        q: &[f64],
        qd: &[f64],
        k: usize,
        out: &mut ContactKinematics,
    ) {
        self.inner.contact_kinematics_into(q, qd, k, out);
    }
    fn contact_kinematics(&self, q: &[f64], qd: &[f64], k: usize) -> ContactKinematics {
        self.inner.contact_kinematics(q, qd, k)
    }
    fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        self.inner.prescribed(t, q, qd, qdd);
        for o in &self.overrides {
            if let (Some(q), Some(qd), Some(qdd)) = (
                q.get_mut(o.coordinate),
                qd.get_mut(o.coordinate),
                qdd.get_mut(o.coordinate),
            ) {
                *q = o.q0 + o.speed * (t - o.t0);
                *qd = o.speed;
                *qdd = 0.0;
            }
        }
    }
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        self.inner.energy(q, qd)
    }
    fn damper_power(&self, qd: &[f64]) -> f64 {
        self.inner.damper_power(qd)
    }
    fn load_power(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        self.inner.load_power(t, q, qd)
    }
    fn groove_flank(&self, q: &[f64], k: usize) -> Option<Flank> {
        self.inner.groove_flank(q, k)
    }
    fn equations(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        m: &mut [f64],
        f: &mut [f64],
        applied: &mut [f64],
    ) {
        self.inner.equations(t, q, qd, m, f, applied);
    }
    fn constraint_terms(&self, q: &[f64], qd: &[f64], j: &mut [f64], c: &mut [f64]) {
        self.inner.constraint_terms(q, qd, j, c);
    }
    fn cache_len(&self) -> usize {
        self.inner.cache_len()
    }
    fn position_terms(&self, q: &[f64], h: &mut [f64], j: &mut [f64], cache: &mut [f64]) {
        self.inner.position_terms(q, h, j, cache);
    }
    fn velocity_terms(&self, t: f64, q: &[f64], qd: &[f64], cache: &[f64], out: VelocityTerms) {
        self.inner.velocity_terms(t, q, qd, cache, out);
    }
    // The articulated route reads the driven accelerations the runtime takes from
    // `prescribed` (this view's), so it is forwarded as it is.
    fn articulated_len(&self) -> usize {
        self.inner.articulated_len()
    }
    fn articulated_rows(&self) -> usize {
        self.inner.articulated_rows()
    }
    fn articulated_terms(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        cache: &[f64],
        out: ArticulatedTerms<'_>,
    ) {
        self.inner.articulated_terms(t, q, qd, cache, out);
    }
    fn articulated_response(
        &self,
        factors: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
        drive: &mut [f64],
    ) {
        self.inner.articulated_response(factors, tau, qdd, drive);
    }
}
