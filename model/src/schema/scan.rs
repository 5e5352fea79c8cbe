//! A small, tolerant RON scanner that maps dotted field paths to source positions and back.
//!
//! serde hands the validator plain values without positions, so errors found after
//! deserialisation (a negative mass, an unknown parent…) are located by walking this
//! scanner's tree with the field path (`bodies[2].mass`). It skips `//` and `/* */`
//! comments and string contents, tracks the nesting of `( [ {`, field names `ident:`, map
//! keys `"key":` and element indices. It never fails: on malformed input it returns what it
//! could recognise, so it is also used to name the field at a RON syntax error.

/// Deeper nesting than this is skipped rather than recursed into (stack safety).
const MAX_DEPTH: usize = 256;

/// Kinds of RON tokens that matter for locating values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// `(`, `[` or `{`.
    Open,
    /// `)`, `]` or `}`.
    Close,
    Comma,
    Colon,
    /// A string or character literal (contents not interpreted).
    Quoted,
    /// Anything else: identifiers, numbers, `true`, `inf`…
    Atom,
}

#[derive(Debug, Clone, Copy)]
struct Token {
    kind: Kind,
    start: usize,
    end: usize,
}

/// A value: an atom, a bracketed group, or a named group `Name(...)`.
#[derive(Debug, Default)]
struct Node {
    /// Byte offset of the value's first character (the name of a named group).
    start: usize,
    /// Byte offset just past the value.
    end: usize,
    /// `Some(name)` for `Name(...)`, e.g. a struct variant or `Some(...)`.
    name: Option<String>,
    /// Entries of a group, in order; empty for atoms.
    entries: Vec<Entry>,
    /// True for a bracketed group (possibly empty), false for an atom.
    group: bool,
}

/// One element of a group: `value`, `field: value` or `"key": value`.
#[derive(Debug)]
struct Entry {
    /// Byte offset of the key, or of the value when there is no key.
    start: usize,
    /// Field name or map key text (string quotes removed).
    key: Option<String>,
    /// True when the key was a string literal (a map key).
    quoted: bool,
    value: Node,
}

/// One step of a field path: `.name`, `["key"]` or `[index]`.
#[derive(Debug, PartialEq)]
enum Segment {
    Name(String),
    Index(usize),
}

/// The scanned structure of one RON source text.
#[derive(Debug)]
pub(super) struct Document {
    root: Node,
}

impl Document {
    /// Scans `source`; never fails.
    pub(super) fn parse(source: &str) -> Document {
        let tokens = tokenize(source);
        let mut parser = Parser {
            source,
            tokens,
            pos: 0,
        };
        Document {
            root: parser.value(0),
        }
    }

    /// Byte offset of the value at `path` (e.g. `bodies[1].joint.axis`), or of the key for
    /// a map entry (`initial.q["q1"]`, which is what such a path names); when the full path
    /// is absent, the offset of the deepest enclosing value found;
    /// `None` when not even the first step matches or the path is malformed.
    pub(super) fn locate(&self, path: &str) -> Option<usize> {
        let segments = parse_path(path)?;
        let mut node = &self.root;
        let mut found = None;
        for segment in &segments {
            match child(node, segment) {
                Some(entry) => {
                    node = &entry.value;
                    found = Some(if entry.quoted {
                        entry.start
                    } else {
                        entry.value.start
                    });
                }
                None => break,
            }
        }
        found
    }

    /// Start of the deepest bracketed group (its name for `Name(...)`) whose text contains
    /// byte `offset`: for a group that is never closed, its text runs to where the scanner
    /// found a closing bracket or to the end of the source.
    pub(super) fn group_at(&self, offset: usize) -> Option<usize> {
        let contains = |n: &Node| n.group && n.start <= offset && offset < n.end;
        let mut node = &self.root;
        let mut found = contains(node).then_some(node.start);
        while let Some((_, entry)) = entry_containing(node, offset) {
            node = &entry.value;
            if contains(node) {
                found = Some(node.start);
            }
        }
        found
    }

    /// The dotted path of the deepest value whose text contains byte `offset`
    /// (empty at the top level).
    pub(super) fn path_at(&self, offset: usize) -> String {
        let mut path = String::new();
        let mut node = unwrap_some(&self.root);
        while let Some((index, entry)) = entry_containing(node, offset) {
            push_segment(&mut path, index, entry);
            node = unwrap_some(&entry.value);
        }
        path
    }
}

