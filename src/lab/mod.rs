//! The lab: a student writes the heart of a technique in WGSL, and Mirador checks it.
//!
//! A lab (`assets/labs/NAME/lab.toml`) names a few of Mirador's own WGSL functions, its *slots*:
//! the mip LOD and a trilinear sample made from texel loads, the finite-difference bump normal,
//! the shadow-map comparison and its PCF, a transparent surface's blend, Snell and Fresnel, the
//! mirrored camera's reflection matrix, the environment maps' direction → texel maps, a volume's
//! opacity correction and front-to-back compositing. The student's file defines them again with
//! the same signatures; at run time every surface pass compiles the student's functions in place
//! of Mirador's ([`crate::shaders::Wgsl`]), so nothing is rebuilt. Mirador's own functions are the reference
//! solution, and the stub is their signatures and comments with neutral bodies, so the three can
//! never drift apart.
//!
//! What a lab checks, in order ([`check`]):
//! 1. the file itself: each slot's signature, then naga's parse and validation of every surface
//!    module, errors given at the student's `file:line:column` ([`source`]);
//! 2. known-answer tests: each function called on tiny inputs in a one-pixel draw, with a value
//!    and a tolerance or a range where several answers are right ([`harness`]);
//! 3. image tests: a scene drawn with the student's functions against the same scene drawn with
//!    Mirador's (tight), or against the ray tracer where theory says the two agree (no worse than
//!    the reference by a margin), each bounded in mean FLIP and in its worst 32×32 region
//!    ([`images`]).
//!
//! A test that fails is matched against the lab's known mistakes (the solution with one typical
//! slip made), and the report names the one it matches ([`checks`]). `mirador lab check` runs the
//! tests in a child process with a time limit ([`run`]): a software GPU cannot be interrupted,
//! and a shader that never returns is a failed test, not a hung grader. The page runs the same
//! tests a frame at a time (src/viewer/lab.rs), and gives the same `results.json` ([`report`]).

// What runs the checks natively: processes and folders, which the page has not.
#[cfg(not(target_arch = "wasm32"))]
pub mod autograder;
#[cfg(not(target_arch = "wasm32"))]
pub mod check;
pub mod checks;
#[cfg(not(target_arch = "wasm32"))]
pub mod folder;
pub mod harness;
pub mod images;
pub mod isolate;
pub mod report;
#[cfg(not(target_arch = "wasm32"))]
pub mod run;
pub mod source;
#[cfg(not(target_arch = "wasm32"))]
pub mod summary;

use serde::Deserialize;

/// A lab as its `lab.toml` declares it.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lab {
    /// What `mirador lab new NAME` takes.
    pub name: String,
    /// The number of the course chapter the lab belongs to (its file: [`chapter_file`]).
    pub chapter: u32,
    pub title: String,
    /// The student's file, as `lab new` writes it into the lab's folder.
    pub file: String,
    /// The functions the student writes.
    pub slots: Vec<Slot>,
    /// Declarations that replace Mirador's while the lab runs, for the reference and the
    /// student alike: where the GPU's fixed function does the work (the sampler's trilinear
    /// filter, its depth comparisons), a constant that routes it through the slots.
    #[serde(default)]
    pub routes: Vec<String>,
    /// What the student is asked to do (TASK.md).
    pub task: String,
    /// For the teacher: what the tests look for and how students go wrong (NOTES.md).
    pub notes: String,
    /// The scenes of the image tests a student gets, under `assets/scenes/`.
    #[serde(default)]
    pub scenes: Vec<String>,
    #[serde(default, rename = "known")]
    pub known_answers: Vec<KnownAnswer>,
    #[serde(default, rename = "image")]
    pub images: Vec<ImageTest>,
    #[serde(default)]
    pub mistakes: Vec<Mistake>,
    /// Other right answers: the solution written another way that the lab accepts (the level of
    /// detail from the footprint's largest component). An image test also passes within its
    /// bounds of an alternative's image; every alternative scores full marks (tests/labs.rs).
    #[serde(default)]
    pub alternatives: Vec<Mistake>,
    /// Why the lab cannot run on a device of the WebGL2 profile (the page where the browser has
    /// no WebGPU), when its routes need what WebGL2's shading language lacks. Kept true by
    /// `tests/webgl2.rs`, which compiles every lab for WebGL2.
    #[serde(default)]
    pub webgl2: Option<String>,
}

/// A function the student writes: one of Mirador's, by name, and the body the stub gives it.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Slot {
    pub name: String,
    /// A body that compiles and returns a neutral value (`return n;`).
    pub neutral: String,
}

/// A function called on tiny inputs: `call` is a WGSL expression of type `vec4f` that may read
/// the harness's textures (`lab_texture`, `lab_depth`: [`harness`]).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KnownAnswer {
    pub name: String,
    pub call: String,
    /// The right value, within `tolerance` in every component.
    #[serde(default)]
    pub expect: Option<[f32; 4]>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f32,
    /// Or a range, where several answers are right: each component within [min, max].
    #[serde(default)]
    pub min: Option<[f32; 4]>,
    #[serde(default)]
    pub max: Option<[f32; 4]>,
    #[serde(default = "one_point")]
    pub points: f32,
}

fn default_tolerance() -> f32 {
    1e-4
}

fn one_point() -> f32 {
    1.0
}

/// A scene drawn with the student's functions and compared.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageTest {
    pub name: String,
    /// Under `assets/scenes/`, or a path a hidden test's file names relative to itself.
    pub scene: String,
    /// `--set` assignments over the scene's own (settings and scene values alike).
    #[serde(default)]
    pub set: Vec<String>,
    /// The image's size: small, so a lab checks in seconds.
    pub size: [u32; 2],
    pub against: Against,
    /// The largest mean FLIP; against the tracer, the largest excess over the reference's own.
    pub mean: f32,
    /// The same bound for the worst 32×32 region.
    pub region: f32,
    #[serde(default = "three_points")]
    pub points: f32,
}

