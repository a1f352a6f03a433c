//! What every pass of a frame reads, in one value ([`FrameContext`]); the frame's command encoder
//! ([`FrameEncoder`]); and what the frame did ([`FrameReport`]), to which each pass adds its own
//! name and figures, so that `mirador render --stats`, the viewer's corner and the benchmarks
//! print a new technique's figures without knowing it.

use std::fmt;
use std::time::Duration;

use web_time::Instant;

use super::scene_gpu::{SceneGpu, SurfaceLayout};
use super::view::FrameView;
use super::view_group::ViewGroups;
use crate::gpu::Gpu;
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// What every pass of one frame reads: the device, the scene on both sides, the settings, the
/// pipeline layout every surface pass shares (groups 0 to 2), and every view's view group (group 2).
pub struct FrameContext<'a> {
    pub gpu: &'a Gpu,
    pub scene: &'a Scene,
    pub scene_gpu: &'a SceneGpu,
    pub settings: &'a RenderSettings,
    pub surface: &'a SurfaceLayout,
    /// Group 2 of each view: the shadow maps, the environment maps and the view's own images.
    pub view_groups: &'a ViewGroups,
}

impl FrameContext<'_> {
    pub fn device(&self) -> &wgpu::Device {
        &self.gpu.device
    }

    pub fn queue(&self) -> &wgpu::Queue {
        &self.gpu.queue
    }

    /// What `view`'s shading reads (group 2 of every surface module).
    pub fn view_group(&self, view: &FrameView) -> &wgpu::BindGroup {
        self.view_groups.get(view)
    }
}

/// One figure a pass reports about a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Figure {
    Count(u64),
    Flag(bool),
    Time(Duration),
}

impl fmt::Display for Figure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Figure::Count(n) => write!(f, "{n}"),
            Figure::Flag(b) => write!(f, "{}", if *b { "yes" } else { "no" }),
            Figure::Time(t) => write!(f, "{:.2} ms", t.as_secs_f64() * 1e3),
        }
    }
}

/// What one pass did in a frame, over every view it drew.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PassReport {
    pub name: &'static str,
    /// Wall time, submitted and waited for on its own; `None` unless the frame was profiled.
    pub time: Option<Duration>,
    pub figures: Vec<(&'static str, Figure)>,
}

/// What a frame did, for `--stats`, the viewer's corner and the tests of the caches.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameReport {
    /// The size the frame was drawn at, before the present pass upscaled it.
    pub drawn_size: (u32, u32),
    /// Triangles drawn per view.
    pub triangles: u64,
    /// The passes in the order they first ran; a pass that ran for several views is one entry,
    /// its counts and times summed.
    pub passes: Vec<PassReport>,
}

impl FrameReport {
    /// Adds `figures` (and `time`) to the pass called `name`.
    pub fn add(&mut self, name: &'static str, time: Option<Duration>, figures: &[(&'static str, Figure)]) {
        let index = match self.passes.iter().position(|p| p.name == name) {
            Some(index) => index,
            None => {
                self.passes.push(PassReport { name, ..Default::default() });
                self.passes.len() - 1
            }
        };
        let pass = &mut self.passes[index];
        if let Some(time) = time {
            pass.time = Some(pass.time.unwrap_or_default() + time);
        }
        for &(figure, value) in figures {
            match pass.figures.iter_mut().find(|(n, _)| *n == figure) {
                Some((_, existing)) => *existing = existing.merged(value),
                None => pass.figures.push((figure, value)),
            }
        }
    }

    /// The figure `figure` of pass `pass`, if the pass ran and reported it.
    pub fn figure(&self, pass: &str, figure: &str) -> Option<Figure> {
        let pass = self.passes.iter().find(|p| p.name == pass)?;
        pass.figures.iter().find(|(n, _)| *n == figure).map(|(_, v)| *v)
    }

    /// A count, 0 where the pass did not run or did not report it.
    pub fn count(&self, pass: &str, figure: &str) -> u64 {
        match self.figure(pass, figure) {
            Some(Figure::Count(n)) => n,
            _ => 0,
        }
    }

    /// A flag, false where the pass did not run or did not report it.
    pub fn flag(&self, pass: &str, figure: &str) -> bool {
        matches!(self.figure(pass, figure), Some(Figure::Flag(true)))
    }

    /// The time of pass `pass` (profiled frames only).
    pub fn time(&self, pass: &str) -> Option<Duration> {
        self.passes.iter().find(|p| p.name == pass)?.time
    }
}

impl Figure {
    /// Two reports of the same figure, from two views: counts and times add, flags or.
    fn merged(self, other: Figure) -> Figure {
        match (self, other) {
            (Figure::Count(a), Figure::Count(b)) => Figure::Count(a + b),
            (Figure::Time(a), Figure::Time(b)) => Figure::Time(a + b),
            (Figure::Flag(a), Figure::Flag(b)) => Figure::Flag(a || b),
            (_, other) => other,
        }
    }
}

/// The frame's command encoder and its report. When profiling, each pass is submitted and waited
/// for on its own, and its wall time recorded; otherwise the whole frame is one submission.
pub struct FrameEncoder<'g> {
    gpu: &'g Gpu,
    pub encoder: wgpu::CommandEncoder,
    profile: bool,
    mark: Instant,
    pub report: FrameReport,
    /// The debug groups open now, outermost first ([`Self::group`]); `None` where the device
    /// records none ([`Gpu::debug_groups`]).
    groups: Option<Vec<String>>,
}

impl<'g> FrameEncoder<'g> {
    pub fn new(gpu: &'g Gpu, profile: bool) -> FrameEncoder<'g> {
        let (mark, report) = (Instant::now(), FrameReport::default());
        let groups = gpu.debug_groups().then(Vec::new);
        FrameEncoder { gpu, encoder: Self::encoder(gpu), profile, mark, report, groups }
    }

    fn encoder(gpu: &Gpu) -> wgpu::CommandEncoder {
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame::encoder") })
    }

    /// Records what `record` records inside a debug group named `name`, so a frame capture
    /// (RenderDoc, Xcode, PIX) shows the frame as its views and each view as its phases. A
    /// profiled frame's [`Self::end`] submits the encoder mid-group: the groups open then are
    /// closed on the encoder it submits and opened again on the next.
    pub fn group<R>(&mut self, name: &str, record: impl FnOnce(&mut Self) -> R) -> R {
        let Some(groups) = &mut self.groups else { return record(self) };
        groups.push(name.to_owned());
        self.encoder.push_debug_group(name);
        let recorded = record(self);
        self.encoder.pop_debug_group();
        if let Some(groups) = &mut self.groups {
            groups.pop();
        }
        recorded
    }

    /// Ends what pass `name` recorded since the last call, with the figures it reports.
    pub fn end(&mut self, name: &'static str, figures: &[(&'static str, Figure)]) {
        let time = self.profile.then(|| {
            let mut encoder = std::mem::replace(&mut self.encoder, Self::encoder(self.gpu));
            for group in self.groups.iter().flatten() {
                encoder.pop_debug_group();
                self.encoder.push_debug_group(group);
            }
            self.gpu.queue.submit([encoder.finish()]);
            self.gpu.wait();
            let time = self.mark.elapsed();
            self.mark = Instant::now();
            time
        });
        self.report.add(name, time, figures);
    }

    /// Submits the frame; returns its report.
    pub fn finish(self) -> FrameReport {
        self.gpu.queue.submit([self.encoder.finish()]);
        self.report
    }
}
