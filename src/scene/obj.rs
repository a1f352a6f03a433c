//! Wavefront OBJ import, with the MTL material libraries the file names: the format most course
//! models (the Utah teapot, the Cornell box, the models of every graphics textbook) still come in.
//! Parsing is the `tobj` crate's; this module checks what `tobj` does not, maps MTL's materials
//! onto Mirador's illumination model, and fills the same [`ModelImport`] as a glTF file, with no
//! lights and no cameras (OBJ has neither). The scene loader places it.
//!
//! # What is read
//!
//! Every group or object (`g`, `o`), split again wherever `usemtl` changes the material, becomes
//! one [`Mesh`] and one object named `<group>/<k>` (`k` counting from 0 within the group; a file
//! without groups is `unnamed_object`). Faces are triangulated as fans (`v0, vi, vi+1`), so convex
//! polygons come out right; points (`p`) and lines (`l`) are skipped with a warning. Each distinct
//! `v/vt/vn` triple becomes one vertex. Texture coordinates are turned to Mirador's convention,
//! `(u, 1 − v)`: OBJ puts `v = 0` at the bottom of the image, Mirador (as glTF) at the top. A mesh
//! in which any vertex lacks a normal (or has a zero one) gets normals computed for all of its
//! vertices, area-weighted, as glTF import does; one in which any vertex lacks texture
//! coordinates gets zeros. Zero-area triangles are removed with a warning.
//!
//! # Materials: MTL onto Mirador's model
//!
//! MTL's colours are read as linear RGB, as glTF's factors are. With `illum` the illumination
//! model the material names (2 when it names none), `Ks` black when absent and `Tf` white:
//!
//! | Mirador              | from MTL                                                         |
//! |----------------------|------------------------------------------------------------------|
//! | `color` (C)          | `Kd` × `map_Kd` (an sRGB texture); without `Kd`: white under a `map_Kd`, else the default grey 0.8 |
//! | `kd`                 | 1                                                                |
//! | `ka`                 | 0 (`Ka` is not read; see below)                                  |
//! | `ks`                 | 1 for `illum` ≥ 2 when `Ks` is not black, else 0                 |
//! | `specular_color` (S) | `Ks` (white when absent)                                         |
//! | `shininess` (e)      | `Ns` (negative read as 0), else 32                               |
//! | `emission`           | `Ke`                                                             |
//! | `mirror` (kps)       | 1 for `illum` 3–9 when `Ks` is not black, else 0                 |
//! | `mirror_color`       | `Ks`                                                             |
//! | `transmission` (kt)  | 1 for `illum` 4, 6, 7 and 9, else 0                              |
//! | `transmission_color` | (1 − `Ks`) ⊗ `Tf`, each component at least 0                     |
//! | `ior`                | `Ni`; else 1.5 on a transmitting material (as glTF), 1.0 on others |
//! | `alpha`              | `d`, else 1 − `Tr`, else 1 (clamped to [0, 1])                   |
//! | `alpha_mode`         | BLEND when `alpha` < 1, else OPAQUE                              |
//! | `height_map`         | `bump` or `map_bump` (a linear, grey-level height map)           |
//! | `bump_scale` (k)     | the bump statement's `-bm` multiplier, else 1                    |
//! | `normal_map`         | `norm` (a tangent-space normal map, the PBR extension's)         |
//! | `wrap`               | repeat; clamp when `map_Kd` (else the bump map) says `-clamp on` |
//!
//! This is MTL's own formula read term by term. Its illumination models 3 to 9 add `Ks·Ir`, the
//! ray-traced reflection weighted by the specular colour, which is Mirador's `kps·MPS·L(r)` with
//! kps = 1 and MPS = `Ks`; models 6 and 7 add `(1 − Ks)·Tf·It`, the refracted light, which is
//! `kt·MT·L(t)` with kt = 1 and MT = `(1 − Ks)·Tf`. Models 4 and 9 (MTL's "glass", transparency
//! that keeps its highlights) are read as 6, refracting by `Ni`. Fresnel (models 5 and 7) is not
//! modelled: the weights are constant. Models 0 and 1 have no highlight; model 0 (colour without
//! lighting) is drawn as 1. Model 10 (shadow matte) is drawn as 2.
//!
//! **Why `ka` = 0.** MTL's `Ka` is the reflectance of a *global* ambient light; Mirador reflects its
//! global ambient `A` by the diffuse colour (`AG = A ⊗ kd·C`, see `shading.rs`), and its `ka` is a
//! different term, the per-light ambient of the course notes (`ka·C` for every visible light).
//! Reading `Ka` into it would add light MTL does not have, and would flatten every model Blender
//! exports (it writes `Ka 1 1 1`).
//!
//! Texture statements may carry options before the file name. `-bm` (on `bump` and `map_bump`)
//! and `-clamp` are read; the others (`-o`, `-s`, `-t`, `-mm`, `-blendu`, …) are skipped with a
//! warning. File names are relative to the MTL file; backslashes are read as `/`, since files
//! written on Windows use them.
//!
//! # What is ignored, with a warning
//!
//! `map_Ka`, `map_Ks`, `map_Ns`, `map_d`, `refl`, `disp`, `decal` and every other statement that
//! is not in the table (the PBR extension's `Pr`, `Pm`, …); vertex colours; free-form curves and
//! surfaces. A `usemtl` naming a material no library defines gets the default material, as do
//! faces before any `usemtl`. A file without `mtllib` draws everything in [`Material::default()`],
//! named `obj-default`.
//!
//! # Errors
//!
//! Bad input gives [`SceneError::Obj`] naming the file and the problem, with the line where there
//! is one ([`SceneError::Io`] when the OBJ file itself cannot be read); it never panics. A number
//! that is not finite in a `v`, `vn` or `vt` statement is refused before parsing, with its line, and
//! so is a face index that no statement backs (0, a relative index before the first statement, or
//! one past the last): `tobj` computes offsets from the indices unchecked, and an index near 2⁶³
//! overflowed inside it (found by fuzzing, `fuzz/`).
//! An `mtllib` file that is not there and a texture file that is not there are warnings (the
//! materials drawn in the default material, the material without the texture), as Blender and
//! three.js draw them: the warning names the file, and the model still shows. So is a `newmtl`
//! without a name (it is called `unnamed-LINE`, and the library's other materials load). A
//! malformed MTL
//! statement, and a texture that is there but cannot be decoded, are errors: that file is
//! broken, and saying so names it. A UTF-16 file is named as such. A face referring to a vertex the file does not
//! have, and a file without a face to draw, are errors too.

