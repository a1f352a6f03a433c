//! The view group: what the shading of one view reads (group 2 of every surface pass's
//! module, declared in `shaders/common/view_group.wgsl`). One bind group per view, holding
//!
//! - the frame's inputs, the same in every view: the shadow maps and how to read them, the
//!   environment maps;
//! - the **view images**: images that earlier phases of *that* view made for its shading to
//!   read ([`ViewImage`]: the projected-shadow mask, the hybrid's traced terms), layers of the
//!   view's two arrays ([`ViewArray`]: the drawn images and the copied ones). Each view draws its
//!   own into its own targets, so a technique that makes one shows in every view: the main
//!   camera, each mirrored camera and each cube face (STYLE rule 17; Bevy's mesh view bind group
//!   is the model).
//!
//! [`VIEW_GROUP`] is the one table of the group: its layout and every view's bind group are
//! made from it, and `tests/layouts.rs` checks it binding by binding against the WGSL. A new view
//! image is a variant of [`ViewImage`] and its first layer in `crate::shaders::constants`: layers
//! of an array the group binds already, never a binding of its own (the fullest entry point is
//! at the downlevel limit of 16 sampled textures); the targets then carry it and every view's
//! group binds the view's own.
//!
//! [`ViewImage`]: super::targets::ViewImage

use super::targets::{ViewArray, ViewImages};
use super::view::{FrameView, ViewSlot, ViewTargets};

/// Where a binding of the view group comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resource {
    ShadowUniform,
    ShadowMaps,
    ShadowSampler,
    TransmissionMaps,
    EnvironmentUniform,
    EnvironmentSampler,
    EnvironmentCube,
    DynamicCubes,
    SphereMap,
    LatlongMap,
    /// One of the view's own arrays of images.
    View(ViewArray),
    /// An inspecting renderer's record of one pixel (`shaders/common/inspect.wgsl`).
    Inspection,
    /// The shadow maps read as floats, for the inspection's texel values.
    ShadowTexels,
}

impl Resource {
    /// Only an inspecting renderer's group has it.
    pub fn inspect_only(self) -> bool {
        matches!(self, Resource::Inspection | Resource::ShadowTexels)
    }
}

/// One binding of the view group: its number, its name in the WGSL, its type, and what it binds.
#[derive(Clone, Copy, Debug)]
pub struct ViewBinding {
    pub binding: u32,
    pub name: &'static str,
    pub ty: wgpu::BindingType,
    pub resource: Resource,
}

const UNIFORM: wgpu::BindingType = wgpu::BindingType::Buffer {
    ty: wgpu::BufferBindingType::Uniform,
    has_dynamic_offset: false,
    min_binding_size: None,
};

const fn texture(
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindingType {
    wgpu::BindingType::Texture { sample_type, view_dimension, multisampled: false }
}

const UNFILTERABLE: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };
const FILTERABLE: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: true };

/// The view group, binding by binding.
pub const VIEW_GROUP: &[ViewBinding] = {
    use wgpu::TextureViewDimension as Dim;
    use wgpu::{BindingType, SamplerBindingType, TextureSampleType};
    &[
        ViewBinding { binding: 0, name: "shadows", ty: UNIFORM, resource: Resource::ShadowUniform },
        ViewBinding {
            binding: 1,
            name: "shadow_maps",
            ty: texture(TextureSampleType::Depth, Dim::D2Array),
            resource: Resource::ShadowMaps,
        },
        ViewBinding {
            binding: 2,
            name: "shadow_sampler",
            ty: BindingType::Sampler(SamplerBindingType::Comparison),
            resource: Resource::ShadowSampler,
        },
        ViewBinding {
            binding: 3,
            name: "transmission_maps",
            ty: texture(UNFILTERABLE, Dim::D2Array),
            resource: Resource::TransmissionMaps,
        },
        ViewBinding {
            binding: 4,
            name: "drawn_images",
            ty: texture(UNFILTERABLE, Dim::D2Array),
            resource: Resource::View(ViewArray::Drawn),
        },
        ViewBinding { binding: 5, name: "environment", ty: UNIFORM, resource: Resource::EnvironmentUniform },
        ViewBinding {
            binding: 6,
            name: "env_sampler",
            ty: BindingType::Sampler(SamplerBindingType::Filtering),
            resource: Resource::EnvironmentSampler,
        },
        ViewBinding {
            binding: 7,
            name: "env_cube",
            ty: texture(FILTERABLE, Dim::Cube),
            resource: Resource::EnvironmentCube,
        },
        ViewBinding {
            binding: 8,
            name: "env_cubes",
            ty: texture(FILTERABLE, Dim::CubeArray),
            resource: Resource::DynamicCubes,
        },
        ViewBinding { binding: 9, name: "env_sphere", ty: texture(FILTERABLE, Dim::D2), resource: Resource::SphereMap },
        ViewBinding {
            binding: 10,
            name: "env_latlong",
            ty: texture(FILTERABLE, Dim::D2),
            resource: Resource::LatlongMap,
        },
        ViewBinding {
            binding: 13,
            name: "copied_images",
            ty: texture(UNFILTERABLE, Dim::D2Array),
            resource: Resource::View(ViewArray::Copied),
        },
        ViewBinding {
            binding: 11,
            name: "inspection",
            ty: BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            resource: Resource::Inspection,
        },
        ViewBinding {
            binding: 12,
            name: "shadow_texels",
            ty: texture(UNFILTERABLE, Dim::D2Array),
            resource: Resource::ShadowTexels,
        },
    ]
};

