//! PLY import: Greg Turk's polygon file format, in which the Stanford 3D Scanning Repository
//! publishes its scans (the bunny, the dragon, Lucy), read in all three encodings (ASCII, binary
//! little-endian and binary big-endian) into one mesh in the default material. It fills the same
//! [`ModelImport`] as a glTF file, with one object and no lights or cameras; the scene loader
//! places it.
//!
//! Parsing is the `ply-rs-bw` crate's, the maintained continuation of `ply-rs`. A header may lie,
//! so before any element is read its counts are checked against the bytes that follow it: every
//! element takes at least its scalars and one count per list in binary, at least a character per
//! property in ASCII, and a file too short for its counts is refused by the header alone. The
//! parser never reserves more than 65 536 elements up front either, so memory grows with what is
//! actually read. A binary element without properties takes no bytes and is not read at all: the
//! parser's loop over its count would read nothing, as long as the count says (a count of 10¹⁵
//! kept `mirador render` busy for good before this check; found by fuzzing, `fuzz/`).
//!
//! # What is read
//!
//! - Element `vertex`: `x`, `y`, `z` (any scalar type, converted to 32-bit floats); `nx`, `ny`,
//!   `nz` when all three are there (normals are computed, area-weighted as for glTF, when they are
//!   not, or when one is zero); texture coordinates from `u`, `v` (or `s`, `t`, `texture_u`,
//!   `texture_v`, `texture_s`, `texture_t`), turned to `(u, 1 − v)`: PLY files written with
//!   texture coordinates follow OBJ's convention of `v = 0` at the bottom of the image.
//! - Element `face`: the list `vertex_indices` (or `vertex_index`, which some scanners write) of
//!   any integer type. Polygons are triangulated as fans (`v0, vi, vi+1`); faces with fewer than
//!   three vertices are skipped with a warning; zero-area triangles are removed with a warning.
//! - The mesh is one object named `mesh` in [`Material::default()`], named `ply-default` (PLY has
//!   no materials). In a scene file, an object's `material` field replaces it.
//!
//! Ignored, with a warning: vertex colours (`red`, `green`, `blue`, `alpha`) and every other
//! vertex or face property; other elements (`edge`, `material`, range-grid data) are read past.
//!
//! # Errors
//!
//! Bad input gives [`SceneError::Ply`] naming the file and the problem ([`SceneError::Io`] when the
//! file cannot be read); it never panics: an empty file, a header the parser rejects, a file that
//! ends before the counts its header declares or is too short to hold them, a file without `vertex`
//! or `face` elements (a point cloud, which Mirador cannot draw), `x`, `y` or `z` missing, face
//! indices that are not integers, a coordinate that is not finite (with its vertex number), and a
//! face index below 0 or past the last vertex (with its face number).

use std::io::Cursor;
use std::path::Path;

use glam::{Mat4, Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use super::gltf::GltfObject;
use super::{Material, Mesh, ModelImport, SceneError};

/// The name of the material a PLY mesh is drawn in.
pub const DEFAULT_MATERIAL: &str = "ply-default";

/// The property pairs read as texture coordinates, in order of preference.
const UV_NAMES: [(&str, &str); 4] = [("u", "v"), ("s", "t"), ("texture_u", "texture_v"), ("texture_s", "texture_t")];

/// The names of a face's vertex index list.
const INDEX_NAMES: [&str; 2] = ["vertex_indices", "vertex_index"];

/// Loads a `.ply` file; see the module documentation.
pub fn import(path: &Path) -> Result<ModelImport, SceneError> {
    if path.as_os_str().is_empty() {
        return Err(SceneError::Ply { path: path.to_path_buf(), message: "no file given (the path is empty)".into() });
    }
    let bytes = super::read_file(path).map_err(|cause| SceneError::Io { path: path.to_path_buf(), cause })?;
    import_bytes(path, &bytes)
}

/// Reads a PLY file already in memory; `path` names it in messages and names its mesh.
pub fn import_bytes(path: &Path, bytes: &[u8]) -> Result<ModelImport, SceneError> {
    let error = |message: String| SceneError::Ply { path: path.to_path_buf(), message };
    if bytes.is_empty() {
        return Err(error("the file is empty".into()));
    }
    super::without_panics(|| read(path, bytes)).map_err(error)
}

/// One vertex as the file gives it; what the file lacks stays zero.
#[derive(Clone, Copy, Debug, Default)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let Some(x) = property.to_f32_lossy() else { return PropertyAccessResult::Ignored };
        let slot = match name {
            "x" => &mut self.position[0],
            "y" => &mut self.position[1],
            "z" => &mut self.position[2],
            "nx" => &mut self.normal[0],
            "ny" => &mut self.normal[1],
            "nz" => &mut self.normal[2],
            "u" | "s" | "texture_u" | "texture_s" => &mut self.uv[0],
            "v" | "t" | "texture_v" | "texture_t" => &mut self.uv[1],
            _ => return PropertyAccessResult::Ignored,
        };
        *slot = x;
        PropertyAccessResult::Set
    }
}

