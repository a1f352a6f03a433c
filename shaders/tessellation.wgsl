// Displacement tessellated adaptively, in two compute entry points: every vertex of every split
// triangle (cs_vertices), then every triangle's three indices (cs_indices). The rules are in
// src/raster/tessellation/mod.rs; src/raster/tessellation/patches.rs is the CPU twin, function
// for function (grid_point, edge_point, surface_normal). Each thread finds its patch by a binary
// search of where each patch's vertices (or triangles) begin.

// One triangle of the object's mesh, in world coordinates (GpuPatch).
struct Patch {
    corners: array<vec4f, 3>,
    moved: array<vec4f, 3>,
    normals: array<vec4f, 3>,
    uvs: array<vec4f, 2>,
    // Per edge: the neighbour's texture coordinates at the edge's first and second corner.
    twin_uvs: array<vec4f, 3>,
    // Per edge: the neighbour's normals at them (2e, 2e + 1).
    twin_normals: array<vec4f, 6>,
    // ∂p/∂u, ∂p/∂v, ∂n/∂u, ∂n/∂v.
    derivatives: array<vec4f, 4>,
    // The corners' welded numbers; bit e of w: the neighbour across edge e goes first.
    groups: vec4u,
}

// One frame's split of a patch: (e0, e1, e2, n), and (first vertex, first triangle, 0, 0).
struct Level {
    split: vec4u,
    first: vec4u,
}

