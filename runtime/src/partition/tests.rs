//! Tests of the partitioned dynamics: the choice of the sets, the kernels against nalgebra
//! and the reduced dynamics against the explicit formulas (18).

use super::linalg::{
    cholesky_factor, cholesky_solve, dot, gather_columns, lu_determinant, lu_factor, lu_solve,
    lu_solve_transposed,
};
use super::workspace::JACOBIAN_FLOOR;
use super::*;
use crate::error::SimError;
use nalgebra::{DMatrix, DVector};

/// Deterministic pseudo-random numbers in [−1, 1) (xorshift64*).
struct Numbers(u64);

impl Numbers {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        bits as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn vector(&mut self, len: usize) -> Vec<f64> {
        (0..len).map(|_| self.next()).collect()
    }

    /// Symmetric positive definite n×n: A Aᵀ + n I.
    fn spd(&mut self, n: usize) -> Vec<f64> {
        let a = DMatrix::from_row_slice(n, n, &self.vector(n * n));
        let m = &a * a.transpose() + DMatrix::identity(n, n) * n as f64;
        m.transpose().as_slice().to_vec()
    }
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Round-off bound for the dense solves below on well-conditioned data of order 1
/// (κ ≲ 10², n ≤ 6): κ·n·ε ≈ 1e-13; 1e-11 leaves a margin of 100.
const SOLVE_TOLERANCE: f64 = 1e-11;

#[test]
fn independent_rows_find_the_rank_and_leave_a_combination_out() {
    // Row 2 = row 0 + row 1: rank 2; the pivots are the largest entries (row 2's 4.0
    // in column 1, then row 0's 1.0 after elimination), row 1 left out.
    let j = [1.0, 1.0, 0.0, 0.0, 3.0, 1.0, 1.0, 4.0, 1.0];
    let (rows, columns) = independent_rows(&j, 3, 3, &[true; 3], 0.0);
    assert_eq!(rows.len(), 2);
    assert_eq!(columns.len(), 2);
    // Full rank: every row kept.
    let identity = [1.0, 0.0, 0.0, 1.0];
    assert_eq!(
        independent_rows(&identity, 2, 2, &[true; 2], 0.0).0,
        vec![0, 1]
    );
    // A row of round-off below the floor counts as zero, whatever the scale.
    let tiny = [1e-17, 0.0, 0.0, 2e-17];
    assert!(
        independent_rows(&tiny, 2, 2, &[true; 2], 1e-12)
            .0
            .is_empty()
    );
    // Only eligible columns are pivots.
    let (_, columns) = independent_rows(&[5.0, 1.0], 1, 2, &[false, true], 0.0);
    assert_eq!(columns, vec![1]);
}

#[test]
fn one_contact_picks_the_largest_eligible_entry() {
    let j = [0.5, -3.0, 2.0, 0.1];
    assert_eq!(choose_dependent(&j, 1, 4, &[true; 4]), Some(vec![1]));
    assert_eq!(
        choose_dependent(&j, 1, 4, &[true, false, true, true]),
        Some(vec![2])
    );
    assert_eq!(
        choose_dependent(&j, 1, 4, &[false, true, false, false]),
        Some(vec![1])
    );
    assert_eq!(
        choose_dependent(&[0.0, 0.0, 1.0], 1, 3, &[true, true, false]),
        None
    );
    assert_eq!(
        choose_dependent(&[f64::NAN, 1.0], 1, 2, &[true, true]),
        None
    );
}

#[test]
fn several_contacts_use_complete_pivoting() {
    // The largest entry, 5, makes column 0 dependent; eliminating it leaves row 1 as
    // (0, 1.6 − 0.4·4, 1.5, 0) = (0, 0, 1.5, 0), so column 2 wins although the original
    // |J_11| = 1.6 exceeds 1.5.
    let j = [5.0, 4.0, 0.0, 0.0, 2.0, 1.6, 1.5, 0.0];
    let chosen = choose_dependent(&j, 2, 4, &[true; 4]).unwrap();
    assert_eq!(chosen, vec![0, 2]);
    // Two identical rows: rank 1, no invertible J_v.
    assert_eq!(
        choose_dependent(&[1.0, 2.0, 1.0, 2.0], 2, 2, &[true, true]),
        None
    );
}

#[test]
fn conditioning_is_the_normalised_pivot() {
    let j = [3.0, 4.0, 100.0];
    let eligible = [true, true, false];
    assert!((conditioning(&j, 1, 3, &[1], &eligible) - 0.8).abs() < 1e-15);
    assert!((conditioning(&j, 1, 3, &[0], &eligible) - 0.6).abs() < 1e-15);
    // Orthogonal rows and J_v = the whole of J: Hadamard ratio 1.
    let j2 = [1.0, 1.0, -1.0, 1.0];
    assert!((conditioning(&j2, 2, 2, &[0, 1], &[true, true]) - 1.0).abs() < 1e-15);
    assert_eq!(conditioning(&[], 0, 3, &[], &eligible), 1.0);
}

#[test]
fn max_abs_is_the_largest_magnitude_and_nan_wherever_a_nan_stands() {
    use super::linalg::max_abs;
    assert_eq!(max_abs(&[]), 0.0);
    for n in 1..12 {
        let x: Vec<f64> = (0..n)
            .map(|i| (i as f64 - 4.5) * if i % 2 == 0 { 1.0 } else { -1.3 })
            .collect();
        let expected = x.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert_eq!(max_abs(&x), expected, "{x:?}");
        assert_eq!(
            max_abs(&[x.clone(), vec![f64::NEG_INFINITY]].concat()),
            f64::INFINITY
        );
        for k in 0..n {
            let mut y = x.clone();
            y[k] = f64::NAN;
            assert!(max_abs(&y).is_nan(), "NaN at {k} of {n}");
        }
    }
}

#[test]
fn a_row_for_the_sweeps_is_given_whole_or_not_at_all() {
    use crate::dynamics::{row_entry, row_weight};
    assert_eq!(row_weight(&[], 3), 0.0);
    assert_eq!(row_weight(&[1.0, 2.0, 3.0], 3), 1.0);
    assert_eq!(row_entry(&[], 2), 0.0);
    assert_eq!(row_entry(&[1.0, 2.0, 3.0], 2), 3.0);
    let short = std::panic::catch_unwind(|| row_weight(&[1.0, 2.0], 3));
    let message = short.expect_err("a row of 2 for 3 coordinates is refused");
    let text = message
        .downcast_ref::<String>()
        .expect("a formatted message");
    assert!(text.contains("has 2 entries, not 3"), "{text}");
}

#[test]
fn lu_and_cholesky_solve_like_nalgebra() {
    let mut numbers = Numbers(7);
    for n in 1..6 {
        let a = numbers.vector(n * n);
        let b = numbers.vector(n);
        let matrix = DMatrix::from_row_slice(n, n, &a);
        let expected = matrix
            .clone()
            .lu()
            .solve(&DVector::from_column_slice(&b))
            .unwrap();
        let expected_t = matrix
            .transpose()
            .lu()
            .solve(&DVector::from_column_slice(&b))
            .unwrap();
        let (mut lu, mut pivots) = (a.clone(), vec![0; n]);
        assert!(lu_factor(&mut lu, &mut pivots, n, 0.0));
        let (mut x, mut x_t) = (b.clone(), b.clone());
        lu_solve(&lu, &pivots, n, &mut x);
        lu_solve_transposed(&lu, &pivots, n, &mut x_t);
        let scale = 1.0 + expected.amax() + expected_t.amax();
        assert!(max_difference(&x, expected.as_slice()) < SOLVE_TOLERANCE * scale);
        assert!(max_difference(&x_t, expected_t.as_slice()) < SOLVE_TOLERANCE * scale);
        let determinant = lu_determinant(&lu, &pivots, n);
        assert!(
            (determinant - matrix.determinant()).abs()
                < SOLVE_TOLERANCE * (1.0 + determinant.abs())
        );

        let mut spd = numbers.spd(n);
        let expected = DMatrix::from_row_slice(n, n, &spd)
            .lu()
            .solve(&DVector::from_column_slice(&b))
            .unwrap();
        assert!(cholesky_factor(&mut spd, n));
        let mut x = b.clone();
        cholesky_solve(&spd, n, &mut x);
        assert!(max_difference(&x, expected.as_slice()) < SOLVE_TOLERANCE);
    }
    assert!(!cholesky_factor(&mut [1.0, 2.0, 2.0, 1.0], 2));
}

/// A workspace filled with random M (SPD), F, Q, J, c and a consistent partition.
fn random_workspace(n: usize, nc: usize, driven: &[bool], seed: u64) -> (Workspace, Partition) {
    let mut numbers = Numbers(seed);
    let eligible: Vec<bool> = driven.iter().map(|d| !d).collect();
    let nu = n - nc - driven.iter().filter(|d| **d).count();
    let mut ws = Workspace::new(n, nc, nu);
    ws.mass = numbers.spd(n);
    ws.inertial = numbers.vector(n);
    ws.applied = numbers.vector(n);
    ws.jacobian = numbers.vector(nc * n);
    ws.bias = numbers.vector(nc);
    ws.qdd = numbers.vector(n);
    let dependent = choose_dependent(&ws.jacobian, nc, n, &eligible).unwrap();
    gather_columns(&ws.jacobian, n, &dependent, &mut ws.jv_lu);
    assert!(lu_factor(&mut ws.jv_lu, &mut ws.pivots, nc, 0.0));
    (ws, Partition::new(driven, &dependent).unwrap())
}

fn submatrix(m: &DMatrix<f64>, rows: &[usize], columns: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), columns.len(), |r, c| m[(rows[r], columns[c])])
}

