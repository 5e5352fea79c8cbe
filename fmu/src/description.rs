//! `modelDescription.xml` (FMI 3.0, Co-Simulation) of a model, and its instantiation token.
//!
//! Written from the model's description by the same [`variables`] the library serves, so the
//! two cannot disagree; the token is a hash of what the XML declares, which the library
//! recomputes from its own model when it is instantiated and compares.

use crate::variables::{Role, Variable, variables};
use camchain_runtime::{Dynamics, IntegratorKind};
use std::collections::BTreeSet;
use std::fmt::Write;

/// The FMI version written and accepted.
pub const FMI_VERSION: &str = "3.0";

/// The instantiation token of a model's FMU: `{camchain-<64-bit FNV-1a of the package
/// version, the model's name and every variable's name, role and start>}`.
pub fn token(model: &dyn Dynamics) -> String {
    let info = model.info();
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for &b in bytes {
            hash ^= u64::from(b);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
        hash ^= 0xff;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    };
    feed(env!("CARGO_PKG_VERSION").as_bytes());
    feed(info.name.as_bytes());
    for v in variables(model) {
        feed(v.name.as_bytes());
        feed(format!("{:?}{:?}", v.role, v.start.map(f64::to_bits)).as_bytes());
    }
    format!("{{camchain-{hash:016x}}}")
}

/// Text for an XML attribute's value (quotes, angle brackets, ampersands and control
/// characters escaped).
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "&#x{:x};", c as u32);
            }
            c => out.push(c),
        }
    }
    out
}

/// A number as XML Schema's `xs:double` reads it back exactly.
fn number(x: f64) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else if x.is_nan() {
        "NaN".into()
    } else if x > 0.0 {
        "INF".into()
    } else {
        "-INF".into()
    }
}

/// The SI base-unit exponents of the units the outputs use (`kg m s rad`), for
/// `UnitDefinitions`; a parameter's unit not among them is declared by name only.
fn base_unit(name: &str) -> Option<&'static str> {
    Some(match name {
        "s" => r#"s="1""#,
        "m" => r#"m="1""#,
        "m/s" => r#"m="1" s="-1""#,
        "rad" => r#"rad="1""#,
        "rad/s" => r#"s="-1" rad="1""#,
        "N" => r#"kg="1" m="1" s="-2""#,
        "N.m" => r#"kg="1" m="2" s="-2""#,
        "J" => r#"kg="1" m="2" s="-2""#,
        _ => return None,
    })
}

/// The `<Enumeration …/>` of the integrator, its type declared in `TypeDefinitions`.
fn integrator_element(v: &Variable) -> String {
    format!(
        r#"    <Enumeration name="{}" valueReference="{}" causality="parameter" variability="fixed" declaredType="Integrator" description="{}" start="{}"/>"#,
        escape(&v.name),
        v.reference,
        escape(&v.description),
        v.start.unwrap_or(1.0) as i64
    ) + "\n"
}

/// `TypeDefinitions`: the integrators as an Enumeration.
fn type_definitions() -> String {
    let mut xml = String::from("  <TypeDefinitions>\n    <EnumerationType name=\"Integrator\">\n");
    for &kind in IntegratorKind::ALL {
        let _ = writeln!(
            xml,
            r#"      <Item name="{}" value="{}" description="{}"/>"#,
            kind.name(),
            crate::variables::integrator_value(kind),
            escape(kind.spec().about)
        );
    }
    xml.push_str("    </EnumerationType>\n  </TypeDefinitions>\n");
    xml
}