/// One face's vertex indices, widened so that negative and 32-bit unsigned values both fit.
#[derive(Clone, Debug, Default)]
struct Face {
    indices: Vec<i64>,
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Face::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if !INDEX_NAMES.contains(&name) {
            return PropertyAccessResult::Ignored;
        }
        self.indices = match property {
            Property::ListChar(list) => list.into_iter().map(i64::from).collect(),
            Property::ListUChar(list) => list.into_iter().map(i64::from).collect(),
            Property::ListShort(list) => list.into_iter().map(i64::from).collect(),
            Property::ListUShort(list) => list.into_iter().map(i64::from).collect(),
            Property::ListInt(list) => list.into_iter().map(i64::from).collect(),
            Property::ListUInt(list) => list.into_iter().map(i64::from).collect(),
            _ => return PropertyAccessResult::UnsupportedType,
        };
        PropertyAccessResult::Set
    }
}

/// An element that is read past and dropped.
#[derive(Clone, Copy, Debug)]
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }
}

fn read(path: &Path, bytes: &[u8]) -> Result<ModelImport, String> {
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = Parser::<Skipped>::new().read_header(&mut reader).map_err(|e| format!("header: {e}"))?;
    let layout = Layout::of(&header)?;
    let payload = bytes.len() as u64 - reader.get_ref().position();
    check_counts(&header, payload)?;
    let mut out = ModelImport::default();
    let mut warn = |message: String| {
        let message = format!("{}: PLY: {message}", path.display());
        log::warn!("{message}");
        out.warnings.push(message);
    };
    if !layout.ignored.is_empty() {
        warn(format!("ignoring propert(ies) {}", layout.ignored.join(", ")));
    }
    if layout.partial_normals {
        warn("the vertices have some but not all of nx, ny, nz; normals are computed".into());
    }
    let (vertices, faces) = read_elements(&mut reader, &header)?;
    let count = vertex_count(&vertices)?;
    let (indices, short_faces) = fans(&faces, count)?;
    if short_faces > 0 {
        warn(format!("skipped {short_faces} face(s) with fewer than three vertices"));
    }
    let name = path.file_stem().map_or_else(|| "mesh".to_string(), |s| s.to_string_lossy().into_owned());
    let mesh = mesh_of(name, &vertices, (indices, faces.len()), &layout, &mut warn)?;
    out.meshes.push(mesh);
    out.materials.push(Material { name: DEFAULT_MATERIAL.into(), ..Material::default() });
    out.objects.push(GltfObject { name: "mesh".into(), mesh: 0, material: 0, world_from_local: Mat4::IDENTITY });
    Ok(out)
}

/// The payload, element by element in the header's order: the vertices and faces, other elements
/// read past.
fn read_elements(reader: &mut Reader<Cursor<&[u8]>>, header: &Header) -> Result<(Vec<Vertex>, Vec<Face>), String> {
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for (name, element) in &header.elements {
        let failed = |e: ply_rs_bw::parser::ParseError| describe_payload_error(element, e);
        if element.properties.is_empty() && header.encoding != Encoding::Ascii {
            // Nothing to read, however many there are; the parser would loop over the count.
            continue;
        }
        match name.as_str() {
            "vertex" => vertices = read_element::<Vertex>(reader, element, header).map_err(failed)?,
            "face" => faces = read_element::<Face>(reader, element, header).map_err(failed)?,
            _ => {
                read_element::<Skipped>(reader, element, header).map_err(failed)?;
            }
        }
    }
    Ok((vertices, faces))
}

