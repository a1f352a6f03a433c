//! The viewer in lab mode (`mirador view --lab DIR`, docs/course/labs.md): the lab's own scene,
//! drawn with the student's functions, redrawn as soon as the student's file is saved.
//!
//! - The file is polled like a scene file (twice a second, without drawing a frame). A saved
//!   file is checked as `lab check` checks it (signatures, then naga on every surface module):
//!   when it compiles, the view is drawn with it at once; when it does not, the error is shown
//!   over the view with its `file:line:column`, and the last version that compiled stays drawn
//!   (the stub's neutral functions until one does).
//! - The L key (or the step `lab student|reference|difference`) switches what the view shows:
//!   the student's functions, Mirador's own (the answer key, routed as the lab routes it), or
//!   the FLIP error map between the two at the view's size, with its mean.
//! - Inspecting a pixel (I, then a click) explains the image shown: the student's pixels are
//!   explained with the student's functions.
//! - The lab starts from its scene and the settings its first image test sets, never from what
//!   the viewer remembered of another scene, and remembers nothing when it closes.
//!
//! - The panel's Check button (or the step `lab check`) runs the lab's tests on the view's device,
//!   one step a frame ([`Checking`]), and lists what each found, with an image test's correct,
//!   yours and difference pictures: what `mirador lab check` finds, without leaving the viewer.
//!
//! In the page (`index.html`'s lab menu) the student's file is the text of an editor beside the
//! view, taken in a moment after the last keystroke, checked the same way (naga's messages, at
//! the same `line:column`; on WebGL2 also as WebGL2 compiles it), and downloaded with the page's
//! button, as is the last check's `results.json`. Everything else is as natively: the three
//! views, the checks ([`super::lab_difference`] and the checks draw over a few frames there).

/// What the view shows in lab mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LabShown {
    /// The scene drawn with the student's functions (the last version that compiled).
    #[default]
    Student,
    /// Drawn with Mirador's own: the answer key.
    Reference,
    /// The FLIP error map between the two.
    Difference,
}

impl LabShown {
    pub const ALL: [LabShown; 3] = [LabShown::Student, LabShown::Reference, LabShown::Difference];

    pub fn label(self) -> &'static str {
        match self {
            LabShown::Student => "student",
            LabShown::Reference => "reference",
            LabShown::Difference => "difference",
        }
    }

    pub fn parse(text: &str) -> Option<LabShown> {
        LabShown::ALL.into_iter().find(|shown| shown.label() == text.trim())
    }

    /// The next one, for the L key.
    pub fn next(self) -> LabShown {
        match self {
            LabShown::Student => LabShown::Reference,
            LabShown::Reference => LabShown::Difference,
            LabShown::Difference => LabShown::Student,
        }
    }
}

/// What the window shows of the lab: the panel's section, the error over the view, the
/// difference view's image.
pub struct LabPanel<'a> {
    pub name: &'a str,
    pub title: &'a str,
    pub file: &'a std::path::Path,
    pub shown: LabShown,
    pub problems: &'a [String],
    /// What is drawn while the file does not compile.
    pub fallback: &'static str,
    /// The difference view's error map and its mean, once made for the current view.
    pub difference: Option<(egui::TextureId, f32)>,
    /// What the view can show.
    pub choices: &'static [LabShown],
    /// When the student's text is taken in.
    pub how: &'static str,
    /// The last check, running or done.
    pub checking: Option<&'a Checking>,
}

/// The lab's tests run from the panel's Check button (or the step `lab check`) on the view's
/// device, a step a frame ([`crate::lab::checks::Progress`]): in the page nothing may wait for
/// the GPU. What each test found is listed in the panel, an image test with its pictures.
pub struct Checking {
    progress: crate::lab::checks::Progress,
    /// Each finished image test's correct, yours and difference pictures, as egui textures.
    textures: Vec<Option<[egui::TextureHandle; 3]>>,
    /// Whether the finished report was handed on (to the page's script, to the terminal).
    handed_on: bool,
}

impl Checking {
    /// Starts checking `text`, the student's file.
    pub fn start(gpu: &crate::gpu::Gpu, lab: &crate::lab::Lab, text: &str) -> Checking {
        let progress = crate::lab::checks::Progress::start(gpu, lab, text);
        Checking { progress, textures: Vec::new(), handed_on: false }
    }

