//! The images a view draws into, and their formats. The main view's targets belong to the caller
//! (a window's frame, a screenshot); mirrored views' and cube faces' belong to the passes that
//! show them (`super::mirror`, `super::environment`). Every view draws into its own, so the
//! phases of one view never read what another is writing.

use crate::gpu::texture::GpuTexture;

/// Linear radiance, before the output transform.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The format of offscreen screenshots.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The images of one view, recreated when their size changes.
pub struct FrameTargets {
    pub size: (u32, u32),
    pub hdr: GpuTexture,
    pub depth: GpuTexture,
    /// What the view's phases make for its own shading (read through its view group).
    pub images: ViewImages,
}

impl FrameTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> FrameTargets {
        FrameTargets {
            size,
            hdr: GpuTexture::target(device, "frame::hdr", size, HDR_FORMAT),
            depth: GpuTexture::target(device, "frame::depth", size, DEPTH_FORMAT),
            images: ViewImages::new(device, size),
        }
    }
}

/// An image a view's phases make for its own shading, kept in the view's targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewImage {
    /// Object-precision shadows: one channel per shadowed light, 1 where the light is hidden
    /// (`super::shadow::projected`, drawn after the view's depth prepass).
    ProjectedMask,
    /// The hybrid's traced terms at each pixel's first opaque surface (`super::traced`, copied in
    /// before the view draws): the surface layer holds `C` and the surface's object + 1, each
    /// traced term its own layers ([`crate::settings::Traced::layer`]): `L(r)`, what a
    /// transparent surface lets through, each shadowed light's
    /// `V_i`. Made at the targets' size only when a frame traces a term.
    Traced,
}

/// The layers of [`ViewImage::Traced`]: the surface's, then each traced term's, numbered by the
/// approximations table (`crate::settings::hybrid`).
pub use crate::settings::hybrid::TRACED_LAYERS;

impl ViewImage {
    /// Every view image, in the order the targets keep them.
    pub const ALL: [ViewImage; 2] = [ViewImage::ProjectedMask, ViewImage::Traced];

    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            ViewImage::ProjectedMask => wgpu::TextureFormat::Rgba8Unorm,
            ViewImage::Traced => wgpu::TextureFormat::Rgba32Float,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            ViewImage::ProjectedMask => "view_group::projected_mask",
            ViewImage::Traced => "view_group::traced",
        }
    }

    /// Its layers: one, or a 2D array.
    pub fn layers(self) -> Option<u32> {
        match self {
            ViewImage::ProjectedMask => None,
            ViewImage::Traced => Some(TRACED_LAYERS),
        }
    }

    /// Made at the targets' size only when a frame asks ([`ViewImages::ensure`]); one pixel
    /// until then, so views that never read it cost nothing.
    fn on_demand(self) -> bool {
        matches!(self, ViewImage::Traced)
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// Every view image of one view's targets, at the targets' size.
pub struct ViewImages {
    images: Vec<GpuTexture>,
}

impl ViewImages {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> ViewImages {
        let made = |i: &ViewImage| make(device, *i, if i.on_demand() { (1, 1) } else { size });
        ViewImages { images: ViewImage::ALL.iter().map(made).collect() }
    }

    pub fn get(&self, image: ViewImage) -> &GpuTexture {
        &self.images[image.index()]
    }

    /// Makes `image` at `size` if it has another size (an image made on demand; once made, it
    /// stays until the targets are remade).
    pub fn ensure(&mut self, device: &wgpu::Device, image: ViewImage, size: (u32, u32)) {
        let made = self.images[image.index()].texture.size();
        if (made.width, made.height) != size {
            self.images[image.index()] = make(device, image, size);
        }
    }
}

fn make(device: &wgpu::Device, image: ViewImage, size: (u32, u32)) -> GpuTexture {
    match image.layers() {
        None => GpuTexture::target(device, image.label(), size, image.format()),
        Some(layers) => GpuTexture::layered_copy_target(device, image.label(), size, layers, image.format()),
    }
}

/// The size a frame is drawn at: the output's times the render scale, at least one pixel.
pub fn drawn_size(output: (u32, u32), render_scale: f32) -> (u32, u32) {
    let scaled = |n: u32| ((n as f32 * render_scale).round() as u32).clamp(1, n.max(1));
    (scaled(output.0), scaled(output.1))
}

/// What a pass keeps for each view's targets (a copy of its depth, the peels' depths, refraction's
/// images), found by the targets' depth image: made the first frame a view draws into them, and
/// dropped the first frame none does.
pub struct PerTarget<T> {
    entries: Vec<(wgpu::TextureView, T)>,
}

impl<T> Default for PerTarget<T> {
    fn default() -> Self {
        PerTarget { entries: Vec::new() }
    }
}

impl<T> PerTarget<T> {
    /// What is kept for `targets`, if anything.
    pub fn get(&self, targets: &FrameTargets) -> Option<&T> {
        self.entries.iter().find(|(depth, _)| *depth == targets.depth.view).map(|(_, kept)| kept)
    }

    /// The index of what is kept for `targets` ([`Self::at`]), made by `make` if nothing is.
    pub fn index_or_insert_with(&mut self, targets: &FrameTargets, make: impl FnOnce() -> T) -> usize {
        match self.entries.iter().position(|(depth, _)| *depth == targets.depth.view) {
            Some(index) => index,
            None => {
                self.entries.push((targets.depth.view.clone(), make()));
                self.entries.len() - 1
            }
        }
    }

    /// What [`Self::index_or_insert_with`] gave `index` for.
    pub fn at(&self, index: usize) -> &T {
        &self.entries[index].1
    }

    /// Drops what is kept for targets no view of `drawn` draws into.
    pub fn keep_drawn<'t>(&mut self, drawn: impl IntoIterator<Item = &'t FrameTargets> + Clone) {
        self.entries.retain(|(depth, _)| drawn.clone().into_iter().any(|t| t.depth.view == *depth));
    }
}
