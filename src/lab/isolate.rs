//! The student's file made safe to compile inside Mirador's modules, before any pass sees it:
//!
//! - **Its names apart from Mirador's.** Every name the student declares at module scope, other
//!   than the slots, is renamed with a prefix found in no module (`project` → `student_project`),
//!   so a helper may have any name WGSL allows: Mirador has about 150 functions, constants and
//!   types the student has never seen, and none of them can meet the student's. The renaming is
//!   a consistent change of one name for a fresh one in the student's text alone (member
//!   accesses, struct members and attribute arguments left as they are), which changes no
//!   meaning.
//! - **Its loops bounded.** A GPU runs a loop until it ends, and a loop that never ends hangs
//!   the GPU (or, on lavapipe, is cut off after about 65 536 iterations and returns a value, so
//!   a hang would score). Every `loop`, `for` and `while` of the student's gets one statement at
//!   the start of its body, `if student_guard() { break; }`: a per-invocation count of every
//!   iteration of the student's loops, which once past [`ITERATIONS`] breaks each loop in turn
//!   and sets a flag the known-answer tests read ([`Isolated::tripped`]). So every device runs the
//!   student's code the same bounded way, and the checker says why it stopped. An image has no
//!   pixel for the flag: the image tests draw a second, *poisoned* compilation beside the graded
//!   one ([`Isolated::poisoned`]), whose slots return NaN once the guard tripped, and the pixels
//!   where the two differ are the ones the guard decided.
//!
//! - **The same answer on every device.** `textureDimensions(t, level)` is compiled as
//!   `max(textureDimensions(t) >> level, 1)`, which WGSL defines it to be: lavapipe answers it
//!   with one fragment's level for a group of fragments whose levels differ (measured: 24 black
//!   pixels and a few wrong squares on the mipmaps lab's floor at 240×136, which a GPU does not
//!   draw).
//!
//! The edits keep the student's lines and columns findable: [`Isolated::original`] maps an
//! offset in the compiled text back to the student's own, and [`Isolated::unprefixed`] takes the
//! prefix out of a compiler's message.

/// How many loop iterations one shader invocation of the student's code may run, all loops
/// together. The labs' own loops need at most a few hundred (a volume's march, a PCF grid); the
/// bound is well under lavapipe's own cut-off (65 536), so lavapipe, a real GPU and the page all
/// stop at the same place.
pub const ITERATIONS: u32 = 16_384;

/// The student's text as the checker compiles it, and how to find the student's own places in it.
#[derive(Clone, Debug, PartialEq)]
pub struct Isolated {
    /// What is compiled: the student's text, renamed and guarded, then the guard's declarations.
    pub text: String,
    /// The prefix of the student's renamed names.
    pub prefix: String,
    /// The prefix of the guard's own names: fresh too, and never the start of a renamed name.
    guard: String,
    /// The names renamed, as the student wrote them.
    pub renamed: Vec<String>,
    /// How many loops were guarded.
    pub loops: usize,
    /// Each change: (where it starts in `text`, its length there, where it starts in the
    /// student's text, its length there), in order.
    edits: Vec<(usize, usize, usize, usize)>,
    /// The student's text's length: offsets past it fall in the guard's declarations.
    original_len: usize,
    /// [`Self::text`] with every value a float-valued slot returns multiplied by the guard's
    /// poison, NaN once the loops were cut off: an image drawn with it differs from one drawn
    /// with `text` exactly where the guard decided a value ([`Self::poisoned`]). `None` without
    /// loops, or without a slot that returns floats.
    poisoned: Option<String>,
}

