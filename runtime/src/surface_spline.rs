//! Bicubic spline surfaces through a grid of points: spatial cams given as heights z(x, y)
//! measured or exported from CAD on a rectangular grid.
//!
//! The grid has knots x₀ < … < x_{nx−1} and y₀ < … < y_{ny−1} and values z_ij = z(x_i, y_j),
//! stored row by row: `z[i * ny + j]`, row i holding the ny values at x_i. A *line along y*
//! is a row (contiguous), a *line along x* is a column (the nx values at one y_j, stride ny).
//!
//! # The one-dimensional cubic
//!
//! On a segment [t_k, t_{k+1}] of length h, with a = (t_{k+1} − t)/h and b = (t − t_k)/h,
//! [`spline`]'s M-form cubic through values f and knot second derivatives M is
//!
//! ```text
//! C[f, M](t) = a f_k + b f_{k+1} + (a³ − a) h²/6 · M_k + (b³ − b) h²/6 · M_{k+1}.
//! ```
//!
//! It takes the values f_k at the knots (a³ − a and b³ − b vanish there) and has second
//! derivative M_k there; it is C² across the knots exactly when M = Σ(f), the second
//! derivatives [`spline::second_derivatives`] solves for under the line's [`Ends`]. Σ is
//! linear for natural and periodic ends; for clamped ends with slopes (p, q) it is affine,
//! Σ(f) = A f + b with b the part due to the slopes. In all cases A 1 = 0: a constant line
//! with zero end slopes is its own spline, of curvature zero.
//!
//! # The surface
//!
//! Three tables of knot derivatives, each by the one-dimensional solve along grid lines:
//!
//! - M^x_ij = ∂²S/∂x²: Σ_x along every line along x of z, with the x axis's ends;
//! - M^y_ij = ∂²S/∂y²: Σ_y along every line along y of z, with the y axis's ends;
//! - M^xy_ij = ∂⁴S/∂x²∂y²: Σ_y′ along every line along y of M^x, where Σ′ is Σ with its
//!   axis's ends made homogeneous (a clamped axis's slopes replaced by zero, see the ends
//!   below; natural and periodic unchanged), that is Σ′(f) = A f.
//!
//! On the cell [x_i, x_{i+1}] × [y_j, y_{j+1}], S is the tensor product of the cubic's basis
//! (a, b, (a³ − a)h²/6, (b³ − b)h²/6 in each variable) applied to the tables at the cell's
//! corners: z weighted by value weights in both variables, M^x by a curvature weight in x
//! and a value weight in y, M^y the converse, M^xy by curvature weights in both.
//! Equivalently, for fixed x,
//!
//! ```text
//! S(x, y) = C_y[u(x), v(x)](y),
//! u_j(x) = C_x[z_·j, M^x_·j](x),  v_j(x) = C_x[M^y_·j, M^xy_·j](x):
//! ```
//!
//! the cubic in y whose knot values u_j(x) and knot second derivatives v_j(x) are themselves
//! the x-cubics along the cell's two lines along x. That is how [`evaluate`] computes it,
//! with [`spline::evaluate`] four times along x and four times along y.
//!
//! # Why S is the C² interpolating spline
//!
//! Write the solves of every line at once as matrices: M^x = A_x Z + b_x 1ᵀ and
//! M^y = Z A_yᵀ + 1 b_yᵀ, Z the nx × ny grid of values and 1 a vector of ones (every line
//! has the same end slopes).
//!
//! 1. *Interpolation*: at a corner the curvature weights vanish in both variables, leaving
//!    S(x_i, y_j) = z_ij.
//! 2. *Every line x = const is a 1D spline in y.* For x in cell i, the knot values along y
//!    are the row u(x) = α z_i· + β z_{i+1}· + γ M^x_i· + δ M^x_{i+1}· with weights the same
//!    for every j and α + β = 1, and v(x) is the same combination of the rows of M^y and
//!    M^xy. The y-solve of the values u(x) is u(x) A_yᵀ + b_yᵀ, which is (using α + β = 1
//!    to share out b_y) α M^y_i· + β M^y_{i+1}· + γ M^xy_i· + δ M^xy_{i+1}·, that is
//!    v(x). So S(x, ·) = C_y\[u(x), Σ_y u(x)\] is, for every x, the C² spline in y through its
//!    values at the knots, with the y axis's ends.
//! 3. *Every line y = const is a 1D spline in x*, by the same argument with the roles
//!    swapped, because M^xy is also Σ_x′ along the lines along x of M^y:
//!    M^x A_yᵀ = A_x Z A_yᵀ + b_x (A_y 1)ᵀ and A_x M^y = A_x Z A_yᵀ + (A_x 1) b_yᵀ, and
//!    A 1 = 0.
//! 4. *C² jointly.* Across a knot line y = y_j, S, S_y and S_yy agree from both sides for
//!    every x (step 2), so their derivatives along the line S_x, S_xx, S_xy agree too;
//!    across x = x_i likewise (step 3). Inside a cell S is a polynomial. Hence S, its
//!    gradient and its Hessian are continuous everywhere (indeed every ∂ᵖ_x ∂ᵠ_y S with
//!    p, q ≤ 2); the third derivatives jump across knot lines, as a cubic spline's do.
//!
//! # Ends per axis
//!
//! Said for the x axis (`ends[0]`); the y axis's (`ends[1]`) likewise.
//!
//! - [`Ends::Natural`]: S_xx = 0 along the edges x = x₀ and x = x_{nx−1}.
//! - [`Ends::Periodic`]: S, its gradient and its Hessian meet across the edges, and S
//!   repeats with period x_{nx−1} − x₀. The last row must repeat the first (within
//!   [`CLOSURE_TOLERANCE`] of the grid's largest magnitude); it is then taken equal to it,
//!   so that the seam is exact.
//! - [`Ends::Clamped`] `{ start, end }`: ∂S/∂x = `start` along the whole edge x = x₀ and
//!   `end` along x = x_{nx−1}: a constant slope across each edge (0 where the surface meets
//!   a flat land, for instance). Along such an edge the twist S_xy is zero and so is
//!   ∂(S_yy)/∂x = ∂²(S_x)/∂y²: the lines of curvature M^y have zero slope across it, which
//!   is why Σ′ takes zero slopes. A slope varying along the edge is not expressible with
//!   [`Ends`]: it would need a table of slopes per edge and the twists at the corners.
//!
//! # Cost, evaluation, outside the grid
//!
//! Construction solves ny lines along x of length nx (M^x) and 2·nx lines along y of length
//! ny (M^y, M^xy), each in O(length) (the Thomas algorithm, Sherman–Morrison for a periodic
//! axis): 3·nx·ny unknowns, O(n) for n grid points. Evaluation finds the cell by bisection
//! on each axis ([`spline::segment`], O(log nx + log ny)) and returns the value and every
//! derivative up to the third exactly. A periodic axis moves the point into its period by
//! whole periods; beyond an open axis's ends the end cells' polynomials continue (in each
//! variable independently), as an open [`spline::Spline`]'s end cubics do.

