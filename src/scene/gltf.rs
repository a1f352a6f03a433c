//! glTF 2.0 import: a `.gltf` file (JSON, with external or `data:` URI buffers and images) or a
//! `.glb` file (the binary container) becomes meshes, materials, textures, objects, lights and
//! cameras in the file's own world coordinates ([`GltfImport`]); the scene loader places them.
//!
//! # What is read
//!
//! The default scene is walked (scene 0 when none is marked default; every root node when the
//! file has no scenes at all), composing node transforms (a matrix, or translation · rotation ·
//! scale) from parent to child. Each triangle primitive of a node's mesh becomes one [`Mesh`] in
//! its local coordinates (`POSITION`, `NORMAL`, `TANGENT`, the `TEXCOORD_n` set its material's
//! textures read (see [Extensions](#extensions)) and the indices; normals are computed when the
//! file has none, texture coordinates are zero when it has none) and one
//! [`GltfObject`] named `<node name or "node N">/<primitive index>` carrying the node's world
//! transform. A primitive used by several nodes is one mesh drawn by several objects. Triangle
//! strips and fans are unrolled into triangle lists; points and lines are skipped with a warning.
//! Zero-area triangles are removed with a warning.
//!
//! `KHR_lights_punctual` lights become [`Light`]s at their node's world position, shining down the
//! node's world −z. glTF lights are physical, so point and spot lights fall off as 1/d², and
//! their photometric intensities (candela for point and spot lights, lux for directional ones)
//! are converted to the course model's by [`light::from_photometric`]: ÷ (683·π), which makes a
//! file exported from Blender render with the radiance Blender renders it with (at exposure 1,
//! Blender's Standard view at exposure 0). `range` is ignored. Camera nodes become
//! [`GltfCamera`]s.
//!
//! # Materials: metallic-roughness onto Mirador's Phong-style model
//!
//! With `m` = `metallicFactor`, `r` = `roughnessFactor` (both clamped to [0, 1]), `kt` the
//! `KHR_materials_transmission` factor (clamped to [0, 1]), and the dielectric's reflectance at
//! normal incidence, a colour,
//!
//! ```text
//! F0 = ((η − 1)/(η + 1))²                                   η = KHR_materials_ior, else 1.5
//! F0 = min(F0 · specularColorFactor, 1) · specularFactor    with KHR_materials_specular
//! ```
//!
//! split into its strength `f = max(F0.r, F0.g, F0.b)` and its hue `H = F0/f` (white when f = 0;
//! without the specular extension `F0` is grey, `H` white and `f` 0.04 for η = 1.5):
//!
//! | Mirador              | from glTF                                                          |
//! |----------------------|--------------------------------------------------------------------|
//! | `color` (C)          | `baseColorFactor.rgb` (linear) × `baseColorTexture` (sRGB texture) |
//! | `ka`                 | 0                                                                  |
//! | `kd`                 | (1 − m) · (1 − kt)                                                 |
//! | `ks`                 | (f · (1 − m) + m) · (1 − r)                                        |
//! | `specular_color` (S) | H · (1 − m) + `baseColorFactor.rgb` · m                            |
//! | `shininess` (e)      | 2/α² − 2 with α = r², clamped to [1, 2048]                         |
//! | `mirror` (kps)       | m · (1 − r)²                                                       |
//! | `mirror_color`       | S                                                                  |
//! | `emission`           | `emissiveFactor` × `KHR_materials_emissive_strength`               |
//! | `transmission` (kt)  | `KHR_materials_transmission` factor                                |
//! | `transmission_color` | `baseColorFactor.rgb`                                              |
//! | `ior`                | `KHR_materials_ior`; else 1.5 when kt > 0, else 1.0                |
//! | `alpha`              | `baseColorFactor.a` (clamped to [0, 1])                            |
//! | `alpha_mode`         | `alphaMode`: OPAQUE; MASK with `alphaCutoff` (default 0.5); BLEND  |
//!
//! and `KHR_materials_clearcoat` then adds its layer (below). Metals have no diffuse term and
//! reflect in their own colour; dielectrics reflect `f` (about 4 %, the Fresnel reflectance at
//! normal incidence of an index of 1.5) in `H`. The exponent `e` is
//! the Blinn-Phong exponent whose lobe matches a GGX lobe of roughness α, and the specular and
//! mirror weights fade with roughness because a rough surface spreads the same energy over a
//! wider lobe that a Phong lobe of bounded exponent cannot hold. The specular, mirror and
//! transmission colours use the factor alone: they have no texture slot.
//!
//! **Transmission** (`KHR_materials_transmission`) takes its light from the diffuse lobe: the
//! light a transmissive dielectric lets through is light it no longer scatters diffusely, hence
//! `kd·(1 − kt)`; the specular and mirror terms stay. Clear glass as exporters write it (white,
//! metallic 0, roughness 0, transmission 1) is `kd = 0`, `kt = 1`, `ks = f`: see-through with a
//! faint highlight, not a white ball (`tests/gltf_import.rs` traces one).
//!
//! **Specular** (`KHR_materials_specular`) changes only the dielectric's `F0`, as the extension
//! does. Mirador's model has no Fresnel term, so what the extension calls F90 (the grazing
//! reflectance, `specularFactor`) has nothing to act on; and one specular weight with one colour
//! cannot hold a coloured `F0` whose channels differ in strength except as strength × hue, which
//! is what `f` and `H` are.
//!
//! **Clearcoat** (`KHR_materials_clearcoat`, factor `c` and roughness `rc`, clamped to [0, 1]) is
//! a white dielectric layer of index 1.5 over the base. It reflects `F = 0.04·c`, and the base
//! below keeps `1 − F`:
//!
//! ```text
//! kd  ← kd·(1 − F)
//! ks  ← ks·(1 − F) + F·(1 − rc)          S   ← the two weights' mix of S and white
//! kps ← kps·(1 − F) + F·(1 − rc)²        MPS ← the two weights' mix of MPS and white
//! e   ← e(rc) where the layer's specular weight is the larger, else the base's e
//! ```
//!
//! What this loses: the layer's Fresnel rise towards grazing angles (most of a clear coat's look,
//! the bright rim on car paint; at normal incidence the layer reflects only 4 %); its second,
//! separate highlight (Mirador has one specular lobe, so a sharp coat over a rough base shows the
//! coat's highlight only, at the summed weight); `clearcoatNormalTexture` and the clearcoat
//! textures.
//!
//! **Alpha** is coverage (`AlphaMode`): `α = alpha ×` the base colour texture's alpha channel,
//! which survives decoding (textures are RGBA8) and is linear, as glTF defines it. OPAQUE ignores
//! `α`; MASK keeps the surface only where `α ≥ alphaCutoff` (a negative cutoff is read as 0, with
//! a warning; `alphaCutoff` on another mode is ignored, as glTF says); BLEND covers a fraction `α`
//! of what lies behind. A BLEND material with transmission keeps both, as glTF's transmission
//! extension defines them: coverage first, then transmission through the covered part, so the
//! ray tracer computes `α·(local model + kps·MPS·L(r) + kt·MT·L(t)) + (1 − α)·L(straight on)`.
//!
//! A primitive without a material gets [`Material::default()`] named `gltf-default`, not the glTF
//! default material: that one is fully metallic and fully rough, which the rule above makes black.
//!
//! # Extensions
//!
//! Read: `KHR_lights_punctual`, `KHR_materials_emissive_strength`, `KHR_materials_transmission`,
//! `KHR_materials_ior`, `KHR_materials_specular`, `KHR_materials_clearcoat` (all above),
//! `KHR_texture_transform` and `KHR_mesh_quantization` (below). A file that *requires* any other
//! (`KHR_draco_mesh_compression`, `EXT_meshopt_compression`, `KHR_texture_basisu`, or one never
//! heard of) is refused with an error naming it; one that merely *uses* others loads, with one
//! warning naming them all, however many materials carry them.
//!
//! **Texture coordinates and `KHR_texture_transform`.** A Mirador material samples all its
//! textures with one set of texture coordinates, so the transform is baked into the mesh: each
//! primitive's `TEXCOORD_n` is read for the set its material's textures name (the transform's
//! `texCoord` overriding the texture's), and carried through
//! `uv' = T(offset) · R(rotation) · S(scale) · uv` with the extension's rotation matrix
//! `[cos sin; −sin cos]`. Barycentric interpolation commutes with an affine map, so this is exact
//! for every point of every triangle, and mip levels follow the transformed coordinates as they
//! should. The file's tangents turn with it (`∂p/∂u'` from `∂p/∂u` and `∂p/∂v`, the handedness
//! flipping under a mirroring transform). The base colour texture decides; a normal texture with
//! a different set or transform is read with the base colour's, with a warning naming both (a
//! texture atlas that places the two maps differently shows the wrong part of the normal map).
//!
//! **`KHR_mesh_quantization`**: `POSITION`, `NORMAL`, `TANGENT` and `TEXCOORD_n` may be 8- or
//! 16-bit integers, signed or not, normalized or not. Normalized ones map to [0, 1] or [−1, 1]
//! (`max(c/127, −1)`, `c/255`, `max(c/32767, −1)`, `c/65535`), others convert by value; the
//! dequantizing scale and offset are the node's transform (positions) and the material's
//! `KHR_texture_transform` (texture coordinates), which Mirador applies as it always does.
//!
//! # What is ignored
//!
//! The metallic-roughness, occlusion, emissive, transmission, specular and clearcoat textures,
//! `doubleSided` (Mirador draws every surface two-sided, its normal turned to the viewer),
//! samplers' filters (filtering is the renderers'; their wrap modes are read), vertex colours,
//! skins (meshes are drawn in their bind pose), morph targets, animations, light `range`, and
//! extensions other than those above.
//!
//! # Errors
//!
//! Bad input gives [`SceneError::Gltf`] naming the file and the problem ([`SceneError::Io`] when
//! the file itself cannot be read); it never panics. Buffers, buffer views and accessors are
//! checked against each other before any byte is read (accessors are read here, not through the
//! `gltf` crate's reader, which panics or truncates silently on such files), node transforms and
//! attribute values must be finite, and indices must be in range. Since any number of primitives
//! may read one accessor, and any number of nodes draw one mesh, what the import builds is held to
//! a budget of 32 times the bytes of the file's buffers plus 16 MiB ([`MESH_BUDGET_FACTOR`]). As a
//! last net, a panic inside the `gltf` crate on a malformed file the checks missed is turned into
//! an error too.

