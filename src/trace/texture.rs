//! Texture lookups and bump mapping for the ray tracer (docs/course/03-mipmaps.md and docs/course/04-bump-mapping.md), matching the
//! rasterizer's sampler so the two images agree: repeat wrapping, texel centres at
//! `(i + ½)/width`, sRGB colour textures decoded to linear before any filtering or averaging.
//!
//! **Preparation.** [`SceneTextures::new`] runs once per scene (in `Tracer::new`): a
//! [`MipChain`] (linear levels down to 1×1, `crate::texture::mipmap`) for every texture some
//! material uses as its colour texture, and a [`TextureHeight`] (level 0's red channel) for every
//! texture used as a height map; a texture used as both gets both.
//!
//! **Level of detail by ray cones.** Every primary ray carries a [`RayCone`]: the angle one pixel
//! subtends (`RayCone::perspective(fovy, height)`), or one pixel's width for an orthographic
//! camera. Mirror and refracted rays continue the cone from the hit (`cone.continued(t)`), so a
//! texture seen in a mirror is read at the level of its total distance; shadow rays read no
//! texture and carry none. At a textured hit ([`hit_lod`]) the cone's width at `t`, stretched by
//! `1/|cos θ|` (`θ` between the ray and the geometric normal: the footprint lies on the actual
//! surface, which for a smoothed mesh is the flat triangle), gives
//! `λ = log2 max(w·footprint/|∂p/∂u|, h·footprint/|∂p/∂v|) + lod_bias`
//! (`crate::texture::lod::lod_from_footprint`). The notes' simpler rule, `λ = log2(d/d₀)` with
//! `d₀` the distance at which a texel fills a pixel (`lod_from_distance`), is not used: it is
//! exact only for a surface facing the camera and knows nothing of slant, texture stretch or
//! bounces. The cone is always one pixel wide, whatever the anti-aliasing: supersampling averages
//! lookups already filtered over a pixel (slightly blurrier than one ray, like a GPU with MSAA,
//! which also picks one level per pixel).
//!
//! **Filters** (`settings.textures.filter`, [`filter_of`]): nearest and bilinear read level 0
//! only (bilinear on level 0 is [`sample_bilinear`], the reference kept here); nearest-mip and
//! trilinear read the chain at `λ`; anisotropic is trilinear here, because the GPU's anisotropic
//! footprint is left to the implementation and has no exact CPU twin. The level-colour view puts
//! `level_colour(λ)` (`LEVEL_PALETTE` blended like trilinear, `λ` clamped to the chain's last
//! level) in place of the textured colour `C`: the material's colour is not multiplied in, as in
//! the rasterizer. Untextured materials keep their colour.
//!
//! **Coverage** ([`SceneTextures::coverage`], for alpha masks and blending, `AlphaMode`):
//! `α = alpha ×` the colour texture's alpha channel, which is stored linear (never sRGB-decoded)
//! and read with the same filter at the same level as the colour, so a mask's edge is as sharp or
//! as soft as the texture it comes from. The level-colour view replaces only the colour: the
//! alpha is then read trilinearly. Shadow rays carry no cone and read level 0.
//!
//! **Against the rasterizer's rule** (`mip_lod` of `dpdx(uv)`, `dpdy(uv)`): the two agree on the
//! optical axis for a surface facing the camera. Off axis the cone over-estimates: a primary ray
//! at `α` from the axis meets a frontal plane at `t = z/cos α` and at incidence `α`, so its
//! footprint `t·γ/cos α = z·γ/cos² α` exceeds the GPU's per-pixel step `z·γ` by `1/cos² α`
//! (`+log2(1/cos² α)` levels: +0.09 in a 20° view's corners, about +0.9 in a 50° 16:9 one).
//! The GPU also differences neighbouring pixels (2×2 quads) rather than differentiating, and
//! takes the longer of two screen-axis vectors where the cone takes one width stretched by
//! `1/|cos θ|`; on slanted surfaces off the image's vertical centre line the two differ a little.
//!
//! **Bump mapping** ([`SceneTextures::shading_normal`]): where bump mapping is on and the material
//! has a height map, `n' = bump_normal(field, k = bump_scale·settings.scale,
//! Δ = delta_texels/(w, h), uv, n, ∂p/∂u, ∂p/∂v)` with the hit's analytic tangents (§3's first
//! source), by central differences on level 0 of the height map (as the GPU's
//! `textureSampleLevel(…, 0.0)`). `n' = normalize(t'_u × t'_v)` takes its direction from the
//! tangents, laid first in the plane of `n` (`perturbed_normal`), so the rasterizer's
//! per-facet tangents (from `dpdx(p)`, `dpdy(p)`) give the same smooth result as the exact
//! surfaces here.
//!
//! **Normal maps** (glTF's `normalTexture`): after any bump, `n' = normal_map_normal(n, (t, ±1),
//! rgb, scale)` with `t` = ∂p/∂u laid in `n`'s plane and the bitangent's sign from ∂p/∂v, the
//! frame MikkTSpace builds from the same texture coordinates.