use crate::spline::{self, CLOSURE_TOLERANCE, Ends, SplineError};
use thiserror::Error;

#[cfg(test)]
mod tests;

/// One of the two axes of a grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// The first index of `z[i * ny + j]`: the knots x_i.
    X,
    /// The second index: the knots y_j.
    Y,
}

impl std::fmt::Display for Axis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Axis::X => "x",
            Axis::Y => "y",
        })
    }
}

/// Why a grid cannot make a surface; `z[i][j]` is the value at (x_i, y_j), both counted
/// from 0.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SurfaceSplineError {
    /// The number of values is not the number of x knots times the number of y knots.
    #[error(
        "a {nx} × {ny} grid needs {} values, the table has {got}",
        *nx as u128 * *ny as u128
    )]
    Shape {
        /// Number of x knots.
        nx: usize,
        /// Number of y knots.
        ny: usize,
        /// Number of values given.
        got: usize,
    },
    /// The knots of one axis are too few for its ends, not finite or not strictly
    /// increasing (the error of [`spline::check_table`] on them, whose "points" are the
    /// axis's knots).
    #[error("the {axis} knots: {error}")]
    Knots {
        /// The axis.
        axis: Axis,
        /// What is wrong with its knots.
        error: SplineError,
    },
    /// Knots so far apart that their distance overflows f64.
    #[error("the {axis} knots run from {first:e} to {last:e}, a width that overflows f64")]
    TooWide {
        /// The axis.
        axis: Axis,
        /// Its first knot.
        first: f64,
        /// Its last knot.
        last: f64,
    },
    /// A clamped axis whose slopes are not finite.
    #[error("the {axis} axis is clamped with slopes {start} and {end}, which must be finite")]
    Slopes {
        /// The axis.
        axis: Axis,
        /// The slope at the first edge.
        start: f64,
        /// The slope at the last edge.
        end: f64,
    },
    /// A value that is NaN or infinite.
    #[error("z[{i}][{j}] (at x_{i}, y_{j}) is not a finite number ({value})")]
    NotFinite {
        /// Its x index.
        i: usize,
        /// Its y index.
        j: usize,
        /// The value found.
        value: f64,
    },
    /// A periodic axis whose last line of values does not repeat its first.
    #[error(
        "the grid is periodic in {axis}, so z[{}][{}] must repeat z[{}][{}], but they are \
         {last} and {first} (difference {:.3e})",
        last_cell.0, last_cell.1, first_cell.0, first_cell.1, (last - first).abs()
    )]
    EdgesDoNotMeet {
        /// The periodic axis.
        axis: Axis,
        /// The value's cell on the first line, (i, j).
        first_cell: (usize, usize),
        /// The value's cell on the last line, which must repeat it.
        last_cell: (usize, usize),
        /// z at `first_cell`.
        first: f64,
        /// z at `last_cell`.
        last: f64,
    },
    /// A knot derivative that overflows f64: values that change too fast for their knots'
    /// spacing (differences divided by the spacing squared).
    #[error(
        "{what} at z[{i}][{j}] is not finite ({value}): the values change too fast for the \
         knots' spacing"
    )]
    Overflow {
        /// `∂²S/∂x²`, `∂²S/∂y²` or `∂⁴S/∂x²∂y²`.
        what: &'static str,
        /// Its x index.
        i: usize,
        /// Its y index.
        j: usize,
        /// The value computed.
        value: f64,
    },
    /// A one-dimensional solve along a grid line refused its line (not expected once
    /// [`check_grid`] passes; kept so that nothing panics).
    #[error("the line along {along} at index {at}: {error}")]
    Line {
        /// The line's direction.
        along: Axis,
        /// Its index on the other axis.
        at: usize,
        /// The solve's error.
        error: SplineError,
    },
}

