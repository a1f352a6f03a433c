//! The command lines of a chapter's shell blocks, read as the shell runs them: just enough of
//! the shell for what a course prints (continued lines, `;`, `for … in …; do … done`, quotes,
//! backslashes, `$name`, comments), so that a link is made from exactly what a student types.
//! Anything more (pipes, `$(…)`, `&&`) is kept as words, and the command it makes is then not
//! one of Mirador's, which the caller says.

use std::collections::HashMap;

/// One command a shell block runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Printed {
    /// The line of the block's closing fence (from 0): where what is said of the block goes.
    pub block_end: usize,
    /// Its words, quotes removed and variables replaced (`cargo`, `run`, `--release`, `--`, …).
    pub words: Vec<String>,
}

/// Every command of every shell block (fenced as `sh`, `bash` or `shell`) of `markdown`, in order.
pub fn commands(markdown: &str) -> Vec<Printed> {
    let lines: Vec<&str> = markdown.lines().collect();
    let mut printed = Vec::new();
    let mut start = None;
    for (i, line) in lines.iter().enumerate() {
        let fence = line.trim_start();
        match start {
            None if ["```sh", "```bash", "```shell"].contains(&fence.trim_end()) => start = Some(i + 1),
            Some(first) if fence.starts_with("```") => {
                let statements = statements(&lines[first..i].join("\n"));
                let mut words = Vec::new();
                run(&statements, &HashMap::new(), &mut words);
                printed.extend(words.into_iter().map(|words| Printed { block_end: i, words }));
                start = None;
            }
            _ => {}
        }
    }
    printed
}

/// A piece of a word: text, or a variable's value.
#[derive(Clone, Debug)]
enum Piece {
    Text(String),
    Variable(String),
}

type Word = Vec<Piece>;

/// The block's statements (split at newlines and `;`), each a list of words; comments dropped,
/// continued lines joined.
fn statements(text: &str) -> Vec<Vec<Word>> {
    let mut statements = vec![Vec::new()];
    let mut word: Option<Word> = None;
    let mut chars = text.chars().peekable();
    let mut quote: Option<char> = None;
    let push_text = |word: &mut Option<Word>, c: char| {
        let pieces = word.get_or_insert_with(Vec::new);
        match pieces.last_mut() {
            Some(Piece::Text(text)) => text.push(c),
            _ => pieces.push(Piece::Text(c.to_string())),
        }
    };
    while let Some(c) = chars.next() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some('"') | None, '\\') => match chars.next() {
                Some('\n') => {}
                Some(next) => push_text(&mut word, next),
                None => {}
            },
            (Some('"') | None, '$') => {
                let braced = chars.next_if_eq(&'{').is_some();
                let mut name = String::new();
                while let Some(c) = chars.next_if(|c| c.is_ascii_alphanumeric() || *c == '_') {
                    name.push(c);
                }
                if braced {
                    chars.next_if_eq(&'}');
                }
                word.get_or_insert_with(Vec::new).push(Piece::Variable(name));
            }
            (Some(_), c) => push_text(&mut word, c),
            (None, '"' | '\'') => {
                word.get_or_insert_with(Vec::new);
                quote = Some(c);
            }
            (None, '#') if word.is_none() => while chars.next_if(|c| *c != '\n').is_some() {},
            (None, ' ' | '\t') => statements.last_mut().unwrap().extend(word.take()),
            (None, '\n' | ';') => {
                statements.last_mut().unwrap().extend(word.take());
                statements.push(Vec::new());
            }
            (None, c) => push_text(&mut word, c),
        }
    }
    statements.last_mut().unwrap().extend(word.take());
    statements.retain(|s| !s.is_empty());
    statements
}

/// The word's text with the variables of `env` in it (an unknown one is empty, as in the shell).
fn expand(word: &Word, env: &HashMap<String, String>) -> String {
    word.iter()
        .map(|piece| match piece {
            Piece::Text(text) => text.as_str(),
            Piece::Variable(name) => env.get(name).map_or("", String::as_str),
        })
        .collect()
}

/// Runs the statements: each command's words into `out`, each `for` loop's body once per value.
fn run(statements: &[Vec<Word>], env: &HashMap<String, String>, out: &mut Vec<Vec<String>>) {
    let mut i = 0;
    while i < statements.len() {
        let words: Vec<String> = statements[i].iter().map(|w| expand(w, env)).collect();
        if words.len() >= 3 && words[0] == "for" && words[2] == "in" {
            let (body, next) = loop_body(statements, i + 1);
            for value in &words[3..] {
                let mut inner = env.clone();
                inner.insert(words[1].clone(), value.clone());
                run(&body, &inner, out);
            }
            i = next;
            continue;
        }
        out.push(words);
        i += 1;
    }
}

/// A loop's body: the statements after its `do` up to its `done` (nested loops kept whole), and
/// the index after the `done`.
fn loop_body(statements: &[Vec<Word>], from: usize) -> (Vec<Vec<Word>>, usize) {
    let is = |word: Option<&Word>, keyword: &str| {
        word.is_some_and(|w| matches!(w.as_slice(), [Piece::Text(t)] if t == keyword))
    };
    let mut body = Vec::new();
    let mut depth = 0;
    for (i, statement) in statements.iter().enumerate().skip(from) {
        let mut statement = statement.clone();
        if is(statement.first(), "do") && depth == 0 && body.is_empty() {
            statement.remove(0);
            if statement.is_empty() {
                continue;
            }
        }
        if is(statement.first(), "for") {
            depth += 1;
        }
        if is(statement.first(), "done") {
            if depth == 0 {
                return (body, i + 1);
            }
            depth -= 1;
        }
        body.push(statement);
    }
    (body, statements.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(markdown: &str) -> Vec<String> {
        commands(markdown).into_iter().map(|p| p.words.join(" ")).collect()
    }

    #[test]
    fn loops_continued_lines_and_quotes_read_as_the_shell_reads_them() {
        let block = "text\n```sh\nfor f in a b; do\n  cargo run -- render s.toml -o floor-$f.png \\\n      --set x=\"$f\"\ndone\n\
                     cargo run -- trace s.toml --set 'camera.eye=[6.0, 3.4]' --set y=\\\"q\\\"   # a comment\n```\n";
        assert_eq!(
            words(block),
            [
                "cargo run -- render s.toml -o floor-a.png --set x=a",
                "cargo run -- render s.toml -o floor-b.png --set x=b",
                "cargo run -- trace s.toml --set camera.eye=[6.0, 3.4] --set y=\"q\"",
            ]
        );
        assert_eq!(commands(block)[0].block_end, 7);
    }

    #[test]
    fn one_line_loops_and_nested_loops_run_their_bodies_once_per_value() {
        let block = "```bash\nfor s in 2 3; do cargo run --example flake -- $s; done\nfor a in x y; do\n  for b in 1 2; do\n    echo ${a}$b\n  done\ndone\n```";
        assert_eq!(
            words(block),
            [
                "cargo run --example flake -- 2",
                "cargo run --example flake -- 3",
                "echo x1",
                "echo x2",
                "echo y1",
                "echo y2"
            ]
        );
    }

    #[test]
    fn other_blocks_are_not_commands() {
        assert!(words("```text\ncargo run\n```\n```toml\na = 1\n```").is_empty());
    }
}
