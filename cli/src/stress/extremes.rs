//! Extreme parameters: stiff springs, tiny and large masses and inertias, fast motion.

use super::case::{REFERENCE_RTOL, execute, numeric_case, paper};
use super::charts::{line_panel, log_points, series};
use super::tables::{table, verdict};
use super::{Context, Section, failed, say};
use crate::CliError;
use crate::plots::{Figure, Row};
use crate::scenarios::{self as stress, Integration};
use camchain_codegen::model::Model;
use camchain_reference::NumericModel;
use camchain_runtime::IntegratorKind;

/// Window over which the stiff-spring figure averages the step size (s).
pub(super) const STEP_WINDOW: f64 = 0.05;

pub(super) fn stiff_springs(ctx: &Context) -> Result<Section, CliError> {
    say("stiff springs\n");
    let t_end = 2.0;
    let sweep = stress::sweep(t_end, 0.01, &[1e-2, 1e-3, 1e-4], &[1e-6, 1e-8, 1e-10]);
    let mut text = String::from(
        "`paper_concave` with every spring stiffness multiplied by 100 and by 10 000 (dampers \
         as in the paper), 2 s. The stiffened springs add fast modes whose frequency sets \
         the stability limit of the explicit integrators. RK4 beyond it diverges: the \
         state grows by orders of magnitude per step until a computed quantity overflows, and \
         the run stops with `NonFinite` (time, state, and a note that the integration \
         diverged). Dormand–Prince has no stability problem to report: its error control \
         keeps the step inside the stability region (the step-size collapse shows in the \
         figure and in the step counts) and it completes at any tolerance — it is the choice \
         that handles stiff springs, at the price of many steps (there is no implicit \
         integrator). *max |q − q_ref|* is against Dormand–Prince at rtol 1e-12.\n\n",
    );
    let mut verdicts = String::new();
    let mut step_series = Vec::new();
    for (i, factor) in [1.0, 100.0, 1e4].into_iter().enumerate() {
        let model = stress::stiffer(paper("paper_concave")?, factor);
        if factor > 1.0 {
            let case = numeric_case(
                &format!("paper_concave, springs × {factor}"),
                model.clone(),
                sweep.clone(),
                true,
            )?;
            let result = execute(&case);
            text.push_str(&table(&result));
            verdicts.push_str(&verdict(&result));
        }
        let numeric = NumericModel::new(model);
        let state = stress::assemble(&numeric).map_err(failed)?;
        for (j, rtol) in [1e-6, 1e-10].into_iter().enumerate() {
            let settings = stress::adaptive(IntegratorKind::Dopri5, t_end, STEP_WINDOW, rtol);
            let (history, _) = stress::step_history(&numeric, state.clone(), &settings);
            let points = log_points(history.iter().map(|&(t, h, _)| (t, h)));
            step_series.push(series(
                &format!("k × {factor}, dopri5 rtol={}", stress::short(rtol)),
                2 * i + j,
                points,
            ));
        }
    }
    let figure = Figure {
        title: "paper_concave with stiff springs: Dormand–Prince step size".into(),
        width: 1200,
        rows: vec![Row {
            height: 480,
            panels: vec![line_panel(
                "mean accepted step in each 50 ms window (steps land on the window ends)",
                "log10 step [s]",
                step_series,
            )],
        }],
    };
    text.push_str(&ctx.figure(
        &figure,
        "stiff_step_size",
        "Dormand–Prince step size against time for the nominal springs and springs × 100 and × 10 000",
    )?);
    Ok(Section {
        heading: "Stiff springs".into(),
        text: format!("{verdicts}\n{text}"),
    })
}

pub(super) fn masses(_ctx: &Context) -> Result<Section, CliError> {
    say("masses and inertias\n");
    let sweep = stress::sweep(10.0, 0.01, &[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10]);
    let mut text = String::from(
        "`paper_concave`, 10 s. *all × s*: every mass, inertia, spring and damper multiplied \
         by s; every term of M q̈ + F + Q scales by s, so the motion is exactly the nominal \
         one (*max |q − q_ref|* is against the **nominal** model at rtol 1e-12: it is the \
         integration error plus round-off, independent of s). *body k × s*: one body's mass \
         and inertia only, which makes the mass matrix ill-conditioned; a very light tip \
         body on its spring is a fast (stiff) mode.\n\n",
    );
    let nominal = NumericModel::new(paper("paper_concave")?);
    let nominal_state = stress::assemble(&nominal).map_err(failed)?;
    let reference = stress::run(
        &nominal,
        &nominal_state,
        &Integration {
            label: "reference".into(),
            settings: stress::adaptive(IntegratorKind::Dopri5, 10.0, 0.01, REFERENCE_RTOL),
        },
    )
    .trajectory;
    let mut verdicts = String::new();
    let variants: Vec<(String, Model, bool)> = vec![
        (
            "all × 1e-4".into(),
            stress::scaled(paper("paper_concave")?, 1e-4),
            true,
        ),
        (
            "all × 1e4".into(),
            stress::scaled(paper("paper_concave")?, 1e4),
            true,
        ),
        (
            "body 4 × 1e-4".into(),
            stress::heavier(paper("paper_concave")?, 1e-4, |i| i == 3),
            false,
        ),
        (
            "body 4 × 1e4".into(),
            stress::heavier(paper("paper_concave")?, 1e4, |i| i == 3),
            false,
        ),
        (
            "body 1 × 1e4, body 2 × 1e-4".into(),
            stress::heavier(
                stress::heavier(paper("paper_concave")?, 1e4, |i| i == 0),
                1e-4,
                |i| i == 1,
            ),
            false,
        ),
    ];
    for (label, model, invariant) in variants {
        let case = numeric_case(
            &format!("paper_concave, {label}"),
            model,
            sweep.clone(),
            !invariant,
        )?;
        let mut result = execute(&case);
        if invariant {
            result.reference = Some(reference.clone());
        }
        text.push_str(&table(&result));
        verdicts.push_str(&verdict(&result));
    }
    Ok(Section {
        heading: "Tiny and large masses and inertias".into(),
        text: format!("{verdicts}\n{text}"),
    })
}

pub(super) fn fast_motion(_ctx: &Context) -> Result<Section, CliError> {
    say("fast motion\n");
    let mut text = String::from(
        "*free swing*: `paper_concave` released with q̇1(0) = 5.5 rad/s, ten times the largest \
         speed of the nominal swing (0.55 rad/s), 10 s, dampers on (the energy balance \
         includes the dissipated energy). *driven*: `driven_concave` with its drive ten times \
         faster, q1(t) = −π/2 + 0.45 sin(2π·10 t/4) (velocities × 10, accelerations × 100), \
         8 s.\n\n",
    );
    let mut verdicts = String::new();
    let free = stress::with_velocity(paper("paper_concave")?, "q1", 5.5).map_err(failed)?;
    let driven = stress::with_drive(
        paper("driven_concave")?,
        "q1",
        "-PI/2 + 0.45*(2.0*PI*10.0*t/4.0).sin()",
    )
    .map_err(failed)?;
    for (title, model, t_end) in [
        ("paper_concave, q̇1(0) = 5.5 rad/s", free, 10.0),
        ("driven_concave, drive × 10 faster", driven, 8.0),
    ] {
        let sweep = stress::sweep(t_end, 0.01, &[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10]);
        let result = execute(&numeric_case(title, model, sweep, true)?);
        text.push_str(&table(&result));
        verdicts.push_str(&verdict(&result));
    }
    Ok(Section {
        heading: "Fast motion".into(),
        text: format!("{verdicts}\n{text}"),
    })
}