/// A surface's value and its derivatives up to the third at one point, all exact (no
/// finite differences). Units: those of z over powers of those of x and y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// S.
    pub value: f64,
    /// [S_x, S_y].
    pub gradient: [f64; 2],
    /// [S_xx, S_xy, S_yy].
    pub hessian: [f64; 3],
    /// [S_xxx, S_xxy, S_xyy, S_yyy].
    pub third: [f64; 4],
}

impl SurfacePoint {
    /// Picks the components out of `d[p][q]` = ∂ᵖ_x ∂ᵠ_y S.
    fn from_partials(d: &[[f64; 4]; 4]) -> Self {
        SurfacePoint {
            value: d[0][0],
            gradient: [d[1][0], d[0][1]],
            hessian: [d[2][0], d[1][1], d[0][2]],
            third: [d[3][0], d[2][1], d[1][2], d[0][3]],
        }
    }
}

/// A surface's tables as borrowed slices: what generated code keeps as constants and passes
/// to [`evaluate`]. Every table is stored row by row, `t[i * ny + j]` at (x_i, y_j).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceTable<'a> {
    /// The x knots, strictly increasing.
    pub x: &'a [f64],
    /// The y knots, strictly increasing.
    pub y: &'a [f64],
    /// The values z_ij.
    pub z: &'a [f64],
    /// ∂²S/∂x² at the knots.
    pub mx: &'a [f64],
    /// ∂²S/∂y² at the knots.
    pub my: &'a [f64],
    /// ∂⁴S/∂x²∂y² at the knots.
    pub mxy: &'a [f64],
    /// Whether the x and the y axis are periodic.
    pub periodic: [bool; 2],
}

impl SurfaceTable<'_> {
    /// True when the slices form a grid of at least 2 × 2 knots with every table of nx·ny
    /// values.
    fn is_grid(&self) -> bool {
        let (nx, ny) = (self.x.len(), self.y.len());
        nx >= 2
            && ny >= 2
            && nx.checked_mul(ny) == Some(self.z.len())
            && [self.mx, self.my, self.mxy]
                .iter()
                .all(|t| t.len() == self.z.len())
    }
}

