//! One generated function's text from its specification: signature (unused parameters
//! prefixed with `_`), input bindings, the emitter's bindings, then the outputs (arrays with
//! many zeros cleared with one `fill`).

use super::emitter::Emitter;
use super::lengths;
use super::names::{Names, is_identifier};
use super::parts;
use super::spec::{FIELD, FIELDS, FunctionSpec, RETURN};
use super::trigonometry::TrigMemo;
use crate::derive::Derivation;
use crate::expr::{Graph, Id, Node, OpCount};
use std::collections::HashSet;
use std::fmt::Write;

/// Emits `spec`; the nodes of `given` are read from the expressions paired with them (e.g.
/// `cache[3]`) instead of being computed.
pub(super) fn emit_function_given(
    d: &Derivation,
    spec: &FunctionSpec,
    prelude: &str,
    method: bool,
    given: &[(Id, String)],
) -> (String, OpCount) {
    emit_function_full(d, spec, prelude, method, given, &[], &[])
}

/// [`emit_function_given`], the sine–cosine pairs of `memo` computed through the cache
/// (`rt::sin_cos_memo`), and the Newton solves of the implicit variables of `warm` started
/// from the solutions kept where it says.
pub(super) fn emit_function_full(
    d: &Derivation,
    spec: &FunctionSpec,
    prelude: &str,
    method: bool,
    given: &[(Id, String)],
    memo: &[TrigMemo],
    warm: &[(Id, String)],
) -> (String, OpCount) {
    let extras = Extras {
        memo,
        warm,
        ..Default::default()
    };
    emit_with(d, spec, prelude, method, given, extras)
}

/// An output array written within its rows' extents: name, columns, each row's [start, end).
pub(super) type SparseArray<'a> = (&'a str, usize, Vec<(usize, usize)>);

/// What a method of `Model` may have beyond its specification.
#[derive(Default)]
pub(super) struct Extras<'a> {
    /// Sine–cosine pairs computed through the cache (`rt::sin_cos_memo`).
    pub(super) memo: &'a [TrigMemo],
    /// Where the Newton solves of implicit variables start (their kept solutions).
    pub(super) warm: &'a [(Id, String)],
    /// Output arrays written only within their rows' extents, as [`sparse_rows`] gives
    /// them (the caller's buffer is zero outside): the same extents the model declares.
    pub(super) sparse: &'a [SparseArray<'a>],
    /// Where the module of a method of at least [`parts::OWN_MODULE_OPS`] operations goes
    /// (outside the `impl` block); `None`: the body stays in the method.
    pub(super) items: Option<&'a mut String>,
    /// Products summed with another term written `a.mul_add(b, c)`
    /// ([`crate::EmitOptions::fused_multiply_add`]).
    pub(super) fused_multiply_add: bool,
    /// An output slice (`out.factors`) written only when the caller passes one long enough:
    /// its outputs go last, in one `if PATH.len() >= K { … }`, and its length is not
    /// asserted. A caller that will not read it passes an empty one and saves the stores,
    /// and the registers and stack traffic of keeping their values to the end (the 16-body
    /// chain's articulated sweeps: 209 values, 657 of 10 976 instructions per call).
    pub(super) written_if_given: Option<&'a str>,
}

/// A method of `Model` as [`emit_function_full`] emits it, with `extras`.
pub(super) fn emit_method(
    d: &Derivation,
    spec: &FunctionSpec,
    given: &[(Id, String)],
    extras: Extras,
) -> (String, OpCount) {
    emit_with(d, spec, "", true, given, extras)
}

