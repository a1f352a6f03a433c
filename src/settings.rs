//! `RenderSettings`: every toggle in one serde struct. The CLI's `--set key=value`, the scene
//! file's `[settings]` table, the viewer's panel and the tests all read and write this one type,
//! so a toggle means the same thing everywhere. Later techniques add their sections here.
//!
//! This module depends on nothing else of Mirador: the scene holds its file's settings, and the
//! renderers read both, so the layers stay one-way (settings ← scene ← renderers).

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderSettings {
    /// Which terms of the illumination model are drawn (teaching toggles).
    pub terms: TermSettings,
    /// Exposure applied to linear radiance before the output transform.
    pub exposure: f32,
    /// The curve from exposed radiance to the display's [0, 1], before the sRGB encoding.
    pub tone_map: ToneMap,
    /// Slices around a tessellated sphere (the rasterizer's; the tracer's spheres are exact).
    pub sphere_segments: u32,
    /// Texture filtering: mipmaps and the sampling modes (TECHNIQUES.md §2).
    pub textures: TextureSettings,
    /// Bump mapping from height fields (TECHNIQUES.md §3).
    pub bump: BumpSettings,
    /// Cast shadows: shadow maps or projected polygons in the rasterizer, shadow rays in the
    /// tracer (TECHNIQUES.md §4).
    pub shadows: ShadowSettings,
    /// Transparent surfaces in sorted Z order (TECHNIQUES.md §5).
    pub transparency: TransparencySettings,
    /// Planar mirrors by a mirrored camera (TECHNIQUES.md §6).
    pub mirrors: MirrorSettings,
    /// Environment maps for curved mirrors, and the world drawn as the background (TECHNIQUES.md
    /// §6).
    pub environment: EnvironmentSettings,
    /// Direct volume rendering of voxel grids: compositing and isosurfaces (TECHNIQUES.md §8).
    pub volume: VolumeSettings,
    /// How the rasterizer spends its time: prepass, tessellation, render scale.
    pub raster: RasterSettings,
    /// The ray tracer's own settings.
    pub trace: TraceSettings,
}

/// The output transform's curve from exposed linear radiance `c` to the display's [0, 1], per
/// channel unless said otherwise; the sRGB encoding follows. Both renderers run the same curve
/// (`src/output.rs`, `shaders/present.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ToneMap {
    /// min(max(c, 0), 1): the course's output; everything above 1 is white.
    Clamp,
    /// c / (1 + c) (Reinhard's global operator): nothing is ever white, highlights keep detail,
    /// mid-tones darken (0.18 shows as 0.15).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve: contrast in the mid-tones, a soft shoulder,
    /// white near c = 10.
    Aces,
    /// Khronos PBR Neutral: base colours up to 0.76 pass unchanged (a colour-accurate product
    /// shot), brighter values compress towards white and desaturate.
    PbrNeutral,
}

/// The order the rasterizer draws transparent surfaces in. `I = Im + kt·Mt·I` depends on it:
/// over two panes it gives `I_z + Mt1·I_y + Mt1·Mt2·I_x` only farthest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum TransparencySort {
    /// In the order the scene lists them, each object's triangles in its own order: shows the
    /// error the formula makes out of order.
    Unsorted,
    /// Objects farthest first by their bounds' centre, each drawn back faces then front faces:
    /// right for separate convex objects, wrong where objects interleave.
    Object,
    /// Every transparent triangle farthest first by its centroid, re-sorted when the view moves:
    /// wrong only for intersecting or cyclically overlapping triangles.
    Triangle,
    /// Depth peeling: the exact order at every pixel, `peel_layers` layers from the back.
    Exact,
}

/// Transparent surfaces (kt > 0, or alpha-blended) in the rasterizer (TECHNIQUES.md §5).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TransparencySettings {
    /// Draw them after the opaque surfaces as `I = Im + kt·Mt·I`; off, they are drawn as opaque
    /// surfaces with their illumination model alone.
    pub enabled: bool,
    pub sort: TransparencySort,
    /// Layers `exact` peels, nearest to the opaque surface first: a pixel behind more
    /// transparent surfaces than this loses the nearest ones.
    pub peel_layers: u32,
}

