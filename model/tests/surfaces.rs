//! Cam surfaces in a model file: what is accepted, and every misuse refused at the field it
//! concerns (file, line, column and field named).

use camchain_model::model::Profile;
use camchain_model::schema::parse_model;
use std::path::Path;

/// A particle on three slides and a surface under it; each line of interest stands alone.
const BASE: &str = r#"(
    name: "surface_test",
    gravity: (0.0, 0.0, -9.81),
    parameters: [(name: "c", value: 2.0, unit: "1/m")],
    bodies: [
        (name: "sx", parent: "ground", mass: 1e-9, inertia: Izz(1e-9),
         joint: (kind: Prismatic, axis: (1.0, 0.0, 0.0), coordinate: "x")),
        (name: "sy", parent: "sx", mass: 1e-9, inertia: Izz(1e-9),
         joint: (kind: Prismatic, axis: (0.0, 1.0, 0.0), coordinate: "y")),
        (name: "p", parent: "sy", mass: 1.0, inertia: Izz(1e-9),
         joint: (kind: Prismatic, axis: (0.0, 0.0, 1.0), coordinate: "z")),
    ],
    markers: [(name: "tip", body: "p", position: (0.0, 0.0, 0.0))],
    contacts: [(
        marker: "tip",
        surface: "c*(x*x + y*y) + 0.1*(x*y).sin()",
    )],
    initial: (q: {"x": 0.1}, hold: ["x", "y"]),
)
"#;

fn edited(old: &str, new: &str) -> String {
    assert_eq!(BASE.matches(old).count(), 1, "{old:?} must occur once");
    BASE.replace(old, new)
}

fn rejected(source: &str, field: &str, line: usize, text: &str) -> camchain_model::ModelError {
    match parse_model(source, Path::new("models/surface.ron")) {
        Ok(m) => panic!("should be rejected, parsed {}", m.name),
        Err(e) => {
            assert_eq!(e.field, field, "{e}");
            assert_eq!(e.line, line, "{e}");
            assert!(e.message.contains(text), "{e} lacks {text:?}");
            assert!(e.to_string().starts_with("models/surface.ron:"), "{e}");
            e
        }
    }
}

#[test]
fn a_surface_parses_as_a_function_of_x_and_y() {
    let model = parse_model(BASE, Path::new("models/surface.ron")).expect("parses");
    let contact = &model.contacts[0];
    let Profile::Surface { f, source } = &contact.profile else {
        panic!("a surface: {:?}", contact.profile)
    };
    assert_eq!(source, "c*(x*x + y*y) + 0.1*(x*y).sin()");
    // Evaluated at (x, y) = (0.3, -0.2) with c = 2: 2·0.13 + 0.1 sin(−0.06).
    let expected = 2.0 * 0.13 + 0.1 * (-0.06f64).sin();
    assert!((f.eval_at(&[0.3, -0.2]) - expected).abs() < 1e-15);
    assert!(contact.profile.is_surface());
    assert_eq!(contact.range, None);
}

#[test]
fn a_surface_expression_names_only_x_y_and_parameters() {
    let e = rejected(
        &edited("0.1*(x*y).sin()", "0.1*(x*z).sin()"),
        "contacts[0].surface",
        16,
        "unknown name `z`: the variables allowed here are `x` and `y`",
    );
    // `z` is byte 23 of the expression, whose quote is at column 18.
    assert_eq!(e.column, 18 + 1 + 23);
}

#[test]
fn a_surface_takes_a_point_or_a_ball_only() {
    for follower in [
        "Flat(normal: (0.0, 0.0, 1.0))",
        "Mushroom(radius: 0.05, normal: (0.0, 0.0, -1.0))",
    ] {
        rejected(
            &edited(
                "marker: \"tip\",\n",
                &format!("marker: \"tip\", follower: {follower},\n"),
            ),
            "contacts[0].follower",
            15,
            "a surface takes a point (`follower: Knife`) or a ball",
        );
    }
}

#[test]
fn a_surface_has_no_range_and_no_second_profile() {
    rejected(
        &edited(
            "marker: \"tip\",\n",
            "marker: \"tip\", range: (0.0, 1.0),\n",
        ),
        "contacts[0].range",
        15,
        "a surface has no `range`",
    );
    rejected(
        &edited("marker: \"tip\",\n", "marker: \"tip\", profile: \"x*x\",\n"),
        "contacts[0].surface",
        16,
        "give only one of",
    );
}