fn three_points() -> f32 {
    3.0
}

/// What an image test compares the student's image with.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Against {
    /// The same scene drawn with Mirador's own functions: the student's must match it closely.
    Reference,
    /// The ray tracer's image: the student's may differ from it no more than Mirador's own does,
    /// plus the test's margins.
    Tracer,
}

/// A typical mistake: the solution with one slip made, and what to tell a student who made it. (An
/// alternative has the same form: the solution with one right change, and why it is right.)
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mistake {
    pub name: String,
    pub sentence: String,
    /// `[[from, to], …]`: the slip, as text replaced once each in the solution.
    pub replace: Vec<[String; 2]>,
}

/// The course's chapter files, by number (docs/course/).
const CHAPTERS: &[&str] = &[
    "01-camera.md",
    "02-illumination.md",
    "03-mipmaps.md",
    "04-bump-mapping.md",
    "05-shadows.md",
    "06-transparency.md",
    "07-planar-mirrors.md",
    "08-environment-maps.md",
    "09-ray-tracing.md",
    "10-anti-aliasing.md",
    "11-volumes.md",
];

/// The file of chapter `number` under docs/course/.
pub fn chapter_file(number: u32) -> Option<&'static str> {
    CHAPTERS.get((number as usize).checked_sub(1)?).copied()
}

/// The labs that come with Mirador, in the course's order.
const LABS: &[&str] = &[
    include_str!("../../assets/labs/mipmaps/lab.toml"),
    include_str!("../../assets/labs/bump/lab.toml"),
    include_str!("../../assets/labs/parallax/lab.toml"),
    include_str!("../../assets/labs/shadow-map/lab.toml"),
    include_str!("../../assets/labs/transparency/lab.toml"),
    include_str!("../../assets/labs/refraction/lab.toml"),
    include_str!("../../assets/labs/planar-mirrors/lab.toml"),
    include_str!("../../assets/labs/environment-maps/lab.toml"),
    include_str!("../../assets/labs/volumes/lab.toml"),
];

/// Every lab that comes with Mirador.
pub fn catalog() -> Vec<Lab> {
    LABS.iter()
        .map(|text| toml::from_str(text).unwrap_or_else(|e| panic!("a built-in lab is malformed: {e}")))
        .collect()
}

/// The built-in lab named `name`.
pub fn find(name: &str) -> Result<Lab, String> {
    let labs = catalog();
    let names: Vec<String> = labs.iter().map(|lab| lab.name.clone()).collect();
    labs.into_iter()
        .find(|lab| lab.name == name)
        .ok_or_else(|| format!("no lab named `{name}`: the labs are {}", names.join(", ")))
}

impl Lab {
    /// The names of Mirador's declarations the lab routes (`const TRILINEAR_BY_HAND = true;` →
    /// `TRILINEAR_BY_HAND`).
    /// Why the lab cannot run on a device of `profile`, if it cannot (its `webgl2` reason).
    pub fn refusal(&self, profile: crate::shaders::Profile) -> Option<&str> {
        match profile {
            crate::shaders::Profile::WebGl2 => self.webgl2.as_deref(),
            crate::shaders::Profile::Standard => None,
        }
    }

    pub fn route_names(&self) -> Vec<String> {
        self.routes.iter().filter_map(|route| source::declared_name(route)).collect()
    }

    /// Mirador's own functions for the slots, with their comments: the answer key.
    pub fn solution(&self) -> String {
        let mut text = self.header("the answer key: Mirador's own functions");
        for slot in &self.slots {
            let (comments, declaration) = source::builtin_declaration(&slot.name)
                .unwrap_or_else(|| panic!("lab {}: Mirador has no WGSL function `{}`", self.name, slot.name));
            text.push('\n');
            text.push_str(&comments);
            text.push_str(declaration.trim_end());
            text.push('\n');
        }
        text
    }

    /// The student's starting file: each slot's comments and signature, and a neutral body.
    pub fn stub(&self) -> String {
        let mut text = self.header("write the body of each function below; keep its signature");
        for slot in &self.slots {
            let (comments, declaration) = source::builtin_declaration(&slot.name)
                .unwrap_or_else(|| panic!("lab {}: Mirador has no WGSL function `{}`", self.name, slot.name));
            let signature = &declaration[..declaration.find('{').expect("a function has a body")];
            text.push('\n');
            text.push_str(&comments);
            text.push_str(signature.trim_end());
            text.push_str(" {\n    // TODO\n    ");
            text.push_str(slot.neutral.trim());
            text.push_str("\n}\n");
        }
        text
    }

    /// The solution with `mistake` made.
    pub fn mistaken(&self, mistake: &Mistake) -> String {
        let mut text = self.solution();
        for [from, to] in &mistake.replace {
            assert!(
                text.contains(from.as_str()),
                "lab {}: mistake `{}` replaces `{from}`, which the solution lacks",
                self.name,
                mistake.name
            );
            text = text.replacen(from.as_str(), to, 1);
        }
        text
    }

    fn header(&self, what: &str) -> String {
        format!(
            "// Lab `{}` (chapter {}): {}.\n// {}. The task is in TASK.md; `mirador lab check .` grades it.\n",
            self.name,
            self.chapter,
            self.title,
            capitalised(what)
        )
    }
}

fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    chars.next().map(|c| c.to_uppercase().chain(chars).collect()).unwrap_or_default()
}