    /// One step of the test under way; returns whether a test finished (the panel changes).
    pub fn advance(&mut self, ctx: &egui::Context) -> bool {
        let advanced = self.progress.advance();
        let pictures = self.progress.pictures();
        for (index, images) in pictures.iter().enumerate().skip(self.textures.len()) {
            let textures = images.as_ref().map(|images| {
                images.each_ref().map(|image| {
                    let size = [image.width() as usize, image.height() as usize];
                    let image = egui::ColorImage::from_rgba_unmultiplied(size, image.as_raw());
                    ctx.load_texture(format!("lab::check::{index}"), image, egui::TextureOptions::NEAREST)
                })
            });
            self.textures.push(textures);
        }
        advanced
    }

    pub fn running(&self) -> bool {
        !self.progress.done()
    }

    pub fn progress(&self) -> &crate::lab::checks::Progress {
        &self.progress
    }

    /// Test `index`'s pictures, correct, yours and difference, once it ran (an image test).
    pub fn pictures(&self, index: usize) -> Option<[egui::TextureId; 3]> {
        self.textures.get(index)?.as_ref().map(|textures| textures.each_ref().map(|t| t.id()))
    }

    /// What the check found so far, as the panel lists it: the score, each test passed or failed
    /// with what it found, an image test's pictures under it.
    pub fn show(&self, ui: &mut egui::Ui) {
        use crate::lab::report::points;
        let (progress, error) = (&self.progress, ui.visuals().error_fg_color);
        // Read in place: the panel is drawn every frame, and a report would copy the lab.
        let results = progress.results();
        let passed = results.iter().filter(|r| r.passed).count();
        let summary = match progress.seconds() {
            Some(seconds) => format!(
                "{} / {} points: {passed} of {} tests passed ({seconds:.1} s).",
                points(results.iter().map(|r| r.score).sum()),
                points(results.iter().map(|r| r.max_score).sum()),
                progress.len(),
            ),
            None => format!("Checking: {} of {} tests run…", results.len(), progress.len()),
        };
        ui.label(egui::RichText::new(summary).strong());
        if let Some(problem) = progress.problems().first() {
            ui.colored_label(error, egui::RichText::new(problem.display(&progress.lab().file)).monospace().small());
        }
        let pass = egui::Color32::from_rgb(90, 190, 110);
        for (index, result) in results.iter().enumerate() {
            let (mark, colour) = if result.passed { ("pass", pass) } else { ("FAIL", error) };
            ui.horizontal_wrapped(|ui| {
                let score = format!("{mark} {}/{}", points(result.score), points(result.max_score));
                ui.label(egui::RichText::new(score).monospace().color(colour));
                ui.label(egui::RichText::new(&result.name).small());
            });
            if !result.passed {
                ui.label(egui::RichText::new(&result.output).small());
            }
            if let Some(pictures) = self.pictures(index) {
                let spacing = ui.spacing().item_spacing.x;
                let width = ((ui.available_width() - 2.0 * spacing) / 3.0).clamp(40.0, 160.0);
                let size = self.textures[index].as_ref().map_or([16, 9], |t| t[0].size());
                let size = egui::vec2(width, width * size[1] as f32 / size[0].max(1) as f32);
                ui.horizontal(|ui| {
                    for (id, what) in pictures.into_iter().zip(["correct", "yours", "difference"]) {
                        ui.add(egui::Image::new((id, size))).on_hover_text(what);
                    }
                });
            }
        }
    }

    /// The finished check's report, once: for the page's script and the terminal.
    pub(in crate::viewer) fn take_finished(&mut self) -> Option<crate::lab::report::Report> {
        (self.progress.done() && !self.handed_on).then(|| {
            self.handed_on = true;
            self.progress.report()
        })
    }
}

/// What a lab mode draws, natively and in the page alike: the student's functions as last
/// compiled (the stub's until a version does), and why the text is not the one drawn.
struct Compiled {
    student: crate::shaders::Wgsl,
    /// How many versions of the student's text compiled so far.
    generation: u64,
    /// Each problem at its place, as `lab check` prints it; empty when the text is the one drawn.
    problems: Vec<String>,
    /// The shader the view draws with changed: the frame rebuilds its renderer.
    changed: bool,
}

impl Compiled {
    fn stub(lab: &crate::lab::Lab) -> Compiled {
        let student = crate::lab::source::student(lab, &lab.stub());
        Compiled { student, generation: 0, problems: Vec::new(), changed: true }
    }

