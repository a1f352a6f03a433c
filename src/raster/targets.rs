//! The images a view draws into, and their formats. The main view's targets belong to the caller
//! (a window's frame, a screenshot); mirrored views' and cube faces' belong to the passes that
//! show them (`super::mirror`, `super::environment`). Every view draws into its own, so the
//! phases of one view never read what another is writing.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::gpu::texture::{GpuTexture, Layers};
use crate::shaders::constants;

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

/// The arrays a view's images are layers of, one view-group binding each. An image is its layers
/// of one of them, so the next image a technique adds costs layers, never a binding: the view
/// group's fullest entry point is at the downlevel limit of 16 sampled textures
/// (docs/architecture.md). Two arrays, not one, because how an image is made fixes its format:
/// a pass that draws and blends needs a blendable format, and a copy from the tracer needs full
/// floats, which would cost a drawn mask four times its bytes and cannot be blended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewArray {
    /// Drawn into and blended by the view's raster passes (`drawn_images` in the WGSL).
    Drawn,
    /// Copied into from the CPU (`copied_images`); made at the targets' size only when a frame
    /// asks ([`ViewImages::ensure`]), one pixel until then, so views that never read it cost
    /// nothing.
    Copied,
}

impl ViewArray {
    /// Every view array, in the order the targets keep them.
    pub const ALL: [ViewArray; 2] = [ViewArray::Drawn, ViewArray::Copied];

    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            ViewArray::Drawn => wgpu::TextureFormat::Rgba8Unorm,
            ViewArray::Copied => wgpu::TextureFormat::Rgba32Float,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            ViewArray::Drawn => "view_group::drawn_images",
            ViewArray::Copied => "view_group::copied_images",
        }
    }

    /// Its layers: up to the last of its images. The texture is made with as many more as GL
    /// needs to keep it an array ([`Layers::count`]: one layer would be a plain 2D texture, and
    /// a square one of six a cube; the copied array's one pixel is square, and so are the cube
    /// faces' targets).
    pub fn layers(self) -> u32 {
        let images = ViewImage::ALL.into_iter().filter(|i| i.array() == self);
        images.map(|i| i.first_layer() + i.layers()).max().unwrap_or(0)
    }

    fn on_demand(self) -> bool {
        matches!(self, ViewArray::Copied)
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// An image a view's phases make for its own shading: layers of one of the view's arrays, from
/// its first layer, which `crate::shaders::constants` numbers once for the Rust and the WGSL.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewImage {
    /// Object-precision shadows: one channel per shadowed light, 1 where the light is hidden
    /// (`super::shadow::projected`, drawn after the view's depth prepass).
    ProjectedMask,
    /// The hybrid's traced terms at each pixel's first opaque surface (`super::traced`, copied in
    /// before the view draws): the surface layer holds `C` and the surface's object + 1, each
    /// traced term its own layers ([`crate::settings::Traced::layer`]): `L(r)`, what a
    /// transparent surface lets through, each shadowed light's `V_i`.
    Traced,
}

/// The layers of [`ViewImage::Traced`]: the surface's, then each traced term's, numbered by the
/// approximations table (`crate::settings::hybrid`).
pub use crate::settings::hybrid::TRACED_LAYERS;

impl ViewImage {
    /// Every view image.
    pub const ALL: [ViewImage; 2] = [ViewImage::ProjectedMask, ViewImage::Traced];

    /// The array it is layers of.
    pub fn array(self) -> ViewArray {
        match self {
            ViewImage::ProjectedMask => ViewArray::Drawn,
            ViewImage::Traced => ViewArray::Copied,
        }
    }

    /// Its first layer of its array.
    pub fn first_layer(self) -> u32 {
        match self {
            ViewImage::ProjectedMask => constants::PROJECTED_MASK_LAYER,
            ViewImage::Traced => constants::TRACED_FIRST_LAYER,
        }
    }

    /// How many layers it has.
    pub fn layers(self) -> u32 {
        match self {
            ViewImage::ProjectedMask => 1,
            ViewImage::Traced => TRACED_LAYERS,
        }
    }
}

