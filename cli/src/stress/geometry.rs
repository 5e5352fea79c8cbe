//! The geometry of the mechanism: re-partitioning through a vanishing Jacobian entry, steep,
//! flat, inflected and wavy profiles, and a cam out of reach.

use super::case::{execute, kind, numeric_case, paper};
use super::tables::{cell, sci, table, verdict};
use super::{Context, Section, failed, say};
use crate::CliError;
use crate::scenarios as stress;
use camchain_reference::NumericModel;
use camchain_runtime::Simulate;
use std::fmt::Write as _;

pub(super) fn repartition(_ctx: &Context) -> Result<Section, CliError> {
    say("near-singular partitioning\n");
    let mut text = String::from(
        "A two-link arm (1 m links) hanging from the origin with its tip on a cam \
         (`cli/scenarios/repartition.ron`; the flat line y = −1.5, and the wavy cam \
         y = −1.5 + 0.2 sin 2x). During the swing the Jacobian entry of the dependent \
         coordinate goes through zero, and the runtime hands the dependent role to the other \
         coordinate. Each integration runs twice: from the automatic partition (q1 \
         dependent) and from the other one (q2 dependent); *vs other start* is the largest \
         |q| difference between the two runs, which follow the same ODE on different charts \
         — a re-partition that lost or corrupted the state would show as a jump there. \
         *max |q − q_ref|* is against the automatic run at rtol 1e-12.\n\n",
    );
    let flat = stress::scenario(stress::REPARTITION, "repartition.ron").map_err(failed)?;
    let wavy = stress::with_profile(flat.clone(), 0, "-1.5 + 0.2*(2.0*x).sin()").map_err(failed)?;
    let mut verdicts = String::new();
    for (title, model) in [
        ("flat cam y = −1.5", flat),
        ("wavy cam y = −1.5 + 0.2 sin 2x", wavy),
    ] {
        let sweep = stress::sweep(6.0, 0.01, &[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10]);
        let case = numeric_case(title, model, sweep, true)?;
        let result = execute(&case);
        let mut other_state = case.state.clone();
        let other_dependent: Vec<usize> = case.state.independent().to_vec();
        other_state
            .set_dependent(&other_dependent[..1])
            .map_err(|e| failed(e.to_string()))?;
        let _ = writeln!(text, "**{}**\n", result.title);
        let _ = writeln!(
            text,
            "| integration | outcome | steps | re-partitions | re-partitions (other start) \
             | vs other start | max \\|h\\| [m] | energy drift [J] | max \\|q − q_ref\\| |"
        );
        let _ = writeln!(text, "|---|---|---|---|---|---|---|---|---|");
        for (record, integration) in result.records.iter().zip(&case.integrations) {
            let other = stress::run(case.subject.dynamics(), &other_state, integration);
            let outcome = match (&record.error, &other.error) {
                (None, None) => "ok".to_string(),
                (Some(e), _) | (None, Some(e)) => {
                    format!("**{}**: {}", kind(e), cell(&e.to_string()))
                }
            };
            let reference = result
                .reference
                .as_ref()
                .map_or(f64::NAN, |r| record.difference(r));
            let _ = writeln!(
                text,
                "| {} | {outcome} | {} | {} | {} | {} | {} | {} | {} |",
                record.label,
                record.stats().steps,
                record.stats().repartitions,
                other.stats().repartitions,
                sci(record.difference(&other.trajectory)),
                sci(record.max_h()),
                sci(record.energy_drift()),
                sci(reference),
            );
        }
        text.push('\n');
        verdicts.push_str(&verdict(&result));
    }
    Ok(Section {
        heading: "Near-singular partitioning".into(),
        text: format!("{verdicts}\n{text}"),
    })
}

pub(super) fn profiles(_ctx: &Context) -> Result<Section, CliError> {
    say("profiles\n");
    let mut text = String::from(
        "`paper_concave` without dampers on other cams through the tip's starting point \
         (x0, y0) = (0.2879, −0.1179) m, 10 s: flat (f′ = f″ = 0), steep (slope 5 and 50: \
         the cam's normal nearly horizontal), an inflection point (a tanh step whose \
         curvature changes sign 0.25 m left of the start) and a wavy cam whose slope changes \
         sign every 0.1 m (curvature up to 20 m⁻¹). *max |q − q_ref|* is against rtol \
         1e-12.\n\n",
    );
    let nominal = NumericModel::new(paper("paper_concave")?);
    let state = stress::assemble(&nominal).map_err(failed)?;
    let start = nominal
        .sample(&state)
        .map_err(|e| failed(e.to_string()))?
        .contacts
        .first()
        .copied()
        .unwrap_or_default();
    let mut verdicts = String::new();
    for (name, profile) in stress::profile_variants(start.x, start.y) {
        let model = stress::with_profile(
            stress::without_dampers(paper("paper_concave")?),
            0,
            &profile,
        )
        .map_err(failed)?;
        let sweep = stress::sweep(10.0, 0.01, &[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10]);
        let mut result = execute(&numeric_case(name, model, sweep, true)?);
        verdicts.push_str(&verdict(&result));
        result.title = format!("{name}: `y = {profile}`");
        text.push_str(&table(&result));
    }
    Ok(Section {
        heading: "Steep, flat, inflected and wavy profiles".into(),
        text: format!("{verdicts}\n{text}"),
    })
}

pub(super) fn unreachable(_ctx: &Context) -> Result<Section, CliError> {
    say("unreachable cam\n");
    let mut text = String::from(
        "`cli/scenarios/unreachable.ron`: a two-link arm whose first joint is driven, \
         q1 = −π/2 + t, lifting the elbow; at t = π/3 s (1.0472 s) the arm is stretched (a \
         dead point: the tip is on the cam but no joint can move it across the cam) and beyond \
         it the tip cannot reach the flat cam. Every integrator stops there, with the state, \
         and the samples up to it are kept: where Dormand–Prince approaches the limit with \
         ever shorter steps (the velocity needed to stay on the cam grows without bound as the \
         arm straightens) it stops at the dead point (`SingularConstraint`, \"the mechanism \
         locks at a dead point\"); where a step lands beyond it, as RK4's do, Newton cannot \
         bring |h| down (`NewtonFailed`, \"the contact point cannot reach the cam\").\n\n",
    );
    let model = stress::scenario(stress::UNREACHABLE, "unreachable.ron").map_err(failed)?;
    let sweep = stress::sweep(2.0, 0.01, &[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10]);
    let result = execute(&numeric_case("unreachable", model, sweep, false)?);
    text.push_str(&table(&result));
    Ok(Section {
        heading: "A cam out of reach".into(),
        text: format!("{}\n{text}", verdict(&result)),
    })
}