fn emit_with(
    d: &Derivation,
    spec: &FunctionSpec,
    prelude: &str,
    method: bool,
    given: &[(Id, String)],
    extras: Extras,
) -> (String, OpCount) {
    let Extras {
        memo,
        warm,
        sparse,
        items,
        fused_multiply_add,
        written_if_given,
    } = extras;
    let g = &d.graph;
    let roots: Vec<Id> = spec.outputs.iter().map(|(_, id)| *id).collect();
    let given_set: HashSet<Id> = given.iter().map(|(id, _)| *id).collect();
    let count = g.op_count_until(&roots, &given_set);
    let items = items.filter(|_| method && count.total() >= parts::OWN_MODULE_OPS);
    let mut body = Emitter::new(g, &spec.outputs, given, &d.symbols.params);
    body.fused_multiply_add = fused_multiply_add;
    for m in memo {
        body.memo.insert(m.sin, *m);
        body.memo.insert(m.cos, *m);
    }
    body.warm = warm.iter().cloned().collect();
    if d.has_runtime_parameters() {
        body.derived_arg = if method {
            "&self.derived, "
        } else {
            "derived, "
        }
        .to_string();
    }
    let (bindings, used_vars) = body.bindings();
    let inputs = input_bindings(d, &used_vars);
    let mut used_params: HashSet<&str> = inputs.iter().map(|(p, _)| *p).collect();
    if body.solves_read_derived && !method {
        used_params.insert("derived");
    }
    // A scalar argument read under its own name.
    for (id, source) in given {
        if is_identifier(source) && body.names.contains_key(id) {
            if let Some(p) = spec.params.iter().find(|p| p.name == source) {
                used_params.insert(p.name);
            }
        }
    }
    // A parameter that a bound given expression reads (`derived.k1`, `cache[3]`).
    for p in &spec.params {
        let reads = |(id, source): &(Id, String)| {
            body.names.contains_key(id)
                && (source.starts_with(&format!("{}.", p.name))
                    || source.starts_with(&format!("{}[", p.name)))
        };
        if given.iter().any(reads) {
            used_params.insert(p.name);
        }
    }
    // The outputs and the tail, after the bindings.
    let mut after = String::new();
    let mut fields = String::new();
    // The outputs into `written_if_given`, and the length they need.
    let (mut optional, mut optional_len) = (String::new(), 0);
    // Arrays written within their rows' extents only: neither cleared nor written outside.
    let extents = sparse;
    let mut filled = zero_filled_arrays(g, &spec.outputs);
    filled.retain(|a| !extents.iter().any(|(s, _, _)| s == a));
    for array in &filled {
        let _ = writeln!(after, "{array}.fill(0.0);");
    }
    for (target, id) in &spec.outputs {
        if g.is_zero(*id) && array_of(target).is_some_and(|a| filled.contains(&a)) {
            continue;
        }
        let outside = |(a, columns, rows): &SparseArray| {
            let k = index_in(target, a)?;
            let (start, end) = rows[k / columns];
            Some(!(start..end).contains(&(k % columns)))
        };
        if g.is_zero(*id) && extents.iter().any(|e| outside(e) == Some(true)) {
            continue;
        }
        if target == RETURN {
            let _ = writeln!(after, "{}", body.print(*id, 0));
        } else if let Some(field) = target.strip_prefix(FIELD) {
            let value = body.print(*id, 0);
            if value == field {
                let _ = writeln!(fields, "{field},");
            } else {
                let _ = writeln!(fields, "{field}: {value},");
            }
        } else if let Some(k) = written_if_given.and_then(|path| index_in(target, path)) {
            optional_len = optional_len.max(k + 1);
            let _ = writeln!(optional, "{target} = {};", body.print(*id, 0));
        } else {
            let _ = writeln!(after, "{target} = {};", body.print(*id, 0));
        }
    }
    if let Some(path) = written_if_given.filter(|_| !optional.is_empty()) {
        let _ = match optional_len {
            1 => writeln!(after, "if !{path}.is_empty() {{\n{optional}}}"),
            _ => writeln!(after, "if {path}.len() >= {optional_len} {{\n{optional}}}"),
        };
    }
    after.push_str(&spec.tail.replace(FIELDS, &fields));
    let mut code = String::new();
    for (_, line) in &inputs {
        code.push_str(line);
    }
    code.push_str(prelude);
    code.push_str(&bindings);
    code.push_str(&after);
    let slices: Vec<(&str, &str)> = spec.params.iter().map(|p| (p.name, p.ty)).collect();
    let mut checked = lengths::length_check(&code, &slices, written_if_given);
    if let Some(path) = written_if_given.filter(|_| optional_len > 1) {
        // Empty, or long enough: a short one would be left as it was, unnoticed.
        let _ = writeln!(
            checked,
            "assert!({path}.is_empty() || {path}.len() >= {optional_len});"
        );
    }
    code.insert_str(0, &checked);
    let params: Vec<(String, &str, bool)> = spec
        .params
        .iter()
        .map(|p| {
            let written = spec
                .outputs
                .iter()
                .any(|(t, _)| t.starts_with(&format!("{}[", p.name)));
            let used = p.always_used || used_params.contains(p.name) || written;
            (p.name.to_string(), p.ty, used)
        })
        .collect();
    let ret = spec.ret.map(|r| format!(" -> {r}")).unwrap_or_default();
    // A large method's body goes to a module of its own; the method passes every argument.
    let (code, params) = match items {
        Some(items) => {
            let (call, module) = parts::moved(&spec.name, &params, &ret, &code);
            items.push_str(&module);
            let all_used = params.into_iter().map(|(n, ty, _)| (n, ty, true));
            (call, all_used.collect())
        }
        None => (code, params),
    };
    let params: Vec<String> = params
        .iter()
        .map(|(name, ty, used)| {
            if *used {
                format!("{name}: {ty}")
            } else {
                format!("_{name}: {ty}")
            }
        })
        .collect();
    let receiver = if method { "&self, " } else { "" };
    let mut text = format!(
        "/// {}\nfn {}({receiver}{}){ret} {{\n",
        spec.doc,
        spec.name,
        params.join(", ")
    );
    text.push_str(&code);
    text.push_str("\n}\n");
    (text, count)
}

