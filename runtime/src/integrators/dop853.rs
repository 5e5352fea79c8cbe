//! Dormand–Prince 8(5,3) with its seventh-order dense output (Hairer, Nørsett & Wanner,
//! *Solving Ordinary Differential Equations I*, §II.10; the coefficients are those of
//! Hairer's `DOP853`).
//!
//! Twelve stages per step plus the derivative at the new point, which the next step reuses
//! (first same as last). The error estimate combines the fifth- and third-order embedded
//! solutions as Hairer does, which keeps it reliable at large steps. Dense output needs three
//! more evaluations; they are made only for steps that contain an output time.

// The coefficients are quoted with the digits of the published tables.
#![allow(clippy::excessive_precision, clippy::unreadable_literal)]

use super::{
    AcceptedStep, Adaptive, CONTROLLER_BETA, Controller, Counters, Tolerances, controlled_step,
};
use crate::error::SimError;

/// Number of stage derivatives kept: k1…k12, k13 = f(t + h, y_new), k14…k16 (dense output).
const STAGES: usize = 16;

/// Nodes c_i of the stages (index = stage − 1); c13 = 1 (the new point).
const C: [f64; STAGES] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510e+00,
    0.281649658092772603273242802490e+00,
    0.333333333333333333333333333333e+00,
    0.25e+00,
    0.307692307692307692307692307692e+00,
    0.651282051282051282051282051282e+00,
    0.6e+00,
    0.857142857142857142857142857142e+00,
    1.0,
    1.0,
    0.1e+00,
    0.2e+00,
    0.777777777777777777777777777778e+00,
];

/// Non-zero coefficients a_ij of stage i (index = i − 1) as (j − 1, a_ij).
const A: [&[(usize, f64)]; STAGES] = [
    &[],
    &[(0, 5.26001519587677318785587544488e-2)],
    &[
        (0, 1.97250569845378994544595329183e-2),
        (1, 5.91751709536136983633785987549e-2),
    ],
    &[
        (0, 2.95875854768068491816892993775e-2),
        (2, 8.87627564304205475450678981324e-2),
    ],
    &[
        (0, 2.41365134159266685502369798665e-1),
        (2, -8.84549479328286085344864962717e-1),
        (3, 9.24834003261792003115737966543e-1),
    ],
    &[
        (0, 3.7037037037037037037037037037e-2),
        (3, 1.70828608729473871279604482173e-1),
        (4, 1.25467687566822425016691814123e-1),
    ],
    &[
        (0, 3.7109375e-2),
        (3, 1.70252211019544039314978060272e-1),
        (4, 6.02165389804559606850219397283e-2),
        (5, -1.7578125e-2),
    ],
    &[
        (0, 3.70920001185047927108779319836e-2),
        (3, 1.70383925712239993810214054705e-1),
        (4, 1.07262030446373284651809199168e-1),
        (5, -1.53194377486244017527936158236e-2),
        (6, 8.27378916381402288758473766002e-3),
    ],
    &[
        (0, 6.24110958716075717114429577812e-1),
        (3, -3.36089262944694129406857109825e0),
        (4, -8.68219346841726006818189891453e-1),
        (5, 2.75920996994467083049415600797e1),
        (6, 2.01540675504778934086186788979e1),
        (7, -4.34898841810699588477366255144e1),
    ],
    &[
        (0, 4.77662536438264365890433908527e-1),
        (3, -2.48811461997166764192642586468e0),
        (4, -5.90290826836842996371446475743e-1),
        (5, 2.12300514481811942347288949897e1),
        (6, 1.52792336328824235832596922938e1),
        (7, -3.32882109689848629194453265587e1),
        (8, -2.03312017085086261358222928593e-2),
    ],
    &[
        (0, -9.3714243008598732571704021658e-1),
        (3, 5.18637242884406370830023853209e0),
        (4, 1.09143734899672957818500254654e0),
        (5, -8.14978701074692612513997267357e0),
        (6, -1.85200656599969598641566180701e1),
        (7, 2.27394870993505042818970056734e1),
        (8, 2.49360555267965238987089396762e0),
        (9, -3.0467644718982195003823669022e0),
    ],
    &[
        (0, 2.27331014751653820792359768449e0),
        (3, -1.05344954667372501984066689879e1),
        (4, -2.00087205822486249909675718444e0),
        (5, -1.79589318631187989172765950534e1),
        (6, 2.79488845294199600508499808837e1),
        (7, -2.85899827713502369474065508674e0),
        (8, -8.87285693353062954433549289258e0),
        (9, 1.23605671757943030647266201528e1),
        (10, 6.43392746015763530355970484046e-1),
    ],
    // Stage 13 is the new point: its coefficients are the weights B.
    &[],
    &[
        (0, 5.61675022830479523392909219681e-2),
        (6, 2.53500210216624811088794765333e-1),
        (7, -2.46239037470802489917441475441e-1),
        (8, -1.24191423263816360469010140626e-1),
        (9, 1.5329179827876569731206322685e-1),
        (10, 8.20105229563468988491666602057e-3),
        (11, 7.56789766054569976138603589584e-3),
        (12, -8.298e-3),
    ],
    &[
        (0, 3.18346481635021405060768473261e-2),
        (5, 2.83009096723667755288322961402e-2),
        (6, 5.35419883074385676223797384372e-2),
        (7, -5.49237485713909884646569340306e-2),
        (10, -1.08347328697249322858509316994e-4),
        (11, 3.82571090835658412954920192323e-4),
        (12, -3.40465008687404560802977114492e-4),
        (13, 1.41312443674632500278074618366e-1),
    ],
    &[
        (0, -4.28896301583791923408573538692e-1),
        (5, -4.69762141536116384314449447206e0),
        (6, 7.68342119606259904184240953878e0),
        (7, 4.06898981839711007970213554331e0),
        (8, 3.56727187455281109270669543021e-1),
        (12, -1.39902416515901462129418009734e-3),
        (13, 2.9475147891527723389556272149e0),
        (14, -9.15095847217987001081870187138e0),
    ],
];

