// The view group (group 2 of every surface pass's module): what the shading of one view reads. One bind
// group per view (src/raster/view_group.rs, whose VIEW_GROUP table tests/layouts.rs checks
// against these declarations binding by binding): the frame's shadow and environment maps, the
// same in every view, and the images earlier phases of this view made for its shading (the
// projected-shadow mask, the traced terms), so a technique that makes one shows in the main camera, every mirrored
// camera and every cube face alike. An inspecting renderer adds bindings 11 and 12
// (shaders/common/inspect.wgsl).

// The shadow pass's outputs and how to read them.
@group(2) @binding(0) var<uniform> shadows: Shadows;
@group(2) @binding(1) var shadow_maps: texture_depth_2d_array;
// One comparison sampler for every filter: GL binds a texture to a single sampler.
@group(2) @binding(2) var shadow_sampler: sampler_comparison;
@group(2) @binding(3) var transmission_maps: texture_2d_array<f32>;
// The environment (shaders/common/environment.wgsl; src/raster/environment): the world's, as a
// cube, a sphere map and a lat–long map, and the cubes drawn from reflective objects' centres.
@group(2) @binding(5) var<uniform> environment: Environment;
// Trilinear; u repeats (the lat–long map's wrap), v clamps. Cube lookups ignore both.
@group(2) @binding(6) var env_sampler: sampler;
@group(2) @binding(7) var env_cube: texture_cube<f32>;
// A cube array; where the device has none (WebGL2), a 2D array whose layers 6k..6k+5 are cube k's
// faces (shaders/profile/).
@group(2) @binding(8) var env_cubes: CubeArray;
@group(2) @binding(9) var env_sphere: texture_2d<f32>;
@group(2) @binding(10) var env_latlong: texture_2d<f32>;
// The view's own images (ViewImage in src/raster/targets.rs): layers of two arrays, so the next
// image is layers of one of them, never a binding; each image's first layer is a constant.
// Drawn and blended by the view's raster passes: from PROJECTED_MASK_LAYER, object-precision
// shadows (src/raster/shadow/projected.rs), per shadowed light a channel that is 1 where the
// polygons cover this view's pixel.
@group(2) @binding(4) var drawn_images: texture_2d_array<f32>;
// Copied in from the CPU: from TRACED_FIRST_LAYER, the hybrid's traced terms
// (src/raster/traced/mod.rs) at the first opaque surface of this view's pixel: layer
// TRACED_SURFACE_LAYER its colour C and object + 1, then each traced term's layers from
// TRACED_NAME_LAYER (the approximations table, src/settings/hybrid.rs).
@group(2) @binding(13) var copied_images: texture_2d_array<f32>;
