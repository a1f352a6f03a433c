//! The student's file: what it replaces, and whether it compiles. Signatures are checked first,
//! because a wrong one would otherwise be reported where Mirador calls the function, in a file
//! the student has never seen; then naga parses and validates every surface module with the
//! student's functions in, and an error in the student's text is given at its own
//! `file:line:column`.

use super::Lab;
use super::isolate::Isolated;
use crate::shaders::{self, Profile, Wgsl};

/// A problem with the student's file, where it is.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Problem {
    /// 1-based line and column in the student's file; `None` for the file as a whole.
    pub line: Option<u32>,
    pub column: Option<u32>,
    /// The line's text.
    pub text: Option<String>,
    pub message: String,
}

impl Problem {
    /// `file:line:column: message`, the line under it.
    pub fn display(&self, file: &str) -> String {
        match (self.line, self.column, &self.text) {
            (Some(line), Some(column), Some(text)) => {
                format!(
                    "{file}:{line}:{column}: {}\n    {}\n    {}^",
                    self.message,
                    text,
                    " ".repeat(column as usize - 1)
                )
            }
            _ => format!("{file}: {}", self.message),
        }
    }
}

/// The name a declaration declares: `const NAME = …;`, `fn NAME(…`.
pub fn declared_name(declaration: &str) -> Option<String> {
    let rest =
        declaration.trim_start().strip_prefix("const ").or_else(|| declaration.trim_start().strip_prefix("fn "))?;
    let name: String = rest.trim_start().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
    (!name.is_empty()).then_some(name)
}

/// Mirador's own declaration of the function `name` in the shared WGSL, and the comment lines
/// right above it.
pub fn builtin_declaration(name: &str) -> Option<(String, String)> {
    for (_, text) in shaders::COMMON.iter().chain(shaders::SURFACE) {
        if let Some(range) = shaders::declaration(text, name) {
            let before = &text[..range.start];
            let comments: Vec<&str> = before.lines().rev().take_while(|line| line.starts_with("//")).collect();
            let comments: String = comments.iter().rev().map(|line| format!("{line}\n")).collect();
            return Some((comments, text[range].to_owned()));
        }
    }
    None
}

/// The WGSL the reference image is drawn with: Mirador's own functions (the answer key), routed as
/// the lab routes them, and compiled as a student's file is ([`student`]), so that the reference
/// and the student meet the same device.
pub fn reference(lab: &Lab) -> Wgsl {
    student(lab, &lab.solution())
}

/// The WGSL the student's image is drawn with: the slots from `student` (its helpers' names put
/// apart from Mirador's and its loops bounded: [`isolated`]), the lab's routes after them. The
/// student's text comes first in what is appended, so its offsets map back to its own.
pub fn student(lab: &Lab, student: &str) -> Wgsl {
    compiled(lab, &isolated(lab, student))
}

/// [`student`], and beside it the same with the slots' values NaN wherever the loop guard cut the
/// student's loops off ([`Isolated::poisoned`]): drawn beside it, the images differ where the
/// guard decided a value. `None` when the student's file has no loop (or no slot that returns
/// floats). The text is isolated once for both.
pub fn student_and_poisoned(lab: &Lab, student: &str) -> (Wgsl, Option<Wgsl>) {
    let isolated = isolated(lab, student);
    (compiled(lab, &isolated), isolated.poisoned().map(|text| routed(lab, text, &isolated)))
}

/// [`student`] of a text already isolated.
fn compiled(lab: &Lab, isolated: &Isolated) -> Wgsl {
    routed(lab, &isolated.text, isolated)
}

/// `text` (the isolated student's, or its poisoned twin) in place of the slots, the lab's routes
/// after it.
fn routed(lab: &Lab, text: &str, isolated: &Isolated) -> Wgsl {
    let mut replaced: Vec<String> = lab.slots.iter().map(|slot| slot.name.clone()).collect();
    replaced.extend(lab.route_names());
    let code = format!("{text}{}", lab.routes.join("\n"));
    Wgsl::replacing(replaced, code).with_tripped(isolated.tripped())
}

/// The student's text as every module compiles it: its own names renamed apart from every text
/// it is composed with, its loops guarded ([`super::isolate`]).
pub fn isolated(lab: &Lab, student: &str) -> Isolated {
    let slots: Vec<String> = lab.slots.iter().map(|slot| slot.name.clone()).collect();
    let passes = [shaders::SCENE, shaders::TRANSPARENCY, shaders::REFRACTION, shaders::VOLUME];
    let profiles = [Profile::Standard.wgsl().1, Profile::WebGl2.wgsl().1];
    let routes = lab.routes.join("\n");
    let others: Vec<&str> = shaders::COMMON
        .iter()
        .chain(shaders::SURFACE)
        .map(|(_, text)| *text)
        .chain(passes)
        .chain(profiles)
        .chain([super::harness::BINDINGS, super::harness::ENTRY, routes.as_str()])
        .collect();
    Isolated::new(student, &slots, &others)
}