impl Default for TransparencySettings {
    fn default() -> Self {
        TransparencySettings { enabled: true, sort: TransparencySort::Object, peel_layers: 8 }
    }
}

/// What the mirror technique shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum MirrorView {
    /// The scene, its mirrors showing their reflections.
    Off,
    /// The first mirror camera's own image, full screen: the scene seen from behind the mirror,
    /// mirrored, with nothing in front of the mirror plane's far side.
    Image,
    /// Each mirrored camera's view volume drawn into the scene: its near face lies on the mirror.
    Camera,
}

/// Planar mirrors (materials with `kps > 0` on flat objects) in the rasterizer.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MirrorSettings {
    /// Render each mirror's reflection with the camera mirrored about its plane and add
    /// `kps·MPS` times it to the mirror's illumination model; off, mirrors show their model alone.
    pub enabled: bool,
    /// Reflections of reflections: mirrors that see each other recurse this deep (0: mirrors show
    /// their plain material), like the tracer's `max_depth` for mirror rays.
    pub depth: u32,
    /// Teaching views.
    pub view: MirrorView,
}

impl Default for MirrorSettings {
    fn default() -> Self {
        MirrorSettings { enabled: true, depth: 3, view: MirrorView::Off }
    }
}

/// Which map the rasterizer looks curved mirrors' reflections up in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum EnvironmentMap {
    /// The six faces of a cube around the object: `r` picks the face and the texel.
    Cube,
    /// One image of a mirror ball seen along −Z in view space (OpenGL's sphere map).
    Sphere,
    /// Longitude and latitude of `r` (`α = a·u`, `β = b·v`).
    Latlong,
}

/// Whose view a sphere map is made for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum SphereView {
    /// Made once, for the camera of the first frame: turn the camera and the reflections turn
    /// with it (the map belongs to one view direction).
    Fixed,
    /// Made again for every frame's camera.
    Follow,
}

/// What the environment technique shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum EnvironmentView {
    /// The scene.
    Off,
    /// The cube map of the first reflective object (or the world's) unfolded as a cross.
    Cross,
    /// The sphere map, as an image.
    Sphere,
    /// The latitude–longitude map, as an image.
    Latlong,
}

/// Environment mapping (materials with `kps > 0` that are not planar mirrors) in the rasterizer.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnvironmentSettings {
    /// Add `kps·MPS·L(r)` to curved mirrors' illumination model, `L(r)` looked up in a map;
    /// off, they show their model alone. The world is drawn as the background either way.
    pub enabled: bool,
    /// The map `L(r)` is looked up in.
    pub map: EnvironmentMap,
    /// Cube maps rendered from each reflective object's centre (six 90° views of the rest of
    /// the scene) instead of the world's environment alone.
    pub dynamic: bool,
    /// Texels on a side of every cube face made by the renderer.
    pub cube_size: u32,
    /// Dynamic cubes are drawn again every `refresh` frames; 0: only when something they see
    /// changes.
    pub refresh: u32,
    /// Whose view the sphere map is made for.
    pub sphere_view: SphereView,
    /// Teaching views.
    pub view: EnvironmentView,
    /// Draw the teaching view in the frame's lower-right corner, the scene around it (in the
    /// viewer, the lat–long view then marks the reflected direction under the cursor); off: over
    /// the whole frame.
    pub inset: bool,
}

impl Default for EnvironmentSettings {
    fn default() -> Self {
        EnvironmentSettings {
            enabled: true,
            map: EnvironmentMap::Cube,
            dynamic: true,
            cube_size: 256,
            refresh: 0,
            sphere_view: SphereView::Fixed,
            view: EnvironmentView::Off,
            inset: true,
        }
    }
}

/// How volumes are shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum VolumeMode {
    /// Each volume as its scene file says (`mode`).
    Scene,
    /// Every volume composited: classified samples, front to back.
    Composite,
    /// Every volume as its isosurface `f = iso`, shaded like a surface.
    Isosurface,
}

/// How the field is read between grid points.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum VolumeReconstruction {
    /// The nearest grid point's value: the voxels show as blocks.
    Nearest,
    /// Trilinear interpolation of the eight surrounding grid points.
    Trilinear,
}