fn subvector(x: &[f64], rows: &[usize]) -> DVector<f64> {
    DVector::from_fn(rows.len(), |r, _| x[rows[r]])
}

#[test]
fn reduced_dynamics_equal_the_explicit_formulas_18() {
    for (n, nc, seed) in [(4, 1, 1), (5, 2, 2), (6, 3, 3), (2, 1, 4)] {
        let (mut ws, partition) = random_workspace(n, nc, &vec![false; n], seed);
        ws.reduce_and_solve(&partition, 0.0).unwrap();

        let (u, v) = (partition.independent(), partition.dependent());
        let mass = DMatrix::from_row_slice(n, n, &ws.mass);
        let jacobian = DMatrix::from_row_slice(nc, n, &ws.jacobian);
        let jv_inverse = submatrix(&jacobian, &(0..nc).collect::<Vec<_>>(), v)
            .try_inverse()
            .unwrap();
        let ju = submatrix(&jacobian, &(0..nc).collect::<Vec<_>>(), u);
        let b_matrix = -&jv_inverse * ju;
        let b_vector = -&jv_inverse * DVector::from_column_slice(&ws.bias);
        let (m_uu, m_uv) = (submatrix(&mass, u, u), submatrix(&mass, u, v));
        let (m_vu, m_vv) = (submatrix(&mass, v, u), submatrix(&mass, v, v));
        let (f_u, f_v) = (subvector(&ws.inertial, u), subvector(&ws.inertial, v));
        let (q_u, q_v) = (subvector(&ws.applied, u), subvector(&ws.applied, v));
        let bt = b_matrix.transpose();
        let m_star = &m_uu + &m_uv * &b_matrix + &bt * &m_vu + &bt * &m_vv * &b_matrix;
        let f_star = &f_u + &m_uv * &b_vector + &bt * (&f_v + &m_vv * &b_vector);
        let q_star = &q_u + &bt * &q_v;
        let udd = m_star.lu().solve(&(-(f_star + q_star))).unwrap();
        let vdd = &b_matrix * &udd + &b_vector;

        let scale = 1.0 + udd.amax() + vdd.amax();
        assert!(
            max_difference(subvector(&ws.qdd, u).as_slice(), udd.as_slice())
                < SOLVE_TOLERANCE * scale
        );
        assert!(
            max_difference(subvector(&ws.qdd, v).as_slice(), vdd.as_slice())
                < SOLVE_TOLERANCE * scale
        );
    }
}

