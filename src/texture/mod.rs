//! Textures beyond plain lookups: mip chains and level of detail (docs/course/03-mipmaps.md
//! §1.1) and bump mapping (docs/course/04-bump-mapping.md), on the CPU for the ray tracer, with WGSL twins in
//! `shaders/common/bump.wgsl` and GPU mip generation in `crate::gpu::mipmap`.
//!
//! - [`mipmap`]: [`MipChain`] (linear f32 levels, box filter, NPOT rule) and its [`Filter`]s,
//!   the level-colour palette.
//! - [`lod`]: which level to read: the notes' distance rule, ray cones for the tracer, and the
//!   GPU's screen-derivative rule.
//! - [`height`]: height fields `f_h(u, v)`: grey textures, a sine field, value noise.
//! - [`bump`]: finite differences and the perturbed normal `n' = normalize(t'_u × t'_v)`.
//! - [`tangents`]: `t_u`, `t_v` per triangle and per vertex (MikkTSpace), glTF normal maps.
//! - [`parallax`]: parallax occlusion mapping, the view ray marched through the relief.
//! - [`displacement`]: the surface `p + k·f(u, v)·n` itself, pre-tessellated for both renderers.
//!
//! How the renderers use them (one meaning in both, so raster and trace stay comparable):
//!
//! - Ray tracer, texture lookup: build one [`MipChain`] per scene texture at load, carry a
//!   [`lod::RayCone`] with each ray (`RayCone::perspective(fovy, height)` for primary rays,
//!   `cone.continued(t)` for reflections and refractions), and at a hit read
//!   `chain.sample(hit.uv, lod, filter)` with
//!   `lod = lod_from_footprint(cone.footprint(hit.t, ray_dir.dot(hit.normal)), hit.dpdu.length(),
//!   hit.dpdv.length(), (w, h), bias)`.
//! - Ray tracer, bump: `bump::bump_normal(&field, &params, hit.uv, hit.normal, hit.dpdu, hit.dpdv)`
//!   with `field` a [`height::TextureHeight`] of the material's `height_map` and
//!   `params.k = material.bump_scale`.
//! - Rasterizer: `crate::gpu::mipmap::upload_with_mipmaps` and `sampler_descriptor(filter, aniso)`;
//!   in the fragment shader, four `textureSampleLevel(height, sampler, uv ± Δ, 0.0).r` into
//!   `bump_central_differences`, tangents from `tangents_from_derivatives(dpdx(p), dpdy(p),
//!   dpdx(uv), dpdy(uv))`, then `perturbed_normal`. Both renderers then use true-length
//!   `∂p/∂u`, `∂p/∂v`, so the same `k` gives the same relief.

pub mod bump;
pub mod displacement;
pub mod height;
pub mod lod;
pub mod mipmap;
pub mod parallax;
pub mod tangents;

pub use bump::{BumpParams, bump_normal, height_gradient, perturbed_normal};
pub use height::{HeightField, SineField, TextureHeight, ValueNoise};
pub use lod::{RayCone, lod_from_distance, lod_from_footprint, lod_from_uv_derivatives};
pub use mipmap::{Filter, LEVEL_PALETTE, MipChain, MipLevel};
pub use tangents::{mesh_tangents, normal_map_normal, triangle_tangents};
