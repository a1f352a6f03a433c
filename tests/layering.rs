//! The layers of docs/architecture.md, enforced: every `use` (and every `crate::…` or `super::…`
//! path) in `src/` is read, resolved to the module it names, and checked against
//!
//! - the crate's layers, each importing only from those below it:
//!   `settings | files | base` ← `output | compare | settings_doc | volume`
//!   ← `scene | linear_output` ← `texture` ← `shaders` ← `trace | gpu` ← `raster` ← `budget | explain | lab`
//!   ← `viewer | course`
//!   ← `web` (← `main.rs`), where modules of one layer never import each other: `base` holds
//!   what `scene` and `volume` share (the ray, the material and texture indices), so the scene
//!   holds volumes and reads their files while `volume` knows nothing of the scene;
//! - inside `raster`: data (`context`, `geometry`, `keys`, `scene_gpu`, `targets`, `uniforms`,
//!   `view`, `view_group`) ← passes (every technique's module) ← frame (`frame`, and `raster` itself);
//! - `gpu` knows nothing of scenes (`scene`, `volume`, `base`);
//! - no two modules importing each other, directly or in a circle.
//!
//! Test code (`#[cfg(test)]` and after) is not read. The checker is tested on made-up files
//! too, so it is known to fail on an import against the layers.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The rank of each top-level module: a module imports only from lower ranks.
const LAYERS: &[(&str, u32)] = &[
    ("settings", 0),
    ("files", 0),
    ("base", 0),
    ("output", 1),
    ("compare", 1),
    ("settings_doc", 1),
    ("volume", 1),
    ("scene", 2),
    ("linear_output", 2),
    ("texture", 3),
    ("shaders", 4),
    ("trace", 5),
    ("gpu", 5),
    ("raster", 6),
    ("budget", 7),
    ("explain", 7),
    ("lab", 7),
    ("viewer", 8),
    ("course", 8),
    ("web", 9),
];

/// Imports the ranks allow but the design does not: the GPU layer knows nothing of scenes.
const FORBIDDEN: &[(&str, &str)] = &[("gpu", "scene"), ("gpu", "volume"), ("gpu", "base")];

/// The layers inside `raster`.
const RASTER_DATA: &[&str] = &["context", "geometry", "keys", "scene_gpu", "targets", "uniforms", "view", "view_group"];
const RASTER_FRAME: &[&str] = &["frame"];

/// A module path without the crate, `raster::shadow::views`; `""` is the crate root.
type Module = String;

/// Every module of the source tree under `src` (but `main.rs`), with its source.
fn modules(src: &Path) -> BTreeMap<Module, String> {
    let mut found = BTreeMap::new();
    for path in common::rust_sources(src) {
        let relative = path.strip_prefix(src).expect("under src").with_extension("");
        let mut parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
        if parts == ["main"] {
            continue;
        }
        if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
            parts.pop();
        }
        found.insert(parts.join("::"), std::fs::read_to_string(&path).expect("reading a source file"));
    }
    found
}

/// The source without comments and without its tests.
fn code(source: &str) -> String {
    let source = source.split("#[cfg(test)]").next().unwrap_or("");
    let mut out = String::new();
    for line in source.lines() {
        out.push_str(line.split("//").next().unwrap_or(""));
        out.push('\n');
    }
    out
}

/// The paths of a `use` tree: `a::{b, c::{d, e}}` is `a::b`, `a::c::d`, `a::c::e`.
fn expand(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let Some(open) = tree.find('{') else { return vec![tree] };
    let (head, body) = (&tree[..open], &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())]);
    let (mut parts, mut depth, mut current) = (Vec::new(), 0, String::new());
    for c in body.chars() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(std::mem::take(&mut current));
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    parts.push(current);
    parts.iter().filter(|p| !p.is_empty()).flat_map(|p| expand(&format!("{head}{p}"))).collect()
}