use std::collections::HashMap;
use std::ffi::OsString;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::json::validation::Checked;
use gltf::khr_lights_punctual::Kind;
use gltf::mesh::{Mode, Semantic};
use gltf::scene::Transform;

use super::material::{AlphaMode, ColorSpace, Wrap};
use super::{Attenuation, Light, LightKind, Material, Mesh, SceneError, Texture, light, texture};
use crate::base::TextureId;

/// What one glTF file contributes to a scene, in the glTF file's own world coordinates.
#[derive(Clone, Debug, Default)]
pub struct GltfImport {
    /// One mesh per glTF primitive, in the primitive's local coordinates.
    pub meshes: Vec<Mesh>,
    /// Materials; `TextureId`s inside index `textures` below.
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub objects: Vec<GltfObject>,
    pub lights: Vec<Light>,
    pub cameras: Vec<GltfCamera>,
    /// Repairs made on the way (skipped degenerate triangles, …), already logged.
    pub warnings: Vec<String>,
}

/// One drawn primitive: indices into `GltfImport::meshes` and `GltfImport::materials`.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfObject {
    pub name: String,
    pub mesh: usize,
    pub material: usize,
    pub world_from_local: Mat4,
}

/// A glTF camera node: it looks down its local −z with +y up.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfCamera {
    pub name: String,
    pub world_from_camera: Mat4,
    pub projection: GltfProjection,
}

#[derive(Clone, Debug, PartialEq)]
pub enum GltfProjection {
    Perspective {
        yfov_radians: f32,
        znear: f32,
        zfar: Option<f32>,
    },
    /// `ymag` is half the window's height, as glTF defines it.
    Orthographic {
        ymag: f32,
        znear: f32,
        zfar: f32,
    },
}

/// Extensions this importer implements (quantized attributes are read by the generic accessor
/// reader below), so a file requiring them is accepted and one using them gets no warning.
const HANDLED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_clearcoat",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
];

/// The reflectance at normal incidence of `KHR_materials_clearcoat`'s layer: a dielectric of
/// index 1.5, as the extension fixes it.
const CLEARCOAT_F0: f32 = 0.04;

/// The largest Phong exponent a glTF material maps to: roughness 0 would give an infinite one,
/// and at 2048 the highlight is already a near-point; the mirror term carries the reflection.
const MAX_SHININESS: f32 = 2048.0;

/// Loads a `.gltf` or `.glb` file; see the module documentation for what is read and how.
pub fn import(path: &Path) -> Result<GltfImport, SceneError> {
    if path.as_os_str().is_empty() {
        return Err(SceneError::Gltf { path: path.to_path_buf(), message: "no file given (the path is empty)".into() });
    }
    let bytes = super::read_file(path).map_err(|cause| SceneError::Io { path: path.to_path_buf(), cause })?;
    import_bytes(path, &bytes)
}

/// Reads a `.gltf` or `.glb` file already in memory; `path` names it in messages, and relative
/// URIs are resolved against its folder.
pub fn import_bytes(path: &Path, bytes: &[u8]) -> Result<GltfImport, SceneError> {
    super::without_panics(|| read(path, bytes))
        .map_err(|message| SceneError::Gltf { path: path.to_path_buf(), message })
}

fn read(path: &Path, bytes: &[u8]) -> Result<GltfImport, String> {
    check_glb_header(bytes)?;
    check_version(bytes)?;
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(describe_gltf_error)?;
    let mut json = document.into_json();
    // Before validation: the `gltf` crate's validation refuses every required extension it does
    // not parse itself (`KHR_mesh_quantization`, `KHR_materials_clearcoat`, …) with a message
    // that does not say Mirador reads them, and a file requiring one Mirador lacks (Draco,
    // meshopt, Basis) is best refused by that extension's name before its odd data is looked at.
    let required: Vec<&str> =
        json.extensions_required.iter().map(String::as_str).filter(|e| !HANDLED_EXTENSIONS.contains(e)).collect();
    if !required.is_empty() {
        return Err(format!("the file requires extension(s) {}, which Mirador does not support", required.join(", ")));
    }
    json.extensions_required.clear();
    check_before_validation(&json)?;
    let document = gltf::Document::from_json(json).map_err(describe_gltf_error)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let buffers = load_buffers(&document, &base, blob)?;
    let nodes: Vec<gltf::Node<'_>> = document.nodes().collect();
    let mut importer = Importer {
        path,
        base,
        document: &document,
        buffers: &buffers,
        out: GltfImport::default(),
        meshes: HashMap::new(),
        materials: HashMap::new(),
        uv_mappings: HashMap::new(),
        textures: HashMap::new(),
        budget: MESH_BUDGET_FACTOR * buffers.iter().map(|b| b.len() as u64).sum::<u64>() + MESH_BUDGET_ALLOWANCE,
    };
    let ignored: Vec<&str> = document.extensions_used().filter(|e| !HANDLED_EXTENSIONS.contains(e)).collect();
    if !ignored.is_empty() {
        importer.warn(format!("ignoring extension(s) {}", ignored.join(", ")));
    }
    importer.walk(&nodes)?;
    Ok(importer.out)
}

/// The `gltf` crate subtracts the header size from the declared length without checking it
/// (an overflow panic on a corrupt header), so the header is checked here first.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if bytes.len() < 12 {
        return Err(format!("invalid GLB: the file is {} bytes, shorter than the 12-byte GLB header", bytes.len()));
    }
    let declared = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
    if declared < 12 || declared > bytes.len() {
        return Err(format!(
            "invalid GLB: the header declares a length of {declared} bytes but the file has {} (truncated or corrupt)",
            bytes.len()
        ));
    }
    Ok(())
}