/// How samples are shaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum VolumeGradient {
    /// No shading: each sample shows its classified colour.
    Off,
    /// Gradient normals by forward differences (first order).
    Forward,
    /// Gradient normals by central differences (second order, the seed's).
    Central,
}

/// What the volume technique shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum VolumeView {
    /// The scene.
    Off,
    /// Where a ray crosses a composited volume, the samples it took, as a heat map (black none,
    /// white `VOLUME_SAMPLES_WHITE`): where early termination saves work.
    Samples,
}

/// Direct volume rendering in both renderers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolumeSettings {
    /// Draw volumes; off, they are left out.
    pub enabled: bool,
    pub mode: VolumeMode,
    /// Distance between samples along a ray, in voxels (of the grid's smallest spacing).
    pub step: f32,
    pub reconstruction: VolumeReconstruction,
    pub gradient: VolumeGradient,
    /// Correct each sample's opacity for its length (`1 − (1 − α)^ℓ`), so the image does not
    /// change with the step; off, the transfer function's opacity is used per sample as it is.
    pub opacity_correction: bool,
    /// Stop a ray once its accumulated opacity reaches `threshold`.
    pub early_termination: bool,
    pub threshold: f32,
    /// Shadows of opaque surfaces on the volume's samples (shadow rays per sample and light in
    /// the tracer, shadow-map lookups in the rasterizer). Isosurfaces are shadowed like any
    /// surface whenever shadows are on.
    pub shadows: bool,
    /// Draw the grid's cells as a wireframe in the rasterizer (every cell up to 32 a side, every
    /// k-th plane beyond, `k = ⌈cells/32⌉`); the tracer does not draw it.
    pub wireframe: bool,
    /// Teaching views.
    pub view: VolumeView,
}

impl Default for VolumeSettings {
    fn default() -> Self {
        VolumeSettings {
            enabled: true,
            mode: VolumeMode::Scene,
            step: 0.5,
            reconstruction: VolumeReconstruction::Trilinear,
            gradient: VolumeGradient::Central,
            opacity_correction: true,
            early_termination: true,
            threshold: 0.99,
            shadows: false,
            wireframe: false,
            view: VolumeView::Off,
        }
    }
}

/// The range of `volume.step`, in voxels.
pub const VOLUME_STEPS: std::ops::RangeInclusive<f32> = 0.05..=8.0;

/// The sample count the samples view shows as white.
pub const VOLUME_SAMPLES_WHITE: u32 = 512;

/// The range of `environment.cube_size`.
pub const CUBE_SIZES: std::ops::RangeInclusive<u32> = 16..=2048;

/// The deepest `mirrors.depth`.
pub const MAX_MIRROR_DEPTH: u32 = 8;

/// The most layers `transparency.sort = "exact"` may peel.
pub const MAX_PEEL_LAYERS: u32 = 32;

/// When the rasterizer draws a depth prepass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Prepass {
    /// When shading is what costs: the frame has fewer triangles than a quarter of its pixels.
    /// (Measured: the showcase is 16 % faster with it; the 7,381-sphere sphereflake, whose cost
    /// is its geometry, 30 % slower.)
    Auto,
    Always,
    Never,
}

/// The rasterizer's speed settings. None of them changes what the techniques compute; each trades
/// time for a documented, measured difference (docs/performance.md).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RasterSettings {
    /// Draw the depth of every pixel first, then run the illumination model only on the visible
    /// surface (once per pixel, not once per fragment drawn), at the price of drawing the
    /// geometry twice.
    pub depth_prepass: Prepass,
    /// Tessellate curved shapes by their size on screen (within a quarter pixel of the true
    /// outline), up to `sphere_segments`; off: every curved shape gets `sphere_segments`.
    pub adaptive_tessellation: bool,
    /// Draw at this fraction of the output's size and upscale in the present pass (0.1 to 1).
    pub render_scale: f32,
    /// Each surface in its material's colour, no lighting: the floor of what the GPU can do with
    /// this geometry, for benchmarks.
    pub flat_colour: bool,
}

