//! A lab's tests, one at a time, natively and in the page alike: a known-answer test calls one of
//! the student's functions ([`super::harness`]), an image test draws a scene with them
//! ([`super::images`]), and a test that fails is matched against the lab's known mistakes.
//!
//! A test is a future whose only waits are GPU readbacks. Natively `mirador lab run` waits for
//! each ([`crate::gpu::readback::block_on`]); the page polls it once a frame, because a browser
//! maps a buffer only after the page returns to its event loop. The same code gives the same
//! findings in both.

use super::harness::Harness;
use super::images::{self, Outcome};
use super::report::TestResult;
use super::{Against, ImageTest, KnownAnswer, Lab, Mistake, source};
use crate::gpu::Gpu;
use crate::shaders::Wgsl;
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A test of a lab: the lab's own, or a teacher's hidden one (from the folder it names).
#[derive(Clone, Debug)]
pub enum Test {
    Known(KnownAnswer, Option<PathBuf>),
    Image(ImageTest, Option<PathBuf>),
}

impl Test {
    pub fn name(&self) -> &str {
        match self {
            Test::Known(test, _) => &test.name,
            Test::Image(test, _) => &test.name,
        }
    }

    pub fn points(&self) -> f32 {
        match self {
            Test::Known(test, _) => test.points,
            Test::Image(test, _) => test.points,
        }
    }

    /// Whether it is a teacher's hidden test: its details are not shown to the student before the
    /// grades are published.
    pub fn hidden(&self) -> bool {
        matches!(self, Test::Known(_, Some(_)) | Test::Image(_, Some(_)))
    }

    /// The lab's own tests: its known answers, then its image tests.
    pub fn of(lab: &Lab) -> Vec<Test> {
        let mut tests: Vec<Test> = lab.known_answers.iter().cloned().map(|t| Test::Known(t, None)).collect();
        tests.extend(lab.images.iter().cloned().map(|t| Test::Image(t, None)));
        tests
    }

    /// The result of this test with `finding`, at `points`' score for it when they name it.
    pub fn result(&self, finding: Finding, points: &BTreeMap<String, f32>) -> TestResult {
        let max_score = points.get(self.name()).copied().unwrap_or(self.points());
        let mut output = finding.output;
        if let Some((name, sentence)) = &finding.mistake {
            output.push_str(&format!("\nThis looks like a known mistake, {name}: {sentence}"));
        }
        TestResult {
            name: self.name().to_owned(),
            score: if finding.passed { max_score } else { 0.0 },
            max_score,
            output,
            mistake: finding.mistake.map(|(name, _)| name),
            status: if finding.passed { "passed" } else { "failed" },
            visibility: if self.hidden() { "after_published" } else { "visible" },
            passed: finding.passed,
            images: finding.images,
        }
    }

    /// The result of a teacher's hidden test that the answer key itself fails (`why`): the
    /// teacher's error, which costs the student nothing and is never shown to them.
    pub fn teachers_error(&self, why: &str) -> TestResult {
        TestResult {
            name: self.name().to_owned(),
            score: 0.0,
            max_score: 0.0,
            output: format!(
                "Not graded: the lab's answer key fails this hidden test, so the test is in error, not the student. The key's result: {why}"
            ),
            mistake: None,
            status: "failed",
            visibility: "hidden",
            passed: false,
            images: None,
        }
    }
}

/// What one test found, as the run reports it to the checker.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Finding {
    pub index: usize,
    pub passed: bool,
    pub output: String,
    /// The known mistake the student's result matches, and what to tell them.
    pub mistake: Option<(String, String)>,
    /// Correct, yours, difference: the image test's PNGs, relative to the lab's folder.
    pub images: Option<[String; 3]>,
    /// The test did not run to its end (not started, stopped at the time limit, the checker
    /// died): no verdict on the functions.
    #[serde(default)]
    pub unfinished: bool,
}

impl Finding {
    /// A test that ran: its verdict, what it found, and the known mistake that matches.
    fn ran(index: usize, passed: bool, output: String, mistake: Option<(String, String)>) -> Finding {
        Finding { index, passed, output, mistake, images: None, unfinished: false }
    }

    /// A test that did not run, and why.
    pub fn unfinished(index: usize, why: &str) -> Finding {
        Finding { index, passed: false, output: why.to_owned(), mistake: None, images: None, unfinished: true }
    }
}

/// What a test found and, for an image test, its pictures: correct, yours, difference.
pub struct Checked {
    pub finding: Finding,
    pub pictures: Option<[RgbaImage; 3]>,
}