/// Eighth-order weights (stages 1, 6–12).
const B: [(usize, f64); 8] = [
    (0, 5.42937341165687622380535766363e-2),
    (5, 4.45031289275240888144113950566e0),
    (6, 1.89151789931450038304281599044e0),
    (7, -5.8012039600105847814672114227e0),
    (8, 3.1116436695781989440891606237e-1),
    (9, -1.52160949662516078556178806805e-1),
    (10, 2.01365400804030348374776537501e-1),
    (11, 4.47106157277725905176885569043e-2),
];

/// The eighth-order weights over k1…k13 (k13, the derivative at the new point, has none).
const QUADRATURE: [f64; 13] = {
    let mut weights = [0.0; 13];
    let mut i = 0;
    while i < B.len() {
        weights[B[i].0] = B[i].1;
        i += 1;
    }
    weights
};

/// Third-order embedded weights (subtracted from the eighth-order increment).
const BHH: [(usize, f64); 3] = [
    (0, 0.244094488188976377952755905512e+00),
    (8, 0.733846688281611857341361741547e+00),
    (11, 0.220588235294117647058823529412e-01),
];

/// Fifth-order error weights.
const ER: [(usize, f64); 8] = [
    (0, 0.1312004499419488073250102996e-01),
    (5, -0.1225156446376204440720569753e+01),
    (6, -0.4957589496572501915214079952e+00),
    (7, 0.1664377182454986536961530415e+01),
    (8, -0.3503288487499736816886487290e+00),
    (9, 0.3341791187130174790297318841e+00),
    (10, 0.8192320648511571246570742613e-01),
    (11, -0.2235530786388629525884427845e-01),
];