impl Default for RasterSettings {
    fn default() -> Self {
        RasterSettings {
            depth_prepass: Prepass::Auto,
            adaptive_tessellation: true,
            render_scale: 1.0,
            flat_colour: false,
        }
    }
}

/// How colour textures are filtered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum TextureFilter {
    /// The nearest texel of the full-size image: aliasing and moiré in the distance.
    Nearest,
    /// Bilinear on the full-size image, no mipmaps: still moiré.
    Bilinear,
    /// Bilinear within the nearest mip level: hard seams where the level changes.
    NearestMip,
    /// Bilinear in the two nearest levels, blended by the fractional level.
    Trilinear,
    /// Anisotropic filtering, up to `anisotropy` samples along the footprint's long axis (the
    /// rasterizer only; the tracer uses trilinear).
    Anisotropic,
    /// Each mip level painted in its own colour: where the level changes, and the blend.
    LevelColour,
}

/// How the ray tracer picks a texture's mip level at a hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum TracerLod {
    /// The footprint of the pixel's ray cone on the surface, stretched by the angle of incidence.
    RayCone,
    /// The seed's simple rule: the level grows with the logarithm of the distance travelled,
    /// whatever the angle (orthographic cameras, whose rays do not spread, use the cone).
    Distance,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureSettings {
    pub filter: TextureFilter,
    pub tracer_lod: TracerLod,
    /// Largest anisotropy, 1 to 16, where the device allows.
    pub anisotropy: u16,
    /// Added to the level of detail: positive is blurrier, negative sharper (and aliased).
    pub lod_bias: f32,
}

impl Default for TextureSettings {
    fn default() -> Self {
        TextureSettings {
            filter: TextureFilter::Trilinear,
            tracer_lod: TracerLod::RayCone,
            anisotropy: 16,
            lod_bias: 0.0,
        }
    }
}

/// What the bump-mapping teaching view shows instead of the shaded colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum BumpView {
    Off,
    /// The (perturbed) shading normal as colour: `0.5 + 0.5·n`.
    Normals,
    /// The tangent `t_u` as colour, the frame the bumps are built in.
    Tangents,
}

/// Where the rasterizer's tangents `t_u`, `t_v` come from (TECHNIQUES.md §3 names three sources;
/// the tracer uses the third, the analytic surface).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum TangentSource {
    /// Constant per triangle, from how position and texture coordinates change across it
    /// (screen-space derivatives): true-length `∂p/∂u`, `∂p/∂v`.
    Derivatives,
    /// Per vertex and interpolated: the file's tangents, or MikkTSpace's; unit length, so `k`
    /// reads as relief per unit of texture coordinate rather than per unit of surface.
    PerVertex,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BumpSettings {
    /// Bump mapping and normal maps.
    pub enabled: bool,
    pub tangents: TangentSource,
    /// Multiplies every material's bump scale `k` (sign allowed).
    pub scale: f32,
    /// The finite-difference step `Δ`, in texels of the height map (for procedural fields, in
    /// units of the field's own step: a 64th of a sine's period, a 16th of a noise cell).
    pub delta_texels: f32,
    /// For procedural height fields, the closed-form derivatives instead of finite differences.
    pub analytic: bool,
    pub view: BumpView,
}

impl Default for BumpSettings {
    fn default() -> Self {
        BumpSettings {
            enabled: true,
            tangents: TangentSource::Derivatives,
            scale: 1.0,
            delta_texels: 1.0,
            analytic: false,
            view: BumpView::Off,
        }
    }
}

/// How the rasterizer finds cast shadows (TECHNIQUES.md §4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ShadowMethod {
    /// Image precision: the two-pass z-buffer algorithm (shadow maps).
    Map,
    /// Object precision: casters projected from the light onto planar receivers and clipped to
    /// them (seed 000's brute force), drawn as detail polygons.
    Projected,
}

/// How a shadow map is filtered where a receiver looks it up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ShadowFilter {
    /// One comparison with the nearest texel: hard, aliased edges.
    None,
    /// The hardware's 2×2 comparison with bilinear weights (4 taps).
    Hardware,
    /// 3×3 hardware taps.
    Pcf3x3,
    /// 5×5 hardware taps.
    Pcf5x5,
    /// 16 hardware taps on a Poisson disc of radius 2.5 texels.
    Poisson,
}