/// The slots whose body in `text` is still the stub's neutral one (comments and spacing aside).
pub fn untouched_slots(lab: &Lab, text: &str) -> Vec<String> {
    let stub = lab.stub();
    let body = |text: &str, name: &str| {
        let range = shaders::declaration(text, name)?;
        let declaration = &text[range];
        let body = &declaration[declaration.find('{')?..];
        let code: String = body.lines().map(|line| line.split("//").next().unwrap_or("")).collect();
        Some(code.split_whitespace().collect::<String>())
    };
    lab.slots
        .iter()
        .filter(|slot| body(text, &slot.name).is_some_and(|theirs| Some(theirs) == body(&stub, &slot.name)))
        .map(|slot| slot.name.clone())
        .collect()
}

/// Everything wrong with the student's file, empty when every surface module compiles with it.
pub fn problems(lab: &Lab, text: &str) -> Vec<Problem> {
    problems_on(lab, text, Profile::Standard)
}

/// [`problems`] for a device of `profile`: on WebGL2, the modules must also be written as GLSL
/// ES 3.00 (naga checks WGSL, not what WebGL2's shading language lacks: `textureNumLevels`, a
/// depth texel read, `firstLeadingBit`).
pub fn problems_on(lab: &Lab, text: &str, profile: Profile) -> Vec<Problem> {
    let signatures = signature_problems(lab, text);
    if !signatures.is_empty() {
        return signatures;
    }
    let compile = |text: &str| {
        compile_problem(lab, text).or_else(|| match profile {
            // The page's WebGPU module never runs on WebGL2, and leaves the GLSL writer out.
            Profile::WebGl2 if cfg!(any(not(target_arch = "wasm32"), feature = "webgl2")) => {
                webgl2_failures(&student(lab, text)).into_iter().next().map(|failure| Problem {
                    line: None,
                    column: None,
                    text: None,
                    message: format!("WebGL2 cannot compile it: {failure}"),
                })
            }
            Profile::WebGl2 | Profile::Standard => None,
        })
    };
    let Some(mut problem) = compile(text) else {
        return Vec::new();
    };
    if problem.line.is_none() {
        // naga gave no place: find the function whose own replacement by Mirador's cures it.
        for slot in &lab.slots {
            let range = shaders::declaration(text, &slot.name).expect("the signatures were checked");
            let (_, builtin) = builtin_declaration(&slot.name).expect("a lab's slots are Mirador's functions");
            let mut cured = text.to_owned();
            cured.replace_range(range.clone(), &builtin);
            if compile(&cured).is_none() {
                let line = text[..range.start].matches('\n').count() as u32 + 1;
                problem.line = Some(line);
                problem.column = Some(1);
                problem.text = text.lines().nth(line as usize - 1).map(str::to_owned);
                problem.message = format!("in `{}` (naga gives no closer place): {}", slot.name, problem.message);
                break;
            }
        }
    }
    vec![problem]
}

/// naga's first complaint about a surface module or the known-answer harness with `text` in.
fn compile_problem(lab: &Lab, text: &str) -> Option<Problem> {
    let isolated = isolated(lab, text);
    let wgsl = compiled(lab, &isolated);
    let passes = [shaders::SCENE, shaders::TRANSPARENCY, shaders::REFRACTION, shaders::VOLUME];
    for pass in passes {
        let composed = wgsl.compose_surface(pass);
        let start = composed.len() - wgsl.code().len();
        if let Some(problem) = naga_problem(&composed, start, text, &isolated) {
            return Some(problem);
        }
    }
    let harness = super::harness::Harness::module(&wgsl, "vec4f(0.0)");
    let start = harness.len() - wgsl.code().len();
    naga_problem(&harness, start, text, &isolated)
}

/// Each slot's signature against Mirador's: the parameter and result types, names aside.
fn signature_problems(lab: &Lab, text: &str) -> Vec<Problem> {
    let mut problems = Vec::new();
    for slot in &lab.slots {
        let (_, builtin) = builtin_declaration(&slot.name).expect("a lab's slots are Mirador's functions");
        let wanted = signature(&builtin);
        match shaders::declaration(text, &slot.name) {
            None => problems.push(Problem {
                line: None,
                column: None,
                text: None,
                message: format!("`{}` is missing: the lab calls `{}`", slot.name, header(&builtin)),
            }),
            Some(range) => {
                let theirs = signature(&text[range.clone()]);
                if theirs != wanted {
                    let line = text[..range.start].matches('\n').count() as u32 + 1;
                    problems.push(Problem {
                        line: Some(line),
                        column: Some(1),
                        text: text.lines().nth(line as usize - 1).map(str::to_owned),
                        message: format!(
                            "`{}` must keep its signature `{}` (the parameters' names may change, not their types)",
                            slot.name,
                            header(&builtin)
                        ),
                    });
                }
            }
        }
    }
    problems
}