/// What every test of one check shares: the device, the harness, and the student's, Mirador's
/// and each known mistake's functions, compiled once.
pub struct Checker {
    pub gpu: Gpu,
    harness: Harness,
    student: Wgsl,
    reference: Wgsl,
    mistakes: Vec<(Mistake, Wgsl)>,
    /// The other right answers the lab accepts, compiled.
    alternatives: Vec<(Mistake, Wgsl)>,
    /// The lab's own known-answer tests, which a known mistake must match on every one before a
    /// failing test names it.
    known: Vec<KnownAnswer>,
    /// The slots the student left as the stub wrote them, and how many slots there are.
    untouched: Vec<String>,
    slots: usize,
    /// The student's values on [`Self::known`], and each mistake's agreement with them, found
    /// when first needed.
    agreement: std::cell::RefCell<BTreeMap<usize, bool>>,
    student_values: std::cell::RefCell<Option<Vec<Option<[f32; 4]>>>>,
    /// Whether a test found the student's loops cut off by the guard: the (other) images
    /// of a shader that would hang a GPU are not graded.
    /// Where: "a known-answer test", or an image test's name.
    tripped: std::cell::RefCell<Option<String>>,
    /// The student's functions with the slots' values NaN where the guard cut the loops off,
    /// when the file has loops: an image test draws it beside [`Self::student`] to find loops
    /// that run away only in its scene ([`super::isolate::Isolated::poisoned`]).
    poisoned: Option<Wgsl>,
}

impl Checker {
    /// The checker of `text` (the student's file) for `lab`, on `gpu`.
    pub fn new(gpu: Gpu, lab: &Lab, text: &str) -> Checker {
        let compiled = |list: &[Mistake]| -> Vec<(Mistake, Wgsl)> {
            list.iter().map(|m| (m.clone(), source::student(lab, &lab.mistaken(m)))).collect()
        };
        let (mistakes, alternatives) = (compiled(&lab.mistakes), compiled(&lab.alternatives));
        let (student, poisoned) = source::student_and_poisoned(lab, text);
        Checker {
            harness: Harness::new(&gpu),
            student,
            reference: source::reference(lab),
            mistakes,
            alternatives,
            known: lab.known_answers.clone(),
            untouched: source::untouched_slots(lab, text),
            slots: lab.slots.len(),
            agreement: Default::default(),
            student_values: Default::default(),
            tripped: Default::default(),
            poisoned,
            gpu,
        }
    }

    /// Runs `test`, the `index`-th of the check. An image test's scene is read from `folder`
    /// when the test came from there (a teacher's hidden tests).
    pub async fn run(&self, test: &Test, index: usize) -> Checked {
        match test {
            Test::Known(known, _) => Checked { finding: self.known_answer(known, index).await, pictures: None },
            Test::Image(image, folder) => self.image_test(image, folder.as_deref(), index).await,
        }
    }

    async fn known_answer(&self, test: &KnownAnswer, index: usize) -> Finding {
        let call = match self.harness.call(&self.gpu, &self.student, &test.call).await {
            Ok(call) => call,
            Err(error) => {
                return Finding::ran(index, false, error, None);
            }
        };
        let value = call.value;
        let (passed, wanted) = judge_value(test, value);
        let shown = |v: [f32; 4]| format!("({}, {}, {}, {})", v[0], v[1], v[2], v[3]);
        let mut output = format!("{} = {}; {wanted}", test.call, shown(value));
        if call.tripped {
            *self.tripped.borrow_mut() = Some("a known-answer test".to_owned());
            output = format!(
                "{}: your loops ran past {} iterations in this one call, and the checker stopped them. On a GPU a loop that does not end hangs it: give every loop a bound it is sure to reach.\n{output}",
                test.call,
                super::isolate::ITERATIONS
            );
            return Finding::ran(index, false, output, None);
        }
        if let Some(name) = not_finite(value) {
            output.push_str(&format!(
                "\nThe result has {name}: a division by zero, or the root or logarithm of a negative number?"
            ));
        }
        if passed {
            return Finding::ran(index, passed, output, None);
        }
        if let Some((said, whole)) = self.stub_said() {
            output.push_str(&said);
            if whole {
                return Finding::ran(index, passed, output, None);
            }
        }
        // The mistakes whose own value is this one (and is wrong) …
        let tolerance = test.tolerance.max(1e-5);
        let mut candidates = Vec::new();
        for (at, (_, wgsl)) in self.mistakes.iter().enumerate() {
            let Ok(theirs) = self.harness.call(&self.gpu, wgsl, &test.call).await else { continue };
            if same_value(theirs.value, value, tolerance) && !judge_value(test, theirs.value).0 {
                candidates.push(at);
            }
        }
        // … and that give the student's value on every known-answer test.
        let mistake = self.named(candidates).await;
        Finding::ran(index, passed, output, mistake)
    }