#[test]
fn partitioned_solution_solves_the_augmented_system_with_drives() {
    // [M  Jᵀ  −E_d] [q̈ ]   [−F − Q]
    // [J  0    0  ] [λ ] = [−c    ]
    // [E_dᵀ 0  0  ] [τ_d]  [q̈_d   ]
    let cases: [(usize, usize, Vec<bool>, u64); 3] = [
        (4, 1, vec![true, false, false, false], 11),
        (6, 2, vec![false, true, false, false, true, false], 12),
        (3, 1, vec![false, false, false], 13),
    ];
    for (n, nc, driven, seed) in cases {
        let (mut ws, partition) = random_workspace(n, nc, &driven, seed);
        ws.reduce_and_solve(&partition, 0.0).unwrap();
        ws.solve_multipliers(&partition, 0.0).unwrap();

        let d = partition.driven();
        let size = n + nc + d.len();
        let mut system = DMatrix::zeros(size, size);
        let mut rhs = DVector::zeros(size);
        for i in 0..n {
            for k in 0..n {
                system[(i, k)] = ws.mass[i * n + k];
            }
            rhs[i] = -ws.inertial[i] - ws.applied[i];
        }
        for k in 0..nc {
            for i in 0..n {
                system[(i, n + k)] = ws.jacobian[k * n + i];
                system[(n + k, i)] = ws.jacobian[k * n + i];
            }
            rhs[n + k] = -ws.bias[k];
        }
        for (e, &i) in d.iter().enumerate() {
            system[(i, n + nc + e)] = -1.0;
            system[(n + nc + e, i)] = 1.0;
            rhs[n + nc + e] = ws.qdd[i];
        }
        let solution = system.lu().solve(&rhs).unwrap();
        let scale = 1.0 + solution.amax();
        assert!(max_difference(&ws.qdd, &solution.as_slice()[..n]) < SOLVE_TOLERANCE * scale);
        assert!(
            max_difference(&ws.lambda, &solution.as_slice()[n..n + nc]) < SOLVE_TOLERANCE * scale
        );
        for (e, &i) in d.iter().enumerate() {
            assert!((ws.drive[i] - solution[n + nc + e]).abs() < SOLVE_TOLERANCE * scale);
        }
        for i in (0..n).filter(|i| !driven[*i]) {
            assert_eq!(ws.drive[i], 0.0);
        }
    }
}