/// Outputs that are zero, per array, from which the array is cleared with one `fill(0.0)`
/// instead of one assignment each: a sparse M or J of a long chain (an N-four-bar's 81×81 M
/// is 98 % zeros) would otherwise be mostly `m[k] = 0.0;` lines. Below it, the assignments
/// are kept (and the small models' code stays as it was).
pub(super) const ZERO_FILL_THRESHOLD: usize = 64;

/// The extents of the rows of the output array `array` (targets `array[k]`, row-major with
/// `columns` columns) when at least [`ZERO_FILL_THRESHOLD`] of its entries are zero: for each
/// row, [first, last + 1) of its nonzero entries ((0, 0) for a zero row). `None` otherwise,
/// or when the outputs do not cover whole rows.
pub(super) fn sparse_rows(
    g: &Graph,
    outputs: &[(String, Id)],
    array: &str,
    columns: usize,
) -> Option<Vec<(usize, usize)>> {
    let entries: Vec<(usize, Id)> = outputs
        .iter()
        .filter_map(|(t, id)| index_in(t, array).map(|k| (k, *id)))
        .collect();
    let zeros = entries.iter().filter(|(_, id)| g.is_zero(*id)).count();
    if columns == 0 || zeros < ZERO_FILL_THRESHOLD || entries.len() % columns != 0 {
        return None;
    }
    let mut rows = vec![(usize::MAX, 0); entries.len() / columns];
    for &(k, id) in &entries {
        let row = rows.get_mut(k / columns)?;
        if !g.is_zero(id) {
            *row = (row.0.min(k % columns), row.1.max(k % columns + 1));
        }
    }
    Some(
        rows.into_iter()
            .map(|(s, e)| if s == usize::MAX { (0, 0) } else { (s, e) })
            .collect(),
    )
}

/// k when `target` is `array[k]`.
fn index_in(target: &str, array: &str) -> Option<usize> {
    let rest = target.strip_prefix(array)?.strip_prefix('[')?;
    rest.strip_suffix(']')?.parse().ok()
}

/// The array of an output target `name[index]` (`m`, `out.mass`), if it is one.
pub(super) fn array_of(target: &str) -> Option<&str> {
    let (array, rest) = target.split_once('[')?;
    (rest.ends_with(']') && !rest.contains('[')).then_some(array)
}

/// The arrays with at least [`ZERO_FILL_THRESHOLD`] zero outputs, in order of appearance.
pub(super) fn zero_filled_arrays<'t>(g: &Graph, outputs: &'t [(String, Id)]) -> Vec<&'t str> {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for (target, id) in outputs {
        let Some(array) = array_of(target) else {
            continue;
        };
        if !g.is_zero(*id) {
            continue;
        }
        match counts.iter_mut().find(|(a, _)| *a == array) {
            Some((_, count)) => *count += 1,
            None => counts.push((array, 1)),
        }
    }
    counts
        .into_iter()
        .filter(|(_, count)| *count >= ZERO_FILL_THRESHOLD)
        .map(|(array, _)| array)
        .collect()
}

