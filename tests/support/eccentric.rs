//! The normal force of `eccentric_flat` in closed form, derived from its model file: in
//! contact the follower has no freedom, the face's height is s = R + e cos θ (θ = ωt), and
//! its equation of motion m s̈ = N − m g − k (s − s_free) − c ṡ gives
//!
//!     N(θ) = A + B cos θ − C sin θ,   A = m g + k (R − s_free), B = e (k − m ω²), C = c e ω,
//!
//! least at A − √(B² + C²). The jump speed ω_j solves e² ((m ω² − k)² + c² ω²) = A², a
//! quadratic in ω². Shared by the one-sided runs (suite/unilateral.rs) and the metrics runs
//! (suite/metrics.rs).

use camchain_models as models;
use std::f64::consts::{PI, TAU};

/// The values of a built-in model file's parameters (constant ones included), by name: what
/// the closed forms are derived from.
pub fn file_parameters(name: &str) -> impl Fn(&str) -> f64 {
    let source = models::source(name).expect("built in");
    let file = std::path::PathBuf::from(format!("models/{name}.ron"));
    let model = camchain_codegen::schema::parse_model(source, &file).expect("valid");
    let values: Vec<(String, f64)> = model
        .parameters
        .iter()
        .map(|p| (p.name.clone(), p.default))
        .collect();
    move |wanted: &str| {
        values
            .iter()
            .find(|(n, _)| n == wanted)
            .map(|p| p.1)
            .unwrap_or_else(|| panic!("{name} has no parameter {wanted}"))
    }
}

/// eccentric_flat's follower, from the file's parameters.
pub struct EccentricFlat {
    m: f64,
    g: f64,
    k: f64,
    r: f64,
    e: f64,
    free: f64,
    c: f64,
}

impl EccentricFlat {
    pub fn from_file() -> Self {
        let p = file_parameters("eccentric_flat");
        EccentricFlat {
            m: p("m"),
            g: p("g"),
            k: p("k"),
            r: p("R"),
            e: p("e"),
            free: p("free"),
            c: p("c"),
        }
    }

    fn a(&self) -> f64 {
        self.m * self.g + self.k * (self.r - self.free)
    }

    pub fn jump_speed(&self) -> f64 {
        let (m, k, c, e) = (self.m, self.k, self.c, self.e);
        // m² x² + (c² − 2 m k) x + k² − A²/e² = 0 with x = ω², the larger root.
        let (qa, qb, qc) = (m * m, c * c - 2.0 * m * k, k * k - (self.a() / e).powi(2));
        ((-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa)).sqrt()
    }

    /// N at cam angle θ and speed ω.
    pub fn force(&self, theta: f64, omega: f64) -> f64 {
        let b = self.e * (self.k - self.m * omega * omega);
        let c = self.c * self.e * omega;
        self.a() + b * theta.cos() - c * theta.sin()
    }

    /// The cam angles in [0, 2π) where N reaches zero going down, and where it is least.
    pub fn lift_off_and_least(&self, omega: f64) -> (f64, f64) {
        let b = self.e * (self.k - self.m * omega * omega);
        let c = self.c * self.e * omega;
        // N = A + ρ cos(θ + φ) with ρ cos φ = B, ρ sin φ = C.
        let (rho, phi) = (b.hypot(c), c.atan2(b));
        let down = (-self.a() / rho).acos() - phi;
        (down.rem_euclid(TAU), (PI - phi).rem_euclid(TAU))
    }
}