/// The entry of `node` selected by `segment`, looking through `Some(...)` wrappers.
fn child<'n>(node: &'n Node, segment: &Segment) -> Option<&'n Entry> {
    let node = unwrap_some(node);
    match segment {
        Segment::Name(name) => node
            .entries
            .iter()
            .find(|e| e.key.as_deref() == Some(name.as_str())),
        Segment::Index(i) => node.entries.get(*i),
    }
}

/// `Some(v)` → `v` (an explicit option around a value is transparent in paths).
fn unwrap_some(mut node: &Node) -> &Node {
    while let (Some("Some"), [only]) = (node.name.as_deref(), node.entries.as_slice()) {
        if only.key.is_some() {
            break;
        }
        node = &only.value;
    }
    node
}

fn entry_containing(node: &Node, offset: usize) -> Option<(usize, &Entry)> {
    node.entries
        .iter()
        .enumerate()
        .find(|(_, e)| e.start <= offset && offset < e.value.end.max(e.start + 1))
}

fn push_segment(path: &mut String, index: usize, entry: &Entry) {
    match (&entry.key, entry.quoted) {
        (Some(key), false) => {
            if !path.is_empty() {
                path.push('.');
            }
            path.push_str(key);
        }
        (Some(key), true) => path.push_str(&format!("[{key:?}]")),
        (None, _) => path.push_str(&format!("[{index}]")),
    }
}

/// Splits `a.b[2]["k"].c` into segments; `None` when malformed.
fn parse_path(path: &str) -> Option<Vec<Segment>> {
    let mut segments = Vec::new();
    let mut rest = path;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("[\"") {
            let close = after.find("\"]")?;
            segments.push(Segment::Name(after[..close].to_string()));
            rest = &after[close + 2..];
        } else if let Some(after) = rest.strip_prefix('[') {
            let close = after.find(']')?;
            segments.push(Segment::Index(after[..close].parse().ok()?));
            rest = &after[close + 1..];
        } else {
            let name_start = rest.strip_prefix('.').unwrap_or(rest);
            let len = name_start.find(['.', '[']).unwrap_or(name_start.len());
            if len == 0 {
                return None;
            }
            segments.push(Segment::Name(name_start[..len].to_string()));
            rest = &name_start[len..];
        }
    }
    Some(segments)
}

