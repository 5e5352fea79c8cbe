use camchain_models as models;
use camchain_runtime::{Dynamics, MetricsOptions, Simulate};
use std::time::Instant;

fn main() {
    let model = models::by_name("paper_concave").unwrap();
    let mut settings = model.info().defaults.clone();
    settings.rtol = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-6);
    settings.atol = settings.rtol;

    let state = model.assemble(0.0).unwrap();
    let reps = 300;
    let time = |f: &mut dyn FnMut() -> usize| {
        let mut times = vec![];
        let mut rhs = 0;
        for _ in 0..reps {
            let t = Instant::now();
            rhs = f();
            times.push(t.elapsed().as_secs_f64() * 1e6);
        }
        times.sort_by(f64::total_cmp);
        (times[reps / 2], rhs)
    };
    if std::env::var("COUNT").is_ok() {
        let c = Counting {
            inner: model,
            pos: Cell::new(0),
            vel: Cell::new(0),
            other: Cell::new(0),
        };
        let m = c
            .simulate_metrics(state.clone(), &settings, MetricsOptions::default())
            .unwrap();
        println!(
            "rhs {} position_terms {} velocity_terms {} other {}",
            m.stats.rhs_evaluations,
            c.pos.get(),
            c.vel.get(),
            c.other.get()
        );
        return;
    }
    if std::env::var("ONLY_METRICS").is_ok() {
        for _ in 0..2000 {
            std::hint::black_box(
                model
                    .simulate_metrics(state.clone(), &settings, MetricsOptions::default())
                    .unwrap(),
            );
        }
        return;
    }
    let full = time(&mut || {
        model
            .simulate(state.clone(), &settings)
            .unwrap()
            .stats
            .rhs_evaluations
    });
    let states_run = time(&mut || {
        model
            .simulate_states(state.clone(), &settings)
            .unwrap()
            .stats
            .rhs_evaluations
    });
    let metrics = time(&mut || {
        let m = model
            .simulate_metrics(state.clone(), &settings, MetricsOptions::default())
            .unwrap();
        m.stats.rhs_evaluations
    });
    let grid = time(&mut || {
        let m = model
            .simulate_metrics(state.clone(), &settings, MetricsOptions { grid: true })
            .unwrap();
        m.stats.rhs_evaluations
    });
    // reduced rhs at 8 states along a run, the cache cleared before each (a new state)
    let mut st = state.clone();
    let mut states = vec![];
    for _ in 0..8 {
        model.step(&mut st, 0.5).unwrap();
        states.push(st.clone());
    }
    let mut dy = vec![0.0; states[0].integrated_len()];
    for s in &mut states {
        model.derivative(s, &mut dy).unwrap();
    }
    let n = 200000;
    let mut med = |with: bool| {
        let mut v = vec![];
        for _ in 0..15 {
            let t = Instant::now();
            for k in 0..n {
                let s = &mut states[k % 8];
                s.clear_evaluation_cache();
                if with {
                    model.derivative(s, &mut dy).unwrap();
                    std::hint::black_box(&dy);
                }
            }
            v.push(t.elapsed().as_secs_f64() * 1e9 / n as f64);
        }
        v.sort_by(f64::total_cmp);
        v[7]
    };
    let with = med(true);
    let without = med(false);
    let rhs_ns = with - without;
    println!("clear alone {without:.1} ns");
    println!("rtol {} reduced rhs {rhs_ns:.0} ns", settings.rtol);
    for (name, (us, rhs)) in [
        ("full", full),
        ("states", states_run),
        ("metrics", metrics),
        ("metrics+grid", grid),
    ] {
        println!(
            "{name:14} {us:8.1} us  {rhs:6} rhs  ratio {:.2}",
            us * 1e3 / (rhs as f64 * rhs_ns)
        );
    }
    let m = model
        .simulate_metrics(state.clone(), &settings, MetricsOptions::default())
        .unwrap();
    let g = model
        .simulate_metrics(state.clone(), &settings, MetricsOptions { grid: true })
        .unwrap();
    println!("{m:?}\n{g:?}");
}

use camchain_runtime::{ContactGeometry, ContactKinematics, Energy, ModelInfo, VelocityTerms};
use std::cell::Cell;
pub struct Counting<'a> {
    pub inner: &'a dyn Dynamics,
    pub pos: Cell<usize>,
    pub vel: Cell<usize>,
    pub other: Cell<usize>,
}
impl Dynamics for Counting<'_> {
    fn info(&self) -> &ModelInfo {
        self.inner.info()
    }
    fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {
        self.other.set(self.other.get() + 1);
        self.inner.mass_matrix(q, m)
    }
    fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {
        self.other.set(self.other.get() + 1);
        self.inner.inertial_forces(q, qd, f)
    }
    fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], o: &mut [f64]) {
        self.other.set(self.other.get() + 1);
        self.inner.applied_forces(t, q, qd, o)
    }
    fn constraint(&self, q: &[f64], h: &mut [f64]) {
        self.other.set(self.other.get() + 1);
        self.inner.constraint(q, h)
    }
    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
        self.other.set(self.other.get() + 1);
        self.inner.constraint_jacobian(q, j)
    }
    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
        self.other.set(self.other.get() + 1);
        self.inner.constraint_bias(q, qd, c)
    }
    fn contact_geometry(&self, q: &[f64], o: &mut [ContactGeometry]) {
        self.other.set(self.other.get() + 1);
        self.inner.contact_geometry(q, o)
    }
    fn contact_kinematics_into(&self, q: &[f64], qd: &[f64], k: usize, o: &mut ContactKinematics) {
        self.inner.contact_kinematics_into(q, qd, k, o)
    }
    fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        self.inner.prescribed(t, q, qd, qdd)
    }
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        self.other.set(self.other.get() + 1);
        self.inner.energy(q, qd)
    }
    fn damper_power(&self, qd: &[f64]) -> f64 {
        self.inner.damper_power(qd)
    }
    fn cache_len(&self) -> usize {
        self.inner.cache_len()
    }
    fn position_terms(&self, q: &[f64], h: &mut [f64], j: &mut [f64], c: &mut [f64]) {
        self.pos.set(self.pos.get() + 1);
        self.inner.position_terms(q, h, j, c)
    }
    fn velocity_terms(&self, t: f64, q: &[f64], qd: &[f64], c: &[f64], o: VelocityTerms) {
        self.vel.set(self.vel.get() + 1);
        self.inner.velocity_terms(t, q, qd, c, o)
    }
}