/// glTF 1.0 (2015; a GLB of version 1, or `asset.version` "1.x") is a different format, which the
/// reader would otherwise refuse with a message about the JSON's shape: say what it is.
fn check_version(bytes: &[u8]) -> Result<(), String> {
    const REFUSED: &str = "glTF 1.0 is not supported (2.0 is): convert the file, for example by opening \
        it in Blender and exporting glTF 2.0";
    if bytes.starts_with(b"glTF") {
        let version = bytes.get(4..8).map_or(2, |v| u32::from_le_bytes([v[0], v[1], v[2], v[3]]));
        return if version == 1 { Err(REFUSED.into()) } else { Ok(()) };
    }
    let json: Option<serde_json::Value> = serde_json::from_slice(bytes).ok();
    let version = json.as_ref().and_then(|j| j.get("asset")?.get("version")?.as_str().map(str::to_owned));
    match version {
        Some(v) if v.starts_with("1.") || v == "1" => Err(REFUSED.into()),
        _ => Ok(()),
    }
}

/// The `gltf` crate's own validation indexes the accessor list with each primitive's `POSITION`
/// unchecked (a panic on a dangling index), so that one reference is checked here first.
fn check_before_validation(json: &gltf::json::Root) -> Result<(), String> {
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive.attributes.get(&Checked::Valid(Semantic::Positions));
            if let Some(accessor) = position.filter(|a| a.value() >= json.accessors.len()) {
                return Err(format!(
                    "invalid glTF document: meshes[{m}].primitives[{p}] takes POSITION from accessor {}, and there \
                     are only {} accessors",
                    accessor.value(),
                    json.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

fn describe_gltf_error(error: gltf::Error) -> String {
    match error {
        gltf::Error::Deserialize(e) => format!("invalid JSON: {e}"),
        gltf::Error::Binary(e) => format!("invalid GLB container: {e}"),
        gltf::Error::Validation(problems) => {
            let listed: Vec<String> = problems.iter().take(8).map(|(at, what)| format!("{at}: {what}")).collect();
            let more = problems.len().saturating_sub(listed.len());
            let more = if more > 0 { format!("; and {more} more") } else { String::new() };
            format!("invalid glTF document: {}{more}", listed.join("; "))
        }
        other => other.to_string(),
    }
}

/// Reads every buffer, whether the walk needs it or not: a file whose buffers cannot all be read
/// is broken, and saying so early names the culprit.
fn load_buffers(document: &gltf::Document, base: &Path, mut blob: Option<Vec<u8>>) -> Result<Vec<Vec<u8>>, String> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let index = buffer.index();
        let (data, source) = match buffer.source() {
            gltf::buffer::Source::Bin => {
                let data = blob.take().ok_or_else(|| {
                    format!(
                        "buffer {index} has no `uri` and there is no (unclaimed) GLB binary chunk to stand in for it"
                    )
                })?;
                (data, "the GLB binary chunk".to_string())
            }
            gltf::buffer::Source::Uri(uri) => {
                let data = read_uri(uri, base).map_err(|e| format!("buffer {index}: {e}"))?;
                (data, format!("`{}`", shorten(uri)))
            }
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {index} ({source}) holds {} bytes, fewer than its declared byteLength {}",
                data.len(),
                buffer.length()
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The bytes behind a buffer or image URI: a base64 `data:` URI, or a file path relative to the
/// glTF file (percent-encoded, as URIs are).
fn read_uri(uri: &str, base: &Path) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) =
            rest.split_once(";base64,").ok_or_else(|| format!("data URI `{}` is not base64-encoded", shorten(uri)))?;
        return decode_base64(data).map_err(|e| format!("data URI `{}`: {e}", shorten(uri)));
    }
    if has_scheme(uri) {
        return Err(format!(
            "URI `{}` has a scheme Mirador cannot read (only relative file paths and data: URIs)",
            shorten(uri)
        ));
    }
    let relative = percent_decode(uri).ok_or_else(|| format!("URI `{}` has an invalid %-escape", shorten(uri)))?;
    let file = base.join(relative);
    super::read_file(&file).map_err(|e| format!("cannot read `{uri}` ({}): {e}", file.display()))
}

/// `scheme:` as RFC 3986 spells it; a single letter is taken for a Windows drive, not a scheme.
fn has_scheme(uri: &str) -> bool {
    let Some((scheme, _)) = uri.split_once(':') else { return false };
    scheme.len() > 1
        && scheme.starts_with(|c: char| c.is_ascii_alphabetic())
        && scheme.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
}

fn percent_decode(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Standard or URL-safe base64, padded or not. Written out here because the crate has no base64
/// dependency of its own and the `gltf` crate's loader panics on some malformed URIs.
fn decode_base64(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut bits, mut held) = (0u32, 0u32);
    let mut padded = false;
    for (at, c) in text.bytes().enumerate() {
        let value = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => {
                padded = true;
                continue;
            }
            b' ' | b'\t' | b'\r' | b'\n' => continue,
            _ => return Err(format!("invalid base64 character {:?} at offset {at}", c as char)),
        };
        if padded {
            return Err(format!("base64 data goes on after `=` padding (offset {at})"));
        }
        bits = (bits << 6) | u32::from(value);
        held += 6;
        if held >= 8 {
            held -= 8;
            out.push((bits >> held) as u8);
            bits &= (1 << held) - 1;
        }
    }
    Ok(out)
}

/// Data URIs can be megabytes long; messages show their start.
fn shorten(uri: &str) -> String {
    const KEEP: usize = 48;
    match uri.char_indices().nth(KEEP) {
        Some((cut, _)) => format!("{}…", &uri[..cut]),
        None => uri.to_string(),
    }
}

/// The importer's state while it walks one document.
struct Importer<'d> {
    path: &'d Path,
    /// The directory relative URIs are resolved against.
    base: PathBuf,
    document: &'d gltf::Document,
    buffers: &'d [Vec<u8>],
    out: GltfImport,
    /// (glTF mesh, primitive) → index into `out.meshes`, `None` for a skipped primitive.
    meshes: HashMap<(usize, usize), Option<usize>>,
    /// glTF material (`None`: the default) → index into `out.materials`.
    materials: HashMap<Option<usize>, usize>,
    /// glTF material → the texture coordinates its textures read.
    uv_mappings: HashMap<Option<usize>, UvMapping>,
    /// glTF image → index into `out.textures`.
    textures: HashMap<(usize, ColorSpace), TextureId>,
    /// The bytes of meshes and objects still allowed ([`MESH_BUDGET_FACTOR`]).
    budget: u64,
}

/// The meshes and objects one file builds may hold at most this many times the bytes of its
/// buffers, plus [`MESH_BUDGET_ALLOWANCE`]. Every accessor is checked against its buffer, but any
/// number of primitives may read the same accessor, each into a mesh of its own, and any number of
/// nodes may draw a mesh of many primitives: without a budget, a file of a few megabytes listing
/// thousands of primitives over one buffer, or thousands of nodes over one mesh of thousands of
/// primitives, would ask for terabytes. An object counts [`OBJECT_BYTES`].
/// A file that reads each byte once builds at most about 12 bytes per byte (8-bit positions
/// widened to floats, with the normals and texture coordinates filled in, or 8-bit strip indices
/// unrolled into 32-bit triangles); 32 leaves room for primitives that share their vertices.
const MESH_BUDGET_FACTOR: u64 = 32;

/// See [`MESH_BUDGET_FACTOR`]: 16 MiB, so that small files sharing data freely still load.
const MESH_BUDGET_ALLOWANCE: u64 = 16 << 20;

/// What one object costs the budget: its name, indices and transform, with room to spare.
const OBJECT_BYTES: u64 = 128;

/// Where the depth-first walk is in each node, to tell a cycle (an error: the walk would never
/// end) from a node listed twice (drawn once, with a warning).
#[derive(Clone, Copy, PartialEq)]
enum Visit {
    Not,
    OnPath,
    Done,
}

enum Step {
    Enter { node: usize, parent_world: Mat4 },
    Leave(usize),
}

impl<'d> Importer<'d> {
    fn warn(&mut self, message: String) {
        let message = format!("{}: glTF: {message}", self.path.display());
        log::warn!("{message}");
        self.out.warnings.push(message);
    }