/// How many vertices there are, once they are known to fit 32-bit indices and to have finite
/// coordinates.
fn vertex_count(vertices: &[Vertex]) -> Result<u32, String> {
    let count = u32::try_from(vertices.len())
        .map_err(|_| format!("{} vertices are more than 32-bit indices reach", vertices.len()))?;
    if let Some((i, v)) = vertices.iter().enumerate().find(|(_, v)| !Vec3::from_array(v.position).is_finite()) {
        return Err(format!(
            "vertex {i} has a coordinate that is not finite ({:?}; NaN, infinity, or a double beyond ±3.4e38, which \
             overflows 32-bit floats)",
            v.position
        ));
    }
    Ok(count)
}

/// The faces triangulated as fans `v0, vi, vi+1`, once every index is known to name one of the
/// `count` vertices; and how many faces had fewer than three vertices (skipped).
fn fans(faces: &[Face], count: u32) -> Result<(Vec<u32>, usize), String> {
    let mut indices = Vec::with_capacity(3 * faces.len());
    let mut short_faces = 0;
    for (f, face) in faces.iter().enumerate() {
        if let Some(&bad) = face.indices.iter().find(|&&i| i < 0 || i >= i64::from(count)) {
            return Err(format!(
                "face {f} refers to vertex {bad}, and the file has {count} vertices (numbered 0 to {})",
                i64::from(count) - 1
            ));
        }
        if face.indices.len() < 3 {
            short_faces += 1;
            continue;
        }
        let v0 = face.indices[0] as u32;
        for pair in face.indices[1..].windows(2) {
            indices.extend_from_slice(&[v0, pair[0] as u32, pair[1] as u32]);
        }
    }
    Ok((indices, short_faces))
}

/// The mesh of `vertices` and the triangles `indices` (made from `faces` faces), degenerate
/// triangles removed, with the file's normals where they are all usable and computed ones
/// otherwise; an error when no triangle is left.
fn mesh_of(
    name: String,
    vertices: &[Vertex],
    (indices, faces): (Vec<u32>, usize),
    layout: &Layout,
    warn: &mut impl FnMut(String),
) -> Result<Mesh, String> {
    let mut mesh = Mesh {
        name,
        positions: vertices.iter().map(|v| Vec3::from_array(v.position)).collect(),
        // A placeholder until the indices are known to be in range, which computing normals
        // relies on.
        normals: vec![Vec3::Y; vertices.len()],
        uvs: if layout.uvs {
            vertices.iter().map(|v| Vec2::new(v.uv[0], 1.0 - v.uv[1])).collect()
        } else {
            vec![Vec2::ZERO; vertices.len()]
        },
        tangents: Vec::new(),
        indices,
    };
    let removed = mesh.validate_and_repair().map_err(|e| e.to_string())?;
    if removed > 0 {
        warn(format!("removed {removed} zero-area (degenerate) triangle(s)"));
    }
    if mesh.indices.is_empty() {
        return Err(format!("no triangles to draw ({faces} faces, none with three vertices and an area)"));
    }
    let given: Option<Vec<Vec3>> =
        layout.normals.then(|| vertices.iter().map(|v| Vec3::from_array(v.normal).try_normalize()).collect()).flatten();
    match given {
        Some(normals) => mesh.normals = normals,
        None => {
            if layout.normals {
                warn("a vertex normal is zero or not finite; normals are computed for all vertices".into());
            }
            mesh.compute_normals();
        }
    }
    Ok(mesh)
}

fn read_element<E: PropertyAccess>(
    reader: &mut Reader<Cursor<&[u8]>>,
    element: &ElementDef,
    header: &Header,
) -> Result<Vec<E>, ply_rs_bw::parser::ParseError> {
    Parser::<E>::new().read_payload_for_element(reader, element, header)
}