/// Dense-output coefficients d_{4..7, j} over the stages 1, 6–16 (zero elsewhere).
const D_STAGES: [usize; 12] = [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];
const D: [[f64; 12]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// Step-ratio bounds of the DOP853 controller (Hairer's 1/3 and 6; safety 0.9 and the
/// exponents are in [`Controller`]).
const MIN_FACTOR: f64 = 1.0 / 3.0;
const MAX_FACTOR: f64 = 6.0;

/// Dormand–Prince 8(5,3) with dense output of order 7.
#[derive(Debug, Clone)]
pub struct Dop853 {
    k: Vec<Vec<f64>>,
    stage: Vec<f64>,
    y_new: Vec<f64>,
    /// State at the start of the last accepted step.
    y_old: Vec<f64>,
    /// Start time and size of the last accepted step.
    t_old: f64,
    h_old: f64,
    /// Interpolation coefficients of the last accepted step (r1…r8 of Hairer's `contd8`).
    dense: Vec<Vec<f64>>,
    dense_ready: bool,
    controlled: usize,
    fsal_valid: bool,
    /// k13 of the last accepted step is the next step's k1 (moved when that step starts, so
    /// that dense output can still be prepared until then).
    fsal_pending: bool,
    controller: Controller,
    /// Work done so far.
    pub counters: Counters,
}

impl Dop853 {
    /// Buffers for a state of `dim` components whose first `controlled` ones enter the
    /// error norm.
    pub fn new(dim: usize, controlled: usize) -> Self {
        Self {
            k: vec![vec![0.0; dim]; STAGES],
            stage: vec![0.0; dim],
            y_new: vec![0.0; dim],
            y_old: vec![0.0; dim],
            t_old: 0.0,
            h_old: 0.0,
            dense: vec![vec![0.0; dim]; 8],
            dense_ready: false,
            controlled: controlled.min(dim),
            fsal_valid: false,
            fsal_pending: false,
            controller: Controller::new(
                0.125 - 0.2 * CONTROLLER_BETA,
                CONTROLLER_BETA,
                MIN_FACTOR,
                MAX_FACTOR,
            ),
            counters: Counters::default(),
        }
    }

    /// Stages 2–13 of a step of size `h`; leaves the eighth-order solution in `y_new` and
    /// f(t + h, y_new) in k13; returns the scaled error estimate (≤ 1: acceptable).
    fn attempt<F>(
        &mut self,
        rhs: &mut F,
        t: f64,
        y: &[f64],
        h: f64,
        tolerances: Tolerances,
    ) -> Result<f64, SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        for i in 1..12 {
            self.evaluate_stage(rhs, t, y, h, i)?;
        }
        combine(&mut self.y_new, y, h, &B, &self.k);
        self.counters.rhs_evaluations += 1;
        rhs(t + h, &self.y_new, &mut self.k[12])?;
        Ok(self.error_norm(y, h, tolerances))
    }

    /// k_i = f(t + c_i h, y + h Σ_j a_ij k_j).
    fn evaluate_stage<F>(
        &mut self,
        rhs: &mut F,
        t: f64,
        y: &[f64],
        h: f64,
        i: usize,
    ) -> Result<(), SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        combine(&mut self.stage, y, h, A[i], &self.k);
        self.counters.rhs_evaluations += 1;
        rhs(t + C[i] * h, &self.stage, &mut self.k[i])
    }

    /// Hairer's estimate: err5² / sqrt(err5² + 0.01 err3²), RMS over the controlled
    /// components, scaled by atol + rtol·max(|y0|, |y1|). NaN becomes +∞ (rejection).
    fn error_norm(&self, y: &[f64], h: f64, tolerances: Tolerances) -> f64 {
        if self.controlled == 0 {
            return 0.0;
        }
        let (mut err5, mut err3) = (0.0, 0.0);
        for (i, (y0, y1)) in y.iter().zip(&self.y_new).enumerate().take(self.controlled) {
            let scale = tolerances.atol + tolerances.rtol * y0.abs().max(y1.abs());
            let eighth: f64 = B.iter().map(|&(j, b)| b * self.k[j][i]).sum();
            let third = eighth - BHH.iter().map(|&(j, b)| b * self.k[j][i]).sum::<f64>();
            let fifth: f64 = ER.iter().map(|&(j, e)| e * self.k[j][i]).sum();
            err5 += (fifth / scale).powi(2);
            err3 += (third / scale).powi(2);
        }
        let mut denominator = err5 + 0.01 * err3;
        if denominator <= 0.0 {
            denominator = 1.0;
        }
        let norm = h.abs() * err5 * (1.0 / (self.controlled as f64 * denominator)).sqrt();
        if norm.is_nan() { f64::INFINITY } else { norm }
    }
}

impl Adaptive for Dop853 {
    const EVALUATIONS_PER_ATTEMPT: usize = 12;
    const QUADRATURE: &'static [f64] = &QUADRATURE;