    /// Takes in the student's `text` (the file `file`) with its `problems`: adopted when it has
    /// none. Returns whether it was.
    fn take_in(&mut self, lab: &crate::lab::Lab, text: &str, problems: &[crate::lab::source::Problem]) -> bool {
        if problems.is_empty() {
            self.student = crate::lab::source::student(lab, text);
            self.generation += 1;
            self.problems.clear();
            self.changed = true;
            true
        } else {
            self.problems = problems.iter().map(|p| p.display(&lab.file)).collect();
            false
        }
    }

    /// What the view draws while the text does not compile.
    fn fallback(&self) -> &'static str {
        if self.generation == 0 { "the stub's neutral functions" } else { "the last version that compiled" }
    }

    /// What the view draws with: the student's functions, or in the reference view Mirador's
    /// (the difference view draws the student's under its error map).
    fn wgsl(&self, lab: &crate::lab::Lab, shown: LabShown) -> crate::shaders::Wgsl {
        match shown {
            LabShown::Reference => crate::lab::source::reference(lab),
            LabShown::Student | LabShown::Difference => self.student.clone(),
        }
    }
}

/// A lab as the viewer shows it, natively and in the page alike: the lab, what is drawn of the
/// student's functions, which view, the difference view and the last check. Each `LabMode` adds
/// where the student's text comes from (a file, or the page's editor) and derefs to this.
pub struct LabView {
    pub lab: crate::lab::Lab,
    compiled: Compiled,
    pub shown: LabShown,
    difference: super::lab_difference::DifferenceView,
    /// The last check run from the panel.
    pub checking: Option<Checking>,
    /// A check asked for (the panel's button, the step `lab check`), started where the frame has
    /// the GPU.
    pub check_next: bool,
    /// The last finished check's `results.json`, until the page takes it.
    pub results: Option<String>,
}

impl LabView {
    fn new(lab: crate::lab::Lab) -> LabView {
        LabView {
            compiled: Compiled::stub(&lab),
            lab,
            shown: LabShown::Student,
            difference: Default::default(),
            checking: None,
            check_next: false,
            results: None,
        }
    }

    /// Whether the shader the view draws with changed since the last call.
    pub(in crate::viewer) fn take_changed(&mut self) -> bool {
        std::mem::take(&mut self.compiled.changed)
    }

    /// What the view draws with ([`Compiled::wgsl`]).
    pub fn wgsl(&self) -> crate::shaders::Wgsl {
        self.compiled.wgsl(&self.lab, self.shown)
    }

    /// What the window shows of the lab, the student's text being `file`, taken in `how`.
    fn panel<'a>(&'a self, file: &'a std::path::Path, how: &'static str) -> LabPanel<'a> {
        LabPanel {
            name: &self.lab.name,
            title: &self.lab.title,
            file,
            shown: self.shown,
            problems: &self.compiled.problems,
            fallback: self.compiled.fallback(),
            difference: self.difference.shown(),
            choices: &LabShown::ALL,
            how,
            checking: self.checking.as_ref(),
        }
    }

    /// Whether a check is under way.
    pub fn checking(&self) -> bool {
        self.checking.as_ref().is_some_and(Checking::running)
    }

    /// Shows `shown` from the next frame on.
    pub fn show(&mut self, shown: LabShown) {
        if shown != self.shown {
            self.shown = shown;
            self.compiled.changed = true;
        }
    }

    /// In the difference view, the error map between the reference's image and the student's of
    /// `scene` (at the view's size) unless it already shows them: at once natively, over the
    /// next frames in the page.
    pub(in crate::viewer) fn update_difference(
        &mut self,
        gpu: &crate::gpu::Gpu,
        ctx: &egui::Context,
        scene: &crate::Scene,
        revision: u64,
    ) {
        if self.shown == LabShown::Difference {
            let functions = (&self.lab, &self.compiled.student, self.compiled.generation);
            self.difference.update(gpu, ctx, functions, scene, revision);
        }
    }

    /// Whether the difference view's images are being drawn.
    pub fn drawing(&self) -> bool {
        self.difference.drawing()
    }
}

/// A `LabMode` (a `view: LabView` and where the student's text comes from) reads and changes its
/// view as its own.
macro_rules! derefs_to_view {
    ($mode:ty) => {
        impl std::ops::Deref for $mode {
            type Target = LabView;
            fn deref(&self) -> &LabView {
                &self.view
            }
        }

        impl std::ops::DerefMut for $mode {
            fn deref_mut(&mut self) -> &mut LabView {
                &mut self.view
            }
        }
    };
}

