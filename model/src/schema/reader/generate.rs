//! Random model-shaped RON texts for the comparison with ron: the schema's structure (every
//! field, optional ones left out or written bare or as `Some(…)`, in any order, structs
//! with or without their name), values in every form the grammar allows (integers in four
//! bases with suffixes, floats with exponents, `inf`, strings with escapes and raw strings,
//! characters), and random blanks, comments and trailing commas between tokens. Now and
//! then one character is deleted or inserted, to compare the errors too.
//!
//! The text is driven by a tape of bytes (as in Hypothesis): proptest shrinks the tape
//! towards zeros, which pick the first, simplest choices, so a failure shrinks to a small
//! model.

/// The choices, one byte each; zeros once exhausted.
pub(super) struct Tape<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Tape<'a> {
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        Tape { bytes, at: 0 }
    }

    fn byte(&mut self) -> usize {
        let b = self.bytes.get(self.at).copied().unwrap_or(0);
        self.at += 1;
        usize::from(b)
    }

    /// A choice in `0..n`.
    fn below(&mut self, n: usize) -> usize {
        self.byte() % n.max(1)
    }

    /// True with about `percent` % probability (false on a zero byte).
    fn chance(&mut self, percent: usize) -> bool {
        self.byte() * 100 / 256 >= 100 - percent
    }

    fn pick<'p>(&mut self, options: &[&'p str]) -> &'p str {
        options[self.below(options.len())]
    }
}

/// Builds the text token by token.
struct Writer<'t, 'a> {
    tape: &'t mut Tape<'a>,
    text: String,
}

/// Blanks between tokens: whitespace (ron's Unicode marks included) and comments.
const BLANKS: &[&str] = &[
    "",
    " ",
    "\n",
    "  ",
    "\t",
    "\r\n",
    " // a comment, with (brackets] and \"quotes\n",
    "/* block */",
    "/* a /* nested */ comment */",
    "\n\n    ",
    "\u{2028}",
    "\u{200E}",
];

impl Writer<'_, '_> {
    fn blank(&mut self) {
        let blank = self.tape.pick(BLANKS);
        self.text.push_str(blank);
    }

    /// A token after a blank; a space keeps two words apart.
    fn token(&mut self, token: &str) {
        self.blank();
        let word = |c: char| c.is_alphanumeric() || matches!(c, '_' | '"' | '\'' | '#');
        let joins = self.text.ends_with(word) && token.starts_with(word);
        if joins {
            self.text.push(' ');
        }
        self.text.push_str(token);
    }

    /// `name: value` pairs in random order, some left out, in `(…)` or `Name(…)`.
    fn structure(&mut self, name: &str, fields: &mut [(&str, bool, Value)]) {
        if self.tape.chance(15) {
            self.token(name);
        }
        self.token("(");
        // A random order: a few swaps.
        for _ in 0..fields.len() {
            let (i, j) = (self.tape.below(fields.len()), self.tape.below(fields.len()));
            fields.swap(i, j);
        }
        let mut first = true;
        for (field, required, value) in fields.iter() {
            if !required && !self.tape.chance(60) {
                continue;
            }
            if !first {
                self.token(",");
            }
            first = false;
            let field = if self.tape.chance(5) {
                format!("r#{field}")
            } else {
                field.to_string()
            };
            self.token(&field);
            self.token(":");
            self.value(*value);
        }
        if !first && self.tape.chance(40) {
            self.token(",");
        }
        self.token(")");
    }

    /// `[…]` of `n` items written by `item`.
    fn list(&mut self, n: usize, mut item: impl FnMut(&mut Self)) {
        self.token("[");
        for i in 0..n {
            if i > 0 {
                self.token(",");
            }
            item(self);
        }
        if n > 0 && self.tape.chance(40) {
            self.token(",");
        }
        self.token("]");
    }