/// 1-based (line, column) of byte `offset`; columns count characters, as ron does.
pub(super) fn line_column(source: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &source[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line = 1 + before.matches('\n').count();
    let column = 1 + before[line_start..].chars().count();
    (line, column)
}

/// The byte range `start..end` of a token.
#[cfg(test)]
pub(super) type Span = (usize, usize);

/// Byte ranges of the token ending last at or before `offset` and of the token starting at
/// `offset` (comments and whitespace are not tokens). Test-only: the reader's errors carry
/// these ranges; the comparison with ron locates ron's errors with it.
#[cfg(test)]
pub(super) fn tokens_around(source: &str, offset: usize) -> (Option<Span>, Option<Span>) {
    let tokens = tokenize(source);
    let before = tokens
        .iter()
        .take_while(|t| t.end <= offset)
        .last()
        .map(|t| (t.start, t.end));
    let at = tokens
        .iter()
        .find(|t| t.start == offset)
        .map(|t| (t.start, t.end));
    (before, at)
}

/// Byte offset of the 1-based (line, column) position; clamped to the text (test-only, as
/// [`tokens_around`]).
#[cfg(test)]
pub(super) fn byte_offset(source: &str, line: usize, column: usize) -> usize {
    let line_start = if line <= 1 {
        0
    } else {
        source
            .match_indices('\n')
            .nth(line - 2)
            .map_or(source.len(), |(i, _)| i + 1)
    };
    let line_text = &source[line_start..];
    let line_text = &line_text[..line_text.find('\n').unwrap_or(line_text.len())];
    let in_line = line_text
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(line_text.len(), |(i, _)| i);
    line_start + in_line
}

/// Byte offset of the first character inside the string literal starting at `offset`
/// (after `"`, `r"` or `r#"`); `offset` itself when no literal starts there.
pub(super) fn string_content_start(source: &str, offset: usize) -> usize {
    let Some(rest) = source.get(offset..) else {
        return offset;
    };
    let prefix = rest.len() - rest.trim_start_matches(['r', '#']).len();
    if rest[prefix..].starts_with('"') {
        offset + prefix + 1
    } else {
        offset
    }
}

struct Parser<'s> {
    source: &'s str,
    tokens: Vec<Token>,
    pos: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<Token> {
        self.tokens.get(self.pos).copied()
    }

    fn peek_is(&self, kind: Kind) -> bool {
        self.peek().is_some_and(|t| t.kind == kind)
    }

    /// A value at the cursor; consumes nothing when the cursor is not at a value.
    fn value(&mut self, depth: usize) -> Node {
        let Some(token) = self.peek() else {
            return atom(self.source.len(), self.source.len());
        };
        match token.kind {
            Kind::Open => {
                self.pos += 1;
                self.group(token.start, None, depth)
            }
            Kind::Atom if self.opens_after_atom() => {
                self.pos += 2;
                let name = self.source[token.start..token.end].to_string();
                self.group(token.start, Some(name), depth)
            }
            Kind::Atom | Kind::Quoted => {
                self.pos += 1;
                atom(token.start, token.end)
            }
            Kind::Close | Kind::Comma | Kind::Colon => atom(token.start, token.start),
        }
    }

    /// `Name(`: an identifier immediately followed by an opening parenthesis.
    fn opens_after_atom(&self) -> bool {
        self.tokens.get(self.pos + 1).is_some_and(|t| {
            t.kind == Kind::Open && self.source.as_bytes().get(t.start) == Some(&b'(')
        })
    }

    /// The entries of a group whose opening bracket has been consumed.
    fn group(&mut self, start: usize, name: Option<String>, depth: usize) -> Node {
        if depth >= MAX_DEPTH {
            let end = self.skip_group();
            return Node {
                start,
                end,
                name,
                entries: Vec::new(),
                group: true,
            };
        }
        let mut entries = Vec::new();
        loop {
            match self.peek() {
                None => {
                    return Node {
                        start,
                        end: self.source.len(),
                        name,
                        entries,
                        group: true,
                    };
                }
                Some(t) if t.kind == Kind::Close => {
                    self.pos += 1;
                    return Node {
                        start,
                        end: t.end,
                        name,
                        entries,
                        group: true,
                    };
                }
                Some(t) if matches!(t.kind, Kind::Comma | Kind::Colon) => self.pos += 1,
                Some(_) => entries.push(self.entry(depth + 1)),
            }
        }
    }

    /// Skips to just past the bracket closing the current group; returns its end offset.
    fn skip_group(&mut self) -> usize {
        let mut open = 1usize;
        while let Some(t) = self.peek() {
            self.pos += 1;
            match t.kind {
                Kind::Open => open += 1,
                Kind::Close => {
                    open -= 1;
                    if open == 0 {
                        return t.end;
                    }
                }
                _ => {}
            }
        }
        self.source.len()
    }

    /// `value`, or `key: value`; the cursor is at an atom, a literal or an opening bracket.
    fn entry(&mut self, depth: usize) -> Entry {
        let first = self.value(depth);
        if !self.peek_is(Kind::Colon) {
            return Entry {
                start: first.start,
                key: None,
                quoted: false,
                value: first,
            };
        }
        self.pos += 1;
        let raw_key = &self.source[first.start..first.end];
        let quoted = raw_key.ends_with('"');
        Entry {
            start: first.start,
            key: Some(unquote(raw_key).to_string()),
            quoted,
            value: self.value(depth),
        }
    }
}

fn atom(start: usize, end: usize) -> Node {
    Node {
        start,
        end,
        ..Node::default()
    }
}

/// The text between the quotes of `"…"`, `r"…"` or `r#"…"#`; other text unchanged.
fn unquote(text: &str) -> &str {
    let trimmed = text.trim_start_matches(['r', '#']).trim_end_matches('#');
    trimmed
        .strip_prefix('"')
        .and_then(|t| t.strip_suffix('"'))
        .unwrap_or(text)
}

/// Splits RON text into the tokens that matter, skipping whitespace and comments.
fn tokenize(source: &str) -> Vec<Token> {
    let bytes = source.as_bytes();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        let (kind, end) = match bytes[i] {
            _ if blank_len(bytes, i) > 0 => (None, i + blank_len(bytes, i)),
            b'/' if bytes.get(i + 1) == Some(&b'/') => (None, line_comment_end(bytes, i)),
            b'/' if bytes.get(i + 1) == Some(&b'*') => (None, block_comment_end(bytes, i)),
            b'(' | b'[' | b'{' => (Some(Kind::Open), i + 1),
            b')' | b']' | b'}' => (Some(Kind::Close), i + 1),
            b',' => (Some(Kind::Comma), i + 1),
            b':' => (Some(Kind::Colon), i + 1),
            b'"' | b'\'' => (Some(Kind::Quoted), quoted_end(bytes, i + 1, bytes[i])),
            b'b' if bytes.get(i + 1) == Some(&b'"') => {
                (Some(Kind::Quoted), quoted_end(bytes, i + 2, b'"'))
            }
            b'r' if raw_string_hashes(bytes, i).is_some() => {
                (Some(Kind::Quoted), raw_string_end(bytes, i))
            }
            _ => (Some(Kind::Atom), atom_end(bytes, i)),
        };
        if let Some(kind) = kind {
            tokens.push(Token { kind, start, end });
        }
        i = end.max(i + 1);
    }
    tokens
}