/// Every path a module's code names through `crate`, `super` or `self`.
fn paths(code: &str) -> Vec<String> {
    let mut paths = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find("use ") {
        let before = rest[..at].chars().last();
        rest = &rest[at + 4..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        if let Some(end) = rest.find(';') {
            paths.extend(expand(&rest[..end]));
        }
    }
    for start in ["crate::", "super::"] {
        let mut rest = code;
        while let Some(at) = rest.find(start) {
            let tail = &rest[at..];
            let end = tail.find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).unwrap_or(tail.len());
            paths.push(tail[..end].trim_end_matches(':').to_string());
            rest = &rest[at + start.len()..];
        }
    }
    paths
}

/// The module each path of `module` names, among `known`.
fn imports(module: &str, code: &str, known: &BTreeSet<Module>) -> BTreeSet<Module> {
    let own: Vec<&str> = if module.is_empty() { Vec::new() } else { module.split("::").collect() };
    let mut found = BTreeSet::new();
    for path in paths(code) {
        let mut parts: Vec<&str> = path.split("::").collect();
        let mut target: Vec<&str> = match parts.first() {
            Some(&"crate") => {
                parts.remove(0);
                Vec::new()
            }
            Some(&"super") | Some(&"self") => {
                let mut base = own.clone();
                while let Some(&first) = parts.first() {
                    match first {
                        "super" => drop(base.pop()),
                        "self" => {}
                        _ => break,
                    }
                    parts.remove(0);
                }
                base
            }
            _ => continue,
        };
        target.extend(parts);
        // The longest prefix that is a module.
        while !target.is_empty() {
            let candidate = target.join("::");
            if known.contains(&candidate) {
                if candidate != module {
                    found.insert(candidate);
                }
                break;
            }
            target.pop();
        }
    }
    found
}

fn top(module: &str) -> &str {
    module.split("::").next().unwrap_or("")
}

/// The raster sub-layer of a module of `raster`: 0 data, 1 passes, 2 frame.
fn raster_layer(module: &str) -> Option<u32> {
    let mut parts = module.split("::");
    if parts.next() != Some("raster") {
        return None;
    }
    Some(match parts.next() {
        None => 2,
        Some(name) if RASTER_FRAME.contains(&name) => 2,
        Some(name) if RASTER_DATA.contains(&name) => 0,
        Some(_) => 1,
    })
}

/// Every import of `graph` against the layers, as `importer → imported: why`.
fn violations(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<String> {
    let rank = |m: &str| LAYERS.iter().find(|(name, _)| *name == top(m)).map(|(_, r)| *r);
    let mut wrong = Vec::new();
    for (from, targets) in graph {
        for to in targets {
            let (a, b) = (top(from), top(to));
            if FORBIDDEN.contains(&(a, b)) {
                wrong.push(format!("{from} → {to}: `{a}` knows nothing of `{b}`"));
            } else if a != b && !a.is_empty() {
                match (rank(from), rank(to)) {
                    (Some(x), Some(y)) if x > y => {}
                    (Some(_), Some(_)) => wrong.push(format!("{from} → {to}: `{a}` may not import `{b}`")),
                    _ => wrong.push(format!("{from} → {to}: `{a}` or `{b}` has no layer in tests/layering.rs")),
                }
            }
            if let (Some(x), Some(y)) = (raster_layer(from), raster_layer(to))
                && x < y
            {
                let names = ["data", "passes", "frame"];
                wrong.push(format!(
                    "{from} → {to}: raster's {} may not import its {}",
                    names[x as usize], names[y as usize]
                ));
            }
        }
    }
    wrong
}

/// Modules in a circle of imports, one list per circle (Tarjan's strongly connected components).
fn circles(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    struct State<'g> {
        graph: &'g BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        circles: Vec<Vec<Module>>,
    }
    fn visit<'g>(state: &mut State<'g>, v: &'g str) {
        let n = state.index.len();
        state.index.insert(v, n);
        state.low.insert(v, n);
        state.stack.push(v);
        for w in state.graph.get(v).into_iter().flatten() {
            if !state.index.contains_key(w.as_str()) {
                visit(state, w);
                let low = state.low[v].min(state.low[w.as_str()]);
                state.low.insert(v, low);
            } else if state.stack.contains(&w.as_str()) {
                let low = state.low[v].min(state.index[w.as_str()]);
                state.low.insert(v, low);
            }
        }
        if state.low[v] == state.index[v] {
            let mut circle = Vec::new();
            while let Some(w) = state.stack.pop() {
                circle.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if circle.len() > 1 {
                state.circles.push(circle);
            }
        }
    }
    let mut state =
        State { graph, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), circles: Vec::new() };
    for v in graph.keys() {
        if !state.index.contains_key(v.as_str()) {
            visit(&mut state, v);
        }
    }
    state.circles
}

