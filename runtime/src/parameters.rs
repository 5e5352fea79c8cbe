//! Run-time parameters of a model: their declarations, the errors a bad value gets, and the
//! checks both the build and the running program make.
//!
//! A model file may declare parameters (`parameters: [(name: "k", value: 40.0, unit: "N/m",
//! min: 0.0)]`) and use them in any numeric field and expression. Parameters marked
//! `constant: true` are folded into the generated code as plain numbers; the others are read
//! at run time, so that a program (or `camchain sweep`) can change them without rebuilding.
//! A value given at run time is checked exactly as the build checks the file's default:
//! against the declared bounds, and every field it changes against that field's rules (a
//! mass stays positive, an inertia tensor physical). The messages come from [`checks`],
//! which the build's validator uses too, so a bad value gets the same located error
//! (`file:line:column: field: message`) whichever way it arrives.

use std::fmt;

/// The declaration of one run-time parameter (from the model file's `parameters:` list).
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterInfo {
    /// Name, as used in the model's expressions (`k`, `omega`, `m1`).
    pub name: String,
    /// Unit, free text from the file (`N/m`); may be empty.
    pub unit: String,
    /// The file's value.
    pub default: f64,
    /// Smallest accepted value (inclusive), if declared.
    pub min: Option<f64>,
    /// Largest accepted value (inclusive), if declared.
    pub max: Option<f64>,
    /// Free text from the file.
    pub description: String,
}

/// A parameter value refused at run time, located in the model file like a build error:
/// displayed as `file:line:column: field: message`.
#[derive(Clone, PartialEq, Eq, thiserror::Error)]
pub struct ParameterError {
    /// The model file, as the build showed it.
    pub file: String,
    /// 1-based line of the field (0 when unknown).
    pub line: usize,
    /// 1-based column of the field (0 when unknown).
    pub column: usize,
    /// Dotted path of the field at fault (`bodies[0].mass`, `parameters[2].max`).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Debug for ParameterError {
    /// The one-line message of `Display`, so that a `main` returning
    /// `Result<(), Box<dyn std::error::Error>>` prints it as it is after `Error: `. The
    /// fields stay public for a program that needs them.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl fmt::Display for ParameterError {
    /// The format of the build's errors (`camchain_codegen::ModelError`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if self.line > 0 {
            write!(f, ":{}:{}", self.line, self.column)?;
        }
        if !self.field.is_empty() {
            write!(f, ": {}", self.field)?;
        }
        write!(f, ": {}", self.message)
    }
}

/// Where a field is written in the model file: what generated code passes to [`located`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Location {
    /// The model file, as the build showed it.
    pub file: &'static str,
    /// 1-based line (0 when unknown).
    pub line: usize,
    /// 1-based column (0 when unknown).
    pub column: usize,
    /// Dotted path of the field.
    pub field: &'static str,
}

impl Location {
    /// The location of `field` at `line`:`column` of `file` (what generated code writes).
    pub const fn at(file: &'static str, line: usize, column: usize, field: &'static str) -> Self {
        Location {
            file,
            line,
            column,
            field,
        }
    }
}

/// Attaches a location to the outcome of a check.
pub fn located<T>(at: Location, outcome: Result<T, String>) -> Result<T, ParameterError> {
    outcome.map_err(|message| ParameterError {
        file: at.file.to_string(),
        line: at.line,
        column: at.column,
        field: at.field.to_string(),
        message,
    })
}

/// A run-time parameter's value against its declared range, located at the parameter's
/// `value`, `min` or `max` (`at`, in that order): what generated code calls first when it is
/// given parameters. The message names the value as `name = value`, as the build does for a
/// value given on the command line.
pub fn check_bounds(
    name: &str,
    value: f64,
    range: (Option<f64>, Option<f64>),
    at: [Location; 3],
) -> Result<(), ParameterError> {
    let what = format!("{name} = {value}");
    checks::within_bounds(name, value, range, &what)
        .map(|_| ())
        .map_err(|(side, message)| {
            let at = match side {
                Bound::Value => at[0],
                Bound::Min => at[1],
                Bound::Max => at[2],
            };
            ParameterError {
                file: at.file.to_string(),
                line: at.line,
                column: at.column,
                field: at.field.to_string(),
                message,
            }
        })
}

/// Which side of a parameter's declared range a value fell out of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    /// Below `min`.
    Min,
    /// Above `max`.
    Max,
    /// Not a finite number (reported at the parameter's `value`).
    Value,
}

/// The checks a field's value must pass, with the messages of the build's validator.
///
/// Each returns the value or the message (without location); `what` names the quantity in
/// the message (`mass`, `stiffness`).
pub mod checks {
    use super::Bound;