use std::cell::RefCell;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3};

use super::gltf::GltfObject;
use super::material::{AlphaMode, ColorSpace, Wrap};
use super::{Material, Mesh, ModelImport, SceneError, texture};
use crate::base::TextureId;

/// The name of the material faces get without a `usemtl` (or with one naming nothing defined).
pub const DEFAULT_MATERIAL: &str = "obj-default";

/// Loads an `.obj` file and the MTL libraries it names; see the module documentation.
pub fn import(path: &Path) -> Result<ModelImport, SceneError> {
    if path.as_os_str().is_empty() {
        return Err(SceneError::Obj { path: path.to_path_buf(), message: "no file given (the path is empty)".into() });
    }
    let bytes = super::read_file(path).map_err(|cause| SceneError::Io { path: path.to_path_buf(), cause })?;
    import_bytes(path, &bytes)
}

/// Reads an OBJ file already in memory; `path` names it in messages, and the MTL libraries it
/// names are read relative to its folder.
pub fn import_bytes(path: &Path, bytes: &[u8]) -> Result<ModelImport, SceneError> {
    let error = |message: String| SceneError::Obj { path: path.to_path_buf(), message };
    if bytes.is_empty() {
        return Err(error("the file is empty".into()));
    }
    // A text editor's "Unicode" is UTF-16, which no OBJ reader reads: say so, rather than "no faces".
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(error("the file is UTF-16 text; OBJ is ASCII (save it as UTF-8 or ASCII)".into()));
    }
    // OBJ is ASCII; old exporters write names and comments in Latin-1, which must not stop it.
    let text = String::from_utf8_lossy(bytes);
    super::without_panics(|| import_text(path, &text)).map_err(error)
}

fn import_text(path: &Path, text: &str) -> Result<ModelImport, String> {
    let scan = scan(text)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let libraries = RefCell::new(Vec::new());
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let mut cursor = Cursor::new(text.as_bytes());
    let loaded = tobj::load_obj_buf(&mut cursor, &options, |name| read_library(&dir, name, &libraries));
    let libraries = libraries.into_inner();
    if let Some(problem) = libraries.iter().find_map(|l| l.problem.as_ref()) {
        return Err(problem.clone());
    }
    let (models, materials) = loaded.map_err(|e| describe_obj_error(e, text, cursor.position()))?;
    // Every library that failed was reported above, so this holds whatever the libraries define.
    let materials = materials.unwrap_or_default();
    let mut reader = Reader {
        path,
        materials: &materials,
        libraries: &libraries,
        out: ModelImport::default(),
        converted: HashMap::new(),
        textures: HashMap::new(),
    };
    for warning in libraries.iter().flat_map(|l| &l.warnings) {
        reader.warn(warning.clone());
    }
    let known: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
    for (line, name) in &scan.usemtl {
        if !known.contains(&name.as_str()) {
            reader.warn(format!(
                "line {line}: `usemtl {name}` names no material the libraries define; drawn in the default material"
            ));
        }
    }
    if scan.skipped > 0 {
        reader.warn(format!("skipped {} point and line statement(s); only faces are drawn", scan.skipped));
    }
    let mut per_group: HashMap<String, usize> = HashMap::new();
    for model in &models {
        let k = per_group.entry(model.name.clone()).or_insert(0);
        let name = format!("{}/{k}", model.name);
        *k += 1;
        let Some(mesh) = reader.mesh(&model.mesh, name.clone())? else { continue };
        let material = reader.material(model.mesh.material_id)?;
        reader.out.meshes.push(mesh);
        let mesh = reader.out.meshes.len() - 1;
        reader.out.objects.push(GltfObject { name, mesh, material, world_from_local: Mat4::IDENTITY });
    }
    if reader.out.objects.is_empty() {
        return Err("the file has no faces to draw (no `f` statement with three or more vertices and an area)".into());
    }
    Ok(reader.out)
}