/// `let q1 = q[0];` lines for the variables the function uses, with the parameter they read.
pub(super) fn input_bindings(d: &Derivation, used: &HashSet<Id>) -> Vec<(&'static str, String)> {
    let mut lines = Vec::new();
    let names = Names::of_vars(&d.graph);
    for (i, id) in d.symbols.q.iter().enumerate() {
        if used.contains(id) {
            lines.push(("q", format!("let {} = q[{i}];\n", names.var(&d.graph, *id))));
        }
    }
    for (i, id) in d.symbols.qd.iter().enumerate() {
        if used.contains(id) {
            lines.push((
                "qd",
                format!("let {} = qd[{i}];\n", names.var(&d.graph, *id)),
            ));
        }
    }
    if used.contains(&d.symbols.t) {
        lines.push(("t", String::new()));
    }
    for &id in &d.symbols.params {
        if used.contains(&id) {
            let Node::Var(k) = d.graph.node(id) else {
                continue;
            };
            let field = &d.graph.var_names()[k as usize];
            lines.push((
                "p",
                format!("let {} = p.{field};\n", names.var(&d.graph, id)),
            ));
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::spec::param;
    use crate::emit::testing::derived;

    #[test]
    fn a_function_binds_the_coordinates_it_reads_and_marks_unused_parameters() {
        let (_, mut d) = derived("double_pendulum");
        let (q1, q2) = (d.symbols.q[0], d.symbols.q[1]);
        let sum = d.graph.add(q1, q2);
        let twice = d.graph.mul(sum, sum);
        let spec = FunctionSpec {
            doc: "A test.".into(),
            name: "f".into(),
            params: vec![
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("out", "&mut [f64]"),
            ],
            ret: None,
            outputs: vec![("out[0]".into(), twice), ("out[1]".into(), q2)],
            tail: String::new(),
        };
        let (text, count) = emit_function_given(&d, &spec, "", false, &[]);
        // q1 + q2 is used twice: bound once; qd is not read.
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| !l.starts_with("__section__"))
            .collect();
        assert_eq!(lines[0], "/// A test.");
        assert_eq!(lines[1], "fn f(q: &[f64], _qd: &[f64], out: &mut [f64]) {");
        // One length check for the slices read and written at constant indices.
        assert_eq!(
            &lines[2..4],
            ["assert!(q.len() >= 2);", "assert!(out.len() >= 2);"]
        );
        assert_eq!(&lines[4..6], ["let q1 = q[0];", "let q2 = q[1];"]);
        assert_eq!(
            lines.iter().filter(|l| l.contains("q1 + q2")).count(),
            1,
            "{text}"
        );
        assert_eq!(lines.last(), Some(&"}"));
        assert!(lines.contains(&"out[1] = q2;"), "{text}");
        assert_eq!((count.add_sub, count.mul, count.total()), (1, 1, 2));
    }

    #[test]
    fn a_given_node_is_read_not_computed() {
        let (_, mut d) = derived("double_pendulum");
        let q1 = d.symbols.q[0];
        let s = d.graph.sin(q1);
        let spec = FunctionSpec {
            doc: "Reads the cache.".into(),
            name: "g".into(),
            params: vec![param("q", "&[f64]"), param("cache", "&[f64]")],
            ret: Some("f64"),
            outputs: vec![(RETURN.into(), s)],
            tail: String::new(),
        };
        let (text, count) = emit_function_given(&d, &spec, "", true, &[(s, "cache[4]".into())]);
        assert!(
            text.starts_with(
                "/// Reads the cache.\nfn g(&self, _q: &[f64], cache: &[f64]) -> f64 {\n"
            ),
            "{text}"
        );
        assert!(text.contains("cache[4]"), "{text}");
        assert!(!text.contains("sin"), "{text}");
        assert_eq!(count.total(), 0);
    }

    #[test]
    fn a_sine_and_cosine_of_one_angle_come_from_one_call_unless_one_is_given() {
        let (_, mut d) = derived("double_pendulum");
        let (q1, q2) = (d.symbols.q[0], d.symbols.q[1]);
        let (s, c, s2) = (d.graph.sin(q1), d.graph.cos(q1), d.graph.sin(q2));
        let (a, b) = (d.graph.mul(s, q2), d.graph.add(c, s2));
        let spec = FunctionSpec {
            doc: "A test.".into(),
            name: "f".into(),
            params: vec![param("q", "&[f64]"), param("out", "&mut [f64]")],
            ret: None,
            outputs: vec![("out[0]".into(), a), ("out[1]".into(), b)],
            tail: String::new(),
        };
        let (text, _) = emit_function_given(&d, &spec, "", false, &[]);
        // The pair by one call; the lone sine of q2 as before.
        assert_eq!(text.matches("rt::trig::sin_cos(").count(), 1, "{text}");
        assert!(
            text.contains("let (s_q1, c_q1) = rt::trig::sin_cos(q1);"),
            "{text}"
        );
        assert!(text.contains("q2.sin()"), "{text}");
        assert!(
            !text.contains("q1.sin()") && !text.contains("q1.cos()"),
            "{text}"
        );
        // With the cosine read from an argument, the sine alone is computed.
        let given = [(c, "cache[0]".into())];
        let (text, _) = emit_function_given(&d, &spec, "", false, &given);
        assert!(!text.contains("rt::trig::sin_cos("), "{text}");
        assert!(
            text.contains("q1.sin()") && text.contains("cache[0]"),
            "{text}"
        );
    }

    #[test]
    fn arrays_with_many_zeros_are_cleared_with_one_fill() {
        assert_eq!(array_of("m[3]"), Some("m"));
        assert_eq!(array_of("out.mass[12]"), Some("out.mass"));
        assert_eq!(array_of("out[0].direction[1]"), None);
        assert_eq!(array_of("let kinetic"), None);
        let mut g = Graph::new();
        let (zero, x) = (g.constant(0.0), g.var("x"));
        let mut outputs: Vec<(String, Id)> = (0..ZERO_FILL_THRESHOLD)
            .map(|k| (format!("m[{k}]"), zero))
            .collect();
        outputs.push(("j[0]".into(), zero));
        outputs.push(("m[99]".into(), x));
        assert_eq!(zero_filled_arrays(&g, &outputs), ["m"]);
        assert!(zero_filled_arrays(&g, &outputs[1..]).is_empty());
    }

    #[test]
    fn a_sparse_array_is_written_within_its_rows_extents_only() {
        // 10 rows of 10 columns, each row nonzero at its diagonal and the next column (the
        // last row at its diagonal only), one zero in row 3's extent: 81 zeros.
        let mut g = Graph::new();
        let zero = g.constant(0.0);
        let x = g.var("x");
        let mut outputs = Vec::new();
        for k in 0..100 {
            let (i, j) = (k / 10, k % 10);
            let nonzero = (j == i || j == i + 1) && !(i == 3 && j == 4);
            let value = if nonzero { x } else { zero };
            outputs.push((format!("m[{k}]"), value));
        }
        outputs[35].1 = x; // row 3: columns 3 and 5, the zero at 4 inside the extent
        let rows = sparse_rows(&g, &outputs, "m", 10).expect("sparse");
        assert_eq!(rows[0], (0, 2));
        assert_eq!(rows[3], (3, 6));
        assert_eq!(rows[9], (9, 10));
        // Fewer zeros than the threshold: written whole.
        assert_eq!(sparse_rows(&g, &outputs[..50], "m", 10), None);
        // Not whole rows.
        assert_eq!(sparse_rows(&g, &outputs[..95], "m", 10), None);

        let (_, d) = crate::emit::testing::derived("double_pendulum");
        let mut d = d;
        let q1 = d.symbols.q[0];
        let zero = d.graph.constant(0.0);
        let outputs: Vec<(String, Id)> = (0..100)
            .map(|k| {
                let value = if k % 11 == 0 { q1 } else { zero };
                (format!("m[{k}]"), value)
            })
            .collect();
        let spec = FunctionSpec {
            doc: "A diagonal.".into(),
            name: "f".into(),
            params: vec![param("q", "&[f64]"), param("m", "&mut [f64]")],
            ret: None,
            outputs,
            tail: String::new(),
        };
        let rows = sparse_rows(&d.graph, &spec.outputs, "m", 10).expect("sparse");
        let sparse = [("m", 10, rows)];
        let extras = Extras {
            sparse: &sparse,
            ..Default::default()
        };
        let (text, _) = emit_with(&d, &spec, "", false, &[], extras);
        assert!(!text.contains("fill"), "{text}");
        assert_eq!(text.matches("m[").count(), 10, "the diagonal only: {text}");
        let (text, _) = emit_function_given(&d, &spec, "", false, &[]);
        assert!(text.contains("m.fill(0.0);"), "{text}");
    }
}
