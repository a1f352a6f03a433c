//! Scripted steps: what `--step "…"` and `--script FILE` feed the viewer, one step per frame, so
//! that a run with `--frames N --screenshot FILE` can be tested under Xvfb like a person at the
//! window. Each step names something the panel or a key does:
//!
//! ```text
//! set shadows.enabled=false     a render setting or a scene value (camera.fovy=30), as `--set`
//!                               takes them
//! view split                    raster | traced | split | difference
//! split 0.3                     the divider, as a fraction of the view's width
//! orbit 40 -10 | pan 20 0       a mouse drag, in pixels
//! zoom 2                        wheel steps (positive: closer)
//! frame | reset                 the F and R keys
//! reset settings                every setting back to the scene file's own (the panel's reset)
//! navigate fly | navigate orbit
//! walk 0 0 1                    fly by (right, up, forward) scene units
//! pick 320 200                  click the 3D view at this pixel (selects the object)
//! inspect 320 200               explain this pixel in both renderers (the I key, then a click)
//! cursor 320 200                hold the mouse over this pixel (the lat–long view's marker, the
//!                               volume ray's samples)
//! probe                         print the volume ray under the cursor (one line on stdout)
//! material kd=0.2               edit the picked object's material
//! load FILE                     as if FILE were dropped on the window
//! scale 0.5                     the lowest render scale while the camera moves (with `fps
//!                               off`: the scale)
//! fps 30 | fps off              the frame rate the render scale holds while the camera moves
//! help on | panel off           show or hide the help window, the side panel
//! overlay off                   hide the frame times over the 3D view
//! wait 10                       let 10 frames pass
//! wait 2s                       let 2 seconds pass (frames go on being drawn)
//! wait traced                   until the ray-traced image (and difference) is complete; in
//!                               the raster view with the hybrid on, its terms at every pixel
//! measure                       start `--stats`' means at the next frame (else they start
//!                               after the last step)
//! screenshot FILE.png           the whole window, written atomically
//! lab student                   in lab mode: the student's image | reference | difference (L)
//! lab check                     in lab mode: run the lab's tests (the panel's Check button)
//! wait checked                  until the lab's check has run every test
//! ```
//!
//! Blank lines and lines starting with `#` are skipped in script files.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use web_time::Instant;

use glam::{Vec2, Vec3};

use super::camera_control::Navigation;
use super::lab::LabShown;
use super::view_mode::ViewMode;

#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    Set(String),
    View(ViewMode),
    Split(f32),
    Orbit(Vec2),
    Pan(Vec2),
    Zoom(f32),
    Frame,
    Reset,
    Navigate(Navigation),
    Walk(Vec3),
    Pick(Vec2),
    Inspect(Vec2),
    Cursor(Vec2),
    Probe,
    Material(String),
    Load(PathBuf),
    Scale(f32),
    /// A target frame rate; 0: none.
    Fps(f32),
    Help(bool),
    Panel(bool),
    Overlay(bool),
    Wait(u32),
    /// Let this much time pass, frames being drawn all along.
    WaitFor(std::time::Duration),
    WaitTraced,
    Measure,
    /// Measure the error budget of the view (the panel's button).
    Budget,
    Screenshot(PathBuf),
    Lab(LabShown),
    /// Open a built-in lab with an editor for its file (the page's lab menu).
    LabOpen(String),
    /// Run the lab's tests (the panel's Check button).
    LabCheck,
    WaitChecked,
    ResetSettings,
}

#[derive(Debug, thiserror::Error)]
pub enum ScriptError {
    #[error("step `{step}`: {message}")]
    Step { step: String, message: String },
    #[error("{path}:{line}: {source}")]
    Line { path: PathBuf, line: usize, source: Box<ScriptError> },
    #[error("{path}: cannot read the script: {source}")]
    Io { path: PathBuf, source: std::io::Error },
}

fn numbers<const N: usize>(args: &str) -> Option<[f32; N]> {
    let values: Vec<f32> = args.split_whitespace().map(str::parse).collect::<Result<_, _>>().ok()?;
    let array: [f32; N] = values.try_into().ok()?;
    array.iter().all(|v| v.is_finite()).then_some(array)
}