/// What a directional light's shadow map covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ShadowFit {
    /// The part of the view frustum within `distance` of the eye: finer texels where the camera
    /// looks, redrawn when the camera moves.
    View,
    /// The whole scene: coarser texels, but independent of the camera, so kept while it moves.
    Scene,
}

/// What the teaching view shows instead of, or over, the shaded image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ShadowView {
    Off,
    /// The shadow map of `view_layer` as grey levels, near black and far white.
    Map,
    /// A checker of the map's texels as they land on the receivers.
    Texels,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    pub enabled: bool,
    pub method: ShadowMethod,
    /// Side of each shadow map in texels (256 to 4096).
    pub map_size: u32,
    pub filter: ShadowFilter,
    /// Constant depth bias, in the depth buffer's smallest steps (acne cure; too much detaches
    /// shadows from their casters: peter-panning).
    pub depth_bias: i32,
    /// Depth bias proportional to the surface's depth slope as the light sees it.
    pub slope_bias: f32,
    /// The receiver's lookup point is pushed along its normal by this many shadow-map texels.
    pub normal_offset: f32,
    /// How far from the eye a directional light's map reaches, in scene units (0: four times the
    /// distance from the eye to the view centre, at most the far plane).
    pub distance: f32,
    /// What a directional light's map covers.
    pub fit: ShadowFit,
    /// Keep each map layer across frames until its light, the casters or the bias change.
    pub cache: bool,
    /// Transparent occluders (kt > 0) cast coloured, partial shadows.
    pub transmission: bool,
    pub view: ShadowView,
    /// Which map layer the `map` view shows (a point light has six).
    pub view_layer: u32,
    /// Draw each shadowed light's frustum into the scene.
    pub show_frusta: bool,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        ShadowSettings {
            enabled: true,
            method: ShadowMethod::Map,
            map_size: 2048,
            filter: ShadowFilter::Pcf3x3,
            depth_bias: 4,
            slope_bias: 1.5,
            normal_offset: 1.0,
            distance: 0.0,
            fit: ShadowFit::View,
            cache: true,
            transmission: true,
            view: ShadowView::Off,
            view_layer: 0,
            show_frusta: false,
        }
    }
}

/// How the ray tracer samples pixels (seeds 003 and 004).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum AntiAliasing {
    /// One ray through each pixel centre: pixel-aligned with the rasterizer.
    Center,
    /// `samples × samples` rays on a regular sub-pixel grid.
    Regular,
    /// `samples × samples` strata, one seeded random ray in each.
    Jittered,
    /// Rays through the pixel corners, each shared by the four pixels that meet there:
    /// `(width + 1)(height + 1)` rays.
    Corners,
    /// Whitted's adaptive subdivision: corner rays, and a square split in four while its corners
    /// differ by more than `adaptive_threshold`, down to `adaptive_max_level`.
    Adaptive,
}

/// Which acceleration structure the ray tracer builds (`--accel bvh|grid|octree|none`). It lives
/// here, not in `trace`, so the layers stay one-way: scene ← settings ← renderers.
#[derive(clap::ValueEnum, Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum AccelKind {
    /// Bounding volume hierarchy, binned SAH.
    #[default]
    Bvh,
    /// Uniform grid walked by 3D-DDA.
    Grid,
    Octree,
    /// Brute force: every primitive for every ray.
    None,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TraceSettings {
    /// Deepest recursion: primary rays are depth 0; reflected and refracted rays add one.
    pub max_depth: u32,
    pub anti_aliasing: AntiAliasing,
    /// Rays per pixel side for `regular` and `jittered` (`samples²` rays a pixel).
    pub samples: u32,
    /// Seed of the jittered pattern: the same seed gives the same image.
    pub seed: u64,
    /// Largest per-channel difference, in output values (0–1), between a square's corners that
    /// adaptive subdivision leaves unsplit.
    pub adaptive_threshold: f32,
    pub adaptive_max_level: u32,
    pub accelerator: AccelKind,
}