fn line_comment_end(bytes: &[u8], start: usize) -> usize {
    bytes[start..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |p| start + p + 1)
}

/// End of a (nestable, as in RON and Rust) block comment starting at `start`.
fn block_comment_end(bytes: &[u8], start: usize) -> usize {
    let mut depth = 0usize;
    let mut i = start;
    while i + 1 < bytes.len() {
        match (bytes[i], bytes[i + 1]) {
            (b'/', b'*') => {
                depth += 1;
                i += 2;
            }
            (b'*', b'/') => {
                depth -= 1;
                i += 2;
                if depth == 0 {
                    return i;
                }
            }
            _ => i += 1,
        }
    }
    bytes.len()
}

/// End (past the closing quote) of a string or char literal whose body starts at `i`.
fn quoted_end(bytes: &[u8], mut i: usize, quote: u8) -> usize {
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b if b == quote => return i + 1,
            _ => i += 1,
        }
    }
    bytes.len()
}

/// Number of `#` in a raw string opener `r#*"` at `start`, if one starts there.
fn raw_string_hashes(bytes: &[u8], start: usize) -> Option<usize> {
    let hashes = bytes[start + 1..]
        .iter()
        .take_while(|&&b| b == b'#')
        .count();
    (bytes.get(start + 1 + hashes) == Some(&b'"')).then_some(hashes)
}

fn raw_string_end(bytes: &[u8], start: usize) -> usize {
    let hashes = raw_string_hashes(bytes, start).unwrap_or(0);
    let mut i = start + hashes + 2;
    while i < bytes.len() {
        if bytes[i] == b'"' && bytes[i + 1..].iter().take(hashes).all(|&b| b == b'#') {
            let end = i + 1 + hashes;
            if end <= bytes.len() {
                return end;
            }
        }
        i += 1;
    }
    bytes.len()
}

/// Length in bytes of the whitespace character at `i` (0 if there is none): RON's
/// whitespace, which has a few Unicode marks besides ASCII's (the line and paragraph
/// separators, the left-to-right and right-to-left marks, NEL).
fn blank_len(bytes: &[u8], i: usize) -> usize {
    const UNICODE: [&[u8]; 5] = [
        "\u{85}".as_bytes(),
        "\u{200E}".as_bytes(),
        "\u{200F}".as_bytes(),
        "\u{2028}".as_bytes(),
        "\u{2029}".as_bytes(),
    ];
    match bytes.get(i) {
        Some(b' ' | b'\t' | b'\n' | b'\r' | b'\x0B' | b'\x0C') => 1,
        Some(_) => UNICODE
            .iter()
            .find(|blank| bytes[i..].starts_with(blank))
            .map_or(0, |blank| blank.len()),
        None => 0,
    }
}