impl Isolated {
    /// `text` (the student's file) with its module-scope names other than `slots` renamed and its
    /// loops guarded. `others` are the texts it will be compiled with: the prefix appears in none
    /// of them.
    pub fn new(text: &str, slots: &[String], others: &[&str]) -> Isolated {
        let tokens = tokens(text);
        let declared: Vec<String> = module_scope_names(text, &tokens)
            .into_iter()
            .filter(|name| !slots.contains(name))
            .fold(Vec::new(), |mut names, name| {
                if !names.contains(&name) {
                    names.push(name);
                }
                names
            });
        let prefix = fresh_prefix("student", text, others);
        let guard_prefix = fresh_prefix("loop_guard", text, others);
        let renamed = |token: &Token| {
            let name = &text[token.range.clone()];
            (token.kind == Kind::Identifier && token.renameable && declared.iter().any(|d| d == name))
                .then(|| format!("{prefix}{name}"))
        };
        // The code of `range` (an argument), its tokens with the student's names renamed, and no
        // comment or line end left between them: nothing can swallow what the rewrite follows
        // it with.
        let rewritten = |range: std::ops::Range<usize>| {
            let mut out = String::new();
            let mut last: Option<usize> = None;
            for t in tokens.iter().filter(|t| t.range.start >= range.start && t.range.end <= range.end) {
                // Spaces between two tokens kept; a comment or a line end, one space instead.
                if let Some(end) = last.filter(|&end| end < t.range.start) {
                    let gap = &text[end..t.range.start];
                    out.push_str(if gap.bytes().all(|b| b == b' ') { gap } else { " " });
                }
                out.push_str(&renamed(t).unwrap_or_else(|| text[t.range.clone()].to_owned()));
                last = Some(t.range.end);
            }
            out
        };
        let mut changes: Vec<(usize, usize, String)> = Vec::new();
        for (index, token) in tokens.iter().enumerate() {
            if let Some(name) = renamed(token) {
                changes.push((token.range.start, token.range.len(), name));
            }
            let name = &text[token.range.clone()];
            if token.kind != Kind::Identifier || token.after_dot {
                continue;
            }
            if name == "textureDimensions"
                && let Some((end, [texture, level])) = two_arguments(&tokens, index)
            {
                let size = format!("textureDimensions({})", rewritten(texture));
                let level = rewritten(level);
                let with = format!("max({size} >> ({size} * 0u + u32({level})), {size} * 0u + 1u)");
                changes.push((token.range.start, end - token.range.start, with));
            }
            if matches!(name, "loop" | "for" | "while")
                && let Some(open) = loop_body(&tokens, index)
            {
                changes.push((open + 1, 0, format!(" if {guard_prefix}step() {{ break; }}")));
            }
        }
        let changes = outermost(changes);
        let loops = changes.iter().filter(|c| c.1 == 0).count();
        let poisons = poisoned_returns(text, &tokens, slots, &guard_prefix);
        let poisoned = (loops > 0 && !poisons.is_empty()).then(|| {
            let (mut out, _) = applied(text, outermost([changes.clone(), poisons].concat()));
            out.push_str(&poison(&guard_prefix));
            out.push_str(&guard(&guard_prefix));
            out
        });
        let (mut out, edits) = applied(text, changes);
        out.push_str(&guard(&guard_prefix));
        Isolated {
            text: out,
            prefix,
            guard: guard_prefix,
            renamed: declared,
            loops,
            edits,
            original_len: text.len(),
            poisoned,
        }
    }

    /// The text to draw an image with beside [`Self::text`] to see whether the guard cut the
    /// student's loops off anywhere in it: where it did, the slot's value is NaN. An image test
    /// has no pixel to read a flag from (the known-answer tests read [`Self::tripped`]), so the
    /// two images are compared instead.
    pub fn poisoned(&self) -> Option<&str> {
        self.poisoned.as_deref()
    }

    /// The offset in the student's text of `offset` in [`Isolated::text`]; an offset inside an
    /// inserted guard or a renamed name is the start of that change; one in the guard's own
    /// declarations, `None`.
    pub fn original(&self, offset: usize) -> Option<usize> {
        let mut shift: isize = 0;
        for &(at, len, old_at, old_len) in &self.edits {
            if offset < at {
                break;
            }
            if offset < at + len {
                return Some(old_at);
            }
            shift += old_len as isize - len as isize;
        }
        let original = (offset as isize + shift) as usize;
        (original <= self.original_len).then_some(original)
    }