/// What a first pass over the text finds: problems `tobj` would let through or report without a
/// line, and what to warn about.
struct Scan {
    /// `usemtl` statements: line and material name.
    usemtl: Vec<(usize, String)>,
    /// Points and lines (`p`, `l`, and `f` with fewer than three vertices), which are not drawn.
    skipped: usize,
}

fn scan(text: &str) -> Result<Scan, String> {
    let mut scan = Scan { usemtl: Vec::new(), skipped: 0 };
    // Statements of each kind `v`, `vt`, `vn` so far, and the largest index a face gives for
    // each, with its line.
    let mut counts = [0usize; 3];
    let mut largest: [Option<(usize, usize)>; 3] = [None; 3];
    for (index, line) in text.lines().enumerate() {
        let number = index + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some(keyword @ ("v" | "vn" | "vt")) => {
                if let Some(word) = words.find(|w| w.parse::<f32>().is_ok_and(|x| !x.is_finite())) {
                    return Err(format!(
                        "line {number}: `{keyword}` has a number that is not finite ({word}; NaN, infinity, or beyond \
                         ±3.4e38, which overflows 32-bit floats)"
                    ));
                }
                counts[match keyword {
                    "v" => 0,
                    "vt" => 1,
                    _ => 2,
                }] += 1;
            }
            Some(keyword @ ("f" | "l")) => {
                let vertices: Vec<&str> = words.collect();
                for vertex in &vertices {
                    check_face_vertex(vertex, number, &counts, &mut largest)
                        .map_err(|e| format!("line {number}: {e}"))?;
                }
                match (keyword, vertices.len()) {
                    ("f", 0) => return Err(format!("line {number}: a face (`f`) with no vertices")),
                    ("f", 1 | 2) | ("l", _) => scan.skipped += 1,
                    _ => {}
                }
            }
            Some("p") => scan.skipped += 1,
            Some("usemtl") => scan.usemtl.push((number, words.collect::<Vec<_>>().join(" "))),
            _ => {}
        }
    }
    for ((largest, count), (keyword, what)) in largest.iter().zip(counts).zip(INDEXED) {
        if let Some((index, line)) = *largest
            && index > count
        {
            return Err(format!(
                "line {line}: a face refers to {what} {index}, past the last `{keyword}` (the file has {count})"
            ));
        }
    }
    Ok(scan)
}

/// The statements a face vertex `v/vt/vn` indexes, in that order, and what they give.
const INDEXED: [(&str, &str); 3] = [("v", "vertex position"), ("vt", "texture coordinates"), ("vn", "normal")];

/// Checks one face vertex's indices before `tobj` sees them: `tobj` turns an index into an offset
/// (`2·vt + 1`) unchecked, which overflows for an index near 2⁶³ (a panic in a debug build, a
/// wrapped offset in a release one), and reads an index of 0 as "none". An index counts from 1,
/// a negative one back from the last statement so far; `counts` are the statements so far, and
/// `largest` keeps the largest positive index of each kind (checked against the whole file's
/// count at its end, since a face may refer to vertices given after it). Words `tobj` cannot
/// parse are left for its error.
fn check_face_vertex(
    vertex: &str,
    line: usize,
    counts: &[usize; 3],
    largest: &mut [Option<(usize, usize)>; 3],
) -> Result<(), String> {
    for (kind, word) in vertex.split('/').enumerate().take(3) {
        let Ok(index) = word.parse::<i64>() else { continue };
        let (keyword, what) = INDEXED[kind];
        if index == 0 {
            return Err(format!("face vertex `{vertex}` gives its {what} an index of 0 (OBJ indices count from 1)"));
        }
        if index < 0 {
            if index.unsigned_abs() > counts[kind] as u64 {
                return Err(format!(
                    "face vertex `{vertex}` gives its {what} the relative index {index}, before the first `{keyword}` \
                     (only {} come before it)",
                    counts[kind]
                ));
            }
            continue;
        }
        let index = usize::try_from(index).unwrap_or(usize::MAX);
        if largest[kind].is_none_or(|(known, _)| index > known) {
            largest[kind] = Some((index, line));
        }
    }
    Ok(())
}