/// A function's header, `fn name(…) -> T`, on one line.
fn header(declaration: &str) -> String {
    let head = &declaration[..declaration.find('{').unwrap_or(declaration.len())];
    head.split_whitespace().collect::<Vec<_>>().join(" ").replace("( ", "(").replace(", )", ")").replace(",)", ")")
}

/// The types of a function's parameters and its result, spelled one way (`vec3<f32>` as
/// `vec3f`), names and spaces left out.
fn signature(declaration: &str) -> (Vec<String>, String) {
    let head = &declaration[..declaration.find('{').unwrap_or(declaration.len())];
    let (Some(open), Some(close)) = (head.find('('), head.rfind(')')) else {
        return (Vec::new(), String::new());
    };
    let params = split_top_level(&head[open + 1..close])
        .into_iter()
        .filter(|p| !p.trim().is_empty())
        .map(|p| canonical_type(p.split_once(':').map_or("", |(_, t)| t)))
        .collect();
    let result = head[close + 1..].trim().strip_prefix("->").map(canonical_type).unwrap_or_default();
    (params, result)
}

fn split_top_level(list: &str) -> Vec<&str> {
    let (mut depth, mut start, mut parts) = (0i32, 0, Vec::new());
    for (i, c) in list.char_indices() {
        match c {
            '<' | '(' => depth += 1,
            '>' | ')' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&list[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&list[start..]);
    parts
}

fn canonical_type(ty: &str) -> String {
    let mut ty: String = ty.chars().filter(|c| !c.is_whitespace()).collect();
    for n in 2..=4 {
        for (scalar, suffix) in [("f32", "f"), ("i32", "i"), ("u32", "u")] {
            ty = ty.replace(&format!("vec{n}<{scalar}>"), &format!("vec{n}{suffix}"));
        }
    }
    ty
}

/// naga's first complaint about `composed`, located in the student's `text` when it falls in it
/// (`isolated`, the text as compiled, begins at byte `start` of `composed`).
fn naga_problem(composed: &str, start: usize, text: &str, isolated: &Isolated) -> Option<Problem> {
    let (message, offset) = match naga::front::wgsl::parse_str(composed) {
        Err(error) => (error.message().to_owned(), error.location(composed).map(|l| l.offset as usize)),
        Ok(module) => {
            let mut validator =
                naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all());
            let error = validator.validate(&module).err()?;
            let mut message = error.as_inner().to_string();
            let mut cause = std::error::Error::source(error.as_inner());
            while let Some(inner) = cause {
                message.push_str(": ");
                message.push_str(&inner.to_string());
                cause = inner.source();
            }
            (message, error.location(composed).map(|l| l.offset as usize))
        }
    };
    let message = isolated.unprefixed(&message);
    let within = offset.and_then(|offset| offset.checked_sub(start)).and_then(|within| isolated.original(within));
    match (within, offset) {
        (Some(within), _) => {
            let within = within.min(text.len());
            let line = text[..within].matches('\n').count() as u32 + 1;
            let line_start = text[..within].rfind('\n').map_or(0, |n| n + 1);
            let column = text[line_start..within].chars().count() as u32 + 1;
            Some(Problem {
                line: Some(line),
                column: Some(column),
                text: text.lines().nth(line as usize - 1).map(str::to_owned),
                message,
            })
        }
        (None, Some(offset)) if offset >= start => {
            // Past the student's text (the guard's declarations, the lab's routes): what the
            // student left open runs into them.
            let line = text.lines().count().max(1) as u32;
            Some(Problem {
                line: Some(line),
                column: Some(1),
                text: text.lines().last().map(str::to_owned),
                message: format!("at the end of your file (is a `}}` or a `;` missing?): {message}"),
            })
        }
        (None, Some(offset)) => {
            // In Mirador's code: say in which of its files, so a teacher can tell.
            let file = composed[..offset]
                .rfind("// ---- ")
                .map(|at| composed[at + 8..].lines().next().unwrap_or("").to_owned());
            let place = file.map_or_else(|| "the pass's own file".to_owned(), |f| format!("shaders/{f}"));
            Some(Problem {
                line: None,
                column: None,
                text: None,
                message: format!("{message} (in Mirador's {place}, where it uses your functions)"),
            })
        }
        (None, None) => Some(Problem { line: None, column: None, text: None, message }),
    }
}

/// Built-in functions GLSL ES 3.10 added, which naga's writer emits for ES 3.00 all the same
/// (it checks types and qualifiers against the version, not every function).
const LATER_BUILTINS: &[&str] = &[
    "textureGather",
    "textureGatherOffset",
    "textureQueryLevels",
    "findMSB",
    "findLSB",
    "bitCount",
    "bitfieldExtract",
    "bitfieldInsert",
    "bitfieldReverse",
    "imageLoad",
    "imageStore",
];

/// Every entry point of every pass of `wgsl` (and of the known-answer tests' harness), composed
/// for the WebGL2 profile, that WebGL2 cannot compile, as `pass::entry: why`: each written as GLSL ES 3.00 by naga, as wgpu's GL
/// backend writes it in the page. Entry points that write a storage buffer (`explain`'s) are
/// left out: a WebGL2 device never draws with them.
pub fn webgl2_failures(wgsl: &Wgsl) -> Vec<String> {
    webgl2_written(wgsl, Profile::WebGl2).1
}

/// The entry points of `wgsl`'s passes composed for `profile` that GLSL ES 3.00 takes, and those
/// it does not, with why (`tests/webgl2.rs` checks the standard profile fails, so this can).
pub fn webgl2_written(wgsl: &Wgsl, profile: Profile) -> (Vec<String>, Vec<String>) {
    let (mut written, mut failed) = (Vec::new(), Vec::new());
    let wgsl = wgsl.for_profile(profile);
    // And the known-answer tests' one-pixel draw, which the page runs on WebGL2 too.
    let harness = ("lab", super::harness::Harness::module(&wgsl, "vec4f(0.0)"));
    for (pass, source) in wgsl.passes().into_iter().chain([harness]) {
        let module = match naga::front::wgsl::parse_str(&source) {
            Ok(module) => module,
            Err(e) => {
                failed.push(format!("{pass}: {}", e.message()));
                continue;
            }
        };
        // As wgpu validates a module for a WebGL2 device: without cube-map arrays, even declared.
        let capabilities = naga::valid::Capabilities::all().difference(naga::valid::Capabilities::CUBE_ARRAY_TEXTURES);
        let validated =
            naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities).validate(&module);
        let info = match validated {
            Ok(info) => info,
            Err(e) => {
                failed.push(format!("{pass}: {}", e.as_inner()));
                continue;
            }
        };
        for (index, entry) in module.entry_points.iter().enumerate() {
            let uses_storage = module.global_variables.iter().any(|(handle, var)| {
                matches!(var.space, naga::AddressSpace::Storage { .. })
                    && !info.get_entry_point(index)[handle].is_empty()
            });
            if uses_storage {
                continue;
            }
            let name = format!("{pass}::{}", entry.name);
            match glsl_es_300(&module, &info, entry) {
                Ok(glsl) => match LATER_BUILTINS.iter().find(|f| glsl.contains(&format!("{f}("))) {
                    Some(builtin) => failed.push(format!("{name}: {builtin}, which GLSL ES 3.00 lacks")),
                    None => written.push(name),
                },
                Err(e) => failed.push(format!("{name}: {e}")),
            }
        }
    }
    (written, failed)
}

