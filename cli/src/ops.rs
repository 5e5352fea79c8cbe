//! `camchain ops [MODEL]...`: the operation count of every generated function.
//!
//! For a built-in model the counts are the ones the build recorded in its generated module
//! (`OP_COUNTS`, the same table as the module's header); for a `.ron` file the model is
//! derived and counted now, by the same code generator, without compiling anything.

use super::CliError;
use super::source::builtin_names;
use camchain_models as models;
use std::fmt::Write;
use std::path::Path;

/// One function's counts: add/sub, mul, div, sin/cos, sqrt, other.
type Row = (String, [usize; 6]);

/// The table of every MODEL (all built-in models when none is given).
pub fn render(args: &[String]) -> Result<String, CliError> {
    let names: Vec<String> = if args.is_empty() {
        builtin_names().into_iter().map(String::from).collect()
    } else {
        args.to_vec()
    };
    let mut text = String::new();
    for (k, arg) in names.iter().enumerate() {
        let (title, rows) = counts(arg)?;
        if k > 0 {
            text.push('\n');
        }
        text.push_str(&table(&title, &rows));
    }
    Ok(text)
}

fn counts(arg: &str) -> Result<(String, Vec<Row>), CliError> {
    if arg.ends_with(".ron") || arg.contains('/') || arg.contains(std::path::MAIN_SEPARATOR) {
        let path = Path::new(arg);
        let generated = camchain_codegen::generate_file(path, path)
            .map_err(|e| CliError::Failed(e.to_string()))?;
        let rows = generated
            .op_counts
            .iter()
            .map(|(name, c)| {
                (
                    name.clone(),
                    [c.add_sub, c.mul, c.div, c.sin_cos, c.sqrt, c.other],
                )
            })
            .collect();
        return Ok((
            format!("{} (from {arg}, derived now)", generated.name),
            rows,
        ));
    }
    let Some((_, table)) = models::OP_COUNTS.iter().find(|(name, _)| *name == arg) else {
        return Err(CliError::Usage(format!(
            "unknown model `{arg}`: built-in models are {} (or give a path to a .ron file)",
            builtin_names().join(", ")
        )));
    };
    let rows = table
        .iter()
        .map(|(name, c)| ((*name).to_string(), *c))
        .collect();
    Ok((format!("{arg} (generated code)"), rows))
}

fn table(title: &str, rows: &[Row]) -> String {
    let mut text = String::new();
    let _ = writeln!(text, "{title}");
    let _ = writeln!(
        text,
        "  {:<24} {:>7} {:>6} {:>5} {:>7} {:>5} {:>5} {:>6}",
        "function", "add/sub", "mul", "div", "sin/cos", "sqrt", "other", "total"
    );
    for (name, c) in rows {
        let total: usize = c.iter().sum();
        let _ = writeln!(
            text,
            "  {name:<24} {:>7} {:>6} {:>5} {:>7} {:>5} {:>5} {total:>6}",
            c[0], c[1], c[2], c[3], c[4], c[5]
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_built_in_model_has_a_table_with_its_functions() {
        let text = render(&[]).expect("built-in models");
        for name in builtin_names() {
            assert!(text.contains(&format!("{name} (generated code)")), "{name}");
        }
        for function in ["equations", "constraint_terms", "energy"] {
            assert!(text.contains(function), "{function}");
        }
    }

    #[test]
    fn a_model_file_is_counted_like_the_build_counts_it() {
        let arg = concat!(env!("CARGO_MANIFEST_DIR"), "/../models/paper_concave.ron");
        let (_, from_file) = counts(arg).expect("the file derives");
        let (_, built) = counts("paper_concave").expect("built in");
        assert_eq!(from_file, built);
    }

    #[cfg(unix)]
    #[test]
    fn a_device_without_end_is_refused_as_a_model_file() {
        // Before, `camchain ops /dev/zero` read until memory ran out; now the reader stops
        // after the 16 MiB a model file may hold.
        match render(&["/dev/zero".to_string()]) {
            Err(CliError::Failed(message)) => assert!(
                message.starts_with("/dev/zero: ") && message.contains("more than 16 MiB"),
                "{message}"
            ),
            _ => panic!("refused"),
        }
    }

    #[test]
    fn an_unknown_model_is_a_usage_error() {
        assert!(matches!(
            render(&["no_such_model".to_string()]),
            Err(CliError::Usage(_))
        ));
    }
}