#[test]
fn partition_validates_and_orders_the_sets() {
    let mut partition = Partition::new(&[false, true, false, false], &[3]).unwrap();
    assert_eq!(partition.driven(), &[1]);
    assert_eq!(partition.independent(), &[0, 2]);
    partition.set_dependent(&[0]).unwrap();
    assert_eq!(partition.independent(), &[2, 3]);
    assert!(partition.set_dependent(&[1]).is_err());
    assert!(partition.set_dependent(&[7]).is_err());
    assert!(partition.set_dependent(&[0, 2]).is_err());
    assert!(Partition::new(&[false; 3], &[0, 0]).is_err());
}

#[test]
fn normal_force_points_along_the_upward_normal() {
    // Flat cam (force scale √(1 + 0²) = 1), point pushed up by the cam: the y row of
    // (14) has +λ, so λ < 0.
    assert_eq!(normal_force(-2.0, 1.0), 2.0);
    // Slope 1: h = y − x has |∇h| = √2, the force √2 times −λ.
    assert!((normal_force(-1.0, 2f64.sqrt()) - 2f64.sqrt()).abs() < 1e-15);
}

#[test]
fn one_contact_row_is_factored_as_its_number_and_checked_whole() {
    // n = 20 (above the size at which rows keep extents), one row, v = coordinate 7.
    let n = 20;
    let mut ws = Workspace::new(n, 1, n - 1);
    let mut numbers = Numbers(7);
    let row = numbers.vector(n);
    ws.jacobian.copy_from_slice(&row);
    ws.jacobian[7] = 2.5;
    ws.factor_current_jacobian(&[7], 0.0)
        .expect("J_v = 2.5 is regular");
    // The velocity level from that factor: J q̇ = 0 with q̇_v solved.
    ws.qd = numbers.vector(n);
    ws.solve_velocities(&[7]);
    let residual: f64 = ws.jacobian.iter().zip(&ws.qd).map(|(j, v)| j * v).sum();
    // Twenty products of order 1 summed: round-off of a few ε.
    assert!(residual.abs() < 1e-14, "J q̇ = {residual:e}");
    // A NaN anywhere in the row, not only in J_v, is reported as a non-finite J.
    ws.jacobian[18] = f64::NAN;
    let error = ws.factor_current_jacobian(&[7], 0.3).unwrap_err();
    assert!(
        matches!(error, SimError::NonFinite { quantity: "J", .. }),
        "{error}"
    );
    ws.jacobian[18] = f64::INFINITY;
    assert!(ws.factor_current_jacobian(&[7], 0.3).is_err());
    // J_v at the floor (length scale 1) is singular, just above it is not.
    ws.jacobian[18] = 0.0;
    ws.jacobian[7] = JACOBIAN_FLOOR;
    let error = ws.factor_current_jacobian(&[7], 0.3).unwrap_err();
    assert!(
        matches!(error, SimError::SingularConstraint { .. }),
        "{error}"
    );
    ws.jacobian[7] = 2.0 * JACOBIAN_FLOOR;
    assert!(ws.factor_current_jacobian(&[7], 0.3).is_ok());
    // The row's shrinking is measured over all of it: the same row scaled by 1e-3 (below
    // ROW_SHRINK of its peak: a singular position near) is reported.
    ws.jacobian.copy_from_slice(&row);
    (ws.jacobian[7], ws.jacobian[18]) = (2.5, 10.0);
    assert!(!ws.rows_shrunk());
    // J_v alone shrinking is not the row shrinking: its largest entry is elsewhere.
    ws.jacobian[7] = 0.01;
    assert!(!ws.rows_shrunk());
    for j in ws.jacobian.iter_mut() {
        *j *= 1e-3;
    }
    assert!(ws.rows_shrunk());
}

#[test]
fn dot_is_the_sum_of_products_to_rounding_for_every_length() {
    let mut numbers = Numbers(11);
    for n in 0..=23 {
        let (a, b) = (numbers.vector(n), numbers.vector(n + 2));
        // Any order of summing the n products errs by at most about n ε Σ|a_i b_i|
        // (Higham, Accuracy and Stability of Numerical Algorithms, §4.2): the sequential
        // sum and the four running sums differ by at most twice that.
        let magnitude: f64 = a.iter().zip(&b).map(|(x, y)| (x * y).abs()).sum();
        let reference: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        let got = dot(&a, &b);
        let bound = 2.0 * n as f64 * f64::EPSILON * magnitude;
        assert!(
            (got - reference).abs() <= bound,
            "n = {n}: {got} against {reference}"
        );
        // The shorter length counts: b's two extra entries are not read.
        assert_eq!(got, dot(&a, &b[..n]));
    }
    // Exact where every partial sum is: small integers.
    let a: Vec<f64> = (1..=17).map(f64::from).collect();
    assert_eq!(dot(&a, &a), (17 * 18 * 35 / 6) as f64);
    assert_eq!(dot(&[], &[1.0]), 0.0);
}
