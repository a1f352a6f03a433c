//! No function in `src/` runs over [`MAX_LINES`] lines, counted from its `fn` line to its closing
//! brace, both included: a longer one is split along its steps into helpers that name them
//! (issue 37). Test code inside `src/` is held to it too.
//!
//! The checker blanks comments, string and character literals before it matches braces, so a
//! `"}"` or a `// {` does not end or open a body, and a lifetime `'a` is not a character. It is
//! tested on a made-up source too, so it is known to fail on a function one line too long.

mod common;

use std::path::Path;

/// The most lines a function may have.
const MAX_LINES: usize = 100;

/// A function found in a source: its name, the line of its `fn` (from 1), and its length in lines.
#[derive(Debug, PartialEq)]
struct Function {
    name: String,
    line: usize,
    lines: usize,
}

/// `source` with comments and string and character literals replaced by spaces, line breaks kept
/// (so lines and offsets stay where they were).
fn blanked(source: &str) -> String {
    let chars: Vec<char> = source.chars().collect();
    let mut out = String::with_capacity(source.len());
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut i = 0;
    // Copies `chars[from..to]` as blanks.
    let blank = |out: &mut String, from: usize, to: usize| {
        out.extend(chars[from..to.min(chars.len())].iter().map(|&c| if c == '\n' { '\n' } else { ' ' }));
    };
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        let prev = if i == 0 { None } else { Some(chars[i - 1]) };
        let end = if c == '/' && next == Some('/') {
            // A line comment, to the end of the line.
            (i..chars.len()).find(|&j| chars[j] == '\n').unwrap_or(chars.len())
        } else if c == '/' && next == Some('*') {
            // A block comment; they nest.
            let (mut depth, mut j) = (0, i);
            loop {
                match (chars.get(j), chars.get(j + 1)) {
                    (Some('/'), Some('*')) => (depth, j) = (depth + 1, j + 2),
                    (Some('*'), Some('/')) => (depth, j) = (depth - 1, j + 2),
                    (Some(_), _) => j += 1,
                    (None, _) => break j,
                }
                if depth == 0 {
                    break j;
                }
            }
        } else if c == 'r'
            && !prev.is_some_and(|p| is_ident(p) && !(p == 'b' && (i < 2 || !is_ident(chars[i - 2]))))
            && matches!(next, Some('"' | '#'))
            && let Some(quote) = (i + 1..chars.len()).find(|&j| chars[j] != '#')
            && chars[quote] == '"'
        {
            // A raw string, r"…" or r#"…"#, to the quote followed by as many hashes.
            let hashes = quote - i - 1;
            let closes = |j: usize| chars[j] == '"' && (1..=hashes).all(|k| chars.get(j + k) == Some(&'#'));
            (quote + 1..chars.len()).find(|&j| closes(j)).map_or(chars.len(), |j| j + 1 + hashes)
        } else if c == '"' {
            // A string, with its escapes.
            let mut j = i + 1;
            while j < chars.len() && chars[j] != '"' {
                j += if chars[j] == '\\' { 2 } else { 1 };
            }
            j + 1
        } else if c == '\'' && next == Some('\\') {
            // An escaped character, '\n', '\'', '\u{7d}'.
            (i + 3..chars.len()).find(|&j| chars[j] == '\'').map_or(chars.len(), |j| j + 1)
        } else if c == '\'' && chars.get(i + 2) == Some(&'\'') {
            // A character, '{'; anything else after a quote is a lifetime or a label.
            i + 3
        } else {
            out.push(c);
            i += 1;
            continue;
        };
        blank(&mut out, i, end);
        i = end;
    }
    out
}

/// Every function with a body in `source`, nested ones included.
fn functions(source: &str) -> Vec<Function> {
    let code: Vec<char> = blanked(source).chars().collect();
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    // The line of each offset, from 1.
    let lines: Vec<usize> = code
        .iter()
        .scan(1, |line, &c| {
            let this = *line;
            *line += usize::from(c == '\n');
            Some(this)
        })
        .collect();
    let line_of = |at: usize| lines[at];
    let mut found = Vec::new();
    for at in 0..code.len().saturating_sub(2) {
        let keyword = code[at] == 'f' && code[at + 1] == 'n' && code[at + 2].is_whitespace();
        if !keyword || (at > 0 && is_ident(code[at - 1])) {
            continue;
        }
        // `fn name`, not the type `fn(…)`.
        let start = (at + 2..code.len()).find(|&j| !code[j].is_whitespace()).unwrap_or(code.len());
        let name: String = code[start..].iter().take_while(|&&c| is_ident(c)).collect();
        if name.is_empty() {
            continue;
        }
        // The body opens at the first `{` outside the signature's brackets; a `;` there ends a
        // declaration without one (`[u8; 4]` is inside brackets).
        let mut depth = 0i32;
        let mut open = None;
        for (j, &c) in code.iter().enumerate().skip(start) {
            match c {
                '(' | '[' => depth += 1,
                ')' | ']' => depth -= 1,
                '{' if depth == 0 => {
                    open = Some(j);
                    break;
                }
                ';' if depth == 0 => break,
                _ => {}
            }
        }
        let Some(open) = open else { continue };
        let mut depth = 0;
        let close = (open..code.len()).find(|&j| {
            match code[j] {
                '{' => depth += 1,
                '}' => depth -= 1,
                _ => {}
            }
            depth == 0
        });
        let close = close.unwrap_or(code.len() - 1);
        let line = line_of(at);
        found.push(Function { name, line, lines: line_of(close) - line + 1 });
    }
    found
}