    /// `message` with the student's names as the student wrote them.
    pub fn unprefixed(&self, message: &str) -> String {
        let mut message = message.to_owned();
        for name in &self.renamed {
            message = message.replace(&format!("{}{name}", self.prefix), name);
        }
        message.replace(&format!("{}step", self.guard), "the checker's loop guard")
    }

    /// A WGSL expression, in a module with this text in, that is true when the student's loops
    /// ran past [`ITERATIONS`] in this invocation.
    pub fn tripped(&self) -> String {
        format!("{}tripped", self.guard)
    }
}

/// `changes` in order, without those inside an earlier one (a name in a rewritten call's
/// arguments, a call inside another's: already part of it). A guard inserted right after a
/// loop's `{` comes before a name renamed there.
fn outermost(mut changes: Vec<(usize, usize, String)>) -> Vec<(usize, usize, String)> {
    changes.sort_by_key(|change| (change.0, change.1 != 0, std::cmp::Reverse(change.1)));
    let mut end = 0;
    changes.retain(|(at, len, _)| {
        let keep = *at >= end;
        if keep {
            end = at + len;
        }
        keep
    });
    changes
}

/// `text` with `changes` (sorted) made, a line end after it; and each change's place in both texts.
#[allow(clippy::type_complexity)]
fn applied(text: &str, changes: Vec<(usize, usize, String)>) -> (String, Vec<(usize, usize, usize, usize)>) {
    let (mut out, mut edits, mut from) = (String::new(), Vec::new(), 0);
    for (at, len, with) in changes {
        out.push_str(&text[from..at]);
        edits.push((out.len(), with.len(), at, len));
        out.push_str(&with);
        from = at + len;
    }
    out.push_str(&text[from..]);
    if !out.ends_with('\n') {
        out.push('\n');
    }
    (out, edits)
}

/// The insertions that make every `return X;` of a slot returning floats (`f32`, a float vector
/// or matrix) `return (X) * GUARDpoison();`.
fn poisoned_returns(text: &str, tokens: &[Token], slots: &[String], guard: &str) -> Vec<(usize, usize, String)> {
    let name = |t: &Token| &text[t.range.clone()];
    let mut changes = Vec::new();
    for i in 0..tokens.len().saturating_sub(1) {
        let declares_slot =
            tokens[i].depth == 0 && name(&tokens[i]) == "fn" && slots.iter().any(|slot| slot == name(&tokens[i + 1]));
        let Some(open) =
            declares_slot.then(|| (i..tokens.len()).find(|&j| tokens[j].kind == Kind::Punct('{'))).flatten()
        else {
            continue;
        };
        let arrow = (i..open).find(|&j| tokens[j].kind == Kind::Punct('-') && tokens[j + 1].kind == Kind::Punct('>'));
        let Some(arrow) = arrow else { continue };
        let returned: String = tokens[arrow + 2..open].iter().map(name).collect();
        if !floats(&returned) {
            continue;
        }
        let body = tokens[open].depth + 1;
        let end = (open + 1..tokens.len()).find(|&j| tokens[j].depth < body).unwrap_or(tokens.len());
        for j in open + 1..end {
            if tokens[j].kind != Kind::Identifier || tokens[j].after_dot || name(&tokens[j]) != "return" {
                continue;
            }
            let Some(semicolon) = (j + 1..end).find(|&k| tokens[k].kind == Kind::Punct(';')) else { continue };
            if semicolon == j + 1 {
                continue;
            }
            changes.push((tokens[j + 1].range.start, 0, "(".to_owned()));
            changes.push((tokens[semicolon].range.start, 0, format!(") * {guard}poison()")));
        }
    }
    changes
}

/// Whether the WGSL type `returned` (its tokens joined) holds floats a scalar multiplies.
fn floats(returned: &str) -> bool {
    let vector =
        ["vec2", "vec3", "vec4"].iter().any(|v| returned == format!("{v}f") || returned == format!("{v}<f32>"));
    let matrix = returned.starts_with("mat") && (returned.ends_with('f') || returned.ends_with("<f32>"));
    returned == "f32" || vector || matrix
}