    /// One accepted step from `(t, y)` trying `h_try` first (see [`super::Dopri5::step`]
    /// for the handling of rejections and failing right-hand sides).
    fn step<F>(
        &mut self,
        rhs: &mut F,
        t: f64,
        y: &mut [f64],
        h_try: f64,
        tolerances: Tolerances,
    ) -> Result<AcceptedStep, SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        if self.fsal_pending {
            self.k.swap(0, 12);
            self.fsal_pending = false;
        }
        if !self.fsal_valid {
            self.counters.rhs_evaluations += 1;
            rhs(t, y, &mut self.k[0])?;
            self.fsal_valid = true;
        }
        self.dense_ready = false;
        let mut controller = self.controller;
        let (outcome, rejected) = controlled_step(t, h_try, &mut controller, |h| {
            self.attempt(rhs, t, y, h, tolerances)
        });
        self.controller = controller;
        self.counters.rejected += rejected;
        let accepted = outcome?;
        self.y_old.copy_from_slice(y);
        y.copy_from_slice(&self.y_new);
        (self.t_old, self.h_old) = (t, accepted.h);
        self.fsal_pending = true;
        self.counters.steps += 1;
        Ok(accepted)
    }

    /// Forget the cached derivative at the current point (after the state was changed
    /// outside this integrator).
    fn invalidate_fsal(&mut self) {
        self.controller.reset();
        self.fsal_valid = false;
        self.fsal_pending = false;
    }

    /// Prepares the interpolant of the last accepted step (three more right-hand sides, on
    /// the first call after a step only). `rhs` must be the one the step used.
    fn prepare_dense<F>(&mut self, rhs: &mut F) -> Result<(), SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        if self.dense_ready {
            return Ok(());
        }
        let (t, h) = (self.t_old, self.h_old);
        let y_old = std::mem::take(&mut self.y_old);
        let outcome = (13..16).try_for_each(|i| self.evaluate_stage(rhs, t, &y_old, h, i));
        self.y_old = y_old;
        outcome?;
        let (k, y0) = (&self.k, &self.y_old);
        // y_new was moved into the caller's y; it is still in `self.y_new`.
        for i in 0..y0.len() {
            let difference = self.y_new[i] - y0[i];
            let r3 = h * k[0][i] - difference;
            self.dense[0][i] = y0[i];
            self.dense[1][i] = difference;
            self.dense[2][i] = r3;
            self.dense[3][i] = difference - h * k[12][i] - r3;
            for (row, d) in D.iter().enumerate() {
                let sum: f64 = D_STAGES.iter().zip(d).map(|(&j, &dj)| dj * k[j][i]).sum();
                self.dense[4 + row][i] = h * sum;
            }
        }
        self.dense_ready = true;
        Ok(())
    }

    /// y(t) inside the last accepted step, from the interpolant [`Self::prepare_dense`]
    /// made (order 7). `t` outside the step extrapolates.
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t_old) / self.h_old;
        let s1 = 1.0 - s;
        let r = &self.dense;
        for (i, o) in out.iter_mut().enumerate() {
            let inner = r[6][i] + s * r[7][i];
            let inner = r[5][i] + s1 * inner;
            let inner = r[4][i] + s * inner;
            let inner = r[3][i] + s1 * inner;
            let inner = r[2][i] + s * inner;
            let inner = r[1][i] + s1 * inner;
            *o = r[0][i] + s * inner;
        }
    }

    fn counters(&self) -> Counters {
        self.counters
    }
}