    /// Largest relative violation of the triangle inequality of principal moments that is
    /// taken as round-off (a thin rod or a lamina sits exactly on the boundary).
    pub const TRIANGLE_SLACK: f64 = 1e-9;

    /// A finite number.
    pub fn finite(value: f64) -> Result<f64, String> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(format!("must be finite, got {value}"))
        }
    }

    /// Largest magnitude of a physical quantity that must be positive (a mass, a stiffness),
    /// and the inverse of the smallest nonzero one: far beyond any mechanism in SI units
    /// (the Sun's mass is 2e30 kg), and far enough inside f64's range (1.8e308) that the
    /// equations' products of a few such values (m g l, k x²) stay finite.
    pub const MAGNITUDE: f64 = 1e100;

    /// A finite number > 0, within 1/[`MAGNITUDE`] … [`MAGNITUDE`].
    pub fn positive(what: &str, value: f64) -> Result<f64, String> {
        if !(value.is_finite() && value > 0.0) {
            Err(format!("{what} must be positive and finite, got {value}"))
        } else if !(1.0 / MAGNITUDE..=MAGNITUDE).contains(&value) {
            Err(out_of_range(what, value))
        } else {
            Ok(value)
        }
    }

    /// A finite number ≥ 0, at most [`MAGNITUDE`] (and 0 or at least 1/[`MAGNITUDE`]).
    pub fn non_negative(what: &str, value: f64) -> Result<f64, String> {
        if !(value.is_finite() && value >= 0.0) {
            Err(format!(
                "{what} must be non-negative and finite, got {value}"
            ))
        } else if value != 0.0 && !(1.0 / MAGNITUDE..=MAGNITUDE).contains(&value) {
            Err(out_of_range(what, value))
        } else {
            Ok(value)
        }
    }

    fn out_of_range(what: &str, value: f64) -> String {
        format!(
            "{what} = {value:e} is outside 1e-100 … 1e100, the range the equations can be \
             computed in without overflow (the products of a few such values must stay below \
             f64's 1.8e308)"
        )
    }

    /// A parameter's value against its declared range; `what` names the value (`its value`
    /// for the file's default, `k = -1` for a value given at run time). On failure, the side
    /// at fault and the message.
    pub fn within_bounds(
        name: &str,
        value: f64,
        (min, max): (Option<f64>, Option<f64>),
        what: &str,
    ) -> Result<f64, (Bound, String)> {
        if !value.is_finite() {
            return Err((Bound::Value, format!("{what} is not a finite number")));
        }
        if let Some(low) = min.filter(|&low| value < low) {
            let message = format!("{what} is below the minimum {low} declared for `{name}`");
            return Err((Bound::Min, message));
        }
        if let Some(high) = max.filter(|&high| value > high) {
            let message = format!("{what} is above the maximum {high} declared for `{name}`");
            return Err((Bound::Max, message));
        }
        Ok(value)
    }

    /// An inertia tensor about the centre of mass (row-major, symmetric): positive definite,
    /// principal moments obeying the triangle inequality.
    pub fn inertia(tensor: &[[f64; 3]; 3]) -> Result<(), String> {
        let mut moments = symmetric_eigenvalues(tensor);
        moments.sort_by(f64::total_cmp);
        let [small, middle, large] = moments;
        let listed = format!("{small}, {middle}, {large}");
        if small.is_nan() || small <= 0.0 {
            return Err(format!(
                "the inertia tensor must be positive definite; its principal moments are {listed}"
            ));
        }
        if large > (small + middle) + TRIANGLE_SLACK * (small + middle + large) {
            return Err(format!(
                "the principal moments {listed} violate the triangle inequality (the largest \
                 may not exceed the sum of the other two): no rigid body has this inertia"
            ));
        }
        Ok(())
    }

    /// The eigenvalues of a symmetric 3×3 matrix (unordered) by cyclic Jacobi rotations: each
    /// rotation zeroes one off-diagonal entry, and the sweeps converge quadratically to
    /// round-off of the matrix's norm, as a library's symmetric eigensolver does. Written here
    /// so that the part of the runtime a compiled model links needs no linear-algebra crate; a
    /// non-finite entry gives NaN moments, which the callers refuse.
    pub(crate) fn symmetric_eigenvalues(tensor: &[[f64; 3]; 3]) -> [f64; 3] {
        let mut a = *tensor;
        for _sweep in 0..32 {
            let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
            let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
            if !off.is_finite() || !scale.is_finite() {
                return [f64::NAN; 3];
            }
            if off <= f64::EPSILON * 1e-3 * scale || off == 0.0 {
                break;
            }
            for (p, r) in [(0, 1), (0, 2), (1, 2)] {
                if a[p][r] == 0.0 {
                    continue;
                }
                // The rotation in the (p, r) plane that zeroes a[p][r] (Golub & Van Loan,
                // Matrix Computations, §8.5.2, the smaller of the two angles).
                let theta = (a[r][r] - a[p][p]) / (2.0 * a[p][r]);
                let t = theta.signum() / (theta.abs() + theta.hypot(1.0));
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / t.hypot(1.0);
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akr) = (row[p], row[r]);
                    row[p] = c * akp - s * akr;
                    row[r] = s * akp + c * akr;
                }
                let (row_p, row_r) = (a[p], a[r]);
                for k in 0..3 {
                    a[p][k] = c * row_p[k] - s * row_r[k];
                    a[r][k] = s * row_p[k] + c * row_r[k];
                }
                a[p][r] = 0.0;
                a[r][p] = 0.0;
            }
        }
        [a[0][0], a[1][1], a[2][2]]
    }

    /// "unknown parameter `name`; known: a, b" (the names sorted), or a note that the model
    /// has none.
    pub fn unknown_parameter(name: &str, known: &[&str]) -> String {
        unknown_parameter_among(name, known, &[])
    }

    /// [`unknown_parameter`] for generated code, which tells the parameters that can be set
    /// (`settable`) from those folded into it at build time (`constant`): only the first are
    /// offered as "known", the second are named as constant so that nobody is told to set a
    /// value the build has folded away.
    pub fn unknown_parameter_among(name: &str, settable: &[&str], constant: &[&str]) -> String {
        let sorted = |names: &[&str]| {
            let mut names = names.to_vec();
            names.sort_unstable();
            names.join(", ")
        };
        match (settable.is_empty(), constant.is_empty()) {
            (true, true) => format!("unknown parameter `{name}`: this model declares no parameter"),
            (true, false) => format!(
                "unknown parameter `{name}`: this build of the model has no parameter that can \
                 be set (constant, folded into the code: {})",
                sorted(constant)
            ),
            (false, true) => format!("unknown parameter `{name}`; known: {}", sorted(settable)),
            (false, false) => format!(
                "unknown parameter `{name}`; known: {} (constant, folded into the code: {})",
                sorted(settable),
                sorted(constant)
            ),
        }
    }

    /// The message for a value given to a parameter folded at build time.
    pub fn constant_parameter(name: &str) -> String {
        format!(
            "parameter `{name}` is constant (folded into the generated code): remove \
             `constant: true` to give it another value"
        )
    }
}

