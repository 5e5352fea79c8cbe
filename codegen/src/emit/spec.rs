//! What a generated function is: its name, doc, parameters, return type and the expressions
//! it assigns to its outputs. Every other part of the emitter builds or reads these.

use crate::expr::Id;

/// One parameter of a generated function.
#[derive(Debug, Clone, Copy)]
pub(super) struct Param {
    pub(super) name: &'static str,
    pub(super) ty: &'static str,
    /// Always used by code outside the expressions (so never prefixed with `_`).
    pub(super) always_used: bool,
}

/// Specification of one generated function.
pub(super) struct FunctionSpec {
    /// Doc comment.
    pub(super) doc: String,
    /// Name.
    pub(super) name: String,
    /// Parameters after `&self`.
    pub(super) params: Vec<Param>,
    /// Return type, if any.
    pub(super) ret: Option<&'static str>,
    /// `target = expression;` statements; a target `let x` declares a binding and the
    /// target [`RETURN`] makes the expression the function's value.
    pub(super) outputs: Vec<(String, Id)>,
    /// Code after the outputs (the returned value).
    pub(super) tail: String,
}

/// Output target meaning "the function's value" (written last, without a semicolon).
pub(super) const RETURN: &str = "return";

pub(super) fn param(name: &'static str, ty: &'static str) -> Param {
    Param {
        name,
        ty,
        always_used: false,
    }
}

/// Output target prefix `field:name`: the value becomes `name: value,` in the place of
/// [`FIELDS`] in the function's tail (a struct built in one literal).
pub(super) const FIELD: &str = "field:";

/// Where the fields of [`FIELD`] targets go in a function's tail.
pub(super) const FIELDS: &str = "__fields__";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plain_parameter_is_prefixed_when_unused() {
        let p = param("qd", "&[f64]");
        assert_eq!((p.name, p.ty, p.always_used), ("qd", "&[f64]", false));
        assert_ne!(RETURN, FIELDS);
        assert!(FIELD.ends_with(':'));
    }
}