/// The fewest bytes one element can take in the file: in binary, its scalars plus each list's
/// count (a list may be empty); in ASCII, one character per property, or one line break for an
/// element without properties. Binary elements without properties take none.
fn smallest_element(element: &ElementDef, encoding: Encoding) -> u64 {
    if encoding == Encoding::Ascii {
        return (element.properties.len() as u64).max(1);
    }
    element
        .properties
        .values()
        .map(|p| match &p.data_type {
            PropertyType::Scalar(scalar) | PropertyType::List(scalar, _) => scalar_size(scalar),
        })
        .sum()
}

fn scalar_size(scalar: &ScalarType) -> u64 {
    match scalar {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Refuses a header whose counts the file cannot hold, before any element is read: each
/// declared element needs at least [`smallest_element`] bytes of the `payload` bytes that follow
/// the header. This bounds both the reading loops and what they allocate by the file's size.
fn check_counts(header: &Header, payload: u64) -> Result<(), String> {
    let mut needed: u64 = 0;
    for element in header.elements.values() {
        let smallest = smallest_element(element, header.encoding);
        let total = (element.count as u64).saturating_mul(smallest);
        needed = needed.saturating_add(total);
        if needed > payload {
            return Err(format!(
                "the header declares {} `{}` element(s) of at least {smallest} byte(s) each, and the {payload} bytes \
                 after the header cannot hold them (truncated, or the header lies)",
                element.count, element.name
            ));
        }
    }
    Ok(())
}

fn describe_payload_error(element: &ElementDef, error: ply_rs_bw::parser::ParseError) -> String {
    let ends_early = error.kind() == std::io::ErrorKind::UnexpectedEof;
    let why = if ends_early { "the file ends before the header's count; truncated, or the header lies: " } else { "" };
    format!("element `{}` ({} declared): {why}{error}", element.name, element.count)
}

/// What the header says the vertices and faces carry, checked before any payload is read.
struct Layout {
    normals: bool,
    partial_normals: bool,
    uvs: bool,
    /// Properties that are not read, as `element.property`.
    ignored: Vec<String>,
}

impl Layout {
    fn of(header: &Header) -> Result<Layout, String> {
        let vertex = header.elements.get("vertex").ok_or("the header declares no `vertex` element")?;
        let face = header
            .elements
            .get("face")
            .ok_or("the header declares no `face` element (a point cloud, which Mirador cannot draw)")?;
        let scalar = |name: &str| matches!(vertex.properties.get(name), Some(p) if matches!(p.data_type, PropertyType::Scalar(_)));
        if let Some(missing) = ["x", "y", "z"].into_iter().find(|&c| !scalar(c)) {
            return Err(format!("the `vertex` element has no scalar property `{missing}`"));
        }
        let normal_count = ["nx", "ny", "nz"].into_iter().filter(|&c| scalar(c)).count();
        let uv = UV_NAMES.into_iter().find(|(u, v)| scalar(u) && scalar(v));
        let index_list = INDEX_NAMES
            .into_iter()
            .find_map(|name| face.properties.get(name))
            .ok_or_else(|| format!("the `face` element has no `{}` (or `{}`) list", INDEX_NAMES[0], INDEX_NAMES[1]))?;
        match index_list.data_type {
            PropertyType::List(_, ScalarType::Float | ScalarType::Double) => {
                return Err(format!("the face list `{}` holds floating-point numbers, not indices", index_list.name));
            }
            PropertyType::Scalar(_) => return Err(format!("the face property `{}` is not a list", index_list.name)),
            PropertyType::List(..) => {}
        }
        let mut read: Vec<&str> = vec!["x", "y", "z"];
        if normal_count == 3 {
            read.extend(["nx", "ny", "nz"]);
        }
        if let Some((u, v)) = uv {
            read.extend([u, v]);
        }
        let mut ignored: Vec<String> =
            vertex.properties.keys().filter(|p| !read.contains(&p.as_str())).map(|p| format!("vertex.{p}")).collect();
        ignored.extend(face.properties.keys().filter(|&p| *p != index_list.name).map(|p| format!("face.{p}")));
        Ok(Layout {
            normals: normal_count == 3,
            partial_normals: matches!(normal_count, 1 | 2),
            uvs: uv.is_some(),
            ignored,
        })
    }
}