/// Resolves `(name, value)` pairs against a model's run-time parameters: the values in
/// declaration order, defaults where not given. Unknown names and non-finite values are
/// refused here (`file`, `line`, `column` locate the `parameters` list); the model checks
/// the bounds and the fields when it is built from the values.
pub fn resolve(
    declared: &[ParameterInfo],
    given: &[(&str, f64)],
) -> Result<Vec<f64>, UnknownParameter> {
    let mut values: Vec<f64> = declared.iter().map(|p| p.default).collect();
    for &(name, value) in given {
        let Some(i) = declared.iter().position(|p| p.name == name) else {
            let known: Vec<&str> = declared.iter().map(|p| p.name.as_str()).collect();
            return Err(UnknownParameter {
                name: name.to_string(),
                message: checks::unknown_parameter(name, &known),
            });
        };
        values[i] = value;
    }
    Ok(values)
}

/// A name that is not one of the model's run-time parameters.
#[derive(Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct UnknownParameter {
    /// The name given.
    pub name: String,
    /// The explanation, listing the known names.
    pub message: String,
}

impl fmt::Debug for UnknownParameter {
    /// The one-line message of `Display`, so that a `main` returning
    /// `Result<(), Box<dyn std::error::Error>>` prints it as it is after `Error: `. The
    /// fields stay public for a program that needs them.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

#[cfg(test)]
mod tests {
    use super::checks::*;
    use super::*;