/// The poison the slots' values are multiplied by in [`Isolated::poisoned`]: 1, or NaN once the
/// guard tripped (a NaN the compiler cannot fold: WGSL makes a constant NaN an error).
fn poison(prefix: &str) -> String {
    format!(
        "// ---- the checker's poison: NaN once the loop guard tripped (src/lab/isolate.rs)
var<private> {prefix}nan_bits: u32 = 0x7fc00000u;
fn {prefix}poison() -> f32 {{
    return select(1.0, bitcast<f32>({prefix}nan_bits), {prefix}tripped);
}}
"
    )
}

/// The guard's declarations: the count, the flag, and the step each loop takes.
fn guard(prefix: &str) -> String {
    format!(
        "// ---- the checker's loop guard (src/lab/isolate.rs)
var<private> {prefix}iterations: u32 = 0u;
var<private> {prefix}tripped: bool = false;
fn {prefix}step() -> bool {{
    {prefix}iterations += 1u;
    if {prefix}iterations > {ITERATIONS}u {{
        {prefix}tripped = true;
    }}
    return {prefix}tripped;
}}
"
    )
}

/// `BASE_`, or `BASE1_`, … : the first that occurs in none of the texts.
fn fresh_prefix(base: &str, text: &str, others: &[&str]) -> String {
    (0..)
        .map(|n| if n == 0 { format!("{base}_") } else { format!("{base}{n}_") })
        .find(|prefix| !text.contains(prefix.as_str()) && others.iter().all(|o| !o.contains(prefix.as_str())))
        .expect("some prefix is fresh")
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Identifier,
    /// A number, whose letters (`1e5`, `2u`, `0x1f`) are no names.
    Number,
    /// One character of punctuation.
    Punct(char),
}

#[derive(Clone, Debug)]
struct Token {
    kind: Kind,
    range: std::ops::Range<usize>,
    /// Right after a `.`: a member or a swizzle, never one of the student's names.
    after_dot: bool,
    /// An identifier that names what the student declared if it names anything: not a member,
    /// not a struct's member declaration, not an attribute's argument.
    renameable: bool,
    /// The brace depth it stands at (0: module scope).
    depth: usize,
}

/// The text's tokens, comments left out.
fn tokens(text: &str) -> Vec<Token> {
    let bytes = text.as_bytes();
    let mut out: Vec<Token> = Vec::new();
    let (mut i, mut depth) = (0, 0usize);
    while i < bytes.len() {
        let c = bytes[i];
        if c == b'/' && bytes.get(i + 1) == Some(&b'/') {
            i = text[i..].find('\n').map_or(bytes.len(), |n| i + n);
            continue;
        }
        if c == b'/' && bytes.get(i + 1) == Some(&b'*') {
            // Block comments nest in WGSL.
            let (mut nesting, mut j) = (0usize, i);
            while j < bytes.len() {
                if bytes[j] == b'/' && bytes.get(j + 1) == Some(&b'*') {
                    nesting += 1;
                    j += 2;
                } else if bytes[j] == b'*' && bytes.get(j + 1) == Some(&b'/') {
                    nesting -= 1;
                    j += 2;
                    if nesting == 0 {
                        break;
                    }
                } else {
                    j += 1;
                }
            }
            i = j;
            continue;
        }
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let start = i;
        let kind = if c.is_ascii_alphabetic() || c == b'_' || c >= 0x80 {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_' || bytes[i] >= 0x80) {
                i += 1;
            }
            Kind::Identifier
        } else if c.is_ascii_digit() || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'.' || bytes[i] == b'_') {
                let exponent = matches!(bytes[i], b'e' | b'E' | b'p' | b'P');
                i += 1;
                if exponent && matches!(bytes.get(i), Some(b'+' | b'-')) {
                    i += 1;
                }
            }
            Kind::Number
        } else {
            let ch = text[i..].chars().next().expect("inside the text");
            i += ch.len_utf8();
            Kind::Punct(ch)
        };
        if kind == Kind::Punct('}') {
            depth = depth.saturating_sub(1);
        }
        let after_dot = out.last().is_some_and(|t| t.kind == Kind::Punct('.'));
        out.push(Token { kind, range: start..i, after_dot, renameable: !after_dot, depth });
        if kind == Kind::Punct('{') {
            depth += 1;
        }
    }
    mark_unrenameable(text, &mut out);
    out
}