/// Every view array of one view's targets, at the targets' size.
pub struct ViewImages {
    arrays: Vec<GpuTexture>,
    /// A 2D view of each layer of [`ViewArray::Drawn`], which its passes draw into.
    drawn_layers: Vec<wgpu::TextureView>,
    /// The number of the traced terms [`ViewImage::Traced`] holds, copied in by a frame
    /// (`super::traced`); 0: none known.
    traced: AtomicU64,
}

impl ViewImages {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> ViewImages {
        let made = |a: &ViewArray| make(device, *a, if a.on_demand() { (1, 1) } else { size });
        let arrays: Vec<GpuTexture> = ViewArray::ALL.iter().map(made).collect();
        let drawn = &arrays[ViewArray::Drawn.index()].texture;
        let drawn_layers = (0..ViewArray::Drawn.layers())
            .map(|layer| {
                drawn.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("view_group::drawn_layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        ViewImages { arrays, drawn_layers, traced: AtomicU64::new(0) }
    }

    /// The number of the traced terms [`ViewImage::Traced`] holds (0: none known).
    pub fn traced(&self) -> u64 {
        self.traced.load(Ordering::Relaxed)
    }

    /// Records that the frame being recorded copies the traced terms numbered `number` into
    /// [`ViewImage::Traced`] (0: terms the next frames cannot count on).
    pub fn hold_traced(&self, number: u64) {
        self.traced.store(number, Ordering::Relaxed);
    }

    /// The array `array`, viewed whole.
    pub fn array(&self, array: ViewArray) -> &GpuTexture {
        &self.arrays[array.index()]
    }

    /// The array that holds `image`.
    pub fn array_of(&self, image: ViewImage) -> &GpuTexture {
        self.array(image.array())
    }

    /// The layer a pass draws `image` into (an image of [`ViewArray::Drawn`]).
    pub fn drawn(&self, image: ViewImage) -> &wgpu::TextureView {
        assert_eq!(image.array(), ViewArray::Drawn, "{image:?} is copied in, not drawn");
        &self.drawn_layers[image.first_layer() as usize]
    }

    /// Makes the array of `image` at `size` if it has another size (an array made on demand;
    /// once made, it stays until the targets are remade).
    pub fn ensure(&mut self, device: &wgpu::Device, image: ViewImage, size: (u32, u32)) {
        let array = image.array();
        assert!(array.on_demand(), "{array:?} is made at the targets' size");
        let made = self.arrays[array.index()].texture.size();
        if (made.width, made.height) != size {
            self.arrays[array.index()] = make(device, array, size);
            self.hold_traced(0);
        }
    }
}

fn make(device: &wgpu::Device, array: ViewArray, size: (u32, u32)) -> GpuTexture {
    let usage = match array {
        ViewArray::Drawn => wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        ViewArray::Copied => wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::TEXTURE_BINDING,
    };
    Layers::Array(array.layers()).texture(
        device,
        &wgpu::TextureDescriptor {
            label: Some(array.label()),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: array.format(),
            usage,
            view_formats: &[],
        },
    )
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Each image's layers lie in its array, apart from every other image's: a first layer
    /// written wrong in `crate::shaders::constants` would have two images share a layer.
    #[test]
    fn the_view_images_share_no_layer() {
        for array in ViewArray::ALL {
            let mut taken = vec![None; array.layers() as usize];
            for image in ViewImage::ALL.into_iter().filter(|i| i.array() == array) {
                assert!(image.layers() > 0, "{image:?}");
                for layer in image.first_layer()..image.first_layer() + image.layers() {
                    let slot = &mut taken[layer as usize];
                    assert_eq!(*slot, None, "{image:?} and {slot:?} both hold layer {layer} of {array:?}");
                    *slot = Some(image);
                }
            }
        }
        // Made square (the copied array's one pixel, a cube face's targets), each is made with a
        // count GL keeps an array.
        for array in ViewArray::ALL {
            let layers = Layers::Array(array.layers()).count((1, 1), crate::shaders::Profile::Standard);
            assert!(layers >= 2 && !layers.is_multiple_of(6), "GL reads {array:?}'s {layers} layers as no array");
        }
    }
}