    #[test]
    fn checks_accept_good_values_and_explain_bad_ones() {
        assert_eq!(positive("mass", 2.0), Ok(2.0));
        assert_eq!(
            positive("mass", -1.0),
            Err("mass must be positive and finite, got -1".to_string())
        );
        assert!(positive("mass", f64::NAN).is_err());
        assert_eq!(non_negative("stiffness", 0.0), Ok(0.0));
        assert!(non_negative("stiffness", -0.5).is_err());
        assert!(finite(f64::INFINITY).is_err());
        let lamina = [[0.05, 0.0, 0.0], [0.0, 0.05, 0.0], [0.0, 0.0, 0.1]];
        assert_eq!(inertia(&lamina), Ok(()));
        let impossible = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.1]];
        assert!(inertia(&impossible).unwrap_err().contains("triangle"));
        let negative = [[-0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]];
        assert!(
            inertia(&negative)
                .unwrap_err()
                .contains("positive definite")
        );
    }

    #[test]
    fn principal_moments_are_those_of_a_rotated_diagonal() {
        // R diag(d) Rᵀ has the eigenvalues d whatever the rotation R: the closed form the
        // Jacobi sweeps are held to. Tolerance: 1e-14 of the largest moment, a few ulps of the
        // rotation's own round-off (each product of R's entries is off by ~1e-16).
        let cases = [
            [1.0, 2.0, 2.5],
            [0.0, 0.05, 0.05],
            [1e-6, 1.0, 1.0],
            [3.0, 3.0, 3.0],
            [-0.5, 0.2, 7.0],
        ];
        for (n, d) in cases.iter().enumerate() {
            let (a, b, c) = (0.3 + n as f64, -1.1 * n as f64, 0.7f64);
            let rx = [
                [1.0, 0.0, 0.0],
                [0.0, a.cos(), -a.sin()],
                [0.0, a.sin(), a.cos()],
            ];
            let ry = [
                [b.cos(), 0.0, b.sin()],
                [0.0, 1.0, 0.0],
                [-b.sin(), 0.0, b.cos()],
            ];
            let rz = [
                [c.cos(), -c.sin(), 0.0],
                [c.sin(), c.cos(), 0.0],
                [0.0, 0.0, 1.0],
            ];
            let mul = |x: [[f64; 3]; 3], y: [[f64; 3]; 3]| {
                let mut out = [[0.0; 3]; 3];
                for i in 0..3 {
                    for j in 0..3 {
                        out[i][j] = (0..3).map(|k| x[i][k] * y[k][j]).sum();
                    }
                }
                out
            };
            let r = mul(mul(rz, ry), rx);
            let mut tensor = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    tensor[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
                }
            }
            let mut got = symmetric_eigenvalues(&tensor);
            got.sort_by(f64::total_cmp);
            let largest = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (g, want) in got.iter().zip(d) {
                assert!((g - want).abs() <= 1e-14 * largest, "{got:?} against {d:?}");
            }
        }
        assert!(symmetric_eigenvalues(&[[f64::NAN, 0.0, 0.0], [0.0; 3], [0.0; 3]])[0].is_nan());
    }

    #[test]
    fn bounds_name_the_side_at_fault() {
        let range = (Some(0.0), Some(10.0));
        assert_eq!(within_bounds("k", 5.0, range, "k = 5"), Ok(5.0));
        assert_eq!(
            within_bounds("k", -1.0, range, "k = -1").unwrap_err().0,
            Bound::Min
        );
        assert_eq!(
            within_bounds("k", 11.0, range, "k = 11").unwrap_err().0,
            Bound::Max
        );
        assert_eq!(
            within_bounds("k", f64::NAN, range, "k = NaN")
                .unwrap_err()
                .0,
            Bound::Value
        );
    }

    #[test]
    fn resolve_fills_defaults_and_refuses_unknown_names() {
        let declared = vec![
            ParameterInfo {
                name: "k".into(),
                unit: "N/m".into(),
                default: 40.0,
                min: Some(0.0),
                max: None,
                description: String::new(),
            },
            ParameterInfo {
                name: "omega".into(),
                unit: "rad/s".into(),
                default: 5.0,
                min: None,
                max: None,
                description: String::new(),
            },
        ];
        assert_eq!(resolve(&declared, &[("omega", 7.0)]), Ok(vec![40.0, 7.0]));
        let e = resolve(&declared, &[("omegaa", 7.0)]).unwrap_err();
        assert_eq!(e.message, "unknown parameter `omegaa`; known: k, omega");
    }
    #[test]
    fn unknown_names_are_offered_only_the_parameters_that_can_be_set() {
        assert_eq!(
            unknown_parameter_among("x", &["omega", "k"], &["m"]),
            "unknown parameter `x`; known: k, omega (constant, folded into the code: m)"
        );
        let none_settable = unknown_parameter_among("x", &[], &["m", "l"]);
        assert!(
            none_settable.contains("no parameter that can be set")
                && none_settable.ends_with("(constant, folded into the code: l, m)"),
            "{none_settable}"
        );
        assert!(!none_settable.contains("; known:"), "{none_settable}");
        assert_eq!(
            unknown_parameter_among("x", &[], &[]),
            unknown_parameter("x", &[])
        );
    }
}