/// Marks the identifiers that are no reference to a declaration: a struct's member names, and
/// the arguments of the attributes that take enumerants, not expressions (`@builtin(position)`,
/// `@interpolate(flat)`, `@diagnostic(off, …)`); `@location(N)` or `@size(N)` may name the
/// student's constant, and keep it.
fn mark_unrenameable(text: &str, tokens: &mut [Token]) {
    let name = |t: &Token| &text[t.range.clone()];
    for i in 0..tokens.len() {
        let enumerants = tokens[i].kind == Kind::Punct('@')
            && tokens.get(i + 1).is_some_and(|t| matches!(name(t), "builtin" | "interpolate" | "diagnostic"))
            && tokens.get(i + 2).is_some_and(|t| t.kind == Kind::Punct('('));
        if enumerants {
            let mut parens = 0;
            for token in &mut tokens[i + 2..] {
                match token.kind {
                    Kind::Punct('(') => parens += 1,
                    Kind::Punct(')') => parens -= 1,
                    _ => token.renameable = false,
                }
                if parens == 0 {
                    break;
                }
            }
        }
        if tokens[i].kind == Kind::Identifier && name(&tokens[i]) == "struct" && !tokens[i].after_dot {
            // struct NAME { member: T, … }: a member is an identifier right before a `:` at the
            // body's own depth. (The body's attributes are met by this loop in their turn.)
            let Some(open) = (i..tokens.len()).find(|&j| tokens[j].kind == Kind::Punct('{')) else { break };
            let body = tokens[open].depth + 1;
            let mut j = open + 1;
            while j < tokens.len() && !(tokens[j].kind == Kind::Punct('}') && tokens[j].depth + 1 == body) {
                if tokens[j].depth == body
                    && tokens[j].kind == Kind::Identifier
                    && tokens.get(j + 1).is_some_and(|t| t.kind == Kind::Punct(':'))
                {
                    tokens[j].renameable = false;
                }
                j += 1;
            }
        }
    }
}

/// The names the text declares at module scope: `fn`, `const`, `override`, `var` (with its
/// `<…>`), `struct` and `alias`.
fn module_scope_names(text: &str, tokens: &[Token]) -> Vec<String> {
    let mut names = Vec::new();
    for (i, token) in tokens.iter().enumerate() {
        if token.depth != 0 || token.kind != Kind::Identifier || token.after_dot {
            continue;
        }
        let keyword = &text[token.range.clone()];
        if !matches!(keyword, "fn" | "const" | "override" | "var" | "struct" | "alias") {
            continue;
        }
        let mut j = i + 1;
        if keyword == "var" && tokens.get(j).is_some_and(|t| t.kind == Kind::Punct('<')) {
            while j < tokens.len() && tokens[j].kind != Kind::Punct('>') {
                j += 1;
            }
            j += 1;
        }
        if let Some(name) = tokens.get(j).filter(|t| t.kind == Kind::Identifier) {
            names.push(text[name.range.clone()].to_owned());
        }
    }
    names
}

/// The call `name(a, b)` starting at `tokens[index]`: the offset after its `)`, and its two
/// arguments' ranges; `None` for any other number of arguments.
fn two_arguments(tokens: &[Token], index: usize) -> Option<(usize, [std::ops::Range<usize>; 2])> {
    let open = tokens.get(index + 1).filter(|t| t.kind == Kind::Punct('('))?;
    let (mut depth, mut commas) = (0i32, Vec::new());
    for token in &tokens[index + 1..] {
        match token.kind {
            Kind::Punct('(') | Kind::Punct('[') => depth += 1,
            Kind::Punct(')') | Kind::Punct(']') => {
                depth -= 1;
                if depth == 0 {
                    // `(a, b)`, or `(a, b,)` with WGSL's trailing comma.
                    let last = text_before(tokens, token).filter(|t| t.kind == Kind::Punct(','));
                    let second_end = last.map_or(token.range.start, |t| t.range.start);
                    let commas: Vec<usize> = commas.into_iter().filter(|&c| c != second_end).collect();
                    let [comma] = commas[..] else { return None };
                    return Some((token.range.end, [open.range.end..comma, comma + 1..second_end]));
                }
            }
            Kind::Punct(',') if depth == 1 => commas.push(token.range.start),
            _ => {}
        }
    }
    None
}