/// `tobj`'s error, with the line it stopped at when the error belongs to one line. `consumed` is
/// how far the reader had read: `tobj` returns as soon as a line fails, so that line is the last
/// one read. Index errors are found later, when a group is finished, so they get no line.
fn describe_obj_error(error: tobj::LoadError, text: &str, consumed: u64) -> String {
    use tobj::LoadError as E;
    let what = match error {
        E::FaceVertexOutOfBounds => {
            return "a face refers to a vertex position the file does not have (an index of 0, or past the last `v`)"
                .into();
        }
        E::FaceTexCoordOutOfBounds => {
            return "a face refers to texture coordinates the file does not have (past the last `vt`)".into();
        }
        E::FaceNormalOutOfBounds => {
            return "a face refers to a normal the file does not have (past the last `vn`)".into();
        }
        E::FaceColorOutOfBounds => {
            return "some `v` statements carry a vertex colour and others do not (vertex colours must be given for \
                    all or none)"
                .into();
        }
        E::InvalidPolygon => return "a face has too few vertices to triangulate".into(),
        E::PositionParseError => "`v` needs three numbers (x y z), optionally followed by w or by r g b",
        E::NormalParseError => "`vn` needs three numbers",
        E::TexcoordParseError => "`vt` needs two numbers",
        E::FaceParseError => "a face vertex is not `v`, `v/vt`, `v//vn` or `v/vt/vn` with whole numbers",
        E::ColorParseError => "`v` has a vertex colour with other than three components",
        E::ScalingByZeroError => "`v` has a w of 0",
        E::MaterialParseError => "`usemtl` names no material",
        E::InvalidObjectName => "an object or group name is invalid",
        other => return format!("{other}"),
    };
    format!("line {}: {what}", line_of(text, consumed))
}

/// The 1-based number of the line that ends at byte `consumed` (the last line a line reader read).
fn line_of(text: &str, consumed: u64) -> usize {
    let read = &text.as_bytes()[..(consumed as usize).min(text.len())];
    let newlines = read.iter().filter(|&&b| b == b'\n').count();
    if read.ends_with(b"\n") { newlines } else { newlines + 1 }
}

/// One `mtllib` as it was read: where it is (texture paths are relative to it), how many materials
/// it added (`tobj` appends each library's to one list), and what went wrong, if anything.
struct Library {
    file: PathBuf,
    materials: usize,
    problem: Option<String>,
    /// What the library's reading let pass and the model's warnings say: a library that is not
    /// there (its materials are drawn in the default one, as Blender and three.js draw them), a
    /// `newmtl` without a name.
    warnings: Vec<String>,
}

/// `tobj`'s material loader: reads the library `name` relative to the OBJ file's folder, keeping
/// the error (which `tobj` would reduce to "open file failed") for the message.
fn read_library(dir: &Path, name: &Path, libraries: &RefCell<Vec<Library>>) -> tobj::MTLLoadResult {
    let file = dir.join(name);
    let mut libraries = libraries.borrow_mut();
    if crate::files::is_missing(&file) {
        let missing = format!(
            "mtllib `{}`: cannot read {}: it is not there; its materials are drawn in the default material",
            name.display(),
            file.display()
        );
        libraries.push(Library { file, materials: 0, problem: None, warnings: vec![missing] });
        return Ok((Vec::new(), HashMap::new()));
    }
    let result = read_mtl(&file).map_err(|e| format!("mtllib `{}`: {e}", name.display()));
    match result {
        Ok((materials, names, warnings)) => {
            let warnings = warnings.into_iter().map(|w| format!("mtllib `{}`: {w}", name.display())).collect();
            libraries.push(Library { file, materials: materials.len(), problem: None, warnings });
            Ok((materials, names))
        }
        Err(problem) => {
            libraries.push(Library { file, materials: 0, problem: Some(problem), warnings: Vec::new() });
            Err(tobj::LoadError::OpenFileFailed)
        }
    }
}

/// The materials of an MTL file, by name, and what was let pass (a `newmtl` without a name:
/// named after its line, as Blender reads it, so the file still loads).
type Mtl = (Vec<tobj::Material>, HashMap<String, usize>, Vec<String>);

fn read_mtl(file: &Path) -> Result<Mtl, String> {
    let bytes = super::read_file(file).map_err(|e| format!("cannot read {}: {e}", file.display()))?;
    let (text, warnings) = name_unnamed_materials(&String::from_utf8_lossy(&bytes));
    let text = expand_grey_colours(&text)?;
    let mut cursor = Cursor::new(text.as_bytes());
    let (materials, names) = tobj::load_mtl_buf(&mut cursor).map_err(|e| {
        let line = line_of(&text, cursor.position());
        format!("{}: line {line}: {}", file.display(), describe_mtl_error(e))
    })?;
    Ok((materials, names, warnings))
}