    fn root_nodes(&self, nodes: &[gltf::Node<'d>]) -> Vec<usize> {
        if let Some(scene) = self.document.default_scene().or_else(|| self.document.scenes().next()) {
            return scene.nodes().map(|n| n.index()).collect();
        }
        let mut is_child = vec![false; nodes.len()];
        for child in nodes.iter().flat_map(|n| n.children()) {
            is_child[child.index()] = true;
        }
        (0..nodes.len()).filter(|&i| !is_child[i]).collect()
    }

    /// An explicit stack rather than recursion, so that a hostile, very deep hierarchy cannot
    /// overflow the call stack.
    fn walk(&mut self, nodes: &[gltf::Node<'d>]) -> Result<(), String> {
        let mut visit = vec![Visit::Not; nodes.len()];
        let mut stack: Vec<Step> = self
            .root_nodes(nodes)
            .into_iter()
            .rev()
            .map(|node| Step::Enter { node, parent_world: Mat4::IDENTITY })
            .collect();
        while let Some(step) = stack.pop() {
            let (index, parent_world) = match step {
                Step::Leave(index) => {
                    visit[index] = Visit::Done;
                    continue;
                }
                Step::Enter { node, parent_world } => (node, parent_world),
            };
            let node = &nodes[index];
            let label = node_label(node);
            match visit[index] {
                Visit::OnPath => {
                    return Err(format!("node `{label}` is its own ancestor (a cycle in the node hierarchy)"));
                }
                Visit::Done => {
                    self.warn(format!("node `{label}` is reached twice in the node hierarchy; it is drawn once"));
                    continue;
                }
                Visit::Not => visit[index] = Visit::OnPath,
            }
            let world = parent_world * local_transform(node, &label)?;
            if !world.is_finite() {
                return Err(format!(
                    "node `{label}`: its world transform is not finite (NaN or infinity; numbers beyond ±3.4e38 \
                     overflow 32-bit floats)"
                ));
            }
            self.node(node, &label, world)?;
            stack.push(Step::Leave(index));
            let children: Vec<usize> = node.children().map(|c| c.index()).collect();
            stack.extend(children.into_iter().rev().map(|child| Step::Enter { node: child, parent_world: world }));
        }
        Ok(())
    }

    /// Takes `bytes` from the budget of what the import builds ([`MESH_BUDGET_FACTOR`]).
    fn spend(&mut self, bytes: u64, what: &str) -> Result<(), String> {
        self.budget = self.budget.checked_sub(bytes).ok_or_else(|| {
            format!(
                "{what}: the file's meshes and objects come to more than {MESH_BUDGET_FACTOR} times the bytes of its \
                 buffers (plus {} MiB); its primitives or nodes read the same data over and over",
                MESH_BUDGET_ALLOWANCE >> 20
            )
        })?;
        Ok(())
    }

    fn node(&mut self, node: &gltf::Node<'d>, label: &str, world: Mat4) -> Result<(), String> {
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                // Every node drawing a mesh adds an object per primitive, however many nodes share it.
                self.spend(OBJECT_BYTES, &format!("node `{label}`"))?;
                let Some(mesh_index) = self.mesh(&mesh, &primitive)? else { continue };
                let material = self.material(primitive.material())?;
                self.out.objects.push(GltfObject {
                    name: format!("{label}/{}", primitive.index()),
                    mesh: mesh_index,
                    material,
                    world_from_local: world,
                });
            }
        }
        if let Some(light) = node.light() {
            self.light(&light, label, world)?;
        }
        if let Some(camera) = node.camera() {
            self.camera(&camera, label, world)?;
        }
        Ok(())
    }

    fn mesh(&mut self, mesh: &gltf::Mesh<'d>, primitive: &gltf::Primitive<'d>) -> Result<Option<usize>, String> {
        let key = (mesh.index(), primitive.index());
        if let Some(&known) = self.meshes.get(&key) {
            return Ok(known);
        }
        let mapping = self.uv_mapping(&primitive.material())?;
        let built = self.build_mesh(mesh, primitive, mapping)?;
        let index = built.map(|m| {
            self.out.meshes.push(m);
            self.out.meshes.len() - 1
        });
        self.meshes.insert(key, index);
        Ok(index)
    }

