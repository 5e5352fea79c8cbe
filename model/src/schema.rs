//! The RON model file: format, parsing and validation.
//!
//! A model file is one unnamed RON struct (see `models/*.ron` for complete examples):
//!
//! ```ron
//! (
//!     name: "paper_concave",            // optional, default: the file stem
//!     description: "…",                 // optional
//!     gravity: (0.0, -9.81, 0.0),       // optional, default (0, 0, 0)
//!     bodies: [(
//!         name: "body1", parent: "ground", mass: 1.0,
//!         com: (0.15, 0.0, 0.0),        // optional
//!         inertia: Izz(0.10),           // | Diagonal(ixx, iyy, izz) | Full(ixx: _, …, iyz: _)
//!         joint: (
//!             kind: Revolute,           // | Prismatic
//!             axis: (0.0, 0.0, 1.0),    // parent frame, normalised here
//!             anchor: (0.38, 0.80, 0.0),  // optional
//!             coordinate: "q1",
//!             spring: (stiffness: 15.0, damping: 1.0, rest: 0.0),  // optional
//!             prescribed: "-PI/2 + 0.45*(2.0*PI*t/4.0).sin()",    // optional
//!         ),
//!     )],
//!     markers: [(name: "A", body: "body4", position: (0.3, 0.0, 0.0))],
//!     contacts: [(marker: "A", profile: "-0.595*x + 0.5*x*x",
//!                 frame: (origin: (0, 0, 0), x_axis: (1, 0, 0), y_axis: (0, 1, 0)))],
//!     initial: (q: {"q1": -1.67}, qd: {}, hold: ["q1"]),
//!     simulation: (t_end: 10.0, dt_out: 0.01, integrator: Dop853, // or Rk4, Dopri5
//!                  dt: 1e-3, rtol: 1e-10, atol: 1e-12),
//! )
//! ```
//!
//! Optional values are written without `Some(...)` (RON's `implicit_some` extension is
//! on) and integers are accepted where numbers are expected. Parsing happens in two stages:
//! a RON reader (`schema/reader.rs`, written for this crate) deserialises into mirror types
//! (syntax, unknown/missing fields, wrong types, unknown variants), then the validator
//! checks physics and names.
//!
//! The reader is a serde `Deserializer` over the text's tokens that reads what ron 0.12
//! reads, with ron's messages (a test compares the two on every model file of the
//! repository and on random model-shaped texts). It is hand-written for two reasons: ron
//! brought four crates (ron, bitflags, typeid, unicode-ident) into every program that reads
//! model files at run time (the facade's `reference` feature), and its errors only said
//! where its cursor stopped, while the reader's carry the byte range of the offending
//! token and the end of the value before it, which the locator turns into the message's
//! line, column and quoted token. Validation errors are located with a small RON scanner
//! that maps the dotted field path (`bodies[1].mass`) back to a line and column, because
//! serde values carry no positions.

mod csv;
mod raw;
mod read;
mod reader;
mod scan;
mod validate;

pub use read::{MAX_FILE_BYTES, read_text};
pub use validate::ranges;

use crate::error::ModelError;
use crate::model::{Model, ParameterMode};
use scan::Document;
use std::path::Path;