/// BASE with its surface replaced by a barrel cam.
fn barrel(fields: &str) -> String {
    edited(
        "surface: \"c*(x*x + y*y) + 0.1*(x*y).sin()\",",
        &format!("barrel: ({fields}),"),
    )
}

#[test]
fn a_barrel_groove_parses_and_closes_round_the_cylinder() {
    let source = barrel("radius: 0.06, groove: \"0.01*theta.sin()\"");
    let model = parse_model(&source, Path::new("models/surface.ron")).expect("parses");
    let Profile::Barrel { f, radius, .. } = &model.contacts[0].profile else {
        panic!("a barrel: {:?}", model.contacts[0].profile)
    };
    assert_eq!(*radius, 0.06);
    assert!((f.eval(1.0) - 0.01 * 1.0f64.sin()).abs() < 1e-17);
    // 0.01 θ grows round the cylinder: refused at the groove's text.
    rejected(
        &barrel("radius: 0.06, groove: \"0.01*theta\""),
        "contacts[0].barrel.groove",
        16,
        "must close round the cylinder",
    );
}

#[test]
fn a_barrel_designed_from_a_law_is_its_base_plus_the_law() {
    let source = barrel(
        "radius: 0.06, law: (base: 0.02, segments: [Dwell(degrees: 60), Rise(law: Cycloidal, \
         lift: 0.03, degrees: 120), Dwell(degrees: 60), Return(law: Cycloidal, degrees: 120)])",
    );
    let model = parse_model(&source, Path::new("models/surface.ron")).expect("parses");
    let f = model.contacts[0].profile_expression();
    // Counterclockwise: the follower at the cam frame's angle θ = −φ reads the law at φ: in
    // the dwell after the rise (φ = 200°) the groove is at base + lift; in the first dwell
    // (φ = 30°) at base.
    assert!((f.eval(-200f64.to_radians()) - 0.05).abs() < 1e-15);
    assert!((f.eval(-30f64.to_radians()) - 0.02).abs() < 1e-15);
    // The middle of the rise (φ = 120°): base + lift/2 (the cycloid's midpoint).
    assert!((f.eval(-120f64.to_radians()) - 0.035).abs() < 1e-15);
}

#[test]
fn a_barrel_needs_a_radius_a_groove_and_a_roller() {
    rejected(
        &barrel("radius: -0.06, groove: \"0.01*theta.sin()\""),
        "contacts[0].barrel.radius",
        16,
        "pitch radius",
    );
    rejected(
        &barrel("radius: 0.06"),
        "contacts[0].barrel",
        16,
        "needs its groove",
    );
    rejected(
        &barrel(
            "radius: 0.06, groove: \"0.01*theta.sin()\", law: (segments: [Dwell(degrees: 360)])",
        ),
        "contacts[0].barrel.law",
        16,
        "not both",
    );
    rejected(
        &edited(
            "marker: \"tip\",\n",
            "marker: \"tip\", follower: Flat(normal: (0.0, 0.0, 1.0)),\n",
        )
        .replace(
            "surface: \"c*(x*x + y*y) + 0.1*(x*y).sin()\",",
            "barrel: (radius: 0.06, groove: \"0.01*theta.sin()\"),",
        ),
        "contacts[0].follower",
        15,
        "cannot run in a barrel cam's groove",
    );
}

#[test]
fn a_surface_of_revolution_is_a_function_of_z_followed_by_a_point_or_a_ball() {
    let source = edited(
        "surface: \"c*(x*x + y*y) + 0.1*(x*y).sin()\",",
        "revolution: \"(0.25 - z*z).sqrt()\",",
    );
    let model = parse_model(&source, Path::new("models/surface.ron")).expect("parses");
    let Profile::Revolution { g, .. } = &model.contacts[0].profile else {
        panic!("a surface of revolution: {:?}", model.contacts[0].profile)
    };
    assert!((g.eval(0.3) - 0.4).abs() < 1e-15);
    rejected(
        &source.replace("(0.25 - z*z).sqrt()", "(0.25 - x*x).sqrt()"),
        "contacts[0].revolution",
        16,
        "the only variable allowed here is `z`",
    );
    // A ball needs the heights its contact point may take; a flat face is refused.
    rejected(
        &source.replace(
            "marker: \"tip\",\n",
            "marker: \"tip\", follower: Roller(radius: 0.01),\n",
        ),
        "contacts[0].marker",
        15,
        "a roller on a surface of revolution (the heights z its contact point may take) needs \
         `range: (from, to)`",
    );
    let ball = source.replace(
        "marker: \"tip\",\n",
        "marker: \"tip\", follower: Roller(radius: 0.01), range: (-0.4, 0.4),\n",
    );
    parse_model(&ball, Path::new("models/surface.ron")).expect("a ball with its range");
    rejected(
        &source.replace(
            "marker: \"tip\",\n",
            "marker: \"tip\", follower: Flat(normal: (1.0, 0.0, 0.0)),\n",
        ),
        "contacts[0].follower",
        15,
        "a flat face cannot follow a surface of revolution",
    );
}