    /// Builds one primitive's mesh, its texture coordinates read from the set its material's
    /// textures use and carried through their `KHR_texture_transform`.
    fn build_mesh(
        &mut self,
        mesh: &gltf::Mesh<'d>,
        primitive: &gltf::Primitive<'d>,
        mapping: UvMapping,
    ) -> Result<Option<Mesh>, String> {
        let mesh_name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_owned);
        let name = format!("{mesh_name}/{}", primitive.index());
        let mode = primitive.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            self.warn(format!("mesh `{name}`: skipped, its primitive mode is {mode:?} and only triangles are drawn"));
            return Ok(None);
        }
        let positions_accessor =
            primitive.get(&Semantic::Positions).ok_or_else(|| format!("mesh `{name}` has no POSITION attribute"))?;
        let positions: Vec<Vec3> = self
            .read_vectors::<3>(&positions_accessor, &format!("POSITION of mesh `{name}`"))?
            .into_iter()
            .map(Vec3::from_array)
            .collect();
        let vertex_count = positions.len();
        let normals: Option<Vec<Vec3>> = match primitive.get(&Semantic::Normals) {
            // glTF asks for unit normals; normalizing tolerates files that store them unscaled.
            Some(accessor) => Some(
                self.read_vectors::<3>(&accessor, &format!("NORMAL of mesh `{name}`"))?
                    .into_iter()
                    .map(|n| Vec3::from_array(n).try_normalize().unwrap_or(Vec3::from_array(n)))
                    .collect(),
            ),
            None => None,
        };
        let set = mapping.set;
        let uvs: Vec<Vec2> = match primitive.get(&Semantic::TexCoords(set)) {
            Some(accessor) => self
                .read_vectors::<2>(&accessor, &format!("TEXCOORD_{set} of mesh `{name}`"))?
                .into_iter()
                .map(Vec2::from_array)
                .collect(),
            None => {
                if set != 0 {
                    self.warn(format!(
                        "mesh `{name}` has no TEXCOORD_{set}, which its material's textures read; its texture \
                         coordinates are all 0"
                    ));
                }
                vec![Vec2::ZERO; vertex_count]
            }
        };
        let tangents: Vec<Vec4> = match primitive.get(&Semantic::Tangents) {
            Some(accessor) => self
                .read_vectors::<4>(&accessor, &format!("TANGENT of mesh `{name}`"))?
                .into_iter()
                .map(Vec4::from_array)
                .collect(),
            None => Vec::new(),
        };
        let vertices: Vec<u32> = match primitive.indices() {
            Some(accessor) => self.read_indices(&accessor, &format!("indices of mesh `{name}`"))?,
            None => {
                let count = u32::try_from(vertex_count).map_err(|_| {
                    format!("mesh `{name}` has {vertex_count} vertices, more than 32-bit indices reach")
                })?;
                (0..count).collect()
            }
        };
        let indices = match mode {
            Mode::TriangleStrip => strip_to_list(&vertices),
            Mode::TriangleFan => fan_to_list(&vertices),
            _ => vertices,
        };
        let has_normals = normals.is_some();
        // Normals and texture coordinates are filled in for every position when missing.
        let bytes = positions.len() as u64 * (12 + 12 + 8) + tangents.len() as u64 * 16 + indices.len() as u64 * 4;
        self.spend(bytes, &format!("mesh `{name}`"))?;
        let mut built = Mesh {
            name,
            positions,
            // A placeholder until the indices are known to be in range, which computing normals
            // relies on.
            normals: normals.unwrap_or_else(|| vec![Vec3::Y; vertex_count]),
            uvs,
            tangents,
            indices,
        };
        let removed = built.validate_and_repair().map_err(|e| e.to_string())?;
        if removed > 0 {
            self.warn(format!("mesh `{}`: removed {removed} zero-area (degenerate) triangle(s)", built.name));
        }
        if built.indices.is_empty() {
            self.warn(format!("mesh `{}`: skipped, it has no triangles with area", built.name));
            return Ok(None);
        }
        if !has_normals {
            built.compute_normals();
        }
        if let Some(transform) = mapping.transform {
            transform.bake(&mut built)?;
        }
        Ok(Some(built))
    }

    /// The bytes of a buffer view, after checking that it lies inside its buffer.
    fn view_bytes(&self, view: &gltf::buffer::View<'d>, what: &str) -> Result<&'d [u8], String> {
        let buffer = view.buffer();
        let data = self
            .buffers
            .get(buffer.index())
            .ok_or_else(|| format!("{what}: buffer {} was not loaded", buffer.index()))?;
        let (start, length) = (view.offset(), view.length());
        match start.checked_add(length) {
            Some(end) if end <= buffer.length() && end <= data.len() => Ok(&data[start..end]),
            _ => Err(format!(
                "{what}: buffer view {} (bytes {start}..{}) runs past the end of buffer {} ({} bytes)",
                view.index(),
                start.saturating_add(length),
                buffer.index(),
                buffer.length()
            )),
        }
    }

    /// The bytes an accessor covers, from its first element's start to its last element's end,
    /// and the stride between elements; every bound is checked against the view and the buffer.
    fn accessor_bytes(&self, accessor: &gltf::Accessor<'d>, what: &str) -> Result<(&'d [u8], usize), String> {
        let index = accessor.index();
        if accessor.sparse().is_some() {
            return Err(format!("{what}: accessor {index} is sparse, which Mirador does not read"));
        }
        let view = accessor.view().ok_or_else(|| format!("{what}: accessor {index} has no bufferView"))?;
        let bytes = self.view_bytes(&view, what)?;
        let count = accessor.count();
        if count == 0 {
            return Ok((&[], 0));
        }
        let element = accessor.size();
        let stride = view.stride().unwrap_or(element);
        if stride < element {
            return Err(format!(
                "{what}: buffer view {} has a byteStride of {stride}, less than the {element}-byte elements of \
                 accessor {index}",
                view.index()
            ));
        }
        let offset = accessor.offset();
        let end =
            (count - 1).checked_mul(stride).and_then(|s| s.checked_add(element)).and_then(|s| s.checked_add(offset));
        match end {
            Some(end) if end <= bytes.len() => Ok((&bytes[offset..end], stride)),
            _ => Err(format!(
                "{what}: accessor {index} reads {count} elements of {element} bytes (stride {stride}) from byte \
                 {offset} of buffer view {}, past the end of the view ({} bytes)",
                view.index(),
                bytes.len()
            )),
        }
    }

    /// Reads an accessor of `N`-component vectors as `f32`, whatever its component type:
    /// normalized integers map to [0, 1] or [−1, 1] as the glTF specification says, other
    /// integers convert by value (which is what `KHR_mesh_quantization` asks).
    fn read_vectors<const N: usize>(&self, accessor: &gltf::Accessor<'d>, what: &str) -> Result<Vec<[f32; N]>, String> {
        let expected = match N {
            1 => Dimensions::Scalar,
            2 => Dimensions::Vec2,
            3 => Dimensions::Vec3,
            _ => Dimensions::Vec4,
        };
        if accessor.dimensions() != expected {
            return Err(format!(
                "{what}: accessor {} holds {:?} elements, not {expected:?}",
                accessor.index(),
                accessor.dimensions()
            ));
        }
        let (bytes, stride) = self.accessor_bytes(accessor, what)?;
        let (kind, normalized) = (accessor.data_type(), accessor.normalized());
        let size = kind.size();
        Ok((0..accessor.count())
            .map(|i| std::array::from_fn(|c| component(&bytes[i * stride + c * size..], kind, normalized)))
            .collect())
    }

    fn read_indices(&self, accessor: &gltf::Accessor<'d>, what: &str) -> Result<Vec<u32>, String> {
        let kind = accessor.data_type();
        if accessor.dimensions() != Dimensions::Scalar || !matches!(kind, DataType::U8 | DataType::U16 | DataType::U32)
        {
            return Err(format!(
                "{what}: accessor {} holds {:?} {:?} elements; indices must be unsigned integer scalars",
                accessor.index(),
                accessor.dimensions(),
                kind
            ));
        }
        let (bytes, stride) = self.accessor_bytes(accessor, what)?;
        Ok((0..accessor.count())
            .map(|i| {
                let b = &bytes[i * stride..];
                match kind {
                    DataType::U8 => u32::from(b[0]),
                    DataType::U16 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                }
            })
            .collect())
    }

    fn material(&mut self, material: gltf::Material<'d>) -> Result<usize, String> {
        let key = material.index();
        if let Some(&known) = self.materials.get(&key) {
            return Ok(known);
        }
        let converted = match key {
            None => Material { name: "gltf-default".into(), ..Material::default() },
            Some(_) => self.convert_material(&material)?,
        };
        self.out.materials.push(converted);
        let index = self.out.materials.len() - 1;
        self.materials.insert(key, index);
        Ok(index)
    }

    /// The texture coordinates `material`'s textures read (see the module documentation),
    /// decided once per material, which warns once when its textures disagree.
    fn uv_mapping(&mut self, material: &gltf::Material<'d>) -> Result<UvMapping, String> {
        let key = material.index();
        if let Some(&known) = self.uv_mappings.get(&key) {
            return Ok(known);
        }
        let name = material_name(material);
        let base = match material.pbr_metallic_roughness().base_color_texture() {
            Some(info) => Some(match info.texture_transform() {
                Some(t) => UvMapping {
                    set: t.tex_coord().unwrap_or(info.tex_coord()),
                    transform: UvTransform::new(
                        t.offset(),
                        t.rotation(),
                        t.scale(),
                        &format!("material `{name}`'s base colour texture"),
                    )?,
                },
                None => UvMapping { set: info.tex_coord(), transform: None },
            }),
            None => None,
        };
        let normal = match material.normal_texture() {
            Some(info) => {
                let what = format!("material `{name}`'s normal texture");
                Some(match info.extension_value("KHR_texture_transform") {
                    Some(value) => {
                        let t: gltf::json::extensions::texture::TextureTransform =
                            gltf::json::deserialize::from_value(value.clone())
                                .map_err(|e| format!("{what}: KHR_texture_transform is malformed: {e}"))?;
                        UvMapping {
                            set: t.tex_coord.unwrap_or(info.tex_coord()),
                            transform: UvTransform::new(t.offset.0, t.rotation.0, t.scale.0, &what)?,
                        }
                    }
                    None => UvMapping { set: info.tex_coord(), transform: None },
                })
            }
            None => None,
        };
        let mapping = match (base, normal) {
            (Some(base), Some(normal)) => {
                if base != normal {
                    self.warn(format!(
                        "material `{name}`: its normal texture reads {normal} and its base colour texture {base}; \
                         a Mirador material has one set of texture coordinates, so both read the base colour's"
                    ));
                }
                base
            }
            (Some(only), None) | (None, Some(only)) => only,
            (None, None) => UvMapping::default(),
        };
        self.uv_mappings.insert(key, mapping);
        Ok(mapping)
    }

    fn convert_material(&mut self, material: &gltf::Material<'d>) -> Result<Material, String> {
        let name = material_name(material);
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, alpha] = pbr.base_color_factor();
        let base = Vec3::new(r, g, b);
        let emission = Vec3::from_array(material.emissive_factor()) * material.emissive_strength().unwrap_or(1.0);
        let transmission = material.transmission().map_or(0.0, |t| t.transmission_factor());
        let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
        let cutoff = material.alpha_cutoff().unwrap_or(AlphaMode::DEFAULT_CUTOFF);
        let specular = material.specular().map(|s| (s.specular_factor(), Vec3::from_array(s.specular_color_factor())));
        let clearcoat = match material.extension_value("KHR_materials_clearcoat") {
            Some(value) => Some(clearcoat_of(value, &name)?),
            None => None,
        };
        let numbers = [r, g, b, alpha, cutoff, metallic, roughness, transmission];
        if numbers.iter().any(|x| !x.is_finite())
            || !emission.is_finite()
            || material.ior().is_some_and(|x| !x.is_finite())
            || specular.is_some_and(|(factor, color)| !factor.is_finite() || !color.is_finite())
        {
            return Err(format!("material `{name}` has a factor that is not a finite number"));
        }
        let texture = match pbr.base_color_texture() {
            Some(info) => self.texture(info.texture().source(), ColorSpace::Srgb)?,
            None => None,
        };
        // One wrap for the whole material: the base colour texture's sampler, else the normal
        // texture's (glTF gives each texture its own; Mirador's materials have one).
        let sampler = pbr
            .base_color_texture()
            .map(|info| info.texture().sampler())
            .or_else(|| material.normal_texture().map(|info| info.texture().sampler()));
        let wrap = sampler.map_or([Wrap::Repeat; 2], |s| [wrap_of(s.wrap_s()), wrap_of(s.wrap_t())]);
        let normal_map = match material.normal_texture() {
            Some(info) => self.texture(info.texture().source(), ColorSpace::Linear)?.map(|id| (id, info.scale())),
            None => None,
        };
        // glTF's index of refraction, 1.5 unless `KHR_materials_ior` says otherwise; it sets the
        // dielectric reflectance whether or not the material transmits.
        let gltf_ior = material.ior().filter(|&ior| ior >= 1.0);
        let f0 = dielectric_f0(gltf_ior.unwrap_or(1.5), specular);
        let mut phong = phong_from_metallic_roughness(base, metallic.clamp(0.0, 1.0), roughness.clamp(0.0, 1.0), f0);
        if let Some((factor, coat_roughness)) = clearcoat {
            phong = with_clearcoat(phong, factor, coat_roughness);
        }
        let transmission = transmission.clamp(0.0, 1.0);
        let default_ior = if transmission > 0.0 { 1.5 } else { 1.0 };
        let alpha_mode = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => {
                if cutoff < 0.0 {
                    self.warn(format!("material `{name}`: alphaCutoff {cutoff} is below 0; read as 0"));
                }
                AlphaMode::Mask { cutoff: cutoff.max(0.0) }
            }
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        Ok(Material {
            name,
            color: base,
            texture,
            wrap,
            ka: 0.0,
            // glTF's transmission takes its share from the diffuse lobe.
            kd: phong.kd * (1.0 - transmission),
            ks: phong.ks,
            specular_color: phong.specular_color,
            shininess: phong.shininess,
            emission,
            mirror: phong.mirror,
            mirror_color: phong.mirror_color,
            transmission,
            transmission_color: base,
            ior: gltf_ior.unwrap_or(default_ior),
            height_map: None,
            height_field: None,
            bump_scale: 1.0,
            normal_map: normal_map.map(|(id, _)| id),
            normal_scale: normal_map.map_or(1.0, |(_, scale)| scale),
            alpha: alpha.clamp(0.0, 1.0),
            alpha_mode,
        })
    }

    /// The image as a texture read in `space`: the same image may serve as colour (sRGB) and as
    /// data (linear), and then becomes two textures. An external image file that is not there is
    /// a warning and `None` (the material drawn without it, as Blender and three.js draw it); one
    /// that is there but broken is an error.
    fn texture(&mut self, image: gltf::Image<'d>, space: ColorSpace) -> Result<Option<TextureId>, String> {
        let index = image.index();
        if let Some(&known) = self.textures.get(&(index, space)) {
            return Ok(Some(known));
        }
        // The raw JSON, because the `gltf` crate's `Image::source` unwraps fields a malformed
        // file may lack.
        let json =
            self.document.as_json().images.get(index).expect("an image index handed out by the validated document");
        let embedded = || {
            let mut path = OsString::from(self.path.as_os_str());
            path.push(format!("#image{index}"));
            PathBuf::from(path)
        };
        let (bytes, texture_path, described): (std::borrow::Cow<'d, [u8]>, PathBuf, String) =
            match (&json.buffer_view, &json.uri) {
                (Some(view), _) => {
                    let view = self
                        .document
                        .views()
                        .nth(view.value())
                        .expect("a buffer view index checked by the document's validation");
                    let what = format!("image {index}");
                    (self.view_bytes(&view, &what)?.into(), embedded(), what)
                }
                (None, Some(uri)) => {
                    let described = format!("image {index} (`{}`)", shorten(uri));
                    let missing = match (uri.starts_with("data:") || has_scheme(uri), percent_decode(uri)) {
                        (false, Some(relative)) => Some(self.base.join(relative)),
                        _ => None,
                    }
                    .filter(|file| crate::files::is_missing(file));
                    if let Some(file) = missing {
                        self.warn(format!(
                            "{described}: cannot read {}: it is not there; the material is drawn without it",
                            file.display()
                        ));
                        return Ok(None);
                    }
                    let bytes = read_uri(uri, &self.base).map_err(|e| format!("image {index}: {e}"))?;
                    let path = match (uri.starts_with("data:"), percent_decode(uri)) {
                        (false, Some(relative)) => self.base.join(relative),
                        _ => embedded(),
                    };
                    (bytes.into(), path, described)
                }
                (None, None) => return Err(format!("image {index} has neither a `uri` nor a `bufferView`")),
            };
        // The content decides the format; a declared MIME type is only the fallback, since files
        // in the wild mislabel JPEGs as PNGs and the other way round.
        let declared = match json.mime_type.as_ref().map(|m| m.0.as_str()) {
            Some("image/png") => Some(image::ImageFormat::Png),
            Some("image/jpeg") => Some(image::ImageFormat::Jpeg),
            _ => None,
        };
        let format = image::guess_format(&bytes)
            .ok()
            .or(declared)
            .ok_or_else(|| format!("{described}: not a recognised image format (PNG or JPEG expected)"))?;
        let reader = image::ImageReader::with_format(Cursor::new(&bytes[..]), format);
        let decoded = texture::decode(reader).map_err(|e| format!("{described}: {e}"))?;
        self.out.textures.push(texture::from_image(&texture_path, decoded, space));
        let id = TextureId(self.out.textures.len() - 1);
        self.textures.insert((index, space), id);
        Ok(Some(id))
    }

    fn light(&mut self, light: &gltf::khr_lights_punctual::Light<'d>, label: &str, world: Mat4) -> Result<(), String> {
        let name = light.name().map_or_else(|| format!("light {}", light.index()), str::to_owned);
        let (color, intensity) = (Vec3::from_array(light.color()), light.intensity());
        if !color.is_finite() || !intensity.is_finite() {
            return Err(format!("light `{name}` has a colour or intensity that is not a finite number"));
        }
        let position = world.transform_point3(Vec3::ZERO);
        let direction = || {
            world.transform_vector3(Vec3::NEG_Z).try_normalize().ok_or_else(|| {
                format!("light `{name}` on node `{label}`: the node's transform collapses the light's direction")
            })
        };
        let (kind, attenuation) = match light.kind() {
            Kind::Point => (LightKind::Point { position }, Attenuation::InverseSquare),
            Kind::Directional => (LightKind::Directional { direction: direction()? }, Attenuation::None),
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                if !inner_cone_angle.is_finite() || !outer_cone_angle.is_finite() {
                    return Err(format!("light `{name}` has a cone angle that is not a finite number"));
                }
                // glTF requires 0 ≤ inner < outer ≤ π/2; clamping keeps a sloppy file drawable.
                let outer = outer_cone_angle.clamp(0.0, std::f32::consts::FRAC_PI_2);
                let inner = inner_cone_angle.clamp(0.0, outer);
                if (inner, outer) != (inner_cone_angle, outer_cone_angle) {
                    self.warn(format!(
                        "light `{name}`: cone angles ({inner_cone_angle}, {outer_cone_angle}) clamped to ({inner}, {outer})"
                    ));
                }
                (LightKind::Spot { position, direction: direction()?, inner, outer }, Attenuation::InverseSquare)
            }
        };
        let intensity = light::from_photometric(intensity);
        self.out.lights.push(Light { name, kind, color, intensity, attenuation });
        Ok(())
    }

    fn camera(&mut self, camera: &gltf::Camera<'d>, label: &str, world: Mat4) -> Result<(), String> {
        use gltf::json::camera::Type;
        let name = camera.name().map_or_else(|| label.to_string(), str::to_owned);
        // The raw JSON, because `Camera::projection` unwraps the block its `type` names, which a
        // malformed file may lack.
        let json = self
            .document
            .as_json()
            .cameras
            .get(camera.index())
            .expect("a camera index handed out by the validated document");
        let missing = |block: &str| format!("camera `{name}` is of type {block} but has no `{block}` block");
        let projection = match json.type_ {
            Checked::Valid(Type::Perspective) => {
                let p = json.perspective.as_ref().ok_or_else(|| missing("perspective"))?;
                GltfProjection::Perspective { yfov_radians: p.yfov, znear: p.znear, zfar: p.zfar }
            }
            Checked::Valid(Type::Orthographic) => {
                let o = json.orthographic.as_ref().ok_or_else(|| missing("orthographic"))?;
                GltfProjection::Orthographic { ymag: o.ymag, znear: o.znear, zfar: o.zfar }
            }
            Checked::Invalid => return Err(format!("camera `{name}` has an unknown type")),
        };
        let numbers = match projection {
            GltfProjection::Perspective { yfov_radians, znear, zfar } => [yfov_radians, znear, zfar.unwrap_or(0.0)],
            GltfProjection::Orthographic { ymag, znear, zfar } => [ymag, znear, zfar],
        };
        if numbers.iter().any(|x| !x.is_finite()) {
            return Err(format!("camera `{name}` has a projection parameter that is not a finite number"));
        }
        self.out.cameras.push(GltfCamera { name, world_from_camera: world, projection });
        Ok(())
    }
}