impl Default for TraceSettings {
    fn default() -> Self {
        TraceSettings {
            max_depth: 5,
            anti_aliasing: AntiAliasing::Center,
            samples: 2,
            seed: 0,
            adaptive_threshold: 0.1,
            adaptive_max_level: 3,
            accelerator: AccelKind::Bvh,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TermSettings {
    pub ambient: bool,
    pub diffuse: bool,
    pub specular: bool,
    pub emission: bool,
}

impl Default for TermSettings {
    fn default() -> Self {
        TermSettings { ambient: true, diffuse: true, specular: true, emission: true }
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            terms: TermSettings::default(),
            exposure: 1.0,
            tone_map: ToneMap::Clamp,
            sphere_segments: 96,
            textures: TextureSettings::default(),
            bump: BumpSettings::default(),
            shadows: ShadowSettings::default(),
            transparency: TransparencySettings::default(),
            mirrors: MirrorSettings::default(),
            environment: EnvironmentSettings::default(),
            volume: VolumeSettings::default(),
            raster: RasterSettings::default(),
            trace: TraceSettings::default(),
        }
    }
}

/// Why a `--set key=value` could not be applied.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    #[error("`{0}` is not of the form key=value")]
    NotAnAssignment(String),
    #[error("`{key}`: {message}")]
    Rejected { key: String, message: String },
    #[error("{0}")]
    Invalid(String),
}

impl RenderSettings {
    /// Applies `key=value` where `key` is a dotted path (`terms.specular`, `exposure`) and `value`
    /// is a TOML value (`true`, `1.5`, `"text"`). Unknown keys and ill-typed values are rejected.
    pub fn set(&mut self, assignment: &str) -> Result<(), SettingsError> {
        let (key, value) =
            assignment.split_once('=').ok_or_else(|| SettingsError::NotAnAssignment(assignment.into()))?;
        let key = key.trim();
        let rejected = |message: String| SettingsError::Rejected { key: key.into(), message };
        let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {}", value.trim()))
            .map(|mut t| t.remove("v").expect("the table was parsed from `v = …`"))
            .unwrap_or_else(|_| toml::Value::String(value.trim().into()));
        let mut table = toml::Table::try_from(&*self).map_err(|e| rejected(e.to_string()))?;
        let mut slot = &mut table;
        let parts: Vec<&str> = key.split('.').collect();
        let (last, path) = parts.split_last().expect("split always yields one part");
        for part in path {
            slot = match slot.get_mut(*part) {
                Some(toml::Value::Table(inner)) => inner,
                _ => return Err(rejected("no such settings section".into())),
            };
        }
        if !slot.contains_key(*last) {
            return Err(rejected("no such setting".into()));
        }
        slot.insert(last.to_string(), value);
        let updated: RenderSettings = table.try_into().map_err(|e: toml::de::Error| rejected(e.message().into()))?;
        updated.validate().map_err(|e| rejected(e.to_string()))?;
        *self = updated;
        Ok(())
    }