/// The token right before `token` in `tokens`.
fn text_before<'t>(tokens: &'t [Token], token: &Token) -> Option<&'t Token> {
    tokens.iter().take_while(|t| t.range.start < token.range.start).last()
}

/// The offset of the `{` that opens the body of the loop whose keyword is `tokens[index]`.
fn loop_body(tokens: &[Token], index: usize) -> Option<usize> {
    let mut parens = 0i32;
    for token in &tokens[index + 1..] {
        match token.kind {
            Kind::Punct('(') => parens += 1,
            Kind::Punct(')') => parens -= 1,
            Kind::Punct('{') if parens == 0 => return Some(token.range.start),
            Kind::Punct(';') if parens == 0 => return None,
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helpers_are_renamed_and_nothing_else() {
        let text = "// fn project in a comment\nstruct Hit { project: f32, t: f32 }\nfn project(x: f32) -> f32 { return x; }\nfn slot(h: Hit, v: vec3f) -> f32 {\n    let project_me = 1.0;\n    return project(h.project) + v.x + project_me;\n}\n";
        let isolated = Isolated::new(text, &["slot".to_owned()], &["fn student_other() {}"]);
        assert_eq!(isolated.prefix, "student1_");
        assert_eq!(isolated.renamed, ["Hit", "project"]);
        let body = &isolated.text[..isolated.text.find("// ---- the checker").unwrap()];
        assert_eq!(
            body,
            "// fn project in a comment\nstruct student1_Hit { project: f32, t: f32 }\nfn student1_project(x: f32) -> f32 { return x; }\nfn slot(h: student1_Hit, v: vec3f) -> f32 {\n    let project_me = 1.0;\n    return student1_project(h.project) + v.x + project_me;\n}\n"
        );
        assert_eq!(isolated.unprefixed("redefinition of `student1_project`"), "redefinition of `project`");
    }

    #[test]
    fn every_loop_is_guarded_and_offsets_map_back() {
        let text = "fn slot(n: u32) -> f32 {\n    var x = 0.0;\n    for (var i = 0u; i < n; i++) { x += 1.0; }\n    while (x > 0.0) { x -= 0.5; }\n    loop { if x > 3.0 { break; } x += 1.0; }\n    return x;\n}\n";
        let isolated = Isolated::new(text, &["slot".to_owned()], &[]);
        assert_eq!(isolated.loops, 3);
        assert_eq!(isolated.text.matches("if loop_guard_step() { break; }").count(), 3);
        // `return x;` is found where the student wrote it.
        let here = isolated.text.find("return x;").unwrap();
        assert_eq!(isolated.original(here), text.find("return x;"));
        let inside = isolated.text.find("loop_guard_step() { break; }").unwrap();
        assert_eq!(isolated.original(inside), Some(text.find("{ x += 1.0").unwrap() + 1));
        assert_eq!(isolated.original(isolated.text.len() - 2), None);
    }

    #[test]
    fn a_float_slots_returns_are_poisoned_only_when_it_has_loops() {
        let text = "fn helper(n: u32) -> f32 {\n    var x = 0.0;\n    loop { x += 1.0; if x > f32(n) { break; } }\n    return x;\n}\nfn slot(n: u32) -> vec3f {\n    if n == 0u { return vec3f(0.0); }\n    return vec3f(helper(n));\n}\nfn other(n: u32) -> bool { return n > 1u; }\n";
        let slots = ["slot".to_owned(), "other".to_owned()];
        let isolated = Isolated::new(text, &slots, &[]);
        let poisoned = isolated.poisoned().expect("a float slot and a loop");
        assert!(poisoned.contains("if n == 0u { return (vec3f(0.0)) * loop_guard_poison(); }"), "{poisoned}");
        assert!(poisoned.contains("return (vec3f(student_helper(n))) * loop_guard_poison();"), "{poisoned}");
        // Neither a helper's return nor a slot of another type is touched.
        assert!(poisoned.contains("    return x;\n") && poisoned.contains("{ return n > 1u; }"), "{poisoned}");
        // Beside the poison, the same text as the graded one.
        let plain = poisoned.replace(") * loop_guard_poison()", "").replace("return (", "return ");
        let cut = plain.find("// ---- the checker's poison").unwrap();
        let guard = plain.find("// ---- the checker's loop guard").unwrap();
        assert_eq!(format!("{}{}", &plain[..cut], &plain[guard..]), isolated.text);
        let no_loop = Isolated::new("fn slot(n: u32) -> f32 { return 1.0; }\n", &slots, &[]);
        assert_eq!(no_loop.poisoned(), None);
    }

    #[test]
    fn a_levels_size_is_computed_from_level_0() {
        let text = "fn slot(t: texture_2d<f32>, l: i32) -> vec2f {\n    return vec2f(textureDimensions(t, l + 1)) + vec2f(textureDimensions(t));\n}\n";
        let isolated = Isolated::new(text, &["slot".to_owned()], &[]);
        assert!(isolated.text.contains("vec2f(max(textureDimensions(t) >> (textureDimensions(t) * 0u + u32(l + 1)), textureDimensions(t) * 0u + 1u)) + vec2f(textureDimensions(t))"), "{}", isolated.text);
    }

    #[test]
    fn a_helper_inside_a_rewritten_call_is_renamed_once() {
        let text = "fn lod(x: i32) -> i32 { return x; }\nfn slot(t: texture_2d<f32>) -> vec2u {\n    return textureDimensions(t, lod(textureDimensions(t, 1).x));\n}\n";
        let isolated = Isolated::new(text, &["slot".to_owned()], &[]);
        assert!(isolated.text.contains("u32(student_lod(textureDimensions(t, 1).x))"), "{}", isolated.text);
        assert!(!isolated.text.contains("student_student_"));
    }

    #[test]
    fn a_loop_whose_body_starts_with_a_renamed_name_is_guarded() {
        let text = "var<private> count: u32;\nfn slot() -> u32 {\n    loop {count += 1u; if count > 3u { break; }}\n    return count;\n}\n";
        let isolated = Isolated::new(text, &["slot".to_owned()], &[]);
        assert_eq!(isolated.loops, 1);
        assert!(
            isolated.text.contains("loop { if loop_guard_step() { break; }student_count += 1u;"),
            "{}",
            isolated.text
        );
    }

    #[test]
    fn a_constant_in_an_expression_attribute_is_renamed_and_comments_leave_calls() {
        let text = "const N = 2;\nstruct S { @size(N) a: f32, @builtin(position) p: vec4f }\nfn slot(t: texture_2d<f32>, l: i32) -> vec2u {\n    return textureDimensions(t, l // the level\n    ,);\n}\n";
        let isolated = Isolated::new(text, &["slot".to_owned()], &[]);
        assert!(isolated.text.contains("@size(student_N) a: f32, @builtin(position) p: vec4f"), "{}", isolated.text);
        assert!(isolated.text.contains("u32(l))"), "{}", isolated.text);
    }

    #[test]
    fn attributes_numbers_and_members_are_left_alone() {
        let text = "fn position() -> f32 { return 1e-5 + 2.5e3f; }\nfn slot(@builtin(position) p: vec4f) -> f32 { return position() + p.position; }\n";
        let isolated = Isolated::new(text, &["slot".to_owned()], &[]);
        assert!(
            isolated
                .text
                .contains("fn slot(@builtin(position) p: vec4f) -> f32 { return student_position() + p.position; }")
        );
        assert!(isolated.text.contains("return 1e-5 + 2.5e3f;"));
    }
}