    fn value(&mut self, value: Value) {
        match value {
            Value::Number => self.number(),
            Value::Float => self.pick_token(FLOATS, BAD_FLOATS),
            Value::Text => self.string(),
            Value::Bool => {
                let b = self.tape.pick(&["true", "false"]);
                self.token(b);
            }
            Value::Vec3 => {
                self.token("(");
                for i in 0..3 {
                    if i > 0 {
                        self.token(",");
                    }
                    self.number();
                }
                if self.tape.chance(20) {
                    self.token(",");
                }
                self.token(")");
            }
            Value::Optional(inner) => match self.tape.below(10) {
                0..=6 => self.value(*inner),
                7 | 8 => {
                    self.token("Some");
                    self.token("(");
                    self.value(*inner);
                    self.token(")");
                }
                _ => self.token("None"),
            },
            Value::Keyword(options) => {
                let keyword = self.tape.pick(options);
                self.token(keyword);
            }
            Value::Names => {
                let n = self.tape.below(3);
                self.list(n, |w| w.string());
            }
            Value::NamedNumbers => {
                self.token("{");
                let n = self.tape.below(3);
                for i in 0..n {
                    if i > 0 {
                        self.token(",");
                    }
                    self.string();
                    self.token(":");
                    self.number();
                }
                self.token("}");
            }
            Value::Inertia => match self.tape.below(3) {
                0 => {
                    self.token("Izz");
                    self.token("(");
                    self.number();
                    self.token(")");
                }
                1 => {
                    self.token("Diagonal");
                    self.token("(");
                    for i in 0..3 {
                        if i > 0 {
                            self.token(",");
                        }
                        self.number();
                    }
                    self.token(")");
                }
                _ => {
                    let n = Value::Number;
                    let mut fields = [
                        ("ixx", true, n),
                        ("iyy", true, n),
                        ("izz", true, n),
                        ("ixy", false, n),
                        ("ixz", false, n),
                        ("iyz", false, n),
                    ];
                    self.token("Full");
                    self.structure("", &mut fields);
                }
            },
            Value::Joint => {
                let mut fields = [
                    ("kind", true, Value::Keyword(&["Revolute", "Prismatic"])),
                    ("axis", true, Value::Vec3),
                    ("anchor", false, Value::Vec3),
                    ("coordinate", true, Value::Text),
                    ("spring", false, Value::Optional(&Value::Spring)),
                    ("prescribed", false, Value::Optional(&Value::Text)),
                    ("load", false, Value::Optional(&Value::Text)),
                ];
                self.structure("Joint", &mut fields);
            }
            Value::Spring => {
                let n = Value::Number;
                let mut fields = [
                    ("stiffness", false, n),
                    ("damping", false, n),
                    ("rest", false, n),
                ];
                self.structure("Spring", &mut fields);
            }
            Value::Simulation => {
                let f = Value::Float;
                let mut fields = [
                    ("t_end", false, f),
                    ("dt_out", false, f),
                    (
                        "integrator",
                        false,
                        Value::Keyword(&["Rk4", "Dopri5", "Dop853", "dop853", "RK4"]),
                    ),
                    ("dt", false, f),
                    ("rtol", false, f),
                    ("atol", false, f),
                    ("restitution", false, Value::Optional(&Value::Float)),
                ];
                self.structure("Simulation", &mut fields);
            }
            Value::Initial => {
                let mut fields = [
                    ("q", false, Value::NamedNumbers),
                    ("qd", false, Value::NamedNumbers),
                    ("hold", false, Value::Names),
                ];
                self.structure("Initial", &mut fields);
            }
        }
    }

    fn body(&mut self) {
        let mut fields = [
            ("name", true, Value::Text),
            ("parent", true, Value::Text),
            ("mass", true, Value::Number),
            ("com", false, Value::Vec3),
            ("inertia", true, Value::Inertia),
            ("joint", true, Value::Joint),
        ];
        self.structure("Body", &mut fields);
    }

    fn number(&mut self) {
        if self.tape.chance(15) {
            self.string();
        } else {
            self.pick_token(NUMBERS, BAD_NUMBERS);
        }
    }

    fn string(&mut self) {
        self.pick_token(STRINGS, BAD_STRINGS);
    }

    /// A token from `good`, or rarely (1 %) from `bad`.
    fn pick_token(&mut self, good: &[&str], bad: &[&str]) {
        let token = if self.tape.chance(1) {
            self.tape.pick(bad)
        } else {
            self.tape.pick(good)
        };
        self.token(token);
    }
}

/// Numbers where any number may be: ron reads all of these, a few as errors.
const NUMBERS: &[&str] = &[
    "1",
    "0",
    "-0",
    "2.5",
    "-9.81",
    "1e-3",
    "1_000",
    "0x1F",
    "0b101",
    "0o17",
    "7u8",
    "-2i32",
    ".5",
    "5.",
    "+3",
    "1E+2",
    "0.1f32",
    "2f64",
    "inf",
    "-inf",
    "NaN",
    "b'a'",
    "'m'",
    "18446744073709551616",
];

/// Numbers ron refuses.
const BAD_NUMBERS: &[&str] = &["300u8", "1._5", "0x", "1.5kg", "0b2"];