    /// What to tell a student about the slots still the stub's, when a test fails, and whether
    /// that is the whole file (then no known mistake is named: the stub made none).
    fn stub_said(&self) -> Option<(String, bool)> {
        (!self.untouched.is_empty()).then(|| {
            let whole = self.untouched.len() == self.slots;
            let said = format!(
                "\n`{}` {} still the stub's neutral body: write {} (TASK.md says what {} computes).",
                self.untouched.join("`, `"),
                if self.untouched.len() == 1 { "is" } else { "are" },
                if self.untouched.len() == 1 { "it" } else { "them" },
                if self.untouched.len() == 1 { "it" } else { "each" },
            );
            (said, whole)
        })
    }

    /// The known mistake to name among `candidates` (indices of mistakes whose output on a failing
    /// test is the student's): those that also give the student's value on every one of the lab's
    /// known-answer tests. Several that the tests cannot tell apart are named together.
    async fn named(&self, candidates: Vec<usize>) -> Option<(String, String)> {
        let mut agreeing = Vec::new();
        for at in candidates {
            if self.agrees(at).await {
                agreeing.push(&self.mistakes[at].0);
            }
        }
        match agreeing.as_slice() {
            [] => None,
            [one] => Some((one.name.clone(), one.sentence.clone())),
            several => Some((
                several.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(" or "),
                several.iter().map(|m| format!("{}: {}", m.name, m.sentence)).collect::<Vec<_>>().join(" Or "),
            )),
        }
    }

    /// Whether mistake `at` gives the student's value on every one of the lab's known-answer tests.
    async fn agrees(&self, at: usize) -> bool {
        if let Some(known) = self.agreement.borrow().get(&at) {
            return *known;
        }
        if self.student_values.borrow().is_none() {
            let mut values = Vec::new();
            for test in &self.known {
                values.push(self.harness.call(&self.gpu, &self.student, &test.call).await.ok().map(|c| c.value));
            }
            *self.student_values.borrow_mut() = Some(values);
        }
        let students = self.student_values.borrow().clone().unwrap_or_default();
        let mut agrees = true;
        for (test, student) in self.known.iter().zip(students) {
            let theirs = self.harness.call(&self.gpu, &self.mistakes[at].1, &test.call).await.ok().map(|c| c.value);
            let tolerance = test.tolerance.max(1e-5);
            if !matches!((theirs, student), (Some(a), Some(b)) if same_value(a, b, tolerance)) {
                agrees = false;
                break;
            }
        }
        self.agreement.borrow_mut().insert(at, agrees);
        agrees
    }