/// A spline surface that owns its tables.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSpline {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    mx: Vec<f64>,
    my: Vec<f64>,
    mxy: Vec<f64>,
    ends: [Ends; 2],
}

impl SurfaceSpline {
    /// The surface through `z[i * ny + j]` at (`x[i]`, `y[j]`) with the ends `ends[0]` on the
    /// x axis and `ends[1]` on the y axis, or why the grid cannot make one.
    pub fn new(
        x: &[f64],
        y: &[f64],
        z: &[f64],
        ends: [Ends; 2],
    ) -> Result<Self, SurfaceSplineError> {
        build(x, y, z, ends, &mut spline::second_derivatives)
    }

    /// The x knots.
    pub fn x_knots(&self) -> &[f64] {
        &self.x
    }

    /// The y knots.
    pub fn y_knots(&self) -> &[f64] {
        &self.y
    }

    /// The number of knots on each axis, (nx, ny).
    pub fn shape(&self) -> (usize, usize) {
        (self.x.len(), self.y.len())
    }

    /// The values interpolated, row by row: the grid's, except that a periodic axis's last
    /// line is exactly its first.
    pub fn values(&self) -> &[f64] {
        &self.z
    }

    /// ∂²S/∂x² at the knots, row by row.
    pub fn knot_curvatures_x(&self) -> &[f64] {
        &self.mx
    }

    /// ∂²S/∂y² at the knots, row by row.
    pub fn knot_curvatures_y(&self) -> &[f64] {
        &self.my
    }

    /// ∂⁴S/∂x²∂y² at the knots, row by row.
    pub fn knot_cross_curvatures(&self) -> &[f64] {
        &self.mxy
    }

    /// The ends it was built with, [x axis, y axis].
    pub fn ends(&self) -> [Ends; 2] {
        self.ends
    }

    /// Whether the x and the y axis are periodic.
    pub fn is_periodic(&self) -> [bool; 2] {
        self.ends.map(|e| e == Ends::Periodic)
    }

    /// Its tables as slices, as generated code stores them.
    pub fn table(&self) -> SurfaceTable<'_> {
        SurfaceTable {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            mx: &self.mx,
            my: &self.my,
            mxy: &self.mxy,
            periodic: self.is_periodic(),
        }
    }

    /// The value and derivatives at (x, y) ([`evaluate`]).
    pub fn eval(&self, x: f64, y: f64) -> SurfacePoint {
        evaluate(&self.table(), x, y)
    }

    /// ∂ᵖ_x ∂ᵠ_y S at (x, y) for every p, q ([`partials`]; zero beyond the third in either
    /// variable).
    pub fn partial(&self, (p, q): (u8, u8), x: f64, y: f64) -> f64 {
        match (usize::from(p), usize::from(q)) {
            (p @ 0..=3, q @ 0..=3) => partials(&self.table(), x, y)[p][q],
            _ => 0.0,
        }
    }
}

/// Checks a grid: the number of values, each axis's knots for its ends (at least 2, or 4
/// for a periodic axis; finite, strictly increasing, a width within f64), a clamped axis's
/// slopes, every value finite, and a periodic axis's last line repeating its first.
pub fn check_grid(
    x: &[f64],
    y: &[f64],
    z: &[f64],
    ends: [Ends; 2],
) -> Result<(), SurfaceSplineError> {
    let (nx, ny) = (x.len(), y.len());
    if nx.checked_mul(ny) != Some(z.len()) {
        return Err(SurfaceSplineError::Shape {
            nx,
            ny,
            got: z.len(),
        });
    }
    for (axis, knots, ends) in [(Axis::X, x, ends[0]), (Axis::Y, y, ends[1])] {
        spline::check_table(knots, &vec![0.0; knots.len()], ends)
            .map_err(|error| SurfaceSplineError::Knots { axis, error })?;
        let (first, last) = (knots[0], knots[knots.len() - 1]);
        if !(last - first).is_finite() {
            return Err(SurfaceSplineError::TooWide { axis, first, last });
        }
        if let Ends::Clamped { start, end } = ends {
            if !(start.is_finite() && end.is_finite()) {
                return Err(SurfaceSplineError::Slopes { axis, start, end });
            }
        }
    }
    if let Some(k) = z.iter().position(|v| !v.is_finite()) {
        return Err(SurfaceSplineError::NotFinite {
            i: k / ny,
            j: k % ny,
            value: z[k],
        });
    }
    let scale = z
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    // The value at index `last` of z must repeat the one at `first`.
    let seam = |axis: Axis, first: usize, last: usize| {
        let (a, b) = (z[first], z[last]);
        if (b - a).abs() > CLOSURE_TOLERANCE * scale {
            return Err(SurfaceSplineError::EdgesDoNotMeet {
                axis,
                first_cell: (first / ny, first % ny),
                last_cell: (last / ny, last % ny),
                first: a,
                last: b,
            });
        }
        Ok(())
    };
    if ends[0] == Ends::Periodic {
        for j in 0..ny {
            seam(Axis::X, j, (nx - 1) * ny + j)?;
        }
    }
    if ends[1] == Ends::Periodic {
        for i in 0..nx {
            seam(Axis::Y, i * ny, i * ny + ny - 1)?;
        }
    }
    Ok(())
}