/// The texture coordinates a material's textures read: one `TEXCOORD_n` set, and the
/// `KHR_texture_transform` baked into it (`None`: none, or the identity).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct UvMapping {
    set: u32,
    transform: Option<UvTransform>,
}

impl std::fmt::Display for UvMapping {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TEXCOORD_{}", self.set)?;
        match self.transform {
            Some(t) => write!(
                f,
                " with offset ({}, {}), rotation {} rad, scale ({}, {})",
                t.offset.x, t.offset.y, t.rotation, t.scale.x, t.scale.y
            ),
            None => write!(f, " untransformed"),
        }
    }
}

/// `KHR_texture_transform`: `uv' = T(offset) · R(rotation) · S(scale) · uv`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvTransform {
    offset: Vec2,
    /// Radians; the extension's matrix turns uv by `−rotation` (the image appears turned by
    /// `rotation` counter-clockwise, as the extension words it).
    rotation: f32,
    scale: Vec2,
}

impl UvTransform {
    /// The extension's fields, `None` for the identity; `what` names them in the error for a
    /// value that is not finite.
    fn new(offset: [f32; 2], rotation: f32, scale: [f32; 2], what: &str) -> Result<Option<UvTransform>, String> {
        if !offset.iter().chain(&scale).all(|x| x.is_finite()) || !rotation.is_finite() {
            return Err(format!("{what}: KHR_texture_transform has a value that is not a finite number"));
        }
        let transform = UvTransform { offset: Vec2::from_array(offset), rotation, scale: Vec2::from_array(scale) };
        Ok((transform != UvTransform { offset: Vec2::ZERO, rotation: 0.0, scale: Vec2::ONE }).then_some(transform))
    }

