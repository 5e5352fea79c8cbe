//! Non-finite values: a profile undefined on part of the cam, and NaN or infinity put into
//! the state.

use super::case::{execute, kind, numeric_case, paper};
use super::tables::{cell, table, verdict};
use super::{Context, Section, failed, say};
use crate::CliError;
use crate::scenarios as stress;
use camchain_reference::NumericModel;
use camchain_runtime::{IntegratorKind, Simulate};
use std::fmt::Write as _;

pub(super) fn non_finite(_ctx: &Context) -> Result<Section, CliError> {
    say("non-finite values\n");
    let mut text = String::from(
        "*A profile undefined for x < 0*: `paper_convex` whose profile has `+ 0.0*x.sqrt()` \
         added (the same cam for x ≥ 0, NaN beyond); the tip slides left and reaches x = 0 \
         near t = 0.39 s. Every integrator stops with `NonFinite` naming h, with the time and \
         the state, and keeps the samples computed so far.\n\n",
    );
    let convex = paper("paper_convex")?;
    let source = convex
        .contacts
        .first()
        .and_then(|c| match &c.profile {
            camchain_codegen::model::Profile::Explicit { source, .. } => {
                Some(format!("{source} + 0.0*x.sqrt()"))
            }
            _ => None,
        })
        .unwrap_or_default();
    let model = stress::with_profile(convex.clone(), 0, &source).map_err(failed)?;
    let sweep = stress::sweep(1.0, 0.01, &[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10]);
    let result = execute(&numeric_case(
        "paper_convex, profile + 0·√x",
        model,
        sweep,
        false,
    )?);
    text.push_str(&table(&result));
    let mut verdicts = verdict(&result);
    text.push_str(
        "*NaN or ∞ put into the state* through its public fields (`State::q`, `State::qd`) \
         before `simulate` (dopri5, rtol 1e-8):\n\n| change | error |\n|---|---|\n",
    );
    let numeric = NumericModel::new(convex);
    let state = stress::assemble(&numeric).map_err(failed)?;
    let settings = stress::adaptive(IntegratorKind::Dopri5, 1.0, 0.01, 1e-8);
    for (label, q, qd, value) in [
        ("q̇1 = NaN", None, Some(0), f64::NAN),
        ("q1 = +∞", Some(0), None, f64::INFINITY),
        ("q3 (dependent) = NaN", Some(2), None, f64::NAN),
    ] {
        let mut bad = state.clone();
        if let Some(i) = q {
            bad.q[i] = value;
        }
        if let Some(i) = qd {
            bad.qd[i] = value;
        }
        let outcome = match numeric.simulate(bad, &settings) {
            Ok(_) => "ok (not detected)".to_string(),
            Err(failure) => format!(
                "**{}**: {} ({} kept)",
                kind(&failure.error),
                cell(&failure.error.to_string()),
                crate::counted(failure.partial.samples.len(), "sample")
            ),
        };
        let _ = writeln!(text, "| {label} | {outcome} |");
        if outcome.starts_with("ok") {
            verdicts.push_str(&format!("- {label} in the state is not detected.\n"));
        }
    }
    text.push('\n');
    Ok(Section {
        heading: "NaN and infinity".into(),
        text: format!("{verdicts}\n{text}"),
    })
}