/// The one-dimensional solve of a line's knot second derivatives from its knots, values and
/// ends: [`spline::second_derivatives`], or a wrapper around it that counts the work (the
/// tests').
type LineSolve<'a> = dyn FnMut(&[f64], &[f64], Ends) -> Result<Vec<f64>, SplineError> + 'a;

/// The ends of a line of curvatures (M^x along y, or M^y along x): a clamped edge has a
/// constant slope along it, so the curvature's slope across it is zero; natural and
/// periodic ends stay as they are.
fn curvature_ends(ends: Ends) -> Ends {
    match ends {
        Ends::Clamped { .. } => Ends::Clamped {
            start: 0.0,
            end: 0.0,
        },
        other => other,
    }
}

/// The surface through the grid with every line's solve done by `solve`: ny solves of length
/// nx and 2·nx of length ny (see the module's documentation).
fn build(
    x: &[f64],
    y: &[f64],
    z: &[f64],
    ends: [Ends; 2],
    solve: &mut LineSolve<'_>,
) -> Result<SurfaceSpline, SurfaceSplineError> {
    check_grid(x, y, z, ends)?;
    let (nx, ny) = (x.len(), y.len());
    let mut z = z.to_vec();
    // A periodic axis's last line is its first one (they agree within the closure
    // tolerance), so that every line of curvatures derived from them closes exactly too.
    if ends[0] == Ends::Periodic {
        let (first, last) = z.split_at_mut((nx - 1) * ny);
        last.copy_from_slice(&first[..ny]);
    }
    if ends[1] == Ends::Periodic {
        for row in z.chunks_exact_mut(ny) {
            row[ny - 1] = row[0];
        }
    }
    let mx = along_x(x, &z, ny, ends[0], solve)?;
    finite(&mx, ny, "∂²S/∂x²")?;
    let my = along_y(y, &z, ends[1], solve)?;
    finite(&my, ny, "∂²S/∂y²")?;
    let mxy = along_y(y, &mx, curvature_ends(ends[1]), solve)?;
    finite(&mxy, ny, "∂⁴S/∂x²∂y²")?;
    Ok(SurfaceSpline {
        x: x.to_vec(),
        y: y.to_vec(),
        z,
        mx,
        my,
        mxy,
        ends,
    })
}

/// The knot second derivatives along x of the table `values` (ny values a row): one solve per
/// column.
fn along_x(
    x: &[f64],
    values: &[f64],
    ny: usize,
    ends: Ends,
    solve: &mut LineSolve<'_>,
) -> Result<Vec<f64>, SurfaceSplineError> {
    let mut out = vec![0.0; values.len()];
    let mut line = vec![0.0; x.len()];
    for j in 0..ny {
        for (v, row) in line.iter_mut().zip(values.chunks_exact(ny)) {
            *v = row[j];
        }
        let m = solve(x, &line, ends).map_err(|error| SurfaceSplineError::Line {
            along: Axis::X,
            at: j,
            error,
        })?;
        for (row, v) in out.chunks_exact_mut(ny).zip(m) {
            row[j] = v;
        }
    }
    Ok(out)
}