    /// The extension's matrix, translation · rotation · scale, with its rotation
    /// `[cos sin; −sin cos]` (rows).
    fn matrix(&self) -> glam::Affine2 {
        let (sin, cos) = self.rotation.sin_cos();
        glam::Affine2::from_cols(Vec2::new(cos, -sin) * self.scale.x, Vec2::new(sin, cos) * self.scale.y, self.offset)
    }

    /// Carries `mesh`'s texture coordinates through the transform, and its tangents (the file's,
    /// if it has them) with them. A tangent is `∂p/∂u`; with `uv' = A·uv + offset`,
    /// `∂p/∂u' = ∂p/∂u · (A⁻¹)₀₀ + ∂p/∂v · (A⁻¹)₁₀`, where `∂p/∂v` is glTF's bitangent
    /// `w·(n × t)`; a mirroring transform (det A < 0) flips the handedness `w`. The lengths of
    /// `∂p/∂u` and `∂p/∂v` are not in the file (its vectors are unit), so a non-uniform scale
    /// turns the tangent as if they were equal.
    fn bake(&self, mesh: &mut Mesh) -> Result<(), String> {
        let matrix = self.matrix();
        for uv in &mut mesh.uvs {
            *uv = matrix.transform_point2(*uv);
        }
        if let Some(vertex) = mesh.uvs.iter().position(|uv| !uv.is_finite()) {
            return Err(format!(
                "mesh `{}`: vertex {vertex}'s texture coordinates overflow under KHR_texture_transform",
                mesh.name
            ));
        }
        let a = matrix.matrix2;
        let determinant = a.determinant();
        if determinant == 0.0 || !determinant.is_finite() {
            return Err(format!("mesh `{}`: its KHR_texture_transform collapses the texture (scale 0)", mesh.name));
        }
        let inverse = a.inverse();
        for (tangent, &normal) in mesh.tangents.iter_mut().zip(&mesh.normals) {
            let (t, w) = (tangent.truncate(), tangent.w);
            let bitangent = normal.cross(t) * w;
            let turned = t * inverse.x_axis.x + bitangent * inverse.x_axis.y;
            let handedness = if determinant < 0.0 { -w } else { w };
            *tangent = turned.try_normalize().unwrap_or(t).extend(handedness);
        }
        Ok(())
    }
}

fn node_label(node: &gltf::Node<'_>) -> String {
    node.name().map_or_else(|| format!("node {}", node.index()), str::to_owned)
}

fn local_transform(node: &gltf::Node<'_>, label: &str) -> Result<Mat4, String> {
    match node.transform() {
        Transform::Matrix { matrix } => Ok(Mat4::from_cols_array_2d(&matrix)),
        Transform::Decomposed { translation, rotation, scale } => {
            // glTF stores unit quaternions, but files round them; normalizing keeps the rotation
            // from scaling or skewing.
            let rotation = Vec4::from_array(rotation).try_normalize().ok_or_else(|| {
                format!("node `{label}`: its rotation {rotation:?} is not a usable quaternion (zero or not finite)")
            })?;
            Ok(Mat4::from_scale_rotation_translation(
                Vec3::from_array(scale),
                glam::Quat::from_vec4(rotation),
                Vec3::from_array(translation),
            ))
        }
    }
}

/// One component at the start of `bytes`, which the caller guarantees holds at least one.
fn component(bytes: &[u8], kind: DataType, normalized: bool) -> f32 {
    let (value, scale) = match kind {
        DataType::F32 => return f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
        DataType::I8 => (f32::from(bytes[0] as i8), 127.0),
        DataType::U8 => (f32::from(bytes[0]), 255.0),
        DataType::I16 => (f32::from(i16::from_le_bytes([bytes[0], bytes[1]])), 32767.0),
        DataType::U16 => (f32::from(u16::from_le_bytes([bytes[0], bytes[1]])), 65535.0),
        DataType::U32 => (u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32, u32::MAX as f32),
    };
    // Signed normalized integers have one value more below zero than above; glTF clamps it to −1.
    if normalized { (value / scale).max(-1.0) } else { value }
}

/// glTF §3.7.2.1: strip triangle i is (v_i, v_{i+1+i%2}, v_{i+2−i%2}), which keeps every
/// triangle's winding the same as the first one's.
fn strip_to_list(vertices: &[u32]) -> Vec<u32> {
    (0..vertices.len().saturating_sub(2))
        .flat_map(|i| [vertices[i], vertices[i + 1 + i % 2], vertices[i + 2 - i % 2]])
        .collect()
}

/// glTF §3.7.2.1: fan triangle i is (v_{i+1}, v_{i+2}, v_0).
fn fan_to_list(vertices: &[u32]) -> Vec<u32> {
    (0..vertices.len().saturating_sub(2)).flat_map(|i| [vertices[i + 1], vertices[i + 2], vertices[0]]).collect()
}