fn switch(args: &str) -> Option<bool> {
    match args {
        "on" | "true" | "show" => Some(true),
        "off" | "false" | "hide" => Some(false),
        _ => None,
    }
}

/// Parses one step.
pub fn parse(text: &str) -> Result<Step, ScriptError> {
    let text = text.trim();
    let (verb, args) = text.split_once(char::is_whitespace).map_or((text, ""), |(v, a)| (v, a.trim()));
    let fail = |message: &str| ScriptError::Step { step: text.into(), message: message.into() };
    let assignment = |what: &str| {
        if args.contains('=') { Ok(args.to_string()) } else { Err(fail(&format!("expected {what} key=value"))) }
    };
    Ok(match verb {
        "set" => Step::Set(assignment("set")?),
        "material" => Step::Material(assignment("material")?),
        "lab" if args.trim() == "check" => Step::LabCheck,
        "lab" => match args.trim().strip_prefix("open ") {
            Some(name) => Step::LabOpen(name.trim().to_owned()),
            None => Step::Lab(
                LabShown::parse(args)
                    .ok_or_else(|| fail("the lab view is student, reference or difference, `open NAME` or `check`"))?,
            ),
        },
        "view" => {
            Step::View(ViewMode::parse(args).ok_or_else(|| fail("the view is raster, traced, split or difference"))?)
        }
        "split" => {
            let [x] = numbers(args).ok_or_else(|| fail("expected a fraction of the width"))?;
            if !(0.0..=1.0).contains(&x) {
                return Err(fail("the divider lies between 0 and 1"));
            }
            Step::Split(x)
        }
        "orbit" | "pan" | "pick" | "cursor" | "inspect" => {
            let [x, y] = numbers(args).ok_or_else(|| fail("expected two numbers: x y in pixels"))?;
            let v = Vec2::new(x, y);
            match verb {
                "orbit" => Step::Orbit(v),
                "pan" => Step::Pan(v),
                "cursor" => Step::Cursor(v),
                "inspect" => Step::Inspect(v),
                _ => Step::Pick(v),
            }
        }
        "zoom" => Step::Zoom(numbers::<1>(args).ok_or_else(|| fail("expected wheel steps"))?[0]),
        "walk" => Step::Walk(Vec3::from(numbers::<3>(args).ok_or_else(|| fail("expected right up forward"))?)),
        "frame" => Step::Frame,
        "probe" => Step::Probe,
        "reset" if args == "settings" => Step::ResetSettings,
        "reset" => Step::Reset,
        "navigate" => Step::Navigate(match args {
            "orbit" => Navigation::Orbit,
            "fly" => Navigation::Fly,
            _ => return Err(fail("navigate orbit or navigate fly")),
        }),
        "load" if !args.is_empty() => Step::Load(PathBuf::from(args)),
        "scale" => {
            let [s] = numbers(args).ok_or_else(|| fail("expected a scale"))?;
            if !(0.1..=1.0).contains(&s) {
                return Err(fail("the render scale lies between 0.1 and 1"));
            }
            Step::Scale(s)
        }
        "fps" if args == "off" => Step::Fps(0.0),
        "fps" => {
            let [fps] = numbers(args).ok_or_else(|| fail("fps N or fps off"))?;
            if !super::budget::MOTION_FPS.contains(&fps) {
                return Err(fail("the frame rate lies between 5 and 120"));
            }
            Step::Fps(fps)
        }
        "measure" => Step::Measure,
        "budget" => Step::Budget,
        "help" => Step::Help(switch(args).ok_or_else(|| fail("help on or help off"))?),
        "panel" => Step::Panel(switch(args).ok_or_else(|| fail("panel on or panel off"))?),
        "overlay" => Step::Overlay(switch(args).ok_or_else(|| fail("overlay on or overlay off"))?),
        "wait" if args == "traced" => Step::WaitTraced,
        "wait" if args == "checked" => Step::WaitChecked,
        "wait" if args.ends_with('s') => {
            let seconds = args[..args.len() - 1].parse::<f32>().ok().filter(|s| s.is_finite() && *s >= 0.0);
            let seconds = seconds.filter(|s| *s <= 3600.0).ok_or_else(|| fail("wait 2s: seconds, up to an hour"))?;
            Step::WaitFor(std::time::Duration::from_secs_f32(seconds))
        }
        "wait" => Step::Wait(args.parse().map_err(|_| fail("wait N (frames), wait 2s, wait traced or wait checked"))?),
        "screenshot" if args.to_ascii_lowercase().ends_with(".png") => Step::Screenshot(PathBuf::from(args)),
        "screenshot" => return Err(fail("the screenshot must be a .png file")),
        _ => return Err(fail("unknown step (see `mirador view --help`)")),
    })
}