/// The knot second derivatives along y of the table `values` (y.len() values a row): one
/// solve per row.
fn along_y(
    y: &[f64],
    values: &[f64],
    ends: Ends,
    solve: &mut LineSolve<'_>,
) -> Result<Vec<f64>, SurfaceSplineError> {
    let mut out = vec![0.0; values.len()];
    for (i, (row, target)) in values
        .chunks_exact(y.len())
        .zip(out.chunks_exact_mut(y.len()))
        .enumerate()
    {
        let m = solve(y, row, ends).map_err(|error| SurfaceSplineError::Line {
            along: Axis::Y,
            at: i,
            error,
        })?;
        for (t, v) in target.iter_mut().zip(m) {
            *t = v;
        }
    }
    Ok(out)
}

/// The first entry of `table` (ny values a row) that is not finite, as an overflow of `what`.
fn finite(table: &[f64], ny: usize, what: &'static str) -> Result<(), SurfaceSplineError> {
    match table.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(SurfaceSplineError::Overflow {
            what,
            i: k / ny,
            j: k % ny,
            value: table[k],
        }),
        None => Ok(()),
    }
}

/// `s` moved into [first, last) of `knots` by whole periods when `periodic`; unchanged
/// otherwise (as [`spline::evaluate`] does).
fn wrap(knots: &[f64], periodic: bool, s: f64) -> f64 {
    let (first, last) = (knots[0], knots[knots.len() - 1]);
    if periodic && !(first <= s && s < last) {
        let period = last - first;
        s - ((s - first) / period).floor() * period
    } else {
        s
    }
}

/// The value and the derivatives up to the third of the surface `table` at (x, y): the cell
/// holding the point found by bisection on each axis ([`spline::segment`]) after a periodic
/// axis moves it into its period; beyond an open axis's ends the end cell's cubic continues.
/// Slices that do not form a grid (fewer than 2 knots on an axis, tables not of nx·ny values)
/// give NaN everywhere rather than a panic; [`check_grid`] and [`SurfaceSpline::new`] are
/// where a grid is checked, once.
pub fn evaluate(table: &SurfaceTable<'_>, x: f64, y: f64) -> SurfacePoint {
    SurfacePoint::from_partials(&partials(table, x, y))
}

/// Every partial derivative ∂ᵖ_x ∂ᵠ_y S at (x, y) with p, q ≤ 3, as `d[p][q]`: the same cell
/// and polynomial as [`evaluate`]. Those with p > 3 or q > 3 vanish (S is cubic in each
/// variable inside a cell), so these sixteen are all the derivatives there are; generated
/// code reads its surfaces' derivatives of any order from them. NaN everywhere for slices
/// that do not form a grid.
pub fn partials(table: &SurfaceTable<'_>, x: f64, y: f64) -> [[f64; 4]; 4] {
    if !table.is_grid() {
        return [[f64::NAN; 4]; 4];
    }
    let x = wrap(table.x, table.periodic[0], x);
    let y = wrap(table.y, table.periodic[1], y);
    let (i, j) = (spline::segment(table.x, x), spline::segment(table.y, y));
    cell(table, i, j, x, y)
}

/// ∂ᵖ_x ∂ᵠ_y S at (x, y), `d[p][q]` for p, q ≤ 3, of the polynomial of cell (i, j) (also
/// outside the cell): along x on the cell's two lines along x, the values u and the y
/// curvatures v with their x derivatives; then along y, for each x derivative, the cubic
/// through those.
fn cell(t: &SurfaceTable<'_>, i: usize, j: usize, x: f64, y: f64) -> [[f64; 4]; 4] {
    let ny = t.y.len();
    let (xs, ys) = (&t.x[i..i + 2], &t.y[j..j + 2]);
    let along_x = |values: &[f64], curvatures: &[f64], k: usize| {
        let (here, next) = (k, k + ny);
        spline::evaluate(
            xs,
            &[values[here], values[next]],
            &[curvatures[here], curvatures[next]],
            false,
            x,
        )
    };
    let corner = i * ny + j;
    let u = [along_x(t.z, t.mx, corner), along_x(t.z, t.mx, corner + 1)];
    let v = [
        along_x(t.my, t.mxy, corner),
        along_x(t.my, t.mxy, corner + 1),
    ];
    std::array::from_fn(|p| {
        spline::evaluate(ys, &[u[0][p], u[1][p]], &[v[0][p], v[1][p]], false, y)
    })
}