#[cfg(not(target_arch = "wasm32"))]
pub use native::LabMode;

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use std::path::{Path, PathBuf};
    use std::time::SystemTime;

    use web_time::Instant;

    use super::LabView;
    use crate::Scene;
    use crate::gpu::Gpu;
    use crate::lab::check::LabFolder;
    use crate::lab::source;
    use crate::viewer::scene_state::{WATCH_PERIOD, modified};

    /// Lab mode natively: the lab's view, and the student's file, watched on disk.
    pub struct LabMode {
        view: LabView,
        /// The student's file.
        pub file: PathBuf,
        /// The file's modification time and length when last read: an editor that truncates and
        /// writes within one tick of the clock still changes the length.
        modified: Option<(SystemTime, u64)>,
        checked: Instant,
    }

    derefs_to_view!(LabMode);

    impl LabMode {
        /// The lab in folder `dir` (made by `mirador lab new`), and the scene it starts from:
        /// its first image test's, from the folder's `scenes/` where the student has a copy,
        /// with the settings the test sets.
        pub fn open(dir: &Path) -> anyhow::Result<(LabMode, Scene)> {
            let folder = LabFolder::read(dir).map_err(anyhow::Error::msg)?;
            let lab = crate::lab::find(&folder.lab)
                .map_err(|e| anyhow::anyhow!("{}: {e}", dir.join("lab.toml").display()))?;
            let test = lab.images.first().cloned().ok_or_else(|| anyhow::anyhow!("lab {} has no scene", lab.name))?;
            // `lab new` copies the scenes into the folder's `scenes/`: the student's copy first.
            let copy = Path::new(&test.scene).file_name().map(|name| Path::new("scenes").join(name));
            let test = match copy.filter(|path| dir.join(path).exists()) {
                Some(path) => crate::lab::ImageTest { scene: path.display().to_string(), ..test },
                None => test,
            };
            let scene = crate::lab::images::scene(&test, Some(dir)).map_err(anyhow::Error::msg)?;
            let file = dir.join(&lab.file);
            let mut mode = LabMode { view: LabView::new(lab), modified: None, checked: Instant::now(), file };
            mode.read();
            Ok((mode, scene))
        }

        /// Reads and checks the student's file: adopted when it compiles, its problems kept
        /// otherwise. Returns whether anything on screen changes.
        fn read(&mut self) -> bool {
            self.modified = modified(&self.file);
            let name = self.lab.file.clone();
            let text = match std::fs::read_to_string(&self.file) {
                Ok(text) => text,
                Err(e) => {
                    self.view.compiled.problems = vec![format!("{}: {e}", self.file.display())];
                    return true;
                }
            };
            let problems = source::problems(&self.lab, &text);
            let view = &mut self.view;
            if view.compiled.take_in(&view.lab, &text, &problems) {
                println!("lab: {name} compiles; the view draws it");
            } else {
                let (fallback, first) = (view.compiled.fallback(), &view.compiled.problems[0]);
                println!("lab: {name} does not compile; the view draws {fallback}\n{first}");
            }
            true
        }

        /// Checks the student's file when it changed on disk (polled, cheap); returns whether
        /// the window must be drawn again.
        pub fn poll(&mut self) -> bool {
            if self.checked.elapsed() < WATCH_PERIOD {
                return false;
            }
            self.checked = Instant::now();
            if modified(&self.file) == self.modified {
                return false;
            }
            self.read()
        }

        /// When the file is next due a look.
        pub fn next_poll(&self) -> Instant {
            self.checked + WATCH_PERIOD
        }

        /// What the window shows of the lab.
        pub fn panel(&self) -> super::LabPanel<'_> {
            self.view.panel(&self.file, "redrawn when saved")
        }

        /// Runs the lab's tests on the file as saved now (the panel's Check button).
        pub(in crate::viewer) fn start_check(&mut self, gpu: &Gpu) {
            match std::fs::read_to_string(&self.file) {
                Ok(text) => self.view.checking = Some(super::Checking::start(gpu, &self.lab, &text)),
                Err(e) => self.view.compiled.problems = vec![format!("{}: {e}", self.file.display())],
            }
        }
    }
}

#[cfg(target_arch = "wasm32")]
pub use page::LabMode;

#[cfg(target_arch = "wasm32")]
mod page {
    use std::time::Duration;

    use web_time::Instant;