/// Each `newmtl` without a name named `unnamed-LINE`, with a warning: nothing can `usemtl` it,
/// but the rest of the library loads.
fn name_unnamed_materials(text: &str) -> (String, Vec<String>) {
    let mut warnings = Vec::new();
    let mut out = String::with_capacity(text.len());
    for (index, line) in text.lines().enumerate() {
        if line.split_whitespace().collect::<Vec<_>>() == ["newmtl"] {
            let name = format!("unnamed-{}", index + 1);
            warnings.push(format!("line {}: `newmtl` without a name; called `{name}`", index + 1));
            out.push_str(&format!("newmtl {name}\n"));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    (out, warnings)
}

fn describe_mtl_error(error: tobj::LoadError) -> String {
    match error {
        tobj::LoadError::MaterialParseError => {
            "malformed statement (a number that does not parse, or a texture statement without a file name)".into()
        }
        tobj::LoadError::InvalidObjectName => "`newmtl` without a name".into(),
        other => other.to_string(),
    }
}

/// MTL allows a colour to be one number, meaning grey (`Kd 0.5` is `Kd 0.5 0.5 0.5`); `tobj`
/// reads three and panics on fewer, so grey colours are spelled out here first. Two numbers, and
/// the `spectral` and `xyz` forms, are errors with their line.
fn expand_grey_colours(text: &str) -> Result<String, String> {
    let mut out = String::with_capacity(text.len());
    for (index, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next();
        if let Some(keyword @ ("Ka" | "Kd" | "Ks" | "Ke" | "Tf")) = keyword {
            let values: Vec<&str> = words.collect();
            match values.as_slice() {
                [first, ..] if matches!(*first, "spectral" | "xyz") => {
                    return Err(format!(
                        "line {}: `{keyword} {first}` colours are not supported (give r g b)",
                        index + 1
                    ));
                }
                [grey] => {
                    out.push_str(&format!("{keyword} {grey} {grey} {grey}\n"));
                    continue;
                }
                [_, _, _] => {}
                _ => {
                    return Err(format!(
                        "line {}: `{keyword}` needs three numbers (r g b) or one (grey), got {}",
                        index + 1,
                        values.len()
                    ));
                }
            }
        }
        out.push_str(line);
        out.push('\n');
    }
    Ok(out)
}

/// The importer's state while it converts one file's meshes and materials.
struct Reader<'a> {
    path: &'a Path,
    materials: &'a [tobj::Material],
    libraries: &'a [Library],
    out: ModelImport,
    /// MTL material (`None`: the default) → index into `out.materials`.
    converted: HashMap<Option<usize>, usize>,
    textures: HashMap<(PathBuf, ColorSpace), TextureId>,
}

impl Reader<'_> {
    fn warn(&mut self, message: String) {
        let message = format!("{}: OBJ: {message}", self.path.display());
        log::warn!("{message}");
        self.out.warnings.push(message);
    }

    /// The mesh of one group, `None` when it has no triangle with area.
    fn mesh(&mut self, source: &tobj::Mesh, name: String) -> Result<Option<Mesh>, String> {
        let positions: Vec<Vec3> = source.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        let count = positions.len();
        if source.indices.is_empty() {
            return Ok(None);
        }
        let given_normals = (source.normals.len() == 3 * count).then(|| {
            source.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2]).try_normalize()).collect::<Vec<_>>()
        });
        let uvs = if source.texcoords.len() == 2 * count {
            source.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], 1.0 - t[1])).collect()
        } else {
            if !source.texcoords.is_empty() {
                self.warn(format!("`{name}`: some vertices lack texture coordinates; all get (0, 0)"));
            }
            vec![Vec2::ZERO; count]
        };
        let mut mesh = Mesh {
            name,
            positions,
            // A placeholder until the indices are known to be in range, which computing normals
            // relies on.
            normals: vec![Vec3::Y; count],
            uvs,
            tangents: Vec::new(),
            indices: source.indices.clone(),
        };
        let removed = mesh.validate_and_repair().map_err(|e| e.to_string())?;
        if removed > 0 {
            self.warn(format!("`{}`: removed {removed} zero-area (degenerate) triangle(s)", mesh.name));
        }
        if mesh.indices.is_empty() {
            self.warn(format!("`{}`: skipped, it has no triangles with area", mesh.name));
            return Ok(None);
        }
        match given_normals.and_then(|normals| normals.into_iter().collect::<Option<Vec<Vec3>>>()) {
            Some(normals) => mesh.normals = normals,
            None => {
                if !source.normals.is_empty() {
                    self.warn(format!(
                        "`{}`: some vertices lack a normal (or have a zero one); normals computed for all",
                        mesh.name
                    ));
                }
                mesh.compute_normals();
            }
        }
        Ok(Some(mesh))
    }

    /// The index into `out.materials` of MTL material `id`, converting it on first use.
    fn material(&mut self, id: Option<usize>) -> Result<usize, String> {
        let id = id.filter(|&i| i < self.materials.len());
        if let Some(&known) = self.converted.get(&id) {
            return Ok(known);
        }
        let material = match id {
            Some(i) => self.convert(i).map_err(|e| format!("material `{}`: {e}", self.materials[i].name))?,
            None => Material { name: DEFAULT_MATERIAL.into(), ..Material::default() },
        };
        self.out.materials.push(material);
        let index = self.out.materials.len() - 1;
        self.converted.insert(id, index);
        Ok(index)
    }

    /// The library MTL material `index` came from: `tobj` lists the libraries' materials in order.
    fn library_of(&self, index: usize) -> &Library {
        let mut first = 0;
        for library in self.libraries {
            if index < first + library.materials {
                return library;
            }
            first += library.materials;
        }
        unreachable!("material {index} comes from one of the libraries that were read")
    }

    /// MTL material `index` by the module documentation's table.
    fn convert(&mut self, index: usize) -> Result<Material, String> {
        let materials = self.materials;
        let m = &materials[index];
        let dir = self.library_of(index).file.parent().map(Path::to_path_buf).unwrap_or_default();
        let default = Material::default();
        let diffuse = colour(m.diffuse, "Kd")?;
        let specular = colour(m.specular, "Ks")?;
        let emission = colour(m.emissive, "Ke")?.unwrap_or(Vec3::ZERO);
        let filter = match m.unknown_param.get("Tf") {
            Some(value) => {
                parse_colour(value).ok_or_else(|| format!("`Tf {value}`: expected r g b or one number ≥ 0"))?
            }
            None => Vec3::ONE,
        };
        let number = |value: Option<f32>, key: &str| -> Result<Option<f32>, String> {
            match value {
                Some(x) if !x.is_finite() => Err(format!("`{key}` is not a finite number ({x})")),
                other => Ok(other),
            }
        };
        let transparency = match m.unknown_param.get("Tr") {
            Some(value) => Some(
                value
                    .parse::<f32>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("`Tr {value}`: expected a number"))?,
            ),
            None => None,
        };
        let alpha = number(m.dissolve, "d")?.or(transparency.map(|t| 1.0 - t)).unwrap_or(1.0).clamp(0.0, 1.0);
        let shininess = number(m.shininess, "Ns")?.map_or(default.shininess, |e| e.max(0.0));
        let illum = m.illumination_model.unwrap_or(2);
        let name = m.name.clone();
        if illum > 10 {
            self.warn(format!("material `{name}`: illum {illum} is not one of MTL's 0–10; read as 2"));
        }
        let illum = if illum > 10 { 2 } else { illum };
        let transmits = matches!(illum, 4 | 6 | 7 | 9);
        let ior = match number(m.optical_density, "Ni")? {
            Some(ni) if ni > 0.0 => ni,
            Some(ni) => {
                self.warn(format!("material `{name}`: Ni {ni} is not > 0; ignored"));
                if transmits { 1.5 } else { 1.0 }
            }
            None if transmits => 1.5,
            None => 1.0,
        };
        let highlight = specular.filter(|s| *s != Vec3::ZERO);
        let ks = if illum >= 2 && highlight.is_some() { 1.0 } else { 0.0 };
        let mirror = if (3..=9).contains(&illum) && highlight.is_some() { 1.0 } else { 0.0 };
        let specular = specular.unwrap_or(Vec3::ONE);

        let mut wrap = None;
        let diffuse_map = match &m.diffuse_texture {
            Some(statement) => self.texture_statement(&name, "map_Kd", statement, &dir, ColorSpace::Srgb)?,
            None => None,
        };
        let bump_map = match &m.normal_texture {
            Some(statement) => self.texture_statement(&name, "bump", statement, &dir, ColorSpace::Linear)?,
            None => None,
        };
        let normal_map = match m.unknown_param.get("norm") {
            Some(statement) => self.texture_statement(&name, "norm", statement, &dir, ColorSpace::Linear)?,
            None => None,
        };
        for map in [&diffuse_map, &bump_map, &normal_map].into_iter().flatten() {
            wrap = wrap.or(map.clamp.map(|clamp| if clamp { Wrap::Clamp } else { Wrap::Repeat }));
        }
        self.warn_ignored(m);
        Ok(Material {
            name,
            color: diffuse.unwrap_or(if diffuse_map.is_some() { Vec3::ONE } else { default.color }),
            texture: diffuse_map.as_ref().map(|t| t.id),
            wrap: [wrap.unwrap_or(Wrap::Repeat); 2],
            ka: 0.0,
            kd: 1.0,
            ks,
            specular_color: specular,
            shininess,
            emission,
            mirror,
            mirror_color: specular,
            transmission: if transmits { 1.0 } else { 0.0 },
            transmission_color: (Vec3::ONE - specular).max(Vec3::ZERO) * filter,
            ior,
            height_map: bump_map.as_ref().map(|t| t.id),
            height_field: None,
            bump_scale: bump_map.as_ref().and_then(|t| t.multiplier).unwrap_or(1.0),
            normal_map: normal_map.map(|t| t.id),
            normal_scale: 1.0,
            alpha,
            alpha_mode: if alpha < 1.0 { AlphaMode::Blend } else { AlphaMode::Opaque },
        })
    }

    fn warn_ignored(&mut self, m: &tobj::Material) {
        let ignored_maps = [
            ("map_Ka", &m.ambient_texture),
            ("map_Ks", &m.specular_texture),
            ("map_Ns", &m.shininess_texture),
            ("map_d", &m.dissolve_texture),
        ];
        let mut ignored: Vec<&str> = ignored_maps.iter().filter(|(_, t)| t.is_some()).map(|(key, _)| *key).collect();
        let mut unknown: Vec<&str> =
            m.unknown_param.keys().map(String::as_str).filter(|k| !matches!(*k, "Tr" | "Tf" | "norm")).collect();
        unknown.sort_unstable();
        ignored.extend(unknown);
        if !ignored.is_empty() {
            self.warn(format!("material `{}`: ignoring {}", m.name, ignored.join(", ")));
        }
    }

    /// Reads the texture a statement names, in `space`, loading each file once per colour space;
    /// `None`, with a warning, where the file is not there (as Blender and three.js draw it).
    fn texture_statement(
        &mut self,
        material: &str,
        keyword: &str,
        statement: &str,
        dir: &Path,
        space: ColorSpace,
    ) -> Result<Option<TextureMap>, String> {
        let parsed = parse_texture_statement(statement).map_err(|e| format!("`{keyword} {statement}`: {e}"))?;
        if !parsed.ignored.is_empty() {
            self.warn(format!("material `{material}`: {keyword}: ignoring option(s) {}", parsed.ignored.join(", ")));
        }
        if parsed.multiplier.is_some() && space != ColorSpace::Linear {
            self.warn(format!("material `{material}`: {keyword}: -bm applies to bump maps only; ignored"));
        }
        let file = dir.join(&parsed.file);
        if crate::files::is_missing(&file) {
            self.warn(format!(
                "material `{material}`: {keyword}: cannot read {}: it is not there; the material is drawn without it",
                file.display()
            ));
            return Ok(None);
        }
        let key = (file.clone(), space);
        let id = match self.textures.get(&key) {
            Some(&id) => id,
            None => {
                let texture = texture::load(&file, space).map_err(|e| format!("{keyword}: {e}"))?;
                self.out.textures.push(texture);
                let id = TextureId(self.out.textures.len() - 1);
                self.textures.insert(key, id);
                id
            }
        };
        Ok(Some(TextureMap { id, multiplier: parsed.multiplier, clamp: parsed.clamp }))
    }
}

