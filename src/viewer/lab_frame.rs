//! The lab's part of the viewer's frame (`mirador view --lab DIR`, the page's lab menu): opening
//! a lab, the steps `lab …`, and a check advanced a step a frame where the frame has the GPU.

use anyhow::bail;

use super::frame::Viewer;
#[cfg(target_arch = "wasm32")]
use super::lab::LabMode;
use super::screen::Screen;

impl Viewer {
    /// Opens the built-in lab `name` (the page's lab menu): its scene, with the settings its
    /// first image test sets, drawn with the stub's functions until the student's text compiles.
    #[cfg(target_arch = "wasm32")]
    pub fn open_lab(&mut self, name: &str) {
        match LabMode::open(name, self.raster.profile()) {
            Ok((lab, scene)) => {
                let settings = scene.settings.clone();
                // The lab's scene is its own: no overrides of the scene it replaces.
                self.scene.overrides.clear();
                self.scene.replace(scene, &settings);
                self.settings = settings;
                self.notice(format!("lab {name}: {}; write its functions in the editor", lab.lab.title));
                self.lab = Some(lab);
            }
            Err(e) => self.notice(format!("lab {name}: {e:#}")),
        }
    }

    /// The step `lab student|reference|difference`.
    pub(super) fn lab_step(&mut self, shown: super::lab::LabShown) -> anyhow::Result<()> {
        match &mut self.lab {
            Some(lab) => lab.show(shown),
            None => bail!("`lab {}`: the viewer is not in lab mode (mirador view --lab DIR)", shown.label()),
        }
        Ok(())
    }

    /// One step of the lab's check under way, started first when the panel's Check button or the
    /// step `lab check` asked for one. A finished check's summary is printed, and its
    /// `results.json` kept for the page's download.
    pub(super) fn advance_lab_check(&mut self, screen: &Screen) {
        if let Some(lab) = self.lab.as_mut()
            && std::mem::take(&mut lab.check_next)
        {
            lab.start_check(&screen.gpu);
            let name = lab.lab.name.clone();
            self.notice(format!("lab {name}: checking"));
        }
        let ctx = &screen.egui;
        let Some(checking) = self.lab.as_mut().and_then(|lab| lab.checking.as_mut()) else { return };
        checking.advance(ctx);
        if let Some(report) = checking.take_finished() {
            print!("{}", crate::lab::report::text(&report));
            if let Some(lab) = self.lab.as_mut() {
                lab.results = Some(crate::lab::report::results_json(&report));
            }
            let summary = format!(
                "lab {}: {} / {} points",
                report.lab.name,
                crate::lab::report::points(report.score()),
                crate::lab::report::points(report.max_score())
            );
            self.notice(summary);
        }
    }

    /// The step `lab open NAME`: the page's lab menu.
    #[cfg(target_arch = "wasm32")]
    pub(super) fn lab_open_step(&mut self, name: &str) -> anyhow::Result<()> {
        self.open_lab(name);
        Ok(())
    }

    /// The step `lab open NAME`, which natively has no lab to open without a folder.
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn lab_open_step(&mut self, name: &str) -> anyhow::Result<()> {
        bail!("`lab open {name}` is the page's; natively: mirador lab new {name} DIR, then mirador view --lab DIR")
    }

    /// The page's lab: the editor's text replaced (a file the student opened), checked at once.
    #[cfg(target_arch = "wasm32")]
    pub fn set_lab_text(&mut self, text: String) {
        match self.lab.as_mut() {
            Some(lab) => lab.replace_text(text),
            None => self.notice("no lab is open: choose one first".into()),
        }
    }

    /// The page's lab: its file's name and the editor's text, for the page's download.
    #[cfg(target_arch = "wasm32")]
    pub fn lab_file(&self) -> Option<(String, String)> {
        self.lab.as_ref().map(|lab| (lab.lab.file.clone(), lab.text.clone()))
    }
}