/// Reads (at most [`MAX_FILE_BYTES`]) and validates a model file.
pub fn load_model(path: &Path) -> Result<Model, ModelError> {
    let source = read_text(path).map_err(|e| ModelError {
        file: path.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    parse_model(&source, path)
}

/// Parses and validates model source text; `file` is used in error messages and for the
/// default model name (the file stem).
///
/// A UTF-8 byte-order mark at the start of the text (as some Windows editors write it) is
/// skipped.
pub fn parse_model(source: &str, file: &Path) -> Result<Model, ModelError> {
    parse_model_with(source, file, &[], ParameterMode::AsDeclared)
}

/// [`parse_model`] with parameter values other than the file's (`overrides`, by name: each
/// checked against the parameter's bounds and every field it changes, exactly as the file's
/// values are) and a choice of which parameters the generated code reads at run time.
pub fn parse_model_with(
    source: &str,
    file: &Path,
    overrides: &[(String, f64)],
    mode: ParameterMode,
) -> Result<Model, ModelError> {
    parse_model_from(source, file, overrides, mode, Files::BesideModel)
}

/// Where the files a model names (its tables of points) are read from.
#[derive(Debug, Clone, Copy, Default)]
pub enum Files<'a> {
    /// A relative path from the directory of the model file's path (the path messages show):
    /// right for a file loaded from where the program runs.
    #[default]
    BesideModel,
    /// A relative path from this directory: the model file's own, when the path messages show
    /// is relative to somewhere else (a build script's workspace root).
    In(&'a Path),
    /// Only these texts, by the path as the model writes it: a built-in model's files,
    /// embedded in the program with it.
    Embedded(&'a [(&'a str, &'a str)]),
}

/// [`parse_model_with`] reading the files the model names from `files`.
pub fn parse_model_from(
    source: &str,
    file: &Path,
    overrides: &[(String, f64)],
    mode: ParameterMode,
    files: Files,
) -> Result<Model, ModelError> {
    let source = without_bom(source);
    let at = Locator::new(file, source);
    let parsed: raw::Model = reader::from_str(source).map_err(|e| at.syntax_error(&e))?;
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let options = validate::Options {
        overrides,
        mode,
        files,
    };
    validate::validate(&parsed, &stem, &at, &options)
}

/// An error about the value at the dotted `field` path (`bodies[2].mass`,
/// `bodies[0].joint.axis`, `contacts[0].profile`, `initial.q`, `initial.q["q1"]`,
/// `initial.hold[1]`, `bodies[0].com[2]`), located in `source`.
///
/// For problems found after parsing (e.g. an initial state that cannot be assembled onto
/// the cam), so they point at the file like parse errors do. The position is the 1-based
/// line and column of the value; when the path is not written out in the file (a default
/// was used), that of the closest enclosing value that is; 0:0 when none is.
pub fn field_error(
    file: &Path,
    source: &str,
    field: &str,
    message: impl Into<String>,
) -> ModelError {
    Locator::new(file, without_bom(source)).error(field, message)
}

/// The text without a leading UTF-8 byte-order mark.
fn without_bom(source: &str) -> &str {
    source.strip_prefix('\u{feff}').unwrap_or(source)
}

/// True for an ASCII Rust identifier that is not a keyword: what a model's name must be
/// for the build to generate a module of that name (the numeric reference runs a model of
/// any name).
pub fn is_identifier(name: &str) -> bool {
    validate::is_identifier(name)
}

/// Builds located errors for one source text.
struct Locator<'a> {
    file: &'a Path,
    source: &'a str,
    document: Document,
}

impl<'a> Locator<'a> {
    fn new(file: &'a Path, source: &'a str) -> Self {
        Locator {
            file,
            source,
            document: Document::parse(source),
        }
    }

    fn at_offset(&self, offset: Option<usize>, field: &str, message: String) -> ModelError {
        let (line, column) = offset.map_or((0, 0), |o| scan::line_column(self.source, o));
        ModelError {
            file: self.file.to_path_buf(),
            line,
            column,
            field: field.to_string(),
            message,
        }
    }

    /// An error at the value of `field`.
    fn error(&self, field: &str, message: impl Into<String>) -> ModelError {
        self.at_offset(self.document.locate(field), field, message.into())
    }

    /// An error about `field`, located at the value of the path `locate` (e.g. the k-th
    /// entry `initial.q[3]` of a map whose key `"q1"` is repeated).
    fn error_located(&self, field: &str, locate: &str, message: impl Into<String>) -> ModelError {
        self.at_offset(self.document.locate(locate), field, message.into())
    }

    /// An error at byte `offset` inside the string literal that is the value of `field`
    /// (exact when the literal has no escapes before that point).
    fn error_in_string(&self, field: &str, offset: usize, message: String) -> ModelError {
        let position = self.document.locate(field).map(|start| {
            let content = scan::string_content_start(self.source, start);
            if content == start {
                start
            } else {
                content + offset
            }
        });
        self.at_offset(position, field, message)
    }

    /// A syntax or type error of the reader, with the field path at its position.
    ///
    /// The position is the offending token's, and the token is quoted (`Expected comma,
    /// found \`kg\``). Where a `,` or closing bracket is missing before a token on a later
    /// line, the error points just after the last value before it, where the character is
    /// missing. A missing field is reported at the opening of the struct that lacks it.
    fn syntax_error(&self, error: &reader::Error) -> ModelError {
        use reader::Code;
        let place = error.place.unwrap_or(reader::Place {
            start: self.source.len(),
            end: self.source.len(),
            before: self.source.len(),
        });
        let clamp = |offset: usize| offset.min(self.source.len());
        let (start, end, before) = (clamp(place.start), clamp(place.end), clamp(place.before));
        let mut offset = start;
        let mut field_offset = start;
        let mut message = error.code.to_string();
        let gap = self.source.get(before..start).unwrap_or("");
        if error.code.is_missing_delimiter() && before > 0 && gap.contains('\n') {
            // `mass: 0.5` ⏎ `com: …`: the comma is missing after `0.5`, not before `com`.
            offset = before;
            field_offset = before - 1;
            message = match self.document.group_at(field_offset) {
                Some(open) if error.code != Code::ExpectedComma => {
                    let (line, column) = scan::line_column(self.source, open);
                    format!(
                        "{message} after this value: the group opened at {line}:{column} is \
                         not closed"
                    )
                }
                _ => format!("{message} after this value"),
            };
        } else if start >= self.source.len() && before > 0 {
            // The file ends where a value or a delimiter was due: name the innermost group
            // left open and the field it belongs to, not the top level.
            field_offset = before - 1;
            if let Some(open) = self.document.group_at(field_offset) {
                let (line, column) = scan::line_column(self.source, open);
                message =
                    format!("the file ends inside the group opened at {line}:{column}: {message}");
            } else {
                message = format!("the file ends here: {message}");
            }
        } else {
            if error.code == Code::ExpectedStringEnd {
                message = format!("{message}: this string has no closing `\"`");
            }
            let token = self.source.get(start..end).unwrap_or("");
            let quotable = !token.is_empty() && token.chars().count() <= 40;
            if quotable && !error.code.names_the_token() && !message.contains("found") {
                message = format!("{message}, found `{token}`");
            }
            if error.code == Code::ExpectedComma && before > 0 {
                // A stray token after a value belongs to that value's field.
                field_offset = before - 1;
            }
        }
        let mut field = self.document.path_at(field_offset);
        if let Code::MissingStructField { field: missing, .. } = &error.code {
            if let Some(open) = self.document.locate(&field).filter(|_| !field.is_empty()) {
                offset = open;
            }
            field = if field.is_empty() {
                (*missing).to_string()
            } else {
                format!("{field}.{missing}")
            };
        }
        let (line, column) = scan::line_column(self.source, offset);
        ModelError {
            file: self.file.to_path_buf(),
            line,
            column,
            field: if field.is_empty() {
                "<top level>".into()
            } else {
                field
            },
            message,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Formulation, IntegratorKind, JointKind};
    use std::path::PathBuf;

    /// A small valid model; every value of interest is on its own line (numbers below).
    const BASE: &str = r#"// test model
(
    name: "test_chain",
    gravity: (0.0, -9.81, 0.0),
    bodies: [
        (
            name: "link1",
            parent: "ground",
            mass: 1.0,
            com: (0.5, 0.0, 0.0),
            inertia: Izz(0.1),
            joint: (
                kind: Revolute,
                axis: (0.0, 0.0, 2.0),
                coordinate: "q1",
            ),
        ),
        (
            name: "link2",
            parent: "link1",
            mass: 0.5,
            inertia: Diagonal(0.01, 0.02, 0.025),
            joint: (
                kind: Prismatic,
                axis: (1.0, 0.0, 0.0),
                anchor: (1.0, 0.0, 0.0),
                coordinate: "q2",
                spring: (stiffness: 10.0, damping: 1.0),
                prescribed: "0.1*t.sin()",
            ),
        ),
    ],
    markers: [(name: "A", body: "link2", position: (0.3, 0.0, 0.0))],
    contacts: [(marker: "A", profile: "0.5*x - x*x")],
    initial: (q: {"q1": -1.0}, hold: ["q1"]),
    simulation: (t_end: 5, integrator: Rk4),
)
"#;

    fn file() -> PathBuf {
        PathBuf::from("models/test.ron")
    }

    fn parse(source: &str) -> Model {
        match parse_model(source, &file()) {
            Ok(m) => m,
            Err(e) => panic!("should parse: {e}"),
        }
    }

    /// BASE with `old` replaced by `new` (which must occur exactly once).
    fn edited(old: &str, new: &str) -> String {
        assert_eq!(
            BASE.matches(old).count(),
            1,
            "{old:?} must occur once in BASE"
        );
        BASE.replace(old, new)
    }

    fn error_of(source: &str) -> ModelError {
        match parse_model(source, &file()) {
            Ok(m) => panic!("should be rejected, parsed {}", m.name),
            Err(e) => e,
        }
    }

    /// Asserts the error for `BASE` with `old` → `new` names `field`, `line` and `text`.
    fn assert_rejected(old: &str, new: &str, field: &str, line: usize, text: &str) -> ModelError {
        let e = error_of(&edited(old, new));
        assert_eq!(e.field, field, "{e}");
        assert_eq!(e.line, line, "{e}");
        assert!(e.message.contains(text), "{e} lacks {text:?}");
        assert!(e.to_string().starts_with("models/test.ron:"), "{e}");
        e
    }

    #[test]
    fn base_model_parses_with_defaults_and_normalisation() {
        let m = parse(BASE);
        assert_eq!(m.name, "test_chain");
        assert_eq!(m.description, "");
        assert_eq!(m.bodies[0].joint.axis, [0.0, 0.0, 1.0]);
        assert_eq!(m.bodies[0].parent, None);
        assert_eq!(m.bodies[1].parent, Some(0));
        assert_eq!(
            m.bodies[0].inertia,
            [[0.05, 0.0, 0.0], [0.0, 0.05, 0.0], [0.0, 0.0, 0.1]]
        );
        assert_eq!(m.bodies[1].com, [0.0; 3]);
        let spring = m.bodies[1]
            .joint
            .spring
            .as_ref()
            .map(|s| (s.stiffness, s.damping, s.rest));
        assert_eq!(spring, Some((10.0, 1.0, 0.0)));
        assert_eq!(m.contacts[0].name, "A");
        assert_eq!(m.contacts[0].x_axis, [1.0, 0.0, 0.0]);
        assert_eq!(m.contacts[0].y_axis, [0.0, 1.0, 0.0]);
        assert_eq!(m.initial.q, vec![-1.0, 0.0]);
        assert_eq!(m.initial.qd, vec![0.0, 0.0]);
        // link2 is driven, so it counts as held even though `hold` lists only q1.
        assert_eq!(m.initial.hold, vec![true, true]);
        assert_eq!(m.simulation.t_end, 5.0);
        assert_eq!(m.simulation.integrator, IntegratorKind::Rk4);
        assert_eq!(m.simulation.dt_out, 0.01);
        assert_eq!(m.simulation.rtol, 1e-10);
    }

    #[test]
    fn name_defaults_to_the_file_stem() {
        let source = edited("    name: \"test_chain\",\n", "");
        let m = match parse_model(&source, Path::new("dir/some_chain.ron")) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(m.name, "some_chain");
        // Any file name runs on the numeric path; the build needs a module name.
        let display = Path::new("dir/some chain-v2.ron");
        let m = parse_model(&source, display).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.name, "some chain-v2");
        // The build refuses it as a module name: codegen/tests/suite/emit.rs.
    }

    /// A keyword as the model's name runs on the numeric path; the build refuses it
    /// (codegen/tests/suite/emit.rs).
    #[test]
    fn a_keyword_as_model_name_parses() {
        let source = edited("\"test_chain\"", "\"fn\"");
        assert!(
            parse_model(&source, &file()).is_ok(),
            "the numeric path runs it"
        );
    }

    #[test]
    fn rejects_negative_mass_with_the_exact_location() {
        let e = assert_rejected("mass: 0.5", "mass: -1", "bodies[1].mass", 21, "positive");
        assert_eq!(
            e.to_string(),
            "models/test.ron:21:19: bodies[1].mass: mass must be positive and finite, got -1"
        );
    }

    #[test]
    fn rejects_nan_mass() {
        assert_rejected("mass: 1.0", "mass: NaN", "bodies[0].mass", 9, "got NaN");
    }

    #[test]
    fn rejects_non_finite_vector_components() {
        let e = assert_rejected(
            "com: (0.5, 0.0, 0.0)",
            "com: (0.5, inf, 0.0)",
            "bodies[0].com[1]",
            10,
            "must be finite, got inf",
        );
        assert_eq!(e.column, 24);
        assert_rejected(
            "gravity: (0.0, -9.81, 0.0)",
            "gravity: (0.0, -9.81, -inf)",
            "gravity[2]",
            4,
            "finite",
        );
    }

    #[test]
    fn rejects_duplicate_body_names() {
        assert_rejected(
            "\"link2\",\n",
            "\"link1\",\n",
            "bodies[1].name",
            19,
            "duplicate body name `link1`",
        );
    }

    #[test]
    fn rejects_a_body_called_ground() {
        assert_rejected(
            "name: \"link1\"",
            "name: \"ground\"",
            "bodies[0].name",
            7,
            "reserved",
        );
    }

    #[test]
    fn rejects_duplicate_coordinates() {
        assert_rejected(
            "coordinate: \"q2\"",
            "coordinate: \"q1\"",
            "bodies[1].joint.coordinate",
            27,
            "duplicate coordinate `q1`",
        );
    }

    #[test]
    fn rejects_an_unknown_parent() {
        assert_rejected(
            "parent: \"link1\"",
            "parent: \"link9\"",
            "bodies[1].parent",
            20,
            "unknown parent `link9`",
        );
    }

    #[test]
    fn rejects_a_parent_cycle() {
        assert_rejected(
            "parent: \"ground\"",
            "parent: \"link2\"",
            "bodies[0].parent",
            8,
            "cycle: link1 -> link2 -> link1",
        );
    }

    #[test]
    fn rejects_a_zero_axis() {
        assert_rejected(
            "axis: (0.0, 0.0, 2.0)",
            "axis: (0.0, 0.0, 0.0)",
            "bodies[0].joint.axis",
            14,
            "non-zero",
        );
    }

    #[test]
    fn rejects_negative_stiffness_and_damping() {
        let line = "spring: (stiffness: 10.0, damping: 1.0)";
        assert_rejected(
            line,
            "spring: (stiffness: -10.0, damping: 1.0)",
            "bodies[1].joint.spring.stiffness",
            28,
            "stiffness must be non-negative",
        );
        assert_rejected(
            line,
            "spring: (stiffness: 10.0, damping: -1)",
            "bodies[1].joint.spring.damping",
            28,
            "damping must be non-negative",
        );
    }

    #[test]
    fn rejects_a_non_physical_inertia() {
        let diagonal = "Diagonal(0.01, 0.02, 0.025)";
        assert_rejected(
            diagonal,
            "Diagonal(0.01, -0.02, 0.025)",
            "bodies[1].inertia",
            22,
            "positive definite",
        );
        assert_rejected(
            diagonal,
            "Diagonal(0.01, 0.02, 0.05)",
            "bodies[1].inertia",
            22,
            "triangle inequality",
        );
        assert_rejected(
            diagonal,
            "Full(ixx: 0.02, iyy: 0.02, izz: 0.03, ixy: 0.025)",
            "bodies[1].inertia",
            22,
            "positive definite",
        );
        assert_rejected(
            diagonal,
            "Full(ixx: 0.02, iyy: 0.02, izz: 0.03, ixy: NaN)",
            "bodies[1].inertia.ixy",
            22,
            "finite",
        );
    }

    #[test]
    fn accepts_a_full_tensor_and_keeps_its_products() {
        let m = parse(&edited(
            "Diagonal(0.01, 0.02, 0.025)",
            "Full(ixx: 0.02, iyy: 0.02, izz: 0.03, ixy: -0.005, iyz: 0.001)",
        ));
        assert_eq!(
            m.bodies[1].inertia,
            [
                [0.02, -0.005, 0.0],
                [-0.005, 0.02, 0.001],
                [0.0, 0.001, 0.03]
            ]
        );
    }

    #[test]
    fn accepts_inertias_exactly_on_the_triangle_boundary() {
        // Izz(v) is a lamina (v/2, v/2, v) and Diagonal(1, 2, 3) a degenerate rod-like body:
        // both have largest moment = sum of the other two and must pass.
        for inertia in [
            "Izz(3e-7)",
            "Izz(1e5)",
            "Diagonal(1, 2, 3)",
            "Diagonal(0.1, 0.2, 0.3)",
        ] {
            parse(&edited("Diagonal(0.01, 0.02, 0.025)", inertia));
        }
    }

    #[test]
    fn ron_checks_the_fields_of_a_full_tensor() {
        assert_rejected(
            "Diagonal(0.01, 0.02, 0.025)",
            "Full(ixx: 1, iyy: 1, izz: 1, iyx: 0)",
            "bodies[1].inertia.iyx",
            22,
            "Unexpected field named `iyx`",
        );
        assert_rejected(
            "Diagonal(0.01, 0.02, 0.025)",
            "Full(iyy: 1, izz: 1)",
            "bodies[1].inertia.ixx",
            22,
            "missing field named `ixx`",
        );
    }

    #[test]
    fn rejects_a_marker_on_an_unknown_body() {
        assert_rejected(
            "body: \"link2\"",
            "body: \"ground\"",
            "markers[0].body",
            33,
            "unknown body `ground`",
        );
    }

    #[test]
    fn rejects_duplicate_marker_names() {
        assert_rejected(
            "markers: [(name: \"A\", body: \"link2\", position: (0.3, 0.0, 0.0))]",
            "markers: [(name: \"A\", body: \"link2\"), (name: \"A\", body: \"link1\")]",
            "markers[1].name",
            33,
            "duplicate marker name `A`",
        );
    }

    #[test]
    fn rejects_a_contact_on_an_unknown_marker() {
        assert_rejected(
            "marker: \"A\"",
            "marker: \"B\"",
            "contacts[0].marker",
            34,
            "unknown marker `B`",
        );
    }

    #[test]
    fn rejects_a_bad_profile_pointing_into_the_string() {
        let e = assert_rejected(
            "\"0.5*x - x*x\"",
            "\"0.5*y - x*x\"",
            "contacts[0].profile",
            34,
            "the only variable allowed here is `x`",
        );
        // The literal's quote is at column 39, so `y` (byte 4 of the text) is at 39 + 1 + 4.
        assert_eq!(e.column, 44);
        assert_rejected(
            "\"0.5*x - x*x\"",
            "\"0.5*x - \"",
            "contacts[0].profile",
            34,
            "not a valid expression",
        );
    }

    #[test]
    fn rejects_a_drive_in_the_wrong_variable() {
        let e = assert_rejected(
            "\"0.1*t.sin()\"",
            "\"0.1*x.sin()\"",
            "bodies[1].joint.prescribed",
            29,
            "`t`",
        );
        // The literal's quote is at column 29; `x` is byte 4 of the expression.
        assert_eq!(e.column, 29 + 1 + 4);
    }

    #[test]
    fn rejects_a_non_orthogonal_or_zero_cam_frame() {
        let profile = "profile: \"0.5*x - x*x\"";
        assert_rejected(
            profile,
            "profile: \"0.5*x - x*x\", frame: (x_axis: (1, 0, 0), y_axis: (1, 1, 0))",
            "contacts[0].frame.y_axis",
            34,
            "orthogonal",
        );
        assert_rejected(
            profile,
            "profile: \"0.5*x - x*x\", frame: (x_axis: (0, 0, 0))",
            "contacts[0].frame.x_axis",
            34,
            "non-zero",
        );
    }

    #[test]
    fn rejects_non_positive_simulation_settings() {
        for (field, value) in [("t_end", "0"), ("dt_out", "-0.1"), ("dt", "0.0")] {
            let e = assert_rejected(
                "simulation: (t_end: 5, integrator: Rk4)",
                &format!("simulation: (integrator: Rk4, {field}: {value})"),
                &format!("simulation.{field}"),
                36,
                &format!("{field} must be positive and finite"),
            );
            assert!(e.column > 0, "{e}");
        }
    }

    #[test]
    fn rejects_tolerances_and_sample_counts_out_of_the_runtime_s_ranges() {
        // The same bounds as camchain_runtime::settings (compared in camchain-reference).
        for (field, value, message) in [
            ("rtol", "1e-20", "rtol must be in [1e-14, 1e-1], got 1e-20"),
            ("rtol", "5", "rtol must be in [1e-14, 1e-1], got 5e0"),
            ("atol", "0", "atol must be in [1e-18, 1e0], got 0e0"),
            ("atol", "inf", "atol must be in [1e-18, 1e0], got inf"),
        ] {
            assert_rejected(
                "simulation: (t_end: 5, integrator: Rk4)",
                &format!("simulation: (t_end: 5, integrator: Dop853, {field}: {value})"),
                &format!("simulation.{field}"),
                36,
                message,
            );
        }
        assert_rejected(
            "simulation: (t_end: 5, integrator: Rk4)",
            "simulation: (t_end: 1e12, integrator: Rk4)",
            "simulation.dt_out",
            36,
            "gives 1.000e14 samples, more than the 1e6 a run keeps",
        );
    }

    #[test]
    fn integrators_are_named_in_any_letter_case() {
        for name in ["Dop853", "dop853", "DOP853"] {
            let source = edited("integrator: Rk4", &format!("integrator: {name}"));
            let m = parse_model(&source, &file()).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(m.simulation.integrator, IntegratorKind::Dop853, "{name}");
        }
        assert_rejected(
            "integrator: Rk4",
            "integrator: Euler",
            "simulation.integrator",
            36,
            "unknown integrator (one of rk4, dopri5, dop853, in any letter case), found `Euler`",
        );
    }

    #[test]
    fn the_formulation_is_a_keyword_of_its_kind() {
        let m = parse_model(BASE, &file()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.simulation.formulation, Formulation::Auto, "the default");
        let source = edited(
            "integrator: Rk4",
            "integrator: Rk4, formulation: Articulated",
        );
        let m = parse_model(&source, &file()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.simulation.formulation, Formulation::Articulated);
        let e = error_of(&edited(
            "integrator: Rk4",
            "integrator: Rk4, formulation: Fast",
        ));
        let text = e.to_string();
        assert!(text.contains("simulation.formulation"), "{text}");
        assert!(
            text.contains("`Auto`") && text.contains("`Dense`") && text.contains("`Articulated`"),
            "{text}"
        );
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        let with_bom = format!("\u{feff}{BASE}");
        let m = parse_model(&with_bom, &file()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.name, "test_chain");
        // Errors are located as in the same file without the mark.
        let e = error_of(&format!("\u{feff}{}", edited("mass: 0.5", "mass: -1")));
        assert_eq!((e.line, e.column), (21, 19), "{e}");
    }

    #[test]
    fn rejects_unknown_coordinates_in_initial() {
        assert_rejected(
            "hold: [\"q1\"]",
            "hold: [\"q1\", \"q9\"]",
            "initial.hold[1]",
            35,
            "unknown coordinate `q9`",
        );
        let e = assert_rejected(
            "q: {\"q1\": -1.0}",
            "q: {\"q1\": -1.0, \"q7\": 2}",
            "initial.q[\"q7\"]",
            35,
            "unknown coordinate `q7`",
        );
        // The key `"q7"` starts at column 31.
        assert_eq!(e.column, 31);
        assert_rejected(
            "q: {\"q1\": -1.0}",
            "qd: {\"x\": 1}",
            "initial.qd[\"x\"]",
            35,
            "unknown coordinate",
        );
    }

    #[test]
    fn rejects_repeated_and_non_finite_initial_values() {
        let e = assert_rejected(
            "q: {\"q1\": -1.0}",
            "q: {\"q1\": -1.0, \"q1\": 2}",
            "initial.q[\"q1\"]",
            35,
            "given twice",
        );
        // At the second `"q1"` (column 31), not the first (column 19).
        assert_eq!(e.column, 31);
        assert_rejected(
            "q: {\"q1\": -1.0}",
            "q: {\"q1\": NaN}",
            "initial.q[\"q1\"]",
            35,
            "finite",
        );
        assert_rejected(
            "hold: [\"q1\"]",
            "hold: [\"q1\", \"q1\"]",
            "initial.hold[1]",
            35,
            "listed twice",
        );
    }

    #[test]
    fn rejects_an_empty_body_list() {
        let e = error_of("(\n    bodies: [],\n)");
        assert_eq!((e.field.as_str(), e.line, e.column), ("bodies", 2, 13));
        assert!(e.message.contains("at least one body"), "{e}");
    }

    #[test]
    fn ron_unknown_field_names_the_path() {
        let e = assert_rejected(
            "mass: 0.5,",
            "mass: 0.5, colour: 3,",
            "bodies[1].colour",
            21,
            "colour",
        );
        assert_eq!(e.column, 24);
    }

    #[test]
    fn a_missing_top_level_field_is_reported_at_the_opening_of_the_model() {
        // As for a nested struct; ron stopped at the closing `)` (line 4).
        let e = error_of("// a model without bodies\n(\n    name: \"x\",\n)\n");
        assert_eq!(
            (e.field.as_str(), e.line, e.column),
            ("bodies", 2, 1),
            "{e}"
        );
        assert!(e.message.contains("missing field named `bodies`"), "{e}");
    }

    #[test]
    fn a_float_with_a_stray_suffix_is_reported_at_it() {
        // ron read `5`, then wanted a comma before `u8`, and the error was moved back after
        // `t_end:` on the line before, as for a missing comma.
        let e = assert_rejected(
            "simulation: (t_end: 5, integrator: Rk4)",
            "simulation: (t_end:\n        5u8, integrator: Rk4)",
            "simulation.t_end",
            37,
            "Expected float, found `5u8`",
        );
        assert_eq!(e.column, 9);
    }

    #[test]
    fn an_invalid_escape_is_reported_at_its_backslash() {
        // ron pointed at the start of the string (or of the text after the escape before).
        let e = assert_rejected(
            "\"test_chain\"",
            r#""test\qchain""#,
            "name",
            3,
            "Unknown escape character",
        );
        assert_eq!(e.column, 16);
    }

    #[test]
    fn an_unclosed_block_comment_is_reported_where_it_opens() {
        // ron stopped at the last `*` or `/` before the end of the text (line 34, in the
        // profile `0.5*x - x*x`).
        let e = assert_rejected(
            "    name: \"test_chain\",\n",
            "    /* name: \"test_chain\",\n",
            "<top level>",
            3,
            "Unclosed block comment",
        );
        assert_eq!(e.column, 5);
    }

    #[test]
    fn an_unknown_field_is_named_once() {
        // The located message used to append ", found `colour`" after ron's, which names it.
        let e = assert_rejected(
            "mass: 0.5,",
            "mass: 0.5, colour: 3,",
            "bodies[1].colour",
            21,
            "Unexpected field named `colour` in `Body`, expected one of `name`",
        );
        assert_eq!(e.message.matches("colour").count(), 1, "{e}");
    }

    #[test]
    fn ron_missing_field_names_the_path() {
        // Located at the opening of the body that lacks it.
        let e = assert_rejected(
            "            mass: 0.5,\n",
            "",
            "bodies[1].mass",
            18,
            "missing field named `mass`",
        );
        assert_eq!(e.column, 9);
    }

    #[test]
    fn ron_wrong_type_names_the_path() {
        let e = assert_rejected(
            "mass: 0.5",
            "mass: true",
            "bodies[1].mass",
            21,
            "Expected a number or a string with an expression of the parameters",
        );
        assert_eq!(e.column, 19, "at the value, not at the space before it");
    }

    #[test]
    fn a_name_in_a_numeric_field_must_be_a_declared_parameter() {
        let e = assert_rejected(
            "mass: 0.5",
            "mass: \"heavy\"",
            "bodies[1].mass",
            21,
            "unknown name `heavy`: the model declares no parameters",
        );
        assert_eq!(e.column, 20, "inside the string, at the name");
    }

    #[test]
    fn ron_unknown_joint_kind_names_the_path() {
        assert_rejected(
            "kind: Prismatic",
            "kind: Slider",
            "bodies[1].joint.kind",
            24,
            "variant named `Slider` in enum `JointKind`",
        );
    }

    #[test]
    fn ron_syntax_error_has_a_position() {
        let e = error_of("(\n  bodies: [\n  (name: \"a\" parent: \"ground\")\n  ],\n)");
        assert_eq!(e.line, 3, "{e}");
        assert!(e.field.starts_with("bodies[0]"), "{e}");
    }

    #[test]
    fn ron_missing_comma_or_bracket_points_at_the_end_of_the_value_before() {
        // BASE line 21 is `            mass: 0.5,`: without its comma ron stops at line 22.
        let e = assert_rejected(
            "mass: 0.5,",
            "mass: 0.5",
            "bodies[1].mass",
            21,
            "Expected comma after this value",
        );
        assert_eq!(e.column, 22, "just after `0.5`");
        // On the same line the unexpected token itself is the defect.
        let e = assert_rejected(
            "mass: 0.5,",
            "mass: 0.5 kg,",
            "bodies[1].mass",
            21,
            "Expected comma, found `kg`",
        );
        assert_eq!(e.column, 23);
        // BASE line 10, `            com: (0.5, 0.0, 0.0),`, with its `)` missing.
        let e = assert_rejected(
            "com: (0.5, 0.0, 0.0),",
            "com: (0.5, 0.0, 0.0,",
            "bodies[0].com",
            10,
            "the group opened at 10:18 is not closed",
        );
        assert_eq!(e.column, 33, "just after the last comma");
    }

    #[test]
    fn a_file_cut_off_names_the_group_left_open_and_its_field() {
        // Cut after a comma, inside a value, and after a value: each names `bodies[0]`
        // (opened by its `(` at 3:14, the `[` being at 3:13), not the top level.
        for (source, field, line, column, text) in [
            (
                "(\n    name: \"x\",\n    bodies: [(name: \"b\", mass: 1.0,\n",
                "bodies[0]",
                4,
                1,
                "Expected identifier",
            ),
            (
                "(\n    name: \"x\",\n    bodies: [(name: \"b\", mass: ",
                "bodies[0].mass",
                3,
                32,
                "Unexpected end of RON",
            ),
            (
                "(\n    name: \"x\",\n    bodies: [(name: \"b\", mass: 1.0",
                "bodies[0].mass",
                3,
                35,
                "Expected comma",
            ),
        ] {
            let e = error_of(source);
            assert_eq!(
                (e.field.as_str(), e.line, e.column),
                (field, line, column),
                "{e}"
            );
            assert!(
                e.message
                    .starts_with("the file ends inside the group opened at 3:14: "),
                "{e}"
            );
            assert!(e.message.ends_with(text), "{e}");
        }
        // The whole file's group left open: the top level's own `(`.
        let e = error_of("(\n    name: \"x\",\n");
        assert!(
            e.message
                .starts_with("the file ends inside the group opened at 1:1: "),
            "{e}"
        );
    }

    #[test]
    fn explicit_some_is_still_accepted() {
        let m = parse(&edited(
            "prescribed: \"0.1*t.sin()\"",
            "prescribed: Some(\"0.1*t.sin()\")",
        ));
        assert!(m.bodies[1].joint.prescribed.is_some());
    }

    #[test]
    fn sorts_parents_first_and_remaps_every_index() {
        // grip's parent is listed after it; the file order is otherwise kept.
        let source = r#"(
            bodies: [
                (name: "grip", parent: "arm", mass: 1, inertia: Izz(1),
                 joint: (kind: Revolute, axis: (0, 0, 1), coordinate: "qg")),
                (name: "side", parent: "ground", mass: 1, inertia: Izz(1),
                 joint: (kind: Revolute, axis: (0, 0, 1), coordinate: "qs")),
                (name: "arm", parent: "ground", mass: 2, inertia: Izz(1),
                 joint: (kind: Prismatic, axis: (1, 0, 0), coordinate: "qa")),
            ],
            markers: [(name: "tip", body: "grip")],
            initial: (q: {"qg": 3, "qa": 1}, hold: ["qa"]),
        )"#;
        let m = parse(source);
        let names: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["arm", "grip", "side"]);
        let parents: Vec<Option<usize>> = m.bodies.iter().map(|b| b.parent).collect();
        assert_eq!(parents, [None, Some(0), None]);
        assert_eq!(m.markers[0].body, 1);
        assert_eq!(m.initial.q, vec![1.0, 3.0, 0.0]);
        assert_eq!(m.initial.hold, vec![true, false, false]);
        assert_eq!(m.coordinate_names(), ["qa", "qg", "qs"]);
    }

    #[test]
    fn field_error_locates_nested_paths() {
        let locate = |field: &str| {
            let e = field_error(&file(), BASE, field, "problem");
            assert_eq!(e.field, field);
            assert_eq!(e.message, "problem");
            (e.line, e.column)
        };
        assert_eq!(locate("bodies[1].mass"), (21, 19));
        assert_eq!(locate("bodies[0].joint.axis"), (14, 23));
        assert_eq!(locate("bodies[1].joint.spring.damping"), (28, 52));
        assert_eq!(locate("bodies[1].inertia[2]"), (22, 43));
        assert_eq!(locate("contacts[0].profile"), (34, 39));
        assert_eq!(locate("initial.q"), (35, 18));
        // A map entry is located at its key.
        assert_eq!(locate("initial.q[\"q1\"]"), (35, 19));
        assert_eq!(locate("initial.hold[0]"), (35, 39));
        // Not written out: fall back to the closest enclosing value, then to 0:0.
        assert_eq!(locate("bodies[1].com"), locate("bodies[1]"));
        assert_eq!(locate("contacts[0].frame.origin"), locate("contacts[0]"));
        assert_eq!(locate("description"), (0, 0));
    }

    fn load(name: &str) -> Model {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../models")
            .join(name);
        match load_model(&path) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        }
    }

    const PAPER_MODELS: [&str; 5] = [
        "paper_concave.ron",
        "paper_convex.ron",
        "paper_convex_text.ron",
        "driven_concave.ron",
        "driven_convex.ron",
    ];

    #[test]
    fn paper_models_have_the_paper_chain() {
        for file in PAPER_MODELS {
            let m = load(file);
            assert_eq!(m.name, file.trim_end_matches(".ron"));
            assert_eq!(m.coordinate_names(), ["q1", "q2", "q3", "q4"], "{file}");
            let masses: Vec<f64> = m.bodies.iter().map(|b| b.mass).collect();
            assert_eq!(masses, [1.0, 0.5, 1.0, 1.0], "{file}");
            let izz: Vec<f64> = m.bodies.iter().map(|b| b.inertia[2][2]).collect();
            assert_eq!(izz, [0.10, 0.01, 0.10, 0.10], "{file}");
            let kinds: Vec<JointKind> = m.bodies.iter().map(|b| b.joint.kind).collect();
            use JointKind::{Prismatic, Revolute};
            assert_eq!(kinds, [Revolute, Revolute, Prismatic, Revolute], "{file}");
            let springs: Vec<Option<(f64, f64)>> = m
                .bodies
                .iter()
                .map(|b| b.joint.spring.as_ref().map(|s| (s.stiffness, s.damping)))
                .collect();
            assert_eq!(
                springs,
                [
                    None,
                    Some((15.0, 1.0)),
                    Some((40.0, 1.0)),
                    Some((18.0, 1.0))
                ]
            );
            assert_eq!(m.bodies[2].joint.anchor, [0.1, 0.0, 0.0], "{file}");
            assert_eq!(m.markers[0].position, [0.3, 0.0, 0.0], "{file}");
            assert_eq!(m.markers[0].body, 3, "{file}");
            assert_eq!(m.contacts[0].name, "A", "{file}");
            assert_eq!(m.initial.hold, vec![true, true, false, true], "{file}");
            assert!(m.is_planar(), "{file}");
        }
    }

    #[test]
    fn paper_models_have_their_scenario_settings() {
        let concave = load("paper_concave.ron");
        assert_eq!(concave.gravity, [0.0, -9.81, 0.0]);
        assert_eq!(concave.bodies[0].joint.anchor, [0.38, 0.80, 0.0]);
        assert_eq!(concave.initial.q[0], -std::f64::consts::FRAC_PI_2 - 0.1);
        assert_eq!(concave.simulation.t_end, 10.0);
        assert!(concave.bodies[0].joint.prescribed.is_none());
        let driven = load("driven_convex.ron");
        assert_eq!(driven.gravity, [0.0; 3]);
        assert_eq!(driven.bodies[0].joint.anchor, [0.35, 0.85, 0.0]);
        assert_eq!(driven.simulation.t_end, 8.0);
        let drive = driven.bodies[0]
            .joint
            .prescribed
            .as_ref()
            .map(|p| p.expr.eval(1.0));
        // q1(1 s) = −π/2 + 0.45 sin(π/2) exactly up to rounding of the operations (1e-15).
        let want = -std::f64::consts::FRAC_PI_2 + 0.45;
        assert!(drive.is_some_and(|v| (v - want).abs() < 1e-15), "{drive:?}");
    }

    #[test]
    fn profiles_are_the_papers() {
        let at = |file: &str, x: f64| load(file).contacts[0].profile_expression().eval(x);
        // The profiles are cubic polynomials evaluated in a different association order from
        // the closed forms below: agreement to 1e-15 at |x| ≤ 1 (a few ulps of values ≤ 1).
        let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
        for x in [-0.5, 0.0, 0.3793, 0.7, 1.0] {
            let concave = 0.5 * x * (x - 0.7) * (x + 1.7);
            assert!(close(at("paper_concave.ron", x), concave));
            assert!(close(at("driven_concave.ron", x), concave));
            assert!(close(at("paper_convex.ron", x), -0.6 * concave));
            assert!(close(at("driven_convex.ron", x), -0.6 * concave));
            let text = -0.357 * x - 0.3 * x * x - 0.3 * x * x * x;
            assert!(close(at("paper_convex_text.ron", x), text));
        }
    }

    #[test]
    fn double_pendulum_is_two_free_rods() {
        let m = load("double_pendulum.ron");
        assert_eq!(m.n(), 2);
        assert!(m.contacts.is_empty());
        assert_eq!(m.bodies[1].joint.anchor, [1.0, 0.0, 0.0]);
        assert_eq!(m.initial.q, vec![-0.6, 0.8]);
        for b in &m.bodies {
            let length = 2.0 * b.com[0];
            let rod = b.mass * length * length / 12.0;
            // The file writes m l²/12 to 16 significant digits: relative 1e-15.
            assert!((b.inertia[2][2] - rod).abs() <= 1e-15 * rod, "{}", b.name);
        }
    }

    #[test]
    fn spatial_arm_is_genuinely_spatial() {
        let m = load("spatial_arm.ron");
        assert!(!m.is_planar());
        assert_eq!(m.n(), 5);
        let products = m
            .bodies
            .iter()
            .all(|b| b.inertia[0][1] != 0.0 && b.inertia[0][2] != 0.0 && b.inertia[1][2] != 0.0);
        assert!(products, "every body has a full inertia tensor");
        let prismatic: Vec<[f64; 3]> = m
            .bodies
            .iter()
            .filter(|b| b.joint.kind == JointKind::Prismatic)
            .map(|b| b.joint.axis)
            .collect();
        assert_eq!(prismatic.len(), 1);
        assert!(prismatic[0].iter().all(|&c| c != 0.0), "not axis-aligned");
        assert_eq!(m.contacts[0].y_axis, [0.0, 0.6, 0.8]);
        assert_eq!(m.initial.hold.iter().filter(|&&h| !h).count(), 1);
    }

    /// Quick forward kinematics following model.rs: at q = 0 a body's frame is its parent's
    /// translated to the anchor; revolute joints rotate about the axis, prismatic joints
    /// slide along it (both in the parent frame).
    fn marker_position(m: &Model, q: &[f64], marker: usize) -> nalgebra::Vector3<f64> {
        use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
        let mut frames: Vec<(Matrix3<f64>, Vector3<f64>)> = Vec::new();
        for (b, &qi) in m.bodies.iter().zip(q) {
            let (r, p) = b
                .parent
                .map_or((Matrix3::identity(), Vector3::zeros()), |i| frames[i]);
            let axis = Vector3::from(b.joint.axis);
            let origin = p + r * Vector3::from(b.joint.anchor);
            frames.push(match b.joint.kind {
                JointKind::Revolute => {
                    let turn = Rotation3::from_axis_angle(&Unit::new_normalize(axis), qi);
                    (r * turn.matrix(), origin)
                }
                JointKind::Prismatic => (r, origin + r * axis * qi),
            });
        }
        let mk = &m.markers[marker];
        let (r, p) = frames[mk.body];
        p + r * Vector3::from(mk.position)
    }

    /// The cam constraint h = y_c − f(x_c) of contact 0.
    fn constraint(m: &Model, q: &[f64]) -> f64 {
        let c = &m.contacts[0];
        let d = marker_position(m, q, c.marker) - nalgebra::Vector3::from(c.origin);
        let x = d.dot(&nalgebra::Vector3::from(c.x_axis));
        let y = d.dot(&nalgebra::Vector3::from(c.y_axis));
        y - c.profile_expression().eval(x)
    }

    /// Newton on the one unheld coordinate from the file's guess (drives evaluated at t = 0):
    /// returns (root, slope ∂h/∂q_free at the root).
    fn assemble(m: &Model) -> (f64, f64) {
        let mut q = m.initial.q.clone();
        for (qi, b) in q.iter_mut().zip(&m.bodies) {
            if let Some(p) = &b.joint.prescribed {
                *qi = p.expr.eval(0.0);
            }
        }
        let free: Vec<usize> = (0..m.n()).filter(|&i| !m.initial.hold[i]).collect();
        assert_eq!(free.len(), 1, "{}: one free coordinate", m.name);
        let j = free[0];
        // Central differences with step 1e-6 on smooth O(1) functions: slope error ~1e-12.
        let slope = |q: &[f64]| {
            let (mut plus, mut minus) = (q.to_vec(), q.to_vec());
            plus[j] += 1e-6;
            minus[j] -= 1e-6;
            (constraint(m, &plus) - constraint(m, &minus)) / 2e-6
        };
        for _ in 0..20 {
            q[j] -= constraint(m, &q) / slope(&q);
        }
        // Positions are O(1) m: 1e-12 m is round-off level after Newton has converged.
        assert!(
            constraint(m, &q).abs() < 1e-12,
            "{}: Newton did not converge",
            m.name
        );
        (q[j], slope(&q))
    }

    #[test]
    fn contact_models_assemble_near_their_guess() {
        // (file, root of the free coordinate): found with an independent Python script (the
        // planar closed form of docs/method.md §7.3 for the paper chain, a separate rotation-
        // matrix implementation for the spatial arm). The driven roots are exact:
        // q3 = -0.15 - f(0.35).
        let cases = [
            ("paper_concave.ron", -0.0774653341948748),
            ("paper_convex.ron", -0.2689938422634498),
            ("paper_convex_text.ron", -0.061469651924050156),
            ("driven_concave.ron", -0.0244375),
            ("driven_convex.ron", -0.2253375),
            ("spatial_arm.ron", 0.014981456113197539),
        ];
        for (file, expected) in cases {
            let (root, slope) = assemble(&load(file));
            // Both sides converge Newton to round-off on O(1) quantities; 1e-12 allows for the
            // different operation order of the two implementations.
            assert!((root - expected).abs() < 1e-12, "{file}: root {root}");
            // |∂h/∂q| ≥ 0.1: the free coordinate moves the marker across the cam, so the
            // partition is well conditioned (the values are ≈ 1 for the paper chain, 0.44
            // for the spatial arm).
            assert!(slope.abs() > 0.1, "{file}: slope {slope}");
        }
    }
}