/// A loaded texture and the options of its statement Mirador reads.
struct TextureMap {
    id: TextureId,
    multiplier: Option<f32>,
    clamp: Option<bool>,
}

/// A texture statement's file and options: `[-option args…]… file name`.
#[derive(Debug, PartialEq)]
struct TextureStatement {
    file: String,
    /// `-bm`: the bump multiplier.
    multiplier: Option<f32>,
    /// `-clamp on|off`.
    clamp: Option<bool>,
    /// The options that were skipped, as written (`-s`).
    ignored: Vec<String>,
}

/// Parses `[-option args…]… file name`, the file name being the rest of the statement (it may
/// hold spaces). MTL's options and how many arguments each takes: `-o`, `-s` and `-t` one to three
/// numbers, `-mm` two, every other one.
fn parse_texture_statement(statement: &str) -> Result<TextureStatement, String> {
    let mut parsed = TextureStatement { file: String::new(), multiplier: None, clamp: None, ignored: Vec::new() };
    let mut rest = statement.trim_start();
    loop {
        let (word, after) = split_word(rest);
        let Some(option) = word.strip_prefix('-').filter(|o| !o.is_empty() && !o.starts_with(char::is_numeric)) else {
            break;
        };
        let mut args = Vec::new();
        let mut remaining = after;
        let (least, most) = match option {
            "o" | "s" | "t" => (1, 3),
            "mm" => (2, 2),
            "blendu" | "blendv" | "cc" | "clamp" | "bm" | "boost" | "texres" | "imfchan" | "type" => (1, 1),
            _ => return Err(format!("unknown option `-{option}`")),
        };
        while args.len() < most {
            let (arg, next) = split_word(remaining);
            let numeric = arg.parse::<f32>().is_ok();
            if arg.is_empty() || (args.len() >= least && !numeric) {
                break;
            }
            args.push(arg);
            remaining = next;
        }
        if args.len() < least {
            return Err(format!("option `-{option}` needs {least} argument(s)"));
        }
        match option {
            "bm" => {
                let k = args[0].parse::<f32>().ok().filter(|k| k.is_finite());
                parsed.multiplier = Some(k.ok_or_else(|| format!("`-bm {}`: expected a number", args[0]))?);
            }
            "clamp" => {
                parsed.clamp = Some(match args[0] {
                    "on" => true,
                    "off" => false,
                    other => return Err(format!("`-clamp {other}`: expected on or off")),
                });
            }
            _ => parsed.ignored.push(format!("-{option}")),
        }
        rest = remaining;
    }
    let file = rest.trim();
    if file.is_empty() {
        return Err("names no file".into());
    }
    parsed.file = file.replace('\\', "/");
    Ok(parsed)
}