/// The view group's layout; `inspect` adds the inspection's bindings.
pub fn layout(device: &wgpu::Device, inspect: bool) -> wgpu::BindGroupLayout {
    let profile = crate::shaders::Profile::of(device);
    let entries: Vec<wgpu::BindGroupLayoutEntry> = VIEW_GROUP
        .iter()
        .filter(|b| inspect || !b.resource.inspect_only())
        .map(|b| wgpu::BindGroupLayoutEntry {
            binding: b.binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: match b.ty {
                wgpu::BindingType::Texture { sample_type, view_dimension, multisampled } => {
                    wgpu::BindingType::Texture {
                        sample_type,
                        view_dimension: profile.view_dimension(view_dimension),
                        multisampled,
                    }
                }
                ty => ty,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("view_group::layout"),
        entries: &entries,
    })
}

/// The frame's inputs to every view's group, from the passes that made them.
pub struct FrameInputs<'a> {
    pub shadow_uniform: wgpu::BindingResource<'a>,
    pub shadow_maps: &'a wgpu::TextureView,
    pub shadow_sampler: &'a wgpu::Sampler,
    pub transmission_maps: &'a wgpu::TextureView,
    pub environment_uniform: wgpu::BindingResource<'a>,
    pub environment_sampler: &'a wgpu::Sampler,
    pub environment_cube: &'a wgpu::TextureView,
    pub dynamic_cubes: &'a wgpu::TextureView,
    pub sphere_map: &'a wgpu::TextureView,
    pub latlong_map: &'a wgpu::TextureView,
    /// An inspecting renderer's buffer; `None`: the group has no inspection bindings.
    pub inspection: Option<&'a wgpu::Buffer>,
}

impl<'a> FrameInputs<'a> {
    /// The images the groups read, to tell when one was made again (wgpu's handles compare by
    /// identity).
    fn images(&self) -> [&'a wgpu::TextureView; 6] {
        [
            self.shadow_maps,
            self.transmission_maps,
            self.environment_cube,
            self.dynamic_cubes,
            self.sphere_map,
            self.latlong_map,
        ]
    }

    fn resource<'r>(&'r self, resource: Resource, images: &'r ViewImages) -> Option<wgpu::BindingResource<'r>> {
        use wgpu::BindingResource::{Sampler, TextureView};
        Some(match resource {
            Resource::ShadowUniform => self.shadow_uniform.clone(),
            Resource::ShadowMaps | Resource::ShadowTexels => TextureView(self.shadow_maps),
            Resource::ShadowSampler => Sampler(self.shadow_sampler),
            Resource::TransmissionMaps => TextureView(self.transmission_maps),
            Resource::EnvironmentUniform => self.environment_uniform.clone(),
            Resource::EnvironmentSampler => Sampler(self.environment_sampler),
            Resource::EnvironmentCube => TextureView(self.environment_cube),
            Resource::DynamicCubes => TextureView(self.dynamic_cubes),
            Resource::SphereMap => TextureView(self.sphere_map),
            Resource::LatlongMap => TextureView(self.latlong_map),
            Resource::View(array) => TextureView(&images.array(array).view),
            Resource::Inspection => self.inspection?.as_entire_binding(),
        })
    }
}

/// Every view's group, kept across frames while the images it reads are the same ones.
#[derive(Default)]
pub struct ViewGroups {
    /// The frame's images the kept groups were made with: a new one makes every group again.
    frame_images: Vec<wgpu::TextureView>,
    /// A group per set of view images (per view targets), with the images it reads.
    kept: Vec<(Vec<wgpu::TextureView>, wgpu::BindGroup)>,
    /// This frame's views: each one's slot and its group in `kept`.
    views: Vec<(ViewSlot, usize)>,
}

impl ViewGroups {
    /// Makes the group of every view of the frame whose images have none yet; forgets the
    /// groups no view of this frame reads (targets since remade, mirrors no longer seen).
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        inputs: &FrameInputs,
        views: &[ViewTargets<'_>],
    ) {
        let frame_images = inputs.images();
        let mut last = std::mem::take(&mut self.kept);
        if self.frame_images.len() != frame_images.len()
            || self.frame_images.iter().zip(frame_images).any(|(a, b)| a != b)
        {
            self.frame_images = frame_images.map(Clone::clone).to_vec();
            last.clear();
        }
        // This frame's groups: the last frame's where a view's images are the same, new ones
        // where not; the rest are dropped.
        self.views.clear();
        for (view, targets) in views {
            let images: Vec<wgpu::TextureView> =
                ViewArray::ALL.iter().map(|&a| targets.images.array(a).view.clone()).collect();
            let index = match self.kept.iter().position(|(kept, _)| *kept == images) {
                Some(index) => index,
                None => {
                    let group = match last.iter().position(|(kept, _)| *kept == images) {
                        Some(k) => last.swap_remove(k).1,
                        None => group(device, layout, inputs, &targets.images),
                    };
                    self.kept.push((images, group));
                    self.kept.len() - 1
                }
            };
            self.views.push((view.slot, index));
        }
    }

    /// The group of `view`, made by [`Self::prepare`] for this frame.
    pub fn get(&self, view: &FrameView) -> &wgpu::BindGroup {
        let found = self.views.iter().find(|(slot, _)| *slot == view.slot);
        &self.kept[found.expect("ViewGroups::prepare was given every view of the frame").1].1
    }
}

fn group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    inputs: &FrameInputs,
    images: &ViewImages,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = VIEW_GROUP
        .iter()
        .filter(|b| inputs.inspection.is_some() || !b.resource.inspect_only())
        .map(|b| wgpu::BindGroupEntry {
            binding: b.binding,
            resource: inputs.resource(b.resource, images).expect("an inspecting group has the inspection buffer"),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("view_group::group"), layout, entries: &entries })
}