fn graph_of(sources: &BTreeMap<Module, String>) -> BTreeMap<Module, BTreeSet<Module>> {
    let known: BTreeSet<Module> = sources.keys().cloned().collect();
    sources.iter().map(|(module, source)| (module.clone(), imports(module, &code(source), &known))).collect()
}

#[test]
fn every_import_follows_the_layers() {
    let sources = modules(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    assert!(sources.len() > 50, "found {} modules", sources.len());
    let graph = graph_of(&sources);
    let wrong = violations(&graph);
    assert!(wrong.is_empty(), "imports against docs/architecture.md's layers:\n{}", wrong.join("\n"));
    let circles = circles(&graph);
    assert!(circles.is_empty(), "modules that import each other: {circles:?}");
}

/// The checker sees what it must: made-up modules with an import against each rule.
#[test]
fn the_checker_finds_imports_against_the_layers() {
    let source = |pairs: &[(&str, &str)]| -> BTreeMap<Module, String> {
        pairs.iter().map(|(m, s)| (m.to_string(), s.to_string())).collect()
    };
    let check = |pairs: &[(&str, &str)]| {
        let graph = graph_of(&source(pairs));
        (violations(&graph), circles(&graph))
    };
    // Below the layers, nothing to report; a comment or a test is not an import.
    let fine = check(&[
        ("scene", "use crate::settings::RenderSettings;"),
        ("settings", "// use crate::scene::Scene;\n#[cfg(test)]\nuse crate::scene::Scene;"),
        ("raster::frame", "use super::{targets::HDR_FORMAT, shadow::ShadowPass};"),
        ("raster::shadow", "use super::targets::DEPTH_FORMAT;"),
        ("raster::targets", ""),
    ]);
    assert_eq!(fine, (vec![], vec![]));
    // Upwards: gpu naming the scene, through a nested `use` tree and through a path.
    let (wrong, _) = check(&[
        ("gpu::mipmap", "use crate::{shaders, scene::{Texture, ColorSpace}};"),
        ("gpu::texture", "fn f(t: &crate::raster::targets::FrameTargets) {}"),
        ("scene", ""),
        ("shaders", ""),
        ("raster::targets", ""),
    ]);
    assert_eq!(wrong.len(), 2, "{wrong:?}");
    assert!(wrong[0].contains("`gpu` knows nothing of `scene`"), "{wrong:?}");
    // Sideways: the tracer and the GPU layer do not know each other.
    let (wrong, _) = check(&[("trace", "use crate::gpu::Gpu;"), ("gpu", "")]);
    assert_eq!(wrong.len(), 1, "{wrong:?}");
    // The scene and its volumes: the scene may hold volumes, a volume may not read the scene's
    // camera (its ray comes from `base`).
    let (wrong, circles) = check(&[
        ("scene", "use crate::volume::Volume;"),
        ("scene::camera", "use crate::base::Ray;"),
        ("volume", "use crate::scene::camera::Ray;\nuse crate::base::MaterialId;"),
        ("base", ""),
    ]);
    assert_eq!(wrong.len(), 1, "{wrong:?}");
    assert!(wrong[0].starts_with("volume → scene::camera: `volume` may not import `scene`"), "{wrong:?}");
    assert!(circles.is_empty(), "{circles:?}");
    // Inside raster: a pass reaching into the frame, data reaching into a pass.
    let (wrong, _) = check(&[
        ("raster::volume", "use super::frame::Renderer;"),
        ("raster::frame", ""),
        ("raster::view", "use super::super::volume::VolumeSet;"),
    ]);
    assert_eq!(wrong.len(), 2, "{wrong:?}");
    // A circle.
    let (_, circles) = check(&[("trace::a", "use super::b::X;"), ("trace::b", "use super::a::Y;")]);
    assert_eq!(circles.len(), 1);
}
