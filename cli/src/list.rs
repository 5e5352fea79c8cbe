//! `camchain list`: the built-in models with their coordinates, contacts and defaults.

use super::source::builtin_file;
use super::summary::unit;
use camchain_models as models;
use camchain_runtime::{ModelInfo, SimSettings};
use std::fmt::Write;

/// The listing of every built-in model.
pub fn render() -> String {
    let mut text = String::from(
        "Built-in models (run one with `camchain simulate NAME`, or a .ron file by its path):\n",
    );
    for (name, model) in models::ALL.iter() {
        text.push('\n');
        text.push_str(&describe(name, model.info()));
    }
    text
}

fn describe(name: &str, info: &ModelInfo) -> String {
    let mut text = String::new();
    let _ = writeln!(text, "{name}");
    if !info.description.is_empty() {
        let _ = writeln!(text, "  {}", info.description);
    }
    let coordinates: Vec<String> = info
        .coordinates
        .iter()
        .map(|c| {
            let driven = if c.driven { ", driven" } else { "" };
            format!("{} [{}{driven}]", c.name, unit(c.kind))
        })
        .collect();
    let _ = writeln!(text, "  coordinates: {}", coordinates.join(", "));
    let contacts = if info.contacts.is_empty() {
        "none".to_string()
    } else {
        info.contacts
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let kind = if info.spatial { "spatial" } else { "planar" };
    let _ = writeln!(text, "  contacts:    {contacts} ({kind})");
    let _ = writeln!(text, "  defaults:    {}", defaults(&info.defaults));
    text.push_str(&parameters(name, info));
    let _ = writeln!(
        text,
        "  file:        {} (compiled in; `--numeric` runs it on the reference)",
        builtin_file(name).display()
    );
    text
}

/// The run-time parameters (`--param NAME=VALUE`, `camchain sweep`), and how many the
/// generated code folds.
fn parameters(name: &str, info: &ModelInfo) -> String {
    let mut text = String::new();
    if info.parameters.is_empty() {
        let _ = writeln!(text, "  parameters:  none at run time");
    } else {
        let _ = writeln!(text, "  parameters (--param NAME=VALUE, camchain sweep):");
        for p in &info.parameters {
            let unit = if p.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", p.unit)
            };
            let range = match (p.min, p.max) {
                (Some(a), Some(b)) => format!(" in [{a}, {b}]"),
                (Some(a), None) => format!(" ≥ {a}"),
                (None, Some(b)) => format!(" ≤ {b}"),
                (None, None) => String::new(),
            };
            let _ = writeln!(
                text,
                "    {:<12} {}{unit}{range}  {}",
                p.name, p.default, p.description
            );
        }
    }
    let folded = super::source::builtin_description(name)
        .map(|m| m.parameters.iter().filter(|p| p.constant).count())
        .unwrap_or(0);
    if folded > 0 {
        let _ = writeln!(
            text,
            "    and {folded} folded into the generated code (constant: true; --numeric sets them too)"
        );
    }
    text
}

fn defaults(s: &SimSettings) -> String {
    format!(
        "--t-end {} --dt-out {} --integrator {} --dt {} --rtol {:e} --atol {:e}",
        s.t_end,
        s.dt_out,
        s.integrator.name(),
        s.dt,
        s.rtol,
        s.atol
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_is_listed_with_its_coordinates() {
        let text = render();
        for (name, model) in models::ALL.iter() {
            assert!(text.contains(&format!("\n{name}\n")), "{name}");
            for c in &model.info().coordinates {
                assert!(text.contains(&c.name));
            }
        }
        assert!(text.contains("q1 [rad, driven]"));
        assert!(text.contains("--t-end 10 --dt-out 0.01 --integrator dop853"));
    }
}