    async fn image_test(&self, test: &ImageTest, folder: Option<&Path>, index: usize) -> Checked {
        let fail = |output: String| Checked { finding: Finding::ran(index, false, output, None), pictures: None };
        if let Some(test) = self.tripped.borrow().as_ref() {
            return fail(format!(
                "not graded: your loops ran past {} iterations in {test} (see above). On a GPU this shader would hang, so its images are not graded.",
                super::isolate::ITERATIONS
            ));
        }
        let gpu = &self.gpu;
        let scene = match images::scene(test, folder) {
            Ok(scene) => scene,
            Err(error) => return fail(format!("the test's scene: {error}")),
        };
        let (yours, your_nans) = match images::drawn_counted(gpu, &scene, &self.student).await {
            Ok(drawn) => drawn,
            Err(error) => return fail(format!("drawing with your functions: {error}")),
        };
        if let Some(cut) = self.cut_off(&scene, &yours).await {
            *self.tripped.borrow_mut() = Some(format!("the image test “{}”", test.name));
            return fail(format!(
                "not graded: your loops ran past {} iterations while drawing this image, and the checker stopped them ({cut} of its pixels depend on where). On a GPU this shader would hang, so its images are not graded: give every loop a bound it is sure to reach.",
                super::isolate::ITERATIONS
            ));
        }
        let (mirador, mirador_nans) = match images::drawn_counted(gpu, &scene, &self.reference).await {
            Ok(drawn) => drawn,
            Err(error) => return fail(format!("drawing with Mirador's functions: {error}")),
        };
        // Against the tracer, the scene is traced once, whichever right answer is the baseline.
        let traced = (test.against == Against::Tracer).then(|| images::traced(&scene));
        let judged = |right: &RgbaImage| match &traced {
            None => images::judge(test, right, &yours, None),
            Some(traced) => images::judge(test, traced, &yours, Some(right)),
        };
        let mut outcome = judged(&mirador);
        // Another right answer draws another image: within the test's bounds of it is right too.
        for (alternative, wgsl) in &self.alternatives {
            if outcome.passed {
                break;
            }
            let Ok(theirs) = images::drawn(gpu, &scene, wgsl).await else { continue };
            let theirs = judged(&theirs);
            if theirs.passed {
                let output = format!(
                    "{}\n(as the lab's other right answer, {}: {})",
                    theirs.output, alternative.name, alternative.sentence
                );
                outcome = Outcome { output, ..theirs };
            }
        }
        let correct = traced.unwrap_or(mirador);
        let Outcome { mut passed, error_map, mut output, .. } = outcome;
        if your_nans > mirador_nans {
            // A NaN shows as whatever the device makes of it: the same shader may pass here and
            // fail on another GPU, so it fails everywhere.
            passed = false;
            output.push_str(&format!(
                "\n{your_nans} of your image's pixels are NaN or infinite before the output transform ({mirador_nans} of Mirador's): a division by zero, or the root or logarithm of a negative number?"
            ));
        }
        let mut mistake = None;
        if !passed {
            let said = self.stub_said();
            if let Some((said, _)) = &said {
                output.push_str(said);
            }
            if !said.is_some_and(|(_, whole)| whole) {
                let mut candidates = Vec::new();
                for (at, (_, wgsl)) in self.mistakes.iter().enumerate() {
                    let Ok(theirs) = images::drawn(gpu, &scene, wgsl).await else { continue };
                    let (same, _) = images::figures(&theirs, &yours);
                    if same.mean <= 0.002 && same.worst_region <= 0.02 {
                        candidates.push(at);
                    }
                }
                mistake = self.named(candidates).await;
            }
        }
        Checked { finding: Finding::ran(index, passed, output, mistake), pictures: Some([correct, yours, error_map]) }
    }
}

impl Checker {
    /// How many pixels of `yours` (the student's image of `scene`) the loop guard decided, when
    /// any: the image drawn again with the slots' values NaN wherever the guard tripped differs
    /// from it there. Two compilations of one shader may round a level apart, so a pixel counts
    /// past [`images::LEVELS`].
    async fn cut_off(&self, scene: &crate::scene::Scene, yours: &RgbaImage) -> Option<usize> {
        let poisoned = images::drawn(&self.gpu, scene, self.poisoned.as_ref()?).await.ok()?;
        let differ = |a: &[u8], b: &[u8]| a.iter().zip(b).any(|(a, b)| a.abs_diff(*b) > images::LEVELS);
        let cut = yours.pixels().zip(poisoned.pixels()).filter(|(a, b)| differ(&a.0, &b.0)).count();
        (cut > 0).then_some(cut)
    }
}

/// Two values equal within `tolerance` in every component, NaN equal to NaN.
fn same_value(a: [f32; 4], b: [f32; 4], tolerance: f32) -> bool {
    a.iter().zip(b).all(|(a, b)| (a - b).abs() <= tolerance || (a.is_nan() && b.is_nan()) || a == &b)
}

/// What is not a number in `value`, named: "NaN in components 1, 2".
fn not_finite(value: [f32; 4]) -> Option<String> {
    let named = |what: &str, wanted: fn(f32) -> bool| {
        let components: Vec<String> = (0..4).filter(|&i| wanted(value[i])).map(|i| (i + 1).to_string()).collect();
        match components.len() {
            0 => None,
            1 => Some(format!("{what} in component {}", components[0])),
            _ => Some(format!("{what} in components {}", components.join(", "))),
        }
    };
    let found: Vec<String> =
        [named("NaN", f32::is_nan), named("an infinity", f32::is_infinite)].into_iter().flatten().collect();
    (!found.is_empty()).then(|| found.join(" and "))
}