/// The first whitespace-separated word of `text` and what follows it (without leading spaces).
fn split_word(text: &str) -> (&str, &str) {
    let text = text.trim_start();
    let end = text.find(char::is_whitespace).unwrap_or(text.len());
    (&text[..end], text[end..].trim_start())
}

/// An MTL colour `tobj` parsed, which must be finite and not negative.
fn colour(value: Option<[f32; 3]>, key: &str) -> Result<Option<Vec3>, String> {
    match value.map(Vec3::from_array) {
        Some(c) if !c.is_finite() || c.min_element() < 0.0 => {
            Err(format!("`{key}` must be three finite numbers ≥ 0, got {} {} {}", c.x, c.y, c.z))
        }
        other => Ok(other),
    }
}

/// `r g b`, or one number for grey, each finite and ≥ 0.
fn parse_colour(text: &str) -> Option<Vec3> {
    let values: Vec<f32> = text.split_whitespace().map(|w| w.parse::<f32>().ok()).collect::<Option<_>>()?;
    let c = match values.as_slice() {
        [grey] => Vec3::splat(*grey),
        [r, g, b] => Vec3::new(*r, *g, *b),
        _ => return None,
    };
    (c.is_finite() && c.min_element() >= 0.0).then_some(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_statements_read_bump_multiplier_and_clamp_and_skip_other_options() {
        let parsed = parse_texture_statement("-bm 0.25 -s 2 2 1 -clamp on textures\\my bumps.png").unwrap();
        assert_eq!(parsed.file, "textures/my bumps.png");
        assert_eq!(parsed.multiplier, Some(0.25));
        assert_eq!(parsed.clamp, Some(true));
        assert_eq!(parsed.ignored, ["-s"]);
        // `-o` takes one to three numbers: here one, then the file.
        let parsed = parse_texture_statement("-o 0.5 wood.png").unwrap();
        assert_eq!((parsed.file.as_str(), parsed.ignored.as_slice()), ("wood.png", &["-o".to_string()][..]));
        assert_eq!(parse_texture_statement("plain.png").unwrap().file, "plain.png");
        assert!(parse_texture_statement("-bm 0.5").is_err(), "no file name");
        assert!(parse_texture_statement("-frobnicate 1 a.png").is_err());
        assert!(parse_texture_statement("-clamp maybe a.png").is_err());
    }

    #[test]
    fn grey_colours_are_spelled_out_and_two_numbers_are_an_error() {
        assert_eq!(expand_grey_colours("Kd 0.5\nKs 1 0 0\n").unwrap(), "Kd 0.5 0.5 0.5\nKs 1 0 0\n");
        let error = expand_grey_colours("newmtl a\nKa 0.1 0.2\n").unwrap_err();
        assert!(error.contains("line 2") && error.contains("`Ka`"), "{error}");
        assert!(expand_grey_colours("Kd spectral file.rfl").unwrap_err().contains("spectral"));
    }

    #[test]
    fn the_line_read_last_is_found_from_the_bytes_consumed() {
        let text = "v 0 0 0\nv 1\nv 2 2 2\n";
        assert_eq!(line_of(text, "v 0 0 0\nv 1\n".len() as u64), 2);
        assert_eq!(line_of("v 0 0 0\nv 1", 12), 2, "a last line without a newline");
    }

    #[test]
    fn the_scan_refuses_non_finite_numbers_and_counts_what_is_not_drawn() {
        let error = scan("v 0 0 0\nvn nan 0 1\n").err().expect("NaN is refused");
        assert!(error.contains("line 2") && error.contains("nan"), "{error}");
        assert!(scan("v 1e39 0 0").is_err(), "beyond f32");
        let found = scan("v 0 0 0\nl 1 2\nf 1 2\np 1\nusemtl glass\nf\n");
        assert!(found.err().expect("an empty face").contains("line 6"));
        let found = scan("v 0 0 0\nv 1 0 0\nl 1 2\nf 1 2\np 1\nusemtl glass\n").unwrap();
        assert_eq!(found.skipped, 3);
        assert_eq!(found.usemtl, [(6, "glass".to_string())]);
    }

    #[test]
    fn the_scan_refuses_face_indices_tobj_would_overflow_on_or_read_as_none() {
        let triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
        assert!(scan(&format!("{triangle}f 1/1/1 2/1/1 3/1/-1\n")).is_ok());
        // A face may name a vertex given after it.
        assert!(scan(&format!("f 1 2 4\n{triangle}v 1 1 0\n")).is_ok());
        let error = scan(&format!("{triangle}f 1/9223372036854775807 2/1 3/1\n")).err().expect("a huge vt index");
        assert!(error.contains("line 6") && error.contains("texture coordinates 9223372036854775807"), "{error}");
        let error = scan(&format!("{triangle}f 1//3 2//1 3//1\n")).err().expect("past the last vn");
        assert!(error.contains("normal 3, past the last `vn` (the file has 1)"), "{error}");
        let error = scan(&format!("{triangle}f 1/0 2/1 3/1\n")).err().expect("a vt index of 0");
        assert!(error.contains("line 6") && error.contains("an index of 0"), "{error}");
        let error = scan(&format!("{triangle}f 1 2 -4\n")).err().expect("before the first v");
        assert!(error.contains("relative index -4") && error.contains("only 3"), "{error}");
        let error = scan(&format!("{triangle}f 1/-9223372036854775808 2/1 3/1\n")).err().expect("the least i64");
        assert!(error.contains("relative index"), "{error}");
    }
}