use glam::{Vec2, Vec3, Vec4};

use super::geometry::SurfaceHit;
use crate::base::TextureId;
use crate::output::srgb_decode;
use crate::scene::{ColorSpace, Material, Scene, Texture};
use crate::settings::{BumpSettings, TextureFilter, TextureSettings, TracerLod};
use crate::texture::height::with_material_field;
use crate::texture::parallax::parallax_uv;
use crate::texture::tangents::normal_map_normal;
use crate::texture::{
    BumpParams, Filter, HeightField, MipChain, RayCone, TextureHeight, bump_normal, height_gradient, lod_from_distance,
    lod_from_footprint,
};

/// The linear RGB value of `texture` at `uv`, bilinearly filtered with repeat wrapping: level 0
/// of the chain read with [`Filter::Bilinear`], written out on the stored bytes (the reference
/// that the mip chain's bilinear filter is checked against).
pub fn sample_bilinear(texture: &Texture, uv: Vec2) -> Vec3 {
    let (w, h) = (texture.width as i64, texture.height as i64);
    let x = uv.x * w as f32 - 0.5;
    let y = uv.y * h as f32 - 0.5;
    if !(x.is_finite() && y.is_finite()) || w == 0 || h == 0 {
        return Vec3::ZERO;
    }
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let texel = |i: i64, j: i64| -> Vec3 {
        let (i, j) = (i.rem_euclid(w) as usize, j.rem_euclid(h) as usize);
        let at = 4 * (j * texture.width as usize + i);
        let Some(bytes) = texture.rgba8.get(at..at + 3) else {
            // Short pixel data (a malformed file) reads as black, as in `MipLevel::from_texture`.
            return Vec3::ZERO;
        };
        let rgb = Vec3::new(bytes[0] as f32, bytes[1] as f32, bytes[2] as f32) / 255.0;
        match texture.color_space {
            ColorSpace::Srgb => Vec3::new(srgb_decode(rgb.x), srgb_decode(rgb.y), srgb_decode(rgb.z)),
            ColorSpace::Linear => rgb,
        }
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let top = texel(i, j).lerp(texel(i + 1, j), fx);
    let bottom = texel(i, j + 1).lerp(texel(i + 1, j + 1), fx);
    top.lerp(bottom, fy)
}

/// The CPU filter for a texture setting. Anisotropic filtering has no CPU twin (the GPU's
/// footprint shape and tap count are the implementation's), so the tracer reads it as trilinear:
/// the same level, blurrier than the GPU along the footprint's short axis.
pub fn filter_of(filter: TextureFilter) -> Filter {
    match filter {
        TextureFilter::Nearest => Filter::Nearest,
        TextureFilter::Bilinear => Filter::Bilinear,
        TextureFilter::NearestMip => Filter::NearestMip,
        TextureFilter::Trilinear | TextureFilter::Anisotropic => Filter::Trilinear,
        TextureFilter::LevelColour => Filter::LevelColour,
    }
}

/// The level of detail of a lookup in a `size`-texel texture at `hit`, reached by a ray along
/// the unit vector `direction` that carries `cone`: the cone's footprint on the surface
/// (stretched by `1/|cos θ|` against the geometric normal) in texels along `u` and `v`.
pub fn hit_lod(cone: &RayCone, direction: Vec3, hit: &SurfaceHit, size: (u32, u32), bias: f32) -> f32 {
    let footprint = cone.footprint(hit.t, direction.dot(hit.geometric_normal));
    lod_from_footprint(footprint, hit.dpdu.length(), hit.dpdv.length(), size, bias)
}

/// The level by the notes' simple rule, `log2(distance / texel_distance)`: the distance is the
/// whole path the cone has travelled (its width over its spread), and `texel_distance` the one at
/// which a level-0 texel, seen head-on, covers a pixel. The angle of incidence plays no part, so
/// a floor seen at a grazing angle keeps too fine a level (aliasing): what ray cones cure.
pub fn distance_lod(cone: &RayCone, hit: &SurfaceHit, size: (u32, u32), bias: f32) -> Option<f32> {
    if !(cone.spread > 0.0) {
        return None;
    }
    let texel = (hit.dpdu.length() / size.0 as f32).min(hit.dpdv.length() / size.1 as f32);
    Some(lod_from_distance(cone.width_at(hit.t) / cone.spread, texel / cone.spread, bias))
}

/// The level at a hit under `settings`' rule.
fn level_at(cone: &RayCone, direction: Vec3, hit: &SurfaceHit, size: (u32, u32), settings: &TextureSettings) -> f32 {
    match settings.tracer_lod {
        TracerLod::Distance => distance_lod(cone, hit, size, settings.lod_bias),
        TracerLod::RayCone => None,
    }
    .unwrap_or_else(|| hit_lod(cone, direction, hit, size, settings.lod_bias))
}

/// The scene's textures as the tracer reads them, indexed by [`TextureId`].
#[derive(Clone, Debug, Default)]
pub struct SceneTextures {
    chains: Vec<Option<MipChain>>,
    heights: Vec<Option<TextureHeight>>,
}

impl SceneTextures {
    /// Mip chains of the colour textures and height fields of the height maps that the scene's
    /// materials use. A texture with no texels (which no loader produces) gets neither, and reads
    /// as untextured.
    pub fn new(scene: &Scene) -> SceneTextures {
        let count = scene.textures.len();
        let (mut chains, mut heights) = (vec![None; count], vec![None; count]);
        let usable = |id: TextureId| scene.textures.get(id.0).filter(|t| t.width > 0 && t.height > 0);
        for material in &scene.materials {
            if let Some(id) = material.texture
                && let Some(texture) = usable(id)
                && chains[id.0].is_none()
            {
                chains[id.0] = Some(MipChain::build(texture));
            }
            if let Some(id) = material.height_map
                && let Some(texture) = usable(id)
                && heights[id.0].is_none()
            {
                heights[id.0] = Some(TextureHeight::new(texture));
            }
            if let Some(id) = material.normal_map
                && let Some(texture) = usable(id)
                && chains[id.0].is_none()
            {
                chains[id.0] = Some(MipChain::build(texture));
            }
        }
        SceneTextures { chains, heights }
    }

    /// The mip chain of colour texture `id`, if a material uses it as one.
    pub fn chain(&self, id: TextureId) -> Option<&MipChain> {
        self.chains.get(id.0).and_then(Option::as_ref)
    }

    /// The height field of height map `id`, if a material uses it as one.
    pub fn height(&self, id: TextureId) -> Option<&TextureHeight> {
        self.heights.get(id.0).and_then(Option::as_ref)
    }

    /// The level of detail the colour texture of `material` is read at, or `None` when the
    /// material has no (usable) colour texture.
    pub fn lod(
        &self,
        material: &Material,
        hit: &SurfaceHit,
        direction: Vec3,
        cone: &RayCone,
        settings: &TextureSettings,
    ) -> Option<f32> {
        let chain = self.chain(material.texture?)?;
        let level0 = &chain.levels[0];
        Some(level_at(cone, direction, hit, (level0.width, level0.height), settings))
    }

    /// `C(p)`: the material's colour times its filtered texture at the hit, or the level colour
    /// in place of both under the level-colour view.
    pub fn colour(
        &self,
        material: &Material,
        hit: &SurfaceHit,
        direction: Vec3,
        cone: &RayCone,
        settings: &TextureSettings,
    ) -> Vec3 {
        let filter = filter_of(settings.filter);
        let Some(texel) = self.colour_texel(material, hit, direction, Some(cone), filter, settings) else {
            return material.color;
        };
        if filter == Filter::LevelColour { texel.truncate() } else { material.color * texel.truncate() }
    }

    /// `α(p)`: the material's `alpha` times its colour texture's alpha at the hit, filtered as the
    /// colour is (the level-colour view replaces the colour, not the coverage, so there the alpha
    /// is read trilinearly). Without a cone (shadow rays) the texture is read at level 0.
    pub fn coverage(
        &self,
        material: &Material,
        hit: &SurfaceHit,
        direction: Vec3,
        cone: Option<&RayCone>,
        settings: &TextureSettings,
    ) -> f32 {
        let filter = match filter_of(settings.filter) {
            Filter::LevelColour => Filter::Trilinear,
            filter => filter,
        };
        let texture_alpha = self.colour_texel(material, hit, direction, cone, filter, settings).map_or(1.0, |t| t.w);
        material.alpha * texture_alpha
    }

    /// The material's colour texture at the hit, linear RGBA read by `filter` at the level `cone`
    /// gives (level 0 without one), or `None` when it has no (usable) colour texture.
    fn colour_texel(
        &self,
        material: &Material,
        hit: &SurfaceHit,
        direction: Vec3,
        cone: Option<&RayCone>,
        filter: Filter,
        settings: &TextureSettings,
    ) -> Option<Vec4> {
        let chain = self.chain(material.texture?)?;
        let level0 = &chain.levels[0];
        let lod = cone.map_or(0.0, |cone| level_at(cone, direction, hit, (level0.width, level0.height), settings));
        Some(chain.sample_wrapped(hit.uv, lod, filter, material.wrap))
    }

    /// The shading normal at the hit, not yet turned to the viewer: bump-mapped where bump
    /// mapping is on and the material has a height map, `hit.normal` otherwise.
    pub fn shading_normal(&self, material: &Material, hit: &SurfaceHit, settings: &BumpSettings) -> Vec3 {
        if !settings.enabled {
            return hit.normal;
        }
        let params = bump_params(material, settings);
        let mut n = self
            .with_height_field(material, |field| {
                bump_normal(field, &params(field), hit.uv, hit.normal, hit.dpdu, hit.dpdv)
            })
            .unwrap_or(hit.normal);
        if let Some(chain) = material.normal_map.and_then(|id| self.chain(id)) {
            // glTF's tangent frame: t along ∂p/∂u, the bitangent's sign from ∂p/∂v's side, as
            // MikkTSpace makes it from the same texture coordinates.
            let t = hit.dpdu - hit.dpdu.dot(n) * n;
            let sign = if n.cross(t).dot(hit.dpdv) < 0.0 { -1.0 } else { 1.0 };
            let rgb = chain.sample_wrapped(hit.uv, 0.0, Filter::Bilinear, material.wrap).truncate();
            n = normal_map_normal(n, t.extend(sign), rgb, material.normal_scale);
        }
        n
    }

    /// Parallax mapping (`bump.method = "parallax"`, `crate::texture::parallax`): `hit` with the
    /// texture coordinates of the point of the displaced surface that the ray along `direction`
    /// meets first, where the material has a height field; `None` otherwise.
    pub fn parallaxed(
        &self,
        material: &Material,
        hit: &SurfaceHit,
        direction: Vec3,
        settings: &BumpSettings,
    ) -> Option<SurfaceHit> {
        if !settings.enabled || settings.method != crate::settings::BumpMethod::Parallax {
            return None;
        }
        let k = material.bump_scale * settings.scale;
        let frame = (hit.normal, hit.dpdu, hit.dpdv);
        let uv = self.with_height_field(material, |field| parallax_uv(field, k, hit.uv, frame, direction))?;
        Some(SurfaceHit { uv, ..*hit })
    }

    /// Bump mapping's slopes `(du, dv) = k·∇f_h` at the hit, where it applies.
    pub fn bump_slopes(&self, material: &Material, hit: &SurfaceHit, settings: &BumpSettings) -> Option<Vec2> {
        if !settings.enabled {
            return None;
        }
        let params = bump_params(material, settings);
        self.with_height_field(material, |field| height_gradient(field, hit.uv, &params(field)))
    }

    /// `f` of the material's height field (procedural, or its height map), if it has one.
    fn with_height_field<T>(&self, material: &Material, f: impl FnOnce(&dyn HeightField) -> T) -> Option<T> {
        with_material_field(material, material.height_map.and_then(|id| self.height(id)), f)
    }
}

/// The bump parameters of `material` under `settings`, for a given field (whose own step sets
/// `Δ`).
fn bump_params(material: &Material, settings: &BumpSettings) -> impl Fn(&dyn HeightField) -> BumpParams {
    let (k, delta_texels, analytic) = (material.bump_scale * settings.scale, settings.delta_texels, settings.analytic);
    move |field: &dyn HeightField| BumpParams { k, delta: Some(delta_texels * field.default_delta()), analytic }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(rgba8: Vec<u8>, width: u32, color_space: ColorSpace) -> Texture {
        let height = rgba8.len() as u32 / 4 / width;
        Texture { path: "test".into(), width, height, rgba8, color_space }
    }

    #[test]
    fn texel_centres_return_texels_and_midpoints_blend_linear_values() {
        let t = texture(vec![0, 0, 0, 255, 255, 255, 255, 255], 2, ColorSpace::Srgb);
        assert_eq!(sample_bilinear(&t, Vec2::new(0.25, 0.5)), Vec3::ZERO);
        assert!(sample_bilinear(&t, Vec2::new(0.75, 0.5)).abs_diff_eq(Vec3::ONE, 1e-6));
        // Halfway between black and white is linear 0.5 (not sRGB 0.5, which is linear 0.214).
        assert!(sample_bilinear(&t, Vec2::new(0.5, 0.5)).abs_diff_eq(Vec3::splat(0.5), 1e-6));
        // Repeat wrapping: u = 1.0 sits between the last texel and the first.
        assert!(sample_bilinear(&t, Vec2::new(1.0, 0.5)).abs_diff_eq(Vec3::splat(0.5), 1e-6));
        assert!(sample_bilinear(&t, Vec2::new(-0.25, 0.5)).abs_diff_eq(Vec3::ONE, 1e-6));
    }

    #[test]
    fn chain_bilinear_on_level_0_is_the_reference() {
        // A 5×3 pattern (odd sizes, both colour spaces) read at texel centres, edges, wrap-arounds.
        let bytes: Vec<u8> = (0..5 * 3 * 4).map(|i| (i * 37 % 256) as u8).collect();
        for space in [ColorSpace::Srgb, ColorSpace::Linear] {
            let t = texture(bytes.clone(), 5, space);
            let chain = MipChain::build(&t);
            for uv in [Vec2::new(0.1, 0.5), Vec2::new(0.0, 0.0), Vec2::new(0.93, 0.71), Vec2::new(-1.37, 2.2)] {
                for lod in [0.0, 3.5] {
                    let got = chain.sample(uv, lod, Filter::Bilinear).truncate();
                    assert!(got.abs_diff_eq(sample_bilinear(&t, uv), 1e-6), "{space:?} at {uv}: {got}");
                }
                let trilinear = chain.sample(uv, 0.0, Filter::Trilinear).truncate();
                assert!(trilinear.abs_diff_eq(sample_bilinear(&t, uv), 1e-6), "trilinear at λ = 0, {uv}");
            }
        }
    }

    #[test]
    fn anisotropic_reads_as_trilinear_and_level_colour_maps_through() {
        assert_eq!(filter_of(TextureFilter::Anisotropic), Filter::Trilinear);
        assert_eq!(filter_of(TextureFilter::LevelColour), Filter::LevelColour);
        assert_eq!(filter_of(TextureFilter::NearestMip), Filter::NearestMip);
    }

    #[test]
    fn frontal_hit_lod_is_log2_of_texels_per_footprint() {
        // A 64-texel texture over 2 units, hit head-on at t = 10 by a cone of 1/100 rad:
        // footprint 0.1 units = 3.2 texels.
        let hit = SurfaceHit {
            t: 10.0,
            point: Vec3::ZERO,
            geometric_normal: Vec3::Z,
            normal: Vec3::Z,
            uv: Vec2::ZERO,
            dpdu: 2.0 * Vec3::X,
            dpdv: -2.0 * Vec3::Y,
            material: crate::base::MaterialId(0),
            object: 0,
        };
        let cone = RayCone { width: 0.0, spread: 0.01 };
        let lod = hit_lod(&cone, -Vec3::Z, &hit, (64, 64), 0.0);
        assert!((lod - 3.2f32.log2()).abs() < 1e-5, "{lod}");
        // The bias adds, and a 60° incidence doubles the footprint.
        let slanted = hit_lod(&cone, Vec3::new(0.0, 3f32.sqrt() / 2.0, -0.5), &hit, (64, 64), 0.25);
        assert!((slanted - lod - 1.25).abs() < 1e-5, "{slanted}");
    }
}