    pub fn validate(&self) -> Result<(), SettingsError> {
        if !(self.exposure.is_finite() && self.exposure > 0.0) {
            return Err(SettingsError::Invalid(format!("exposure must be positive, got {}", self.exposure)));
        }
        if !(3..=4096).contains(&self.sphere_segments) {
            return Err(SettingsError::Invalid(format!(
                "sphere_segments must lie in 3..=4096, got {}",
                self.sphere_segments
            )));
        }
        let textures = &self.textures;
        if !(1..=16).contains(&textures.anisotropy) {
            return Err(SettingsError::Invalid(format!(
                "textures.anisotropy must lie in 1..=16, got {}",
                textures.anisotropy
            )));
        }
        if !(textures.lod_bias.is_finite() && textures.lod_bias.abs() <= 8.0) {
            return Err(SettingsError::Invalid(format!(
                "textures.lod_bias must lie in −8..=8, got {}",
                textures.lod_bias
            )));
        }
        let bump = &self.bump;
        if !bump.scale.is_finite() {
            return Err(SettingsError::Invalid(format!("bump.scale must be finite, got {}", bump.scale)));
        }
        if !(bump.delta_texels.is_finite() && bump.delta_texels > 0.0 && bump.delta_texels <= 64.0) {
            return Err(SettingsError::Invalid(format!(
                "bump.delta_texels must lie in (0, 64], got {}",
                bump.delta_texels
            )));
        }
        let layers = self.transparency.peel_layers;
        if !(1..=MAX_PEEL_LAYERS).contains(&layers) {
            return Err(SettingsError::Invalid(format!(
                "transparency.peel_layers must lie in 1..={MAX_PEEL_LAYERS}, got {layers}"
            )));
        }
        if self.mirrors.depth > MAX_MIRROR_DEPTH {
            return Err(SettingsError::Invalid(format!(
                "mirrors.depth must lie in 0..={MAX_MIRROR_DEPTH}, got {}",
                self.mirrors.depth
            )));
        }
        let cube = self.environment.cube_size;
        if !CUBE_SIZES.contains(&cube) {
            return Err(SettingsError::Invalid(format!(
                "environment.cube_size must lie in {}..={}, got {cube}",
                CUBE_SIZES.start(),
                CUBE_SIZES.end()
            )));
        }
        let volume = &self.volume;
        if !VOLUME_STEPS.contains(&volume.step) {
            return Err(SettingsError::Invalid(format!(
                "volume.step must lie in {}..={} voxels, got {}",
                VOLUME_STEPS.start(),
                VOLUME_STEPS.end(),
                volume.step
            )));
        }
        if !(volume.threshold > 0.0 && volume.threshold <= 1.0) {
            return Err(SettingsError::Invalid(format!(
                "volume.threshold must lie in (0, 1], got {}",
                volume.threshold
            )));
        }
        let scale = self.raster.render_scale;
        if !(scale.is_finite() && (0.1..=1.0).contains(&scale)) {
            return Err(SettingsError::Invalid(format!("raster.render_scale must lie in 0.1..=1, got {scale}")));
        }
        let shadows = &self.shadows;
        if !(256..=4096).contains(&shadows.map_size) {
            return Err(SettingsError::Invalid(format!(
                "shadows.map_size must lie in 256..=4096, got {}",
                shadows.map_size
            )));
        }
        let finite_non_negative = [
            ("shadows.slope_bias", shadows.slope_bias),
            ("shadows.normal_offset", shadows.normal_offset),
            ("shadows.distance", shadows.distance),
        ];
        if let Some((name, value)) = finite_non_negative.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            return Err(SettingsError::Invalid(format!("{name} must be a finite number ≥ 0, got {value}")));
        }
        if !(0..=10_000).contains(&shadows.depth_bias) {
            return Err(SettingsError::Invalid(format!(
                "shadows.depth_bias must lie in 0..=10000, got {}",
                shadows.depth_bias
            )));
        }
        let trace = &self.trace;
        if !(1..=16).contains(&trace.samples) {
            return Err(SettingsError::Invalid(format!("trace.samples must lie in 1..=16, got {}", trace.samples)));
        }
        if trace.max_depth > 64 {
            return Err(SettingsError::Invalid(format!("trace.max_depth must be at most 64, got {}", trace.max_depth)));
        }
        if !(trace.adaptive_threshold.is_finite() && trace.adaptive_threshold >= 0.0) {
            return Err(SettingsError::Invalid(format!(
                "trace.adaptive_threshold must be ≥ 0, got {}",
                trace.adaptive_threshold
            )));
        }
        if trace.adaptive_max_level > 6 {
            return Err(SettingsError::Invalid(format!(
                "trace.adaptive_max_level must be at most 6, got {}",
                trace.adaptive_max_level
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_reaches_nested_keys_and_rejects_unknown_ones() {
        let mut s = RenderSettings::default();
        s.set("terms.specular=false").unwrap();
        s.set("exposure = 2.5").unwrap();
        assert!(!s.terms.specular);
        assert_eq!(s.exposure, 2.5);
        assert!(s.set("terms.glow=true").is_err());
        assert!(s.set("exposure=bright").is_err());
        assert!(s.set("exposure=-1").is_err());
        assert!(s.set("exposure").is_err());
        assert_eq!(s.exposure, 2.5, "a rejected assignment leaves the settings unchanged");
    }
}