/// The functions of `source` longer than `max` lines.
fn too_long(source: &str, max: usize) -> Vec<Function> {
    functions(source).into_iter().filter(|f| f.lines > max).collect()
}

#[test]
fn no_function_in_src_runs_over_100_lines() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let files = common::rust_sources(&src);
    assert!(files.len() > 50, "found {} files", files.len());
    let mut long = Vec::new();
    let mut count = 0;
    for path in &files {
        let source = std::fs::read_to_string(path).expect("reading a source file");
        count += functions(&source).len();
        for f in too_long(&source, MAX_LINES) {
            let path = path.strip_prefix(&src).expect("under src").display();
            long.push(format!("src/{path}:{} `{}`: {} lines", f.line, f.name, f.lines));
        }
    }
    assert!(count > 1000, "found {count} functions");
    assert!(long.is_empty(), "functions over {MAX_LINES} lines:\n{}", long.join("\n"));
}

/// The WGSL is held to the same limit, and the shading of a surface, which every technique
/// reaches into, to 80 lines: each technique's part in a function of its own
/// (`shaders/common/surface.wgsl`).
#[test]
fn no_wgsl_function_runs_over_100_lines_and_the_shading_over_80() {
    let files = common::sources(&Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders"), "wgsl");
    assert!(files.len() > 15, "found {} files", files.len());
    let mut long = Vec::new();
    let mut shading = None;
    for path in &files {
        let source = std::fs::read_to_string(path).expect("reading a shader");
        for f in functions(&source) {
            if f.name == "shade_surface" {
                shading = Some(f.lines);
            }
            if f.lines > MAX_LINES {
                long.push(format!("{}:{} `{}`: {} lines", path.display(), f.line, f.name, f.lines));
            }
        }
    }
    assert!(long.is_empty(), "WGSL functions over {MAX_LINES} lines:\n{}", long.join("\n"));
    let shading = shading.expect("shade_surface is found");
    assert!(shading <= 80, "shade_surface has {shading} lines");
}

/// The viewer's frame stays one reader's worth: `Viewer` holds at most 15 fields (each tool's
/// state is its own: the script, the cursor's tools, the inspection, the error budget, the lab)
/// and `src/viewer/frame.rs` at most 500 lines (the steps, the lab's part, the settings' changes
/// and each tool's work live beside it).
#[test]
fn the_viewer_is_tools_around_a_small_frame() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/viewer/frame.rs");
    let source = std::fs::read_to_string(&path).expect("reading the viewer's frame");
    let lines = source.lines().count();
    assert!(lines <= 500, "src/viewer/frame.rs has {lines} lines");
    let fields = struct_fields(&source, "Viewer").expect("pub struct Viewer in src/viewer/frame.rs");
    assert!(fields.len() <= 15, "Viewer has {} fields: {fields:?}", fields.len());
    // The counter can tell.
    let made_up = "pub struct Viewer {\n    /// A doc.\n    pub a: u32,\n    b: Option<(u32, u32)>,\n    #[cfg(x)]\n    c: Vec<u8>,\n}\n";
    assert_eq!(struct_fields(made_up, "Viewer").unwrap(), ["a", "b", "c"]);
}

/// The fields of `pub struct NAME { … }` in `source`, by name.
fn struct_fields(source: &str, name: &str) -> Option<Vec<String>> {
    let start = source.find(&format!("pub struct {name} {{"))?;
    let body = &source[start..];
    let body = &body[body.find('{')? + 1..body.find("\n}")?];
    Some(
        body.lines()
            .map(str::trim)
            .filter(|line| !line.starts_with("//") && !line.starts_with("#["))
            .filter_map(|line| {
                let line = line.trim_start_matches("pub(super) ").trim_start_matches("pub ");
                let (field, _) = line.split_once(':')?;
                field.chars().all(|c| c.is_ascii_alphanumeric() || c == '_').then(|| field.to_owned())
            })
            .collect(),
    )
}

/// The checker on a made-up source: braces in comments, strings, raw strings and characters,
/// lifetimes, an array type in a signature, a nested function, a declaration without a body, a
/// function of exactly the limit and one a line over it.
#[test]
fn the_checker_measures_functions() {
    let body = |n: usize| (0..n).map(|i| format!("    let x{i} = {i};\n")).collect::<String>();
    let source = [
        "/// fn not_a_function() {\n",
        "fn short<'a>(s: &'a str, b: [u8; 4]) -> char {\n",
        "    let _ = \"}\\\"}\"; let _ = r#\"}\"#; let _ = b'}'; /* } /* } */ */\n",
        "    fn inner(f: fn(u8) -> u8) {}\n",
        "    '}'\n",
        "}\n",
        "trait T { fn declared(&self) -> [u8; 2]; }\n",
        &format!("fn over() {{\n{}}}\n", body(99)),
        &format!("impl X {{\n    fn exactly() {{\n{}    }}\n}}\n", body(98)),
    ]
    .concat();
    let found: Vec<(String, usize, usize)> =
        functions(&source).into_iter().map(|f| (f.name, f.line, f.lines)).collect();
    let expected = [("short", 2, 5), ("inner", 4, 1), ("over", 8, 101), ("exactly", 110, 100)];
    assert_eq!(found, expected.map(|(n, line, lines)| (n.to_string(), line, lines)));
    assert_eq!(too_long(&source, MAX_LINES), [Function { name: "over".into(), line: 8, lines: 101 }]);
}