    use super::LabView;
    use crate::lab::source;
    use crate::shaders::Profile;

    /// How long after the last keystroke the editor's text is checked and drawn.
    const PAUSE: Duration = Duration::from_millis(300);

    /// Lab mode in the page: the lab's view, and the student's file as the editor holds it.
    pub struct LabMode {
        view: LabView,
        /// The student's file, as the editor holds it.
        pub text: String,
        /// The last keystroke not yet checked.
        edited: Option<Instant>,
        /// The device's profile: on WebGL2 the text must also compile to its shading language.
        profile: Profile,
    }

    derefs_to_view!(LabMode);

    impl LabMode {
        /// The built-in lab `name`, its text the stub, and the scene its first image test draws.
        /// A lab whose routes WebGL2 cannot compile is refused there with its reason.
        pub fn open(name: &str, profile: Profile) -> anyhow::Result<(LabMode, crate::Scene)> {
            let lab = crate::lab::find(name).map_err(anyhow::Error::msg)?;
            if let Some(reason) = lab.refusal(profile) {
                anyhow::bail!("this page draws with WebGL2 here, and the lab cannot run there: {reason}");
            }
            let test = lab.images.first().ok_or_else(|| anyhow::anyhow!("lab {} has no scene", lab.name))?;
            let scene = crate::lab::images::scene(test, None).map_err(anyhow::Error::msg)?;
            let mode = LabMode { text: lab.stub(), view: LabView::new(lab), edited: None, profile };
            Ok((mode, scene))
        }

        /// The editor changed the text: it is checked after a pause.
        pub fn edited(&mut self) {
            self.edited = Some(Instant::now());
        }

        /// A whole new text (a file the student opened): checked at once.
        pub(in crate::viewer) fn replace_text(&mut self, text: String) {
            self.text = text;
            self.edited = None;
            self.check();
        }

        /// Checks the text as `lab check` checks a file (and, on WebGL2, as WebGL2 compiles it):
        /// adopted when it compiles.
        fn check(&mut self) {
            let problems = source::problems_on(&self.lab, &self.text, self.profile);
            let view = &mut self.view;
            view.compiled.take_in(&view.lab, &self.text, &problems);
        }

        /// Why the text is not the one drawn, each problem at its place.
        pub fn problems(&self) -> &[String] {
            &self.view.compiled.problems
        }

        /// Checks the text once the student paused; returns whether the window must be drawn.
        pub fn poll(&mut self) -> bool {
            match self.edited {
                Some(at) if at.elapsed() >= PAUSE => {
                    self.edited = None;
                    self.check();
                    true
                }
                _ => false,
            }
        }

        /// When the text is next due a look: a pause after the last keystroke; none pending, an
        /// hour away.
        pub fn next_poll(&self) -> Instant {
            self.edited.map_or_else(|| Instant::now() + Duration::from_secs(3600), |at| at + PAUSE)
        }

        /// What the window shows of the lab.
        pub fn panel(&self) -> super::LabPanel<'_> {
            self.view.panel(std::path::Path::new(&self.lab.file), "redrawn as you type")
        }

        /// Runs the lab's tests on the editor's text (the panel's Check button).
        pub(in crate::viewer) fn start_check(&mut self, gpu: &crate::gpu::Gpu) {
            self.view.checking = Some(super::Checking::start(gpu, &self.lab, &self.text));
        }
    }
}

/// The student's file in an editor beside the view, on the window's right (the page's lab mode),
/// with the file's problems under it at their `line:column`.
pub struct LabEditor<'a> {
    pub file: &'a str,
    pub text: &'a mut String,
    pub problems: &'a [String],
}

impl LabEditor<'_> {
    /// Lays the editor out as the window's right panel; returns whether the text changed.
    pub fn show(&mut self, ui: &mut egui::Ui) -> bool {
        let mut changed = false;
        egui::Panel::right("lab_editor").resizable(true).default_size(480.0).show(ui, |ui| {
            ui.label(egui::RichText::new(self.file).monospace().strong());
            for problem in self.problems {
                ui.colored_label(ui.visuals().error_fg_color, egui::RichText::new(problem).monospace().small());
            }
            egui::ScrollArea::vertical().show(ui, |ui| {
                let edit =
                    egui::TextEdit::multiline(self.text).code_editor().desired_width(f32::INFINITY).desired_rows(40);
                changed = ui.add(edit).changed();
            });
        });
        changed
    }
}