// GpuParams in src/raster/tessellation/pass.rs.
struct Params {
    k: f32,
    // 0: the height map in `heights`; 1: a sine; 2: value noise.
    kind: u32,
    amplitude: f32,
    patch_count: u32,
    frequency: vec2f,
    _pad: vec2f,
    map_size: vec2u,
    noise_seed: u32,
    noise_cells: u32,
    noise_octaves: u32,
    vertex_count: u32,
    triangle_count: u32,
    // Threads per row of the dispatch (its x workgroups times 64).
    row: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> patches: array<Patch>;
@group(0) @binding(2) var<storage, read> levels: array<Level>;
// The height map's red channel, linear, read texel by texel (a 1×1 zero for a procedural field).
@group(0) @binding(3) var heights: texture_2d<f32>;
// Vertex: position (3), normal (3), uv (2), tangent (4): Vertex in src/raster/uniforms.rs.
@group(0) @binding(4) var<storage, read_write> vertices: array<f32>;
@group(0) @binding(5) var<storage, read_write> indices: array<u32>;

const VERTEX_FLOATS: u32 = 12u;
const GRID_CORNER: u32 = 0u;
const GRID_EDGE: u32 = 3u;
const GRID_INTERIOR: u32 = 6u;

// The height map's texel (i, j), repeated.
fn map_texel(i: i32, j: i32) -> f32 {
    let size = vec2i(params.map_size);
    let x = ((i % size.x) + size.x) % size.x;
    let y = ((j % size.y) + size.y) % size.y;
    return textureLoad(heights, vec2i(x, y), 0).r;
}

// Bilinear between the four texel centres around uv, as MipLevel::bilinear.
fn map_height(uv: vec2f) -> f32 {
    let xy = uv * vec2f(params.map_size) - 0.5;
    let origin = floor(xy);
    let f = xy - origin;
    let i = i32(origin.x);
    let j = i32(origin.y);
    let top = mix(map_texel(i, j), map_texel(i + 1, j), f.x);
    let bottom = mix(map_texel(i, j + 1), map_texel(i + 1, j + 1), f.x);
    return mix(top, bottom, f.y);
}

// f(u, v) of the object's height field.
fn field_height(uv: vec2f) -> f32 {
    switch params.kind {
        case 1u: {
            return sine_height(uv, params.frequency, params.amplitude);
        }
        case 2u: {
            return value_noise(uv, params.noise_seed, params.noise_cells, params.noise_octaves, params.amplitude).x;
        }
        default: {
            return map_height(uv);
        }
    }
}

fn normalize_or_zero(v: vec3f) -> vec3f {
    let length = length(v);
    if length > 0.0 {
        return v / length;
    }
    return vec3f(0.0);
}

fn snap(s: u32, n: u32, e: u32) -> u32 {
    return (2u * s * e + n) / (2u * n);
}

// Where grid point (a, b) lies: GRID_CORNER + c, GRID_EDGE + e (and its snapped step), or
// GRID_INTERIOR.
fn grid_point(n: u32, edges: vec3u, a: u32, b: u32) -> vec2u {
    let c = n - a - b;
    if a == 0u && b == 0u {
        return vec2u(GRID_CORNER, 0u);
    }
    if b == 0u && c == 0u {
        return vec2u(GRID_CORNER + 1u, 0u);
    }
    if a == 0u && c == 0u {
        return vec2u(GRID_CORNER + 2u, 0u);
    }
    if b == 0u {
        return vec2u(GRID_EDGE, snap(a, n, edges.x));
    }
    if c == 0u {
        return vec2u(GRID_EDGE + 1u, snap(b, n, edges.y));
    }
    if a == 0u {
        return vec2u(GRID_EDGE + 2u, snap(c, n, edges.z));
    }
    return vec2u(GRID_INTERIOR, 0u);
}

fn uv_of(p: u32, corner: u32) -> vec2f {
    switch corner {
        case 0u: {
            return patches[p].uvs[0].xy;
        }
        case 1u: {
            return patches[p].uvs[0].zw;
        }
        default: {
            return patches[p].uvs[1].xy;
        }
    }
}

// Step s of `level` along edge `edge` of patch p, displaced: from the end with the smaller welded
// number, by the mean of both sides' heights along the mean of both sides' normals, the side of
// the patch with the smaller number first: the neighbour's thread runs the same operations on the
// same numbers in the same order, and makes the same bits.
fn edge_point(p: u32, edge: u32, s: u32, level: u32) -> vec3f {
    let first = edge;
    let second = (edge + 1u) % 3u;
    let backward = patches[p].groups[first] > patches[p].groups[second];
    let start = select(first, second, backward);
    let finish = select(second, first, backward);
    let steps = select(s, level - s, backward);
    if steps == 0u {
        return patches[p].moved[start].xyz;
    }
    if steps == level {
        return patches[p].moved[finish].xyz;
    }
    let t = f32(steps) / f32(level);
    let twin = patches[p].twin_uvs[edge];
    // The side of the patch with the smaller number first, on both sides.
    let twin_first = ((patches[p].groups.w >> edge) & 1u) == 1u;
    var height = 0.0;
    var normal = vec3f(0.0);
    for (var side = 0u; side < 2u; side++) {
        var uv_from = uv_of(p, start);
        var uv_to = uv_of(p, finish);
        var n_from = patches[p].normals[start].xyz;
        var n_to = patches[p].normals[finish].xyz;
        if (side == 0u) == twin_first {
            uv_from = select(twin.xy, twin.zw, backward);
            uv_to = select(twin.zw, twin.xy, backward);
            n_from = patches[p].twin_normals[2u * edge + select(0u, 1u, backward)].xyz;
            n_to = patches[p].twin_normals[2u * edge + select(1u, 0u, backward)].xyz;
        }
        height += field_height(mix(uv_from, uv_to, t));
        normal += mix(n_from, n_to, t);
    }
    let at = mix(patches[p].corners[start].xyz, patches[p].corners[finish].xyz, t);
    return at + params.k * (height * 0.5) * normalize_or_zero(normal);
}

// The displaced surface's unit normal at uv, where the undisplaced one is `normal`, as the mesh's
// own normals are made: the area-weighted normal of the six grid triangles around the point, the
// grid (spacing: the triangle's split n ways) laid on the smooth surface's tangent plane (the
// triangle's t_u, t_v made tangent to it, else the undisplaced mesh's facets would show), each
// neighbour moved by k·f along the normal, which turns as ∂n/∂u, ∂n/∂v say.
fn surface_normal(p: u32, uv: vec2f, normal: vec3f, n: u32) -> vec3f {
    let flat_u = patches[p].derivatives[0].xyz;
    let flat_v = patches[p].derivatives[1].xyz;
    if all(flat_u == vec3f(0.0)) && all(flat_v == vec3f(0.0)) {
        return normal;
    }
    let tu = flat_u - dot(flat_u, normal) * normal;
    let tv = flat_v - dot(flat_v, normal) * normal;
    let nu = patches[p].derivatives[2].xyz;
    let nv = patches[p].derivatives[3].xyz;
    // One grid step along a and along b, in texture coordinates.
    let along_a = (uv_of(p, 1u) - uv_of(p, 0u)) / f32(n);
    let along_b = (uv_of(p, 2u) - uv_of(p, 0u)) / f32(n);
    let centre = params.k * field_height(uv) * normal;
    var around = array<vec2f, 6>(vec2f(1.0, 0.0), vec2f(0.0, 1.0), vec2f(-1.0, 1.0), vec2f(-1.0, 0.0), vec2f(0.0, -1.0), vec2f(1.0, -1.0));
    var sum = vec3f(0.0);
    var last = vec3f(0.0);
    for (var i = 0u; i < 7u; i++) {
        let d = around[i % 6u].x * along_a + around[i % 6u].y * along_b;
        let moved = tu * d.x + tv * d.y + params.k * field_height(uv + d) * (normal + nu * d.x + nv * d.y) - centre;
        if i > 0u {
            sum += cross(last, moved);
        }
        last = moved;
    }
    let oriented = select(sum, -sum, dot(sum, normal) < 0.0);
    let length = length(oriented);
    if length > 0.0 {
        return oriented / length;
    }
    return normal;
}

// The patch whose run (of vertices: which 0; of triangles: 1) holds item i.
fn patch_of(i: u32, which: u32) -> u32 {
    var low = 0u;
    var high = params.patch_count;
    while high - low > 1u {
        let middle = (low + high) / 2u;
        if levels[middle].first[which] <= i {
            low = middle;
        } else {
            high = middle;
        }
    }
    return low;
}

// Grid point (a, b)'s place among its triangle's vertices, row b after row b − 1.
fn vertex_index(n: u32, a: u32, b: u32) -> u32 {
    return b * (n + 1u) - b * (max(b, 1u) - 1u) / 2u + a;
}

// A thread's item: its vertex (which 0) or triangle (1), the patch that owns it, and its place
// among the patch's.
struct Item {
    index: u32,
    owner: u32,
    local: u32,
}

fn item_of(id: vec3u, which: u32) -> Item {
    let index = id.x + id.y * params.row;
    let p = patch_of(index, which);
    return Item(index, p, index - levels[p].first[which]);
}

@compute @workgroup_size(64)
fn cs_vertices(@builtin(global_invocation_id) id: vec3u) {
    if id.x + id.y * params.row >= params.vertex_count {
        return;
    }
    let item = item_of(id, 0u);
    let v = item.index;
    let p = item.owner;
    let n = levels[p].split.w;
    let edges = levels[p].split.xyz;
    // Row b holds n + 1 − b vertices.
    var local = item.local;
    var b = 0u;
    while local > n - b {
        local -= n + 1u - b;
        b += 1u;
    }
    let a = local;
    let at = grid_point(n, edges, a, b);
    var w = vec3f(f32(n - a - b), f32(a), f32(b)) / f32(n);
    if at.x < GRID_EDGE {
        w = vec3f(0.0);
        w[at.x] = 1.0;
    } else if at.x < GRID_INTERIOR {
        let e = at.x - GRID_EDGE;
        let t = f32(at.y) / f32(edges[e]);
        w = vec3f(0.0);
        w[e] = 1.0 - t;
        w[(e + 1u) % 3u] = t;
    }
    let uv = uv_of(p, 0u) * w.x + uv_of(p, 1u) * w.y + uv_of(p, 2u) * w.z;
    let corner_normals = patches[p].normals;
    let normal = normalize_or_zero(corner_normals[0].xyz * w.x + corner_normals[1].xyz * w.y + corner_normals[2].xyz * w.z);
    var position: vec3f;
    if at.x < GRID_EDGE {
        position = patches[p].moved[at.x].xyz;
    } else if at.x < GRID_INTERIOR {
        position = edge_point(p, at.x - GRID_EDGE, at.y, edges[at.x - GRID_EDGE]);
    } else {
        let corners = patches[p].corners;
        let at_surface = corners[0].xyz * w.x + corners[1].xyz * w.y + corners[2].xyz * w.z;
        position = at_surface + params.k * field_height(uv) * normal;
    }
    let shading = surface_normal(p, uv, normal, n);
    let tangent = normalize_or_zero(patches[p].derivatives[0].xyz);
    let o = v * VERTEX_FLOATS;
    vertices[o] = position.x;
    vertices[o + 1u] = position.y;
    vertices[o + 2u] = position.z;
    vertices[o + 3u] = shading.x;
    vertices[o + 4u] = shading.y;
    vertices[o + 5u] = shading.z;
    vertices[o + 6u] = uv.x;
    vertices[o + 7u] = uv.y;
    vertices[o + 8u] = tangent.x;
    vertices[o + 9u] = tangent.y;
    vertices[o + 10u] = tangent.z;
    vertices[o + 11u] = 1.0;
}

@compute @workgroup_size(64)
fn cs_indices(@builtin(global_invocation_id) id: vec3u) {
    if id.x + id.y * params.row >= params.triangle_count {
        return;
    }
    let item = item_of(id, 1u);
    let t = item.index;
    let n = levels[item.owner].split.w;
    let first_vertex = levels[item.owner].first.x;
    // Row b holds 2(n − b) − 1 triangles: upright at a, then upside down beside it.
    var local = item.local;
    var b = 0u;
    while local >= 2u * (n - b) - 1u {
        local -= 2u * (n - b) - 1u;
        b += 1u;
    }
    let a = local / 2u;
    var grid = array<vec2u, 3>(vec2u(a, b), vec2u(a + 1u, b), vec2u(a, b + 1u));
    if local % 2u == 1u {
        grid = array<vec2u, 3>(vec2u(a + 1u, b), vec2u(a + 1u, b + 1u), vec2u(a, b + 1u));
    }
    for (var i = 0u; i < 3u; i++) {
        let g = grid[i];
        indices[3u * t + i] = first_vertex + vertex_index(n, g.x, g.y);
    }
}