/// Parses a script file: one step a line, `#` comments and blank lines skipped.
pub fn parse_file(path: &Path) -> Result<Vec<Step>, ScriptError> {
    let text = std::fs::read_to_string(path).map_err(|source| ScriptError::Io { path: path.into(), source })?;
    text.lines()
        .enumerate()
        .filter(|(_, line)| !line.trim().is_empty() && !line.trim_start().starts_with('#'))
        .map(|(number, line)| {
            parse(line).map_err(|e| ScriptError::Line { path: path.into(), line: number + 1, source: Box::new(e) })
        })
        .collect()
}

/// Scripted steps still to run and the wait in progress.
#[derive(Default)]
pub struct Script {
    pub(super) steps: VecDeque<Step>,
    pub(super) wait_frames: u32,
    /// A `wait 2s` step's end.
    pub(super) wait_until: Option<Instant>,
    pub(super) wait_traced_since: Option<Instant>,
    /// A `wait checked` step's start.
    pub(super) wait_checked_since: Option<Instant>,
    /// A `measure` step ran: the stats start where it said, not after the last step.
    pub(super) measured: bool,
    /// Start the stats again after this frame.
    pub(super) reset_stats: bool,
    /// A scripted run: every frame follows the last at once.
    pub scripted: bool,
    /// The screenshot asked for (a step, the panel's button, the page), and since when it has
    /// waited for egui's animations to end.
    pub(super) screenshot: Option<PathBuf>,
    pub(super) screenshot_waiting: Option<Instant>,
    /// Print the volume ray under the cursor after this frame's UI (the `probe` step).
    pub(super) print_probe: bool,
}

impl Script {
    /// A script of `steps`.
    pub fn new(steps: Vec<Step>) -> Script {
        Script { steps: steps.into(), ..Default::default() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_parse_and_bad_ones_are_explained() {
        assert_eq!(parse("set shadows.enabled=false").unwrap(), Step::Set("shadows.enabled=false".into()));
        assert_eq!(parse("  view   split ").unwrap(), Step::View(ViewMode::Split));
        assert_eq!(parse("orbit 40 -10").unwrap(), Step::Orbit(Vec2::new(40.0, -10.0)));
        assert_eq!(parse("wait traced").unwrap(), Step::WaitTraced);
        assert_eq!(parse("wait checked").unwrap(), Step::WaitChecked);
        assert_eq!(parse("lab check").unwrap(), Step::LabCheck);
        assert_eq!(parse("probe").unwrap(), Step::Probe);
        assert_eq!(parse("wait 3").unwrap(), Step::Wait(3));
        assert_eq!(parse("wait 1.5s").unwrap(), Step::WaitFor(std::time::Duration::from_millis(1500)));
        assert_eq!(parse("fps 20").unwrap(), Step::Fps(20.0));
        assert_eq!(parse("fps off").unwrap(), Step::Fps(0.0));
        assert_eq!(parse("measure").unwrap(), Step::Measure);
        assert_eq!(parse("budget").unwrap(), Step::Budget);
        assert_eq!(parse("screenshot out.png").unwrap(), Step::Screenshot("out.png".into()));
        for bad in [
            "view sideways",
            "orbit 1",
            "split 2",
            "set shadows",
            "screenshot a.jpg",
            "dance",
            "pick nan 1",
            "fps 0",
            "wait -1s",
            "wait 1hs",
        ] {
            let error = parse(bad).unwrap_err().to_string();
            assert!(error.contains(bad.split_whitespace().next().unwrap()), "{bad}: {error}");
        }
    }
}