/// End of a run of non-delimiter characters (identifier, number, `-inf`…).
fn atom_end(bytes: &[u8], start: usize) -> usize {
    let mut i = start;
    while i < bytes.len() {
        let b = bytes[i];
        let comment = b == b'/' && matches!(bytes.get(i + 1), Some(b'/' | b'*'));
        if blank_len(bytes, i) > 0 || b"()[]{},:\"".contains(&b) || comment {
            break;
        }
        i += 1;
    }
    i.max(start + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SOURCE: &str = r##"// a comment with (brackets] and "quotes
(
    name: "x", /* block (with ( nesting /* inner */ ) */
    bodies: [
        (name: "a", mass: 1.0, inertia: Izz(0.1)),
        (name: "b(", mass: -1,
         inertia: Full(ixx: 1, iyy: 1, izz: 1, ixy: 0.5, ixz: 0, iyz: 0),
         joint: (kind: Revolute, axis: (0, 0, 1), spring: Some((stiffness: -2)))),
    ],
    initial: (q: {"q1": 0.5, "q2": r#"x"#}, hold: ["q1", "q2"]),
)
"##;

    fn locate(path: &str) -> Option<(usize, usize)> {
        Document::parse(SOURCE)
            .locate(path)
            .map(|o| line_column(SOURCE, o))
    }

    /// 1-based (line, column) of the first `needle` on `line` of SOURCE.
    fn at(line: usize, needle: &str) -> Option<(usize, usize)> {
        let text = SOURCE.lines().nth(line - 1)?;
        text.find(needle)
            .map(|i| (line, text[..i].chars().count() + 1))
    }

    #[test]
    fn locates_nested_fields_list_elements_and_map_keys() {
        assert_eq!(locate("name"), at(3, "\"x\""));
        assert_eq!(locate("bodies"), at(4, "["));
        assert_eq!(locate("bodies[0]"), at(5, "("));
        assert_eq!(locate("bodies[1].mass"), at(6, "-1"));
        assert_eq!(locate("bodies[0].inertia"), at(5, "Izz"));
        assert_eq!(locate("bodies[0].inertia[0]"), at(5, "0.1"));
        assert_eq!(locate("bodies[1].inertia.ixy"), at(7, "0.5"));
        assert_eq!(locate("bodies[1].joint.axis"), at(8, "(0, 0, 1)"));
        assert_eq!(locate("bodies[1].joint.axis[2]"), at(8, "1)"));
        assert_eq!(locate("bodies[1].joint.spring.stiffness"), at(8, "-2"));
        // A map entry is located at its key.
        assert_eq!(locate("initial.q[\"q2\"]"), at(10, "\"q2\": r#"));
        assert_eq!(locate("initial.hold[1]"), at(10, "\"q2\"]"));
    }

    #[test]
    fn missing_paths_fall_back_to_the_closest_enclosing_value() {
        assert_eq!(locate("bodies[1].com"), locate("bodies[1]"));
        assert_eq!(locate("bodies[7].mass"), locate("bodies"));
        assert_eq!(locate("simulation.t_end"), None);
        assert_eq!(locate("bodies[x"), None);
    }

    #[test]
    fn names_the_field_at_an_offset() {
        let doc = Document::parse(SOURCE);
        let path_at =
            |line, needle| at(line, needle).map(|(l, c)| doc.path_at(byte_offset(SOURCE, l, c)));
        assert_eq!(path_at(6, "-1").as_deref(), Some("bodies[1].mass"));
        assert_eq!(path_at(6, "mass").as_deref(), Some("bodies[1].mass"));
        assert_eq!(path_at(7, "0.5").as_deref(), Some("bodies[1].inertia.ixy"));
        assert_eq!(
            path_at(8, "-2").as_deref(),
            Some("bodies[1].joint.spring.stiffness")
        );
        assert_eq!(path_at(10, "r#").as_deref(), Some("initial.q[\"q2\"]"));
        assert_eq!(
            path_at(10, "\"q1\", \"q2\"").as_deref(),
            Some("initial.hold[0]")
        );
        assert_eq!(path_at(1, "comment").as_deref(), Some(""));
    }

    #[test]
    fn unicode_blanks_are_not_part_of_names() {
        // RON reads U+2028 and U+200E as whitespace; a name next to them is the name alone.
        let text = "(\u{2028}bodies\u{200E}: [(mass\u{2028}:\u{200E}1)])";
        let doc = Document::parse(text);
        let mass = text.find("1)").unwrap_or(0);
        assert_eq!(doc.path_at(mass), "bodies[0].mass");
        assert_eq!(doc.locate("bodies[0].mass"), Some(mass));
    }

    #[test]
    fn line_column_and_byte_offset_are_inverse_with_unicode() {
        let text = "é\n  ü: (1, 2)\n";
        for offset in [0, 3, 5, 9, 12] {
            let (line, column) = line_column(text, offset);
            assert_eq!(byte_offset(text, line, column), offset);
        }
        assert_eq!(line_column(text, 5), (2, 3));
    }

    #[test]
    fn survives_malformed_text() {
        for text in [
            "",
            "(",
            ")",
            "(a: [1, (",
            "\"unterminated",
            "/* open",
            "r#\"x",
            "a: : ,",
        ] {
            let doc = Document::parse(text);
            let _ = doc.locate("a.b[0]");
            let _ = doc.path_at(1);
        }
        let deep = "[".repeat(10_000);
        // Index 0 of the outer list is the list opened at byte 1, its index 0 at byte 2.
        assert_eq!(Document::parse(&deep).locate("[0][0]"), Some(2));
    }

    #[test]
    fn string_content_start_skips_the_opening_quote() {
        assert_eq!(string_content_start("  \"ab\"", 2), 3);
        assert_eq!(string_content_start("r#\"ab\"#", 0), 3);
        assert_eq!(string_content_start("12", 0), 0);
    }
}