/// A material's name for messages: its own, or `material N`.
fn material_name(material: &gltf::Material<'_>) -> String {
    material.name().map_or_else(|| format!("material {}", material.index().unwrap_or(0)), str::to_owned)
}

/// `KHR_materials_clearcoat`'s `clearcoatFactor` and `clearcoatRoughnessFactor` (both 0 when
/// absent), clamped to [0, 1]. The `gltf` crate does not parse this extension; its JSON is read
/// here.
fn clearcoat_of(value: &gltf::json::Value, name: &str) -> Result<(f32, f32), String> {
    let number = |key: &str| match value.get(key) {
        None => Ok(0.0),
        Some(v) => {
            v.as_f64().map(|x| x as f32).filter(|x| x.is_finite()).map(|x| x.clamp(0.0, 1.0)).ok_or_else(|| {
                format!("material `{name}`: KHR_materials_clearcoat's `{key}` is {v}, not a finite number")
            })
        }
    };
    Ok((number("clearcoatFactor")?, number("clearcoatRoughnessFactor")?))
}

/// The Phong-style terms of the module documentation's material rule.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PhongTerms {
    kd: f32,
    ks: f32,
    specular_color: Vec3,
    shininess: f32,
    mirror: f32,
    mirror_color: Vec3,
}

/// glTF's reflectance of a dielectric at normal incidence: `((ior − 1)/(ior + 1))²` (0.04 for
/// the default 1.5), and with `KHR_materials_specular`'s (factor, colour)
/// `min(F0 · specularColorFactor, 1) · specularFactor`, per channel.
fn dielectric_f0(ior: f32, specular: Option<(f32, Vec3)>) -> Vec3 {
    let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
    match specular {
        Some((factor, color)) => (Vec3::splat(f0) * color.max(Vec3::ZERO)).min(Vec3::ONE) * factor.clamp(0.0, 1.0),
        None => Vec3::splat(f0),
    }
}

/// The Phong exponent whose lobe matches a GGX lobe of `roughness` (α = roughness²).
fn shininess_of(roughness: f32) -> f32 {
    let alpha = roughness * roughness;
    // Roughness 0 divides by zero; the infinite exponent clamps to the sharpest lobe.
    (2.0 / (alpha * alpha) - 2.0).clamp(1.0, MAX_SHININESS)
}

/// `metallic` and `roughness` in [0, 1]; `base` is `baseColorFactor.rgb`; `f0` the dielectric
/// reflectance ([`dielectric_f0`]), whose largest channel is the dielectric's specular weight
/// and whose hue is its specular colour.
fn phong_from_metallic_roughness(base: Vec3, metallic: f32, roughness: f32, f0: Vec3) -> PhongTerms {
    let strength = f0.max_element();
    let hue = if strength > 0.0 { f0 / strength } else { Vec3::ONE };
    let specular_color = hue.lerp(base, metallic);
    PhongTerms {
        kd: 1.0 - metallic,
        ks: (strength * (1.0 - metallic) + metallic) * (1.0 - roughness),
        specular_color,
        shininess: shininess_of(roughness),
        mirror: metallic * (1.0 - roughness) * (1.0 - roughness),
        mirror_color: specular_color,
    }
}

/// `KHR_materials_clearcoat` (factor `c`, roughness `rc`) as a white dielectric layer of
/// reflectance `F = 0.04·c` over the base: the base's diffuse, specular and mirror weights keep
/// `1 − F`, the layer adds `F·(1 − rc)` to the specular weight and `F·(1 − rc)²` to the mirror
/// weight, the colours become the weights' mix of the base's and white, and the one specular lobe
/// takes the exponent of whichever of the two weighs more.
fn with_clearcoat(base: PhongTerms, factor: f32, roughness: f32) -> PhongTerms {
    let reflectance = CLEARCOAT_F0 * factor;
    let below = 1.0 - reflectance;
    let (coat_ks, coat_mirror) = (reflectance * (1.0 - roughness), reflectance * (1.0 - roughness).powi(2));
    let (base_ks, base_mirror) = (base.ks * below, base.mirror * below);
    let mix = |base_weight: f32, base_color: Vec3, coat_weight: f32| {
        let sum = base_weight + coat_weight;
        if sum > 0.0 { (base_color * base_weight + Vec3::ONE * coat_weight) / sum } else { base_color }
    };
    PhongTerms {
        kd: base.kd * below,
        ks: base_ks + coat_ks,
        specular_color: mix(base_ks, base.specular_color, coat_ks),
        shininess: if coat_ks > base_ks { shininess_of(roughness) } else { base.shininess },
        mirror: base_mirror + coat_mirror,
        mirror_color: mix(base_mirror, base.mirror_color, coat_mirror),
    }
}

/// glTF's wrapping mode as Mirador's.
fn wrap_of(mode: gltf::texture::WrappingMode) -> Wrap {
    match mode {
        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
        gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn material_rule_at_its_extremes() {
        let gold = Vec3::new(1.0, 0.8, 0.3);
        let f0 = dielectric_f0(1.5, None);
        assert!((f0 - Vec3::splat(0.04)).abs().max_element() < 1e-7, "ior 1.5 reflects 4 %: {f0}");
        let smooth_metal = phong_from_metallic_roughness(gold, 1.0, 0.0, f0);
        assert_eq!(smooth_metal.kd, 0.0);
        assert_eq!(smooth_metal.ks, 1.0);
        assert_eq!(smooth_metal.specular_color, gold);
        assert_eq!(smooth_metal.shininess, MAX_SHININESS);
        assert_eq!(smooth_metal.mirror, 1.0);
        let rough_plastic = phong_from_metallic_roughness(gold, 0.0, 1.0, f0);
        assert_eq!(rough_plastic.kd, 1.0);
        assert_eq!(rough_plastic.ks, 0.0);
        assert_eq!(rough_plastic.specular_color, Vec3::ONE);
        assert_eq!(rough_plastic.shininess, 1.0);
        assert_eq!(rough_plastic.mirror, 0.0);
        // α = 0.25, e = 2/0.0625 − 2.
        assert!((phong_from_metallic_roughness(gold, 0.0, 0.5, f0).shininess - 30.0).abs() < 1e-4);
    }

    #[test]
    fn base64_decodes_padded_unpadded_and_rejects_junk() {
        assert_eq!(decode_base64("TWFu").unwrap(), b"Man");
        assert_eq!(decode_base64("TWE=").unwrap(), b"Ma");
        assert_eq!(decode_base64("TQ==").unwrap(), b"M");
        assert_eq!(decode_base64("TWE").unwrap(), b"Ma");
        assert_eq!(decode_base64("").unwrap(), b"");
        assert!(decode_base64("TW*u").is_err());
        assert!(decode_base64("TQ==TQ==").is_err());
    }

    #[test]
    fn uris_percent_decode_and_schemes_are_told_from_drives() {
        assert_eq!(percent_decode("my%20model.bin").as_deref(), Some("my model.bin"));
        assert_eq!(percent_decode("bad%2"), None);
        assert_eq!(percent_decode("bad%zz"), None);
        assert_eq!(percent_decode("%FF"), None);
        assert!(has_scheme("https://example.com/a.bin"));
        assert!(!has_scheme("C:/models/a.bin"));
        assert!(!has_scheme("textures/a.png"));
    }

    #[test]
    fn strips_and_fans_unroll_with_consistent_winding() {
        assert_eq!(strip_to_list(&[0, 1, 2, 3]), vec![0, 1, 2, 1, 3, 2]);
        assert_eq!(fan_to_list(&[0, 1, 2, 3]), vec![1, 2, 0, 2, 3, 0]);
        assert!(strip_to_list(&[0, 1]).is_empty());
    }

    #[test]
    fn normalized_components_map_to_unit_range() {
        assert_eq!(component(&[255], DataType::U8, true), 1.0);
        assert_eq!(component(&[0x80], DataType::I8, true), -1.0);
        assert_eq!(component(&[7], DataType::U8, false), 7.0);
        assert_eq!(component(&1.5f32.to_le_bytes(), DataType::F32, false), 1.5);
    }
}