/// `out = y + h Σ w_j k_j`.
fn combine(out: &mut [f64], y: &[f64], h: f64, weights: &[(usize, f64)], k: &[Vec<f64>]) {
    out.copy_from_slice(y);
    for &(j, w) in weights {
        let scale = h * w;
        for (o, &kj) in out.iter_mut().zip(&k[j]) {
            *o += scale * kj;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y'' = −y as (y, y'); exact solution from (1, 0): (cos t, −sin t).
    fn oscillator(_t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = y[1];
        dy[1] = -y[0];
        Ok(())
    }

    /// Huge tolerances: every step of the requested size is accepted.
    const LOOSE: Tolerances = Tolerances {
        rtol: 1e10,
        atol: 1e10,
    };

    #[test]
    fn the_stage_quadrature_has_order_eight() {
        // Σ bᵢ cᵢᵏ = 1/(k + 1) for k ≤ 7, at the nodes of the start, stages 2–12 and the new
        // point: the order conditions of the quadrature alone.
        assert_eq!(QUADRATURE.len(), 1 + Dop853::EVALUATIONS_PER_ATTEMPT);
        for k in 0..=7 {
            let sum: f64 = QUADRATURE
                .iter()
                .zip(&C[..13])
                .map(|(b, c)| b * c.powi(k))
                .sum();
            assert!(
                (sum - 1.0 / f64::from(k + 1)).abs() < 1e-14,
                "degree {k}: {sum}"
            );
        }
    }

    #[test]
    fn tableau_is_consistent() {
        // Row sums equal the nodes (Σ_j a_ij = c_i) and the weights sum to one: a single
        // mistyped coefficient breaks one of these to far more than round-off.
        for (i, row) in A.iter().enumerate() {
            if i == 0 || i == 12 {
                continue;
            }
            let sum: f64 = row.iter().map(|&(_, a)| a).sum();
            assert!(
                (sum - C[i]).abs() < 1e-14,
                "row {}: {sum} vs {}",
                i + 1,
                C[i]
            );
        }
        let b: f64 = B.iter().map(|&(_, b)| b).sum();
        assert!((b - 1.0).abs() < 1e-14);
        let bhh: f64 = BHH.iter().map(|&(_, b)| b).sum();
        assert!((bhh - 1.0).abs() < 1e-14);
        let er: f64 = ER.iter().map(|&(_, e)| e).sum();
        assert!(
            er.abs() < 1e-14,
            "the fifth-order error weights sum to 0: {er}"
        );
    }

    /// Error at t = 2 after `steps` fixed steps, and the largest error of the dense output
    /// at 7 interior points of every step.
    fn errors(steps: usize) -> (f64, f64) {
        let h = 2.0 / steps as f64;
        let mut y = vec![1.0, 0.0];
        let mut solver = Dop853::new(2, 2);
        let mut rhs = oscillator;
        let mut dense_error: f64 = 0.0;
        let mut point = [0.0; 2];
        for i in 0..steps {
            let t = i as f64 * h;
            let accepted = solver.step(&mut rhs, t, &mut y, h, LOOSE).unwrap();
            assert_eq!(accepted.h, h);
            solver.prepare_dense(&mut rhs).unwrap();
            for m in 1..8 {
                let tm = t + h * m as f64 / 8.0;
                solver.interpolate(tm, &mut point);
                dense_error = dense_error
                    .max((point[0] - tm.cos()).abs())
                    .max((point[1] + tm.sin()).abs());
            }
        }
        let end_error = (y[0] - 2.0_f64.cos())
            .abs()
            .max((y[1] + 2.0_f64.sin()).abs());
        (end_error, dense_error)
    }

    #[test]
    fn step_has_order_eight_and_dense_output_order_seven() {
        // Observed orders log2(e(h)/e(h/2)) over h = 0.5 … 0.125 (before round-off at
        // ~1e-15 takes over): the step's global error is O(h⁸); the interpolant adds an
        // O(h⁸) local error (order 7) to it. Bands of ±0.6 separate the orders clearly
        // (measured: 8.05–8.08 for the steps, 8.00 for the dense output, whose leading
        // term on this problem is still the steps' accumulated error).
        let levels: Vec<(f64, f64)> = [4, 8, 16].iter().map(|&n| errors(n)).collect();
        for pair in levels.windows(2) {
            let step_order = (pair[0].0 / pair[1].0).log2();
            let dense_order = (pair[0].1 / pair[1].1).log2();
            assert!((7.4..=8.8).contains(&step_order), "step order {step_order}");
            assert!(dense_order > 6.4, "dense-output order {dense_order}");
        }
    }

    #[test]
    fn meets_tight_tolerances_with_few_steps() {
        // Ten periods of the oscillator at rtol = atol = 1e-12: the global error stays
        // within 100 × the tolerance (it accumulates over the steps; measured 1.0e-11 in
        // 317 steps), and an eighth-order method needs only ~30 steps per period.
        let mut y = vec![1.0, 0.0];
        let mut solver = Dop853::new(2, 2);
        let mut rhs = oscillator;
        let tolerances = Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
        };
        let t_end = 20.0 * std::f64::consts::PI;
        let (mut t, mut h): (f64, f64) = (0.0, 1e-3);
        while t < t_end {
            let accepted = solver
                .step(&mut rhs, t, &mut y, h.min(t_end - t), tolerances)
                .unwrap();
            t += accepted.h;
            h = accepted.h_next;
        }
        let error = (y[0] - 1.0).abs().max(y[1].abs());
        assert!(error < 1e-10, "error {error:e}");
        assert!(
            solver.counters.steps < 1000,
            "steps {}",
            solver.counters.steps
        );
    }
}