#[test]
fn a_barrel_groove_must_lie_on_its_cylinder() {
    let law = "law: (base: 0.02, segments: [Dwell(degrees: 60), Rise(law: Cycloidal, lift: 0.03, \
               degrees: 120), Dwell(degrees: 60), Return(law: Cycloidal, degrees: 120)])";
    let roller = |source: String| {
        source.replace(
            "marker: \"tip\",\n",
            "marker: \"tip\", follower: Roller(radius: 0.01),\n",
        )
    };
    // Flanks from z = 0.01 to 0.06: a 0.06 m cylinder holds them, a 0.055 m one does not.
    let fits = roller(barrel(&format!("radius: 0.06, length: 0.06, {law}")));
    parse_model(&fits, Path::new("models/surface.ron")).expect("the groove fits");
    let e = rejected(
        &roller(barrel(&format!("radius: 0.06, length: 0.055, {law}"))),
        "contacts[0].barrel.length",
        16,
        "the groove leaves the cylinder: its upper flank reaches z = 0.06",
    );
    assert!(e.message.contains("0.055 m long"), "{e}");
}

#[test]
fn a_surface_is_checked_over_its_region_before_running() {
    let with_region = |surface: &str, region: &str| {
        edited(
            "surface: \"c*(x*x + y*y) + 0.1*(x*y).sin()\",",
            &format!("surface: \"{surface}\", region: {region},"),
        )
    };
    let fine = with_region("c*(x*x + y*y)", "((-0.2, 0.2), (-0.3, 0.3))");
    parse_model(&fine, Path::new("models/surface.ron")).expect("defined over its region");
    // ln(1 − x) is −∞ at x = 1 (a grid point: 33 points over [0, 2]) and NaN beyond: refused
    // at the surface, naming the first point.
    let e = rejected(
        &with_region("c*y*y + (1.0 - x).ln()", "((0.0, 2.0), (-0.1, 0.1))"),
        "contacts[0].surface",
        16,
        "the surface is not defined over its region: f = -inf at (x, y) = (1, -0.1)",
    );
    assert!(e.message.contains("x ∈ [0, 2]"), "{e}");
    // √ has an infinite slope where its argument vanishes: the derivatives are checked too.
    rejected(
        &with_region("(x + 0.5).sqrt()", "((-0.5, 0.5), (-0.1, 0.1))"),
        "contacts[0].surface",
        16,
        "∂f/∂x = inf",
    );
    rejected(
        &with_region("c*x*x", "((0.2, -0.2), (-0.1, 0.1))"),
        "contacts[0].region",
        16,
        "must be increasing",
    );
    rejected(
        &barrel("radius: 0.06, groove: \"0.01*theta.sin()\"").replace(
            "marker: \"tip\",\n",
            "marker: \"tip\", region: ((0.0, 1.0), (0.0, 1.0)),\n",
        ),
        "contacts[0].region",
        15,
        "only a surface",
    );
}