/// Whether `value` is right, and what was wanted.
fn judge_value(test: &KnownAnswer, value: [f32; 4]) -> (bool, String) {
    if let Some(expect) = test.expect {
        let ok = value.iter().zip(expect).all(|(v, e)| (v - e).abs() <= test.tolerance);
        return (
            ok,
            format!("expected ({}, {}, {}, {}) ± {}", expect[0], expect[1], expect[2], expect[3], test.tolerance),
        );
    }
    let min = test.min.unwrap_or([f32::NEG_INFINITY; 4]);
    let max = test.max.unwrap_or([f32::INFINITY; 4]);
    let ok = (0..4).all(|i| value[i] >= min[i] && value[i] <= max[i]);
    (ok, format!("expected each component within [{:?}, {:?}]", min, max))
}

/// A test under way: a future the page polls once a frame.
type Running = std::pin::Pin<Box<dyn std::future::Future<Output = Checked>>>;

/// A whole check polled a step at a time ([`Progress::advance`]), as the viewer's lab panel runs
/// it: in the page, where nothing may wait, and natively alike. It finds what `mirador lab check`
/// finds for the same text, without the child process and its time limit.
pub struct Progress {
    lab: Lab,
    problems: Vec<source::Problem>,
    checker: std::rc::Rc<Checker>,
    tests: Vec<Test>,
    running: Option<Running>,
    results: Vec<TestResult>,
    pictures: Vec<Option<[RgbaImage; 3]>>,
    started: web_time::Instant,
    seconds: Option<f64>,
}

impl Progress {
    /// Starts checking `text` against `lab`'s own tests on `gpu`: its problems first (as the
    /// device compiles it); a text with any runs no test.
    pub fn start(gpu: &Gpu, lab: &Lab, text: &str) -> Progress {
        let problems = source::problems_on(lab, text, gpu.profile());
        let tests = Test::of(lab);
        let mut progress = Progress {
            lab: lab.clone(),
            checker: std::rc::Rc::new(Checker::new(gpu.clone(), lab, text)),
            tests,
            running: None,
            results: Vec::new(),
            pictures: Vec::new(),
            started: web_time::Instant::now(),
            seconds: None,
            problems,
        };
        if !progress.problems.is_empty() {
            let why = format!("not run: {} does not compile (see the first problem above)", lab.file);
            for index in 0..progress.tests.len() {
                progress.finish(Checked { finding: Finding::unfinished(index, &why), pictures: None });
            }
        }
        progress
    }

    /// Polls the test under way once, starting it first if none is; returns whether a test
    /// finished.
    pub fn advance(&mut self) -> bool {
        let index = self.results.len();
        if index == self.tests.len() {
            return false;
        }
        let running = self.running.get_or_insert_with(|| {
            let (checker, test) = (self.checker.clone(), self.tests[index].clone());
            Box::pin(async move { checker.run(&test, index).await })
        });
        match crate::gpu::readback::poll_once(running.as_mut()) {
            Some(checked) => {
                self.running = None;
                self.finish(checked);
                true
            }
            None => false,
        }
    }

    fn finish(&mut self, checked: Checked) {
        let test = &self.tests[self.results.len()];
        self.results.push(test.result(checked.finding, &BTreeMap::new()));
        self.pictures.push(checked.pictures);
        if self.results.len() == self.tests.len() {
            self.seconds = Some(self.started.elapsed().as_secs_f64());
        }
    }

    /// Whether every test has run.
    pub fn done(&self) -> bool {
        self.seconds.is_some()
    }

    /// How long the whole check took, once it is done.
    pub fn seconds(&self) -> Option<f64> {
        self.seconds
    }

    /// The lab checked.
    pub fn lab(&self) -> &Lab {
        &self.lab
    }

    /// How many tests the check runs.
    pub fn len(&self) -> usize {
        self.tests.len()
    }

    /// Whether the lab has no test at all.
    pub fn is_empty(&self) -> bool {
        self.tests.is_empty()
    }

    /// The results so far, in the tests' order.
    pub fn results(&self) -> &[TestResult] {
        &self.results
    }

    /// Each finished test's pictures (correct, yours, difference), for an image test.
    pub fn pictures(&self) -> &[Option<[RgbaImage; 3]>] {
        &self.pictures
    }

    /// The problems that kept the tests from running.
    pub fn problems(&self) -> &[source::Problem] {
        &self.problems
    }

    /// The check's report so far (whole once [`Progress::done`]): what `results.json` holds.
    pub fn report(&self) -> super::report::Report {
        super::report::Report {
            lab: self.lab.clone(),
            problems: self.problems.clone(),
            results: self.results.clone(),
            seconds: self.seconds.unwrap_or_else(|| self.started.elapsed().as_secs_f64()),
        }
    }
}