/// Numbers where a float is expected; hexadecimal and suffixed integers are errors there.
const FLOATS: &[&str] = &[
    "1", "0.5", "-0", "1e-9", "2.5E3", "1_0.5", ".25", "7.", "inf", "NaN", "-inf", "1f64",
];

/// What ron refuses where a float is expected.
const BAD_FLOATS: &[&str] = &["0x10", "1f32", "5u8", "\"1\"", "'1'"];

/// String literals: plain, with escapes, raw, spanning lines, continued.
const STRINGS: &[&str] = &[
    "\"q1\"",
    "\"ground\"",
    "\"m1*2\"",
    "\"\"",
    "\"a\\nb\\t\\\"c\\\"\"",
    "\"\\u{e9}\\x41\\u{1F600}\"",
    "\"\\xC3\\xA9\"",
    "r\"raw \\n\"",
    "r#\"has \"quotes\"\"#",
    "\"two\nlines\"",
    "\"con\\\n    tinued\"",
    "\"é ü ∂\"",
];

/// Strings ron refuses.
const BAD_STRINGS: &[&str] = &["\"\\q\"", "\"\\u{D800}\"", "\"\\xC3\"", "'s'", "b\"s\""];

/// What a field holds.
#[derive(Clone, Copy)]
enum Value {
    Number,
    Float,
    Text,
    Bool,
    Vec3,
    Optional(&'static Value),
    Keyword(&'static [&'static str]),
    Names,
    NamedNumbers,
    Inertia,
    Joint,
    Spring,
    Simulation,
    Initial,
}

/// A random model-shaped text.
pub(super) fn model(tape: &mut Tape) -> String {
    let mut w = Writer {
        tape,
        text: String::new(),
    };
    if w.tape.chance(10) {
        w.text.push_str("#![enable(implicit_some)]\n");
    }
    w.blank();
    if w.tape.chance(10) {
        w.token("Model");
    }
    w.token("(");
    let bodies = w.tape.below(4);
    // The top-level fields, in random order, each written or left out (bodies always).
    let mut order = [0, 1, 2, 3, 4, 5, 6, 7];
    for _ in 0..order.len() {
        let (i, j) = (w.tape.below(order.len()), w.tape.below(order.len()));
        order.swap(i, j);
    }
    let mut first = true;
    for field in order {
        if field != 0 && !w.tape.chance(50) {
            continue;
        }
        if !first {
            w.token(",");
        }
        first = false;
        match field {
            0 => {
                w.token("bodies");
                w.token(":");
                w.list(bodies, |w| w.body());
            }
            1 => {
                w.token("name");
                w.token(":");
                w.value(Value::Optional(&Value::Text));
            }
            2 => {
                w.token("description");
                w.token(":");
                w.string();
            }
            3 => {
                w.token("gravity");
                w.token(":");
                w.value(Value::Vec3);
            }
            4 => {
                w.token("initial");
                w.token(":");
                w.value(Value::Initial);
            }
            5 => {
                w.token("simulation");
                w.token(":");
                w.value(Value::Simulation);
            }
            6 => {
                w.token("parameters");
                w.token(":");
                let n = w.tape.below(3);
                w.list(n, |w| {
                    let f = Value::Optional(&Value::Float);
                    let mut fields = [
                        ("name", true, Value::Text),
                        ("value", true, Value::Float),
                        ("unit", false, Value::Text),
                        ("min", false, f),
                        ("max", false, f),
                        ("constant", false, Value::Bool),
                        ("description", false, Value::Text),
                    ];
                    w.structure("Parameter", &mut fields);
                });
            }
            _ => {
                w.token("markers");
                w.token(":");
                let n = w.tape.below(3);
                w.list(n, |w| {
                    let mut fields = [
                        ("name", true, Value::Text),
                        ("body", true, Value::Text),
                        ("position", false, Value::Vec3),
                    ];
                    w.structure("Marker", &mut fields);
                });
            }
        }
    }
    if w.tape.chance(30) {
        w.token(",");
    }
    w.token(")");
    w.blank();
    if w.tape.chance(25) {
        mutate(&mut w);
    }
    w.text
}

/// Deletes or inserts one character somewhere, to make an error.
fn mutate(w: &mut Writer) {
    let text = &mut w.text;
    let mut at = w.tape.byte() * 256 + w.tape.byte();
    at %= text.len() + 1;
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    if w.tape.chance(50) {
        if at < text.len() {
            text.remove(at);
        }
    } else {
        let inserted = w
            .tape
            .pick(&[",", ")", "]", "(", "x", "\"", "1", ":", "/*", "\n"]);
        text.insert_str(at, inserted);
    }
}