/// BASE with its surface given as the grid table `grid.csv`, embedded as `csv`.
fn grid_model(csv: &str, ends: &str) -> Result<camchain_model::Model, camchain_model::ModelError> {
    use camchain_model::model::ParameterMode;
    use camchain_model::schema::{Files, parse_model_from};
    let source = edited(
        r#"surface: "c*(x*x + y*y) + 0.1*(x*y).sin()","#,
        &format!(r#"table: (form: Surface, file: "grid.csv"{ends}),"#),
    );
    let files = [("grid.csv", csv)];
    parse_model_from(
        &source,
        Path::new("models/surface.ron"),
        &[],
        ParameterMode::AsDeclared,
        Files::Embedded(&files),
    )
}

/// x, y, z rows of z = x² − x y + 3 y on nx × ny knots, in the order given by `order`.
fn grid_rows(nx: usize, ny: usize, order: impl Fn(usize, usize) -> (usize, usize)) -> String {
    let mut text = String::from("x, y, z\n");
    for a in 0..nx {
        for b in 0..ny {
            let (i, j) = order(a, b);
            let (x, y) = (0.1 * i as f64 - 0.2, 0.05 * j as f64);
            text.push_str(&format!("{x}, {y}, {}\n", x * x - x * y + 3.0 * y));
        }
    }
    text
}

#[test]
fn a_grid_table_is_a_surface_whatever_the_order_of_its_rows() {
    // The same 5 × 4 grid written row by row and column by column (reversed): the two
    // surfaces agree at every point, and interpolate the grid's values at its knots.
    let by_rows = grid_model(&grid_rows(5, 4, |a, b| (a, b)), "").expect("a grid");
    let by_columns = grid_model(&grid_rows(4, 5, |a, b| (4 - b, 3 - a)), "").expect("a grid");
    let f = |m: &camchain_model::Model| match &m.contacts[0].profile {
        Profile::Surface { f, source } => {
            assert!(source.contains("5 × 4 grid of grid.csv"), "{source}");
            f.clone()
        }
        other => panic!("{other:?}"),
    };
    let (a, b) = (f(&by_rows), f(&by_columns));
    for (x, y) in [
        (-0.2, 0.0),
        (0.0, 0.1),
        (0.13, 0.07),
        (0.2, 0.15),
        (-0.05, 0.12),
    ] {
        let (u, v) = (a.eval_at(&[x, y]), b.eval_at(&[x, y]));
        // The same spline from the same numbers: equal to rounding.
        assert!((u - v).abs() < 1e-15, "({x}, {y}): {u} against {v}");
    }
    // At the knots the surface takes the grid's values (the spline interpolates).
    let (x, y) = (0.1 * 3.0 - 0.2, 0.05 * 2.0);
    assert!((a.eval_at(&[x, y]) - (x * x - x * y + 3.0 * y)).abs() < 1e-15);
}

#[test]
fn a_grid_table_refuses_its_misuses_where_they_are() {
    // A grid needs a file, and no more than 250 000 points (the generated code keeps each).
    let error = grid_model(&grid_rows(501, 500, |a, b| (a, b)), "").expect_err("too large");
    assert_eq!(
        (error.line, error.field.as_str()),
        (250_002, "contacts[0].table.file")
    );
    assert!(
        error
            .message
            .contains("more than the 250000 a table may hold"),
        "{error}"
    );
    // `y_ends` belongs to surfaces only; `degrees` to polar tables only.
    let source = edited(
        r#"surface: "c*(x*x + y*y) + 0.1*(x*y).sin()","#,
        r#"table: (form: Explicit, points: [(0.0, 0.0), (1.0, 1.0)], y_ends: Natural),"#,
    );
    rejected(
        &source,
        "contacts[0].table.y_ends",
        16,
        "only a surface's table",
    );
    let error =
        grid_model(&grid_rows(3, 3, |a, b| (a, b)), ", degrees: true").expect_err("degrees");
    assert_eq!(error.field, "contacts[0].table.degrees");
    // Too few knots along y for a periodic axis (4 at least).
    let error = grid_model(&grid_rows(4, 3, |a, b| (a, b)), ", y_ends: Periodic").expect_err("few");
    assert!(error.message.contains("the y knots"), "{error}");
}

#[test]
fn a_tapered_groove_takes_a_roller_of_constant_size() {
    // A roller of 10 mm at the pitch radius 60 mm: half-angle atan(1/6).
    let with_roller = |radius: &str| {
        edited(
            "marker: \"tip\",\n",
            &format!("marker: \"tip\", follower: Roller(radius: {radius}),\n"),
        )
        .replace(
            "surface: \"c*(x*x + y*y) + 0.1*(x*y).sin()\",",
            "barrel: (radius: 0.06, groove: \"0.01*theta.sin()\", tapered: true),",
        )
    };
    let model = parse_model(&with_roller("0.01"), Path::new("models/surface.ron")).expect("parses");
    assert_eq!(model.contacts[0].taper, (0.01f64 / 0.06).atan());
    // A knife edge has no cone; a roller read at run time would change the half-angle the
    // generated code keeps.
    rejected(
        &barrel("radius: 0.06, groove: \"0.01*theta.sin()\", tapered: true"),
        "contacts[0].barrel.tapered",
        16,
        "a tapered groove takes a roller",
    );
    rejected(
        &with_roller("\"c/200.0\""),
        "contacts[0].follower.radius",
        15,
        "half-angle atan(ρ/R) is fixed",
    );
}
