//! The initial state: coordinate values and rates by name, which coordinates are held, and
//! which were given.

use super::fields::{lookup, unknown};
use super::{Checked, Context};
use crate::model::{Body, Field, Initial};
use crate::schema::raw;
use std::collections::HashMap;

pub(super) fn initial(file: &raw::Initial, bodies: &[Body], cx: &Context) -> Checked<Initial> {
    let at = cx.at;
    let by_name: HashMap<&str, usize> = bodies
        .iter()
        .enumerate()
        .map(|(i, b)| (b.joint.coordinate.as_str(), i))
        .collect();
    let (q, given_q) = coordinate_values(cx, "initial.q", &file.q, &by_name, Field::InitialQ)?;
    let (qd, given_qd) = coordinate_values(cx, "initial.qd", &file.qd, &by_name, Field::InitialQd)?;
    let mut hold: Vec<bool> = bodies
        .iter()
        .map(|b| b.joint.prescribed.is_some())
        .collect();
    let mut listed = vec![false; bodies.len()];
    for (k, name) in file.hold.iter().enumerate() {
        let field = format!("initial.hold[{k}]");
        let i = lookup(at, &field, &by_name, name, "coordinate")?;
        if std::mem::replace(&mut listed[i], true) {
            return Err(at.error(&field, format!("coordinate `{name}` is listed twice")));
        }
        hold[i] = true;
    }
    Ok(Initial {
        q,
        qd,
        hold,
        given_q,
        given_qd,
    })
}

/// `{"name": value}` → a value per coordinate in body order, 0 where absent, and which
/// were given.
pub(super) fn coordinate_values(
    cx: &Context,
    path: &str,
    values: &raw::NamedValues,
    index: &HashMap<&str, usize>,
    key: fn(usize) -> Field,
) -> Checked<(Vec<f64>, Vec<bool>)> {
    let at = cx.at;
    let mut out = vec![0.0; index.len()];
    let mut given = vec![false; index.len()];
    for (k, (name, value)) in values.0.iter().enumerate() {
        let field = format!("{path}[{name:?}]");
        // Located by position, so a repeated key points at its second occurrence.
        let entry = format!("{path}[{k}]");
        let i = index
            .get(name.as_str())
            .copied()
            .ok_or_else(|| at.error_located(&field, &entry, unknown(index, name, "coordinate")))?;
        if std::mem::replace(&mut given[i], true) {
            let message = format!("coordinate `{name}` is given twice");
            return Err(at.error_located(&field, &entry, message));
        }
        out[i] = match value {
            raw::Number::Value(v) if !v.is_finite() => {
                let message = format!("must be finite, got {v}");
                return Err(at.error_located(&field, &entry, message));
            }
            raw::Number::Value(v) => *v,
            expr => cx.number(&entry, expr, Some(key(i)))?,
        };
    }
    Ok((out, given))
}