/// `entry` of `module` as GLSL ES 3.00 for WebGL, its overrides at their defaults.
fn glsl_es_300(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    entry: &naga::EntryPoint,
) -> Result<String, String> {
    let constants = naga::back::PipelineConstants::default();
    let (module, info) =
        naga::back::pipeline_constants::process_overrides(module, info, Some((entry.stage, &entry.name)), &constants)
            .map_err(|e| e.to_string())?;
    let options = naga::back::glsl::Options {
        version: naga::back::glsl::Version::Embedded { version: 300, is_webgl: true },
        ..Default::default()
    };
    let pipeline = naga::back::glsl::PipelineOptions {
        shader_stage: entry.stage,
        entry_point: entry.name.clone(),
        multiview: None,
    };
    let mut glsl = String::new();
    let mut writer = naga::back::glsl::Writer::new(
        &mut glsl,
        &module,
        &info,
        &options,
        &pipeline,
        naga::proc::BoundsCheckPolicies::default(),
    )
    .map_err(|e| e.to_string())?;
    writer.write().map_err(|e| e.to_string())?;
    Ok(glsl)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn types_are_spelled_one_way_and_names_are_ignored() {
        let a = signature("fn f(n: vec3f, t: texture_2d<f32>, k: f32) -> vec2<f32> {");
        let b = signature("fn f(normal : vec3<f32>,\n tex: texture_2d<f32>, scale: f32)->vec2f {");
        assert_eq!(a, b);
        assert_ne!(a, signature("fn f(n: vec3f, t: texture_2d<f32>) -> vec2f {"));
        assert_eq!(declared_name("const TRILINEAR_BY_HAND = true;").as_deref(), Some("TRILINEAR_BY_HAND"));
    }
}