/// The element of one variable.
fn element(v: &Variable) -> String {
    if v.role == Role::Setting(crate::variables::Setting::Integrator) {
        return integrator_element(v);
    }
    let (causality, variability) = match v.role {
        Role::Time => ("independent", "continuous"),
        Role::Parameter(_) | Role::Setting(_) => ("parameter", "fixed"),
        Role::Input(_) => ("input", "continuous"),
        Role::Output(_) => ("output", "continuous"),
    };
    let mut e = format!(
        r#"    <Float64 name="{}" valueReference="{}" causality="{causality}" variability="{variability}""#,
        escape(&v.name),
        v.reference
    );
    if !v.description.is_empty() {
        let _ = write!(e, r#" description="{}""#, escape(&v.description));
    }
    if !v.unit.is_empty() {
        let _ = write!(e, r#" unit="{}""#, escape(&v.unit));
    }
    if let Some(min) = v.min {
        let _ = write!(e, r#" min="{}""#, number(min));
    }
    if let Some(max) = v.max {
        let _ = write!(e, r#" max="{}""#, number(max));
    }
    if let Some(start) = v.start {
        let _ = write!(e, r#" start="{}""#, number(start));
    }
    e.push_str("/>\n");
    e
}

/// The whole `modelDescription.xml` of a model whose library is `identifier` (the file
/// `binaries/<platform>/<identifier>.so`).
pub fn model_description(model: &dyn Dynamics, identifier: &str) -> String {
    let info = model.info();
    let all = variables(model);
    let mut xml = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        xml,
        r#"<fmiModelDescription fmiVersion="{FMI_VERSION}" modelName="{}" instantiationToken="{}" description="{}" generationTool="camchain {}" variableNamingConvention="flat">"#,
        escape(&info.name),
        token(model),
        escape(info.description.lines().next().unwrap_or("")),
        env!("CARGO_PKG_VERSION"),
    );
    let _ = writeln!(
        xml,
        r#"  <CoSimulation modelIdentifier="{}" canHandleVariableCommunicationStepSize="true" canGetAndSetFMUState="false" canSerializeFMUState="false"/>"#,
        escape(identifier)
    );
    let units: BTreeSet<&str> = all
        .iter()
        .map(|v| v.unit.as_str())
        .filter(|u| !u.is_empty())
        .collect();
    if !units.is_empty() {
        xml.push_str("  <UnitDefinitions>\n");
        for unit in units {
            match base_unit(unit) {
                Some(base) => {
                    let _ = writeln!(
                        xml,
                        r#"    <Unit name="{}"><BaseUnit {base}/></Unit>"#,
                        escape(unit)
                    );
                }
                None => {
                    let _ = writeln!(xml, r#"    <Unit name="{}"/>"#, escape(unit));
                }
            }
        }
        xml.push_str("  </UnitDefinitions>\n");
    }
    xml.push_str(&type_definitions());
    xml.push_str(
        "  <LogCategories>\n    <Category name=\"logStatusError\" description=\"why a call \
         failed: bad values, a failed step, a call out of order\"/>\n    <Category \
         name=\"logEvents\" description=\"re-partitions and contact events inside a \
         step\"/>\n  </LogCategories>\n",
    );
    let d = &info.defaults;
    let _ = writeln!(
        xml,
        r#"  <DefaultExperiment startTime="0.0" stopTime="{}" tolerance="{}" stepSize="{}"/>"#,
        number(d.t_end),
        number(d.rtol),
        number(d.dt_out)
    );
    xml.push_str("  <ModelVariables>\n");
    for v in &all {
        xml.push_str(&element(v));
    }
    xml.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    let outputs: Vec<u32> = all
        .iter()
        .filter(|v| matches!(v.role, Role::Output(_)))
        .map(|v| v.reference)
        .collect();
    for r in &outputs {
        let _ = writeln!(xml, r#"    <Output valueReference="{r}"/>"#);
    }
    for r in &outputs {
        let _ = writeln!(xml, r#"    <InitialUnknown valueReference="{r}"/>"#);
    }
    xml.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    xml
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_description_declares_every_variable_once_with_its_reference() {
        let model = camchain_models::by_name("paper_concave").expect("built in");
        let xml = model_description(model, "paper_concave");
        for v in variables(model) {
            let needle = format!(
                "name=\"{}\" valueReference=\"{}\"",
                escape(&v.name),
                v.reference
            );
            assert_eq!(xml.matches(&needle).count(), 1, "{needle}");
        }
        assert!(xml.contains(&format!("instantiationToken=\"{}\"", token(model))));
        assert!(xml.contains("<CoSimulation modelIdentifier=\"paper_concave\""));
    }

    #[test]
    fn attribute_text_is_escaped() {
        assert_eq!(escape("a<b & \"c\"\n"), "a&lt;b &amp; &quot;c&quot;&#xa;");
        assert_eq!(number(f64::INFINITY), "INF");
        assert_eq!(number(0.1), "0.1");
    }
}
