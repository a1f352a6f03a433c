//! OBJ (with MTL) and PLY import: the Utah teapot and a hand-written material library read number
//! by number, a Stanford-bunny-sized scan in all three PLY encodings, broken files that must give
//! an error naming the file instead of a panic, the models as scene objects and as bare scenes,
//! and both models drawn alike by the rasterizer and the ray tracer.

mod common;

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Vec2, Vec3};
use mirador::scene::file::parse;
use mirador::scene::{AlphaMode, ColorSpace, LightKind, Material, ModelImport, Scene, SceneError, Wrap, obj, ply};

// ---------------------------------------------------------------------------------------------
// Helpers.

fn data(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(relative)
}

/// A fresh, empty folder under the system's temporary folder, unique to this process and call.
fn temp_dir(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("mirador-obj-ply-{}-{n}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the temporary folder can be made");
    dir
}

/// Writes `files` (name, contents) into a fresh folder; returns the path of the first.
fn write_files(test: &str, files: &[(&str, &[u8])]) -> PathBuf {
    let dir = temp_dir(test);
    for (name, contents) in files {
        std::fs::write(dir.join(name), contents).expect("the fixture can be written");
    }
    dir.join(files[0].0)
}

fn load_obj(path: &Path) -> ModelImport {
    obj::import(path).unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

fn load_ply(path: &Path) -> ModelImport {
    ply::import(path).unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

/// The import must fail with an error of the expected kind whose message names the file and
/// mentions each of `words`.
fn assert_error(result: Result<ModelImport, SceneError>, path: &Path, kind: &str, words: &[&str]) -> String {
    let message = match result {
        Ok(_) => panic!("{} should not load", path.display()),
        Err(e @ (SceneError::Obj { .. } | SceneError::Ply { .. })) => e.to_string(),
        Err(e) => panic!("{}: expected an {kind} error, got {e:?}", path.display()),
    };
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(message.contains(&*name), "the message does not name {name}: {message}");
    assert!(message.contains(&format!(": {kind}: ")), "not an {kind} error: {message}");
    for word in words {
        assert!(message.contains(word), "the message does not mention `{word}`: {message}");
    }
    message
}

fn obj_error(test: &str, files: &[(&str, &[u8])], words: &[&str]) -> String {
    let path = write_files(test, files);
    assert_error(obj::import(&path), &path, "OBJ", words)
}

fn ply_error(test: &str, bytes: &[u8], words: &[&str]) -> String {
    let path = write_files(test, &[("broken.ply", bytes)]);
    assert_error(ply::import(&path), &path, "PLY", words)
}

fn material<'a>(import: &'a ModelImport, object: &str) -> &'a Material {
    let found = import.objects.iter().find(|o| o.name == object).unwrap_or_else(|| panic!("no object `{object}`"));
    &import.materials[found.material]
}

fn assert_close3(actual: Vec3, expected: Vec3, what: &str) {
    assert!(actual.abs_diff_eq(expected, 1e-5), "{what}: {actual} ≠ {expected}");
}

fn bounds(import: &ModelImport) -> (Vec3, Vec3) {
    let points = import.meshes.iter().flat_map(|m| m.positions.iter().copied());
    points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

// ---------------------------------------------------------------------------------------------
// OBJ: the teapot.

/// `tests/data/obj/teapot.obj`, written by `cargo run --example teapot_obj`: Newell's 32 patches
/// at 8 × 8 quads each, five groups, two materials.
#[test]
fn the_teapot_has_its_groups_counts_and_bounds() {
    let path = data("obj/teapot.obj");
    let import = load_obj(&path);
    assert!(import.warnings.is_empty(), "{:?}", import.warnings);
    let names: Vec<&str> = import.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["body/0", "handle/0", "spout/0", "lid/0", "bottom/0"]);
    assert!(import.lights.is_empty() && import.cameras.is_empty());

    // Counted from the file: a face of n vertices is n − 2 triangles, and each `v` is one point.
    let text = std::fs::read_to_string(&path).unwrap();
    let faces: Vec<usize> =
        text.lines().filter(|l| l.starts_with("f ")).map(|l| l.split_whitespace().count() - 1).collect();
    let triangles: usize = import.meshes.iter().map(|m| m.triangle_count()).sum();
    assert_eq!(triangles, faces.iter().map(|n| n - 2).sum::<usize>());
    // 32 patches × 64 quads, less the quads that collapse to triangles where the lid's and the
    // bottom's patches meet in a point (8 per patch on those 8 patches).
    assert_eq!(faces.len(), 32 * 64);
    assert_eq!(faces.iter().filter(|&&n| n == 3).count(), 8 * 8);
    assert_eq!(triangles, 32 * 64 * 2 - 8 * 8);
    // Neighbouring patches share their edge points: the meshes hold no more distinct positions
    // than the file's `v` statements.
    let distinct: HashSet<[u32; 3]> =
        import.meshes.iter().flat_map(|m| m.positions.iter().map(|p| p.to_array().map(f32::to_bits))).collect();
    assert_eq!(distinct.len(), text.lines().filter(|l| l.starts_with("v ")).count());

    // Newell's teapot stands on y = 0, its knob's top at 3.15, its body 4 across at its widest
    // (the patch corners (±2, 0.9, 0) and (0, 0.9, ±2) are on the surface); the spout and the
    // handle stay inside their control points' x range.
    let (lo, hi) = bounds(&import);
    assert!((lo.y - 0.0).abs() < 1e-6 && (hi.y - 3.15).abs() < 1e-6, "height {lo} {hi}");
    assert!((lo.z + 2.0).abs() < 1e-6 && (hi.z - 2.0).abs() < 1e-6, "depth {lo} {hi}");
    assert!(lo.x >= -3.0 && lo.x < -2.9 && hi.x <= 3.525 && hi.x > 3.3, "width {lo} {hi}");
}

#[test]
fn the_teapot_faces_outward_with_unit_normals() {
    let import = load_obj(&data("obj/teapot.obj"));
    let body = &import.meshes[import.objects[0].mesh];
    // The widest point of the body faces +x.
    let widest = body.positions.iter().position(|p| p.abs_diff_eq(Vec3::new(2.0, 0.9, 0.0), 1e-5)).unwrap();
    assert!(body.normals[widest].dot(Vec3::X) > 0.999, "{}", body.normals[widest]);
    let lid = &import.meshes[import.objects[3].mesh];
    let top = lid.positions.iter().position(|p| p.abs_diff_eq(Vec3::new(0.0, 3.15, 0.0), 1e-5)).unwrap();
    assert!(lid.normals[top].dot(Vec3::Y) > 0.99, "the knob's top faces up: {}", lid.normals[top]);
    let bottom = &import.meshes[import.objects[4].mesh];
    let centre = bottom.positions.iter().position(|p| p.abs_diff_eq(Vec3::ZERO, 1e-5)).unwrap();
    assert!(bottom.normals[centre].dot(Vec3::NEG_Y) > 0.99, "the bottom faces down: {}", bottom.normals[centre]);
    let handle = &import.meshes[import.objects[1].mesh];
    let back = (0..handle.positions.len()).min_by(|&a, &b| handle.positions[a].x.total_cmp(&handle.positions[b].x));
    let back = back.unwrap();
    assert!(handle.normals[back].dot(Vec3::NEG_X) > 0.9, "the handle's back faces away: {}", handle.normals[back]);
    for mesh in &import.meshes {
        assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4), "{}: unit normals", mesh.name);
        // Counter-clockwise seen from the side the normals point to.
        let agreeing = mesh
            .indices
            .chunks_exact(3)
            .filter(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
                let n: Vec3 = [t[0], t[1], t[2]].iter().map(|&i| mesh.normals[i as usize]).sum();
                (b - a).cross(c - a).dot(n) > 0.0
            })
            .count();
        assert_eq!(agreeing, mesh.triangle_count(), "{}: winding and normals agree", mesh.name);
    }
}

#[test]
fn the_teapot_materials_follow_the_mtl_rule() {
    let import = load_obj(&data("obj/teapot.obj"));
    assert_eq!(import.materials.len(), 2);
    let porcelain = material(&import, "body/0");
    assert_eq!(porcelain.name, "porcelain");
    assert_close3(porcelain.color, Vec3::new(0.8, 0.76, 0.7), "C = Kd");
    assert_eq!((porcelain.ka, porcelain.kd, porcelain.ks), (0.0, 1.0, 1.0), "Ka is not read; kd = ks = 1");
    assert_close3(porcelain.specular_color, Vec3::splat(0.35), "S = Ks");
    assert_eq!(porcelain.shininess, 80.0);
    assert_eq!((porcelain.mirror, porcelain.transmission, porcelain.alpha), (0.0, 0.0, 1.0), "illum 2");
    let glaze = material(&import, "lid/0");
    assert_eq!(glaze.name, "glaze");
    assert_eq!(glaze.shininess, 160.0);
    assert_eq!(import.objects[1].material, import.objects[0].material, "one material, converted once");
}

// ---------------------------------------------------------------------------------------------
// OBJ: the MTL table, statement by statement (tests/data/obj/materials.mtl).

#[test]
fn every_mtl_statement_maps_by_the_documented_table() {
    let import = load_obj(&data("obj/materials.obj"));

    let plastic = material(&import, "plastic/0");
    assert_close3(plastic.color, Vec3::new(0.8, 0.1, 0.1), "C = Kd");
    assert_eq!((plastic.ka, plastic.kd, plastic.ks, plastic.shininess), (0.0, 1.0, 1.0, 64.0), "Ka 1 1 1 is not read");
    assert_close3(plastic.specular_color, Vec3::splat(0.5), "S = Ks");
    assert_eq!((plastic.mirror, plastic.transmission, plastic.ior), (0.0, 0.0, 1.0));
    assert_eq!((plastic.alpha, plastic.alpha_mode), (1.0, AlphaMode::Opaque));

    let matte = material(&import, "matte/0");
    assert_close3(matte.color, Vec3::splat(0.5), "`Kd 0.5` is grey");
    assert_eq!(matte.ks, 0.0, "illum 1 has no highlight, whatever Ks says");
    assert_eq!(matte.shininess, Material::default().shininess, "no Ns: the default exponent");

    let mirror = material(&import, "mirror/0");
    assert_eq!((mirror.mirror, mirror.ks, mirror.shininess), (1.0, 1.0, 500.0), "illum 3: kps = 1");
    assert_close3(mirror.mirror_color, Vec3::new(0.9, 0.8, 0.7), "MPS = Ks");
    assert_eq!(mirror.transmission, 0.0);

    let glass = material(&import, "glass/0");
    assert_eq!((glass.transmission, glass.mirror, glass.ior), (1.0, 1.0, 1.45), "illum 7: kt = kps = 1, ior = Ni");
    assert_close3(glass.transmission_color, Vec3::new(0.81, 0.9, 0.81), "MT = (1 − Ks)·Tf");
    assert_close3(glass.color, Vec3::ZERO, "C = Kd");
    assert_eq!(glass.alpha_mode, AlphaMode::Opaque, "d 1");

    let veil = material(&import, "veil/0");
    assert_eq!((veil.alpha, veil.alpha_mode), (0.25, AlphaMode::Blend), "alpha = 1 − Tr");
    assert_close3(veil.emission, Vec3::new(0.1, 0.2, 0.3), "emission = Ke");

    let textured = material(&import, "textured/0");
    let texture = textured.texture.expect("map_Kd gives the colour texture");
    let height = textured.height_map.expect("bump gives the height map");
    assert_eq!(import.textures[texture.0].color_space, ColorSpace::Srgb);
    assert_eq!(import.textures[height.0].color_space, ColorSpace::Linear);
    assert_ne!(texture, height, "one image read as colour and as data is two textures");
    assert!(import.textures[texture.0].path.ends_with("textures/ramp.png"), "relative to the MTL file");
    assert_eq!(textured.bump_scale, 0.05, "k = -bm");
    assert_eq!(textured.wrap, [Wrap::Clamp; 2], "-clamp on");
    assert_close3(textured.color, Vec3::ONE, "no Kd under a map_Kd: white");

    let before = material(&import, "unnamed_object/0");
    assert_eq!(before.name, obj::DEFAULT_MATERIAL, "faces before any usemtl");
    assert_eq!(before.color, Material::default().color);
    assert_eq!(material(&import, "ghost/0").name, obj::DEFAULT_MATERIAL, "usemtl naming nothing defined");

    let warnings = import.warnings.join("\n");
    for expected in ["`usemtl nowhere`", "map_Ks", "Pr"] {
        assert!(warnings.contains(expected), "no warning about {expected}: {warnings}");
    }
}

#[test]
fn an_obj_without_mtl_is_drawn_in_the_default_material_with_fans_and_flipped_v() {
    // A pentagon in the z = 0 plane, with texture coordinates and without normals.
    let text = "v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 2 0\nv -0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0.5 1\nvt 0 1\n\
                f 1/1 2/2 3/3 4/4 5/5\n";
    let path = write_files("pentagon", &[("pentagon.obj", text.as_bytes())]);
    let import = load_obj(&path);
    assert_eq!(import.materials.len(), 1);
    assert_eq!(import.materials[0].name, obj::DEFAULT_MATERIAL);
    let mesh = &import.meshes[0];
    assert_eq!(mesh.indices, [0, 1, 2, 0, 2, 3, 0, 3, 4], "a fan around the first vertex");
    assert_eq!(mesh.normals, vec![Vec3::Z; 5], "computed, facing the counter-clockwise side");
    assert_eq!(mesh.uvs[0], Vec2::new(0.0, 1.0), "OBJ's v = 0 is the image's bottom row");
    assert_eq!(mesh.uvs[3], Vec2::new(0.5, 0.0));
}

// ---------------------------------------------------------------------------------------------
// OBJ: broken files.

#[test]
fn a_truncated_obj_names_the_line_it_stopped_at() {
    obj_error("truncated", &[("cut.obj", b"v 0 0 0\nv 1 0 0\nv 0 1")], &["line 3", "`v` needs three numbers"]);
    obj_error("face", &[("cut.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1/x 2 3\n")], &["line 5", "face vertex"]);
}

#[test]
fn obj_faces_past_the_last_vertex_are_an_error() {
    obj_error(
        "past",
        &[("past.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")],
        &["vertex position", "past the last `v`"],
    );
    obj_error("zero", &[("zero.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")], &["an index of 0"]);
    obj_error("vt", &[("vt.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n")], &["texture coordinates"]);
}

#[test]
fn nan_and_infinite_obj_coordinates_are_an_error_at_their_line() {
    obj_error("nan", &[("nan.obj", b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")], &["line 2", "not finite"]);
    obj_error("inf", &[("inf.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 inf\nf 1 2 3\n")], &["line 4", "`vn`"]);
    obj_error("huge", &[("huge.obj", b"v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n")], &["line 2"]);
}

#[test]
fn empty_objs_and_objs_without_faces_are_errors() {
    obj_error("empty", &[("empty.obj", b"")], &["empty"]);
    obj_error("points", &[("points.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\np 1\nl 1 2\n")], &["no faces"]);
    obj_error("flat", &[("flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")], &["no faces"]);
    let path = data("obj/no_such_model.obj");
    match obj::import(&path) {
        Err(e @ SceneError::Io { .. }) => assert!(e.to_string().contains("no_such_model.obj"), "{e}"),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

/// A missing MTL file or texture file inside a model from elsewhere is a warning naming it, and
/// the model still shows, in the default material or without the texture (as Blender and
/// three.js draw it; issue 35); a malformed MTL or a bad number stays an error, as does UTF-16.
#[test]
fn a_missing_mtl_or_texture_is_a_warning_and_a_broken_one_an_error() {
    let triangle = "mtllib looks.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wood\nf 1 2 3\n";
    let path = write_files("no-mtl", &[("model.obj", triangle.as_bytes())]);
    let import = load_obj(&path);
    let warned = |import: &ModelImport, words: &[&str]| {
        let found = import.warnings.iter().any(|w| words.iter().all(|word| w.contains(word)));
        assert!(found, "no warning with {words:?}: {:?}", import.warnings);
    };
    warned(&import, &["mtllib `looks.mtl`", "cannot read", "default material"]);
    assert_eq!(material(&import, &import.objects[0].name).name, obj::DEFAULT_MATERIAL);
    let path = write_files(
        "no-texture",
        &[("model.obj", triangle.as_bytes()), ("looks.mtl", b"newmtl wood\nKd 1 0.5 0.25\nmap_Kd textures/wood.png\n")],
    );
    let import = load_obj(&path);
    warned(&import, &["material `wood`", "map_Kd", "textures/wood.png", "without it"]);
    let wood = material(&import, &import.objects[0].name);
    assert_eq!((wood.name.as_str(), wood.texture), ("wood", None), "the material, without its texture");
    assert_eq!(wood.color, Vec3::new(1.0, 0.5, 0.25));
    obj_error(
        "bad-mtl",
        &[("model.obj", triangle.as_bytes()), ("looks.mtl", b"newmtl wood\nKd 1 1\n")],
        &["looks.mtl", "line 2", "`Kd` needs three numbers"],
    );
    obj_error(
        "nan-mtl",
        &[("model.obj", triangle.as_bytes()), ("looks.mtl", b"newmtl wood\nKs nan 0 0\n")],
        &["material `wood`", "`Ks`"],
    );
    // A `newmtl` without a name (Blender and three.js load such files): named after its line,
    // with a warning, and the library's other materials still load.
    let path = write_files(
        "unnamed-mtl",
        &[("model.obj", triangle.as_bytes()), ("looks.mtl", b"newmtl\nKd 0 1 0\nnewmtl wood\nKd 1 0.5 0.25\n")],
    );
    let import = load_obj(&path);
    warned(&import, &["mtllib `looks.mtl`", "line 1", "`newmtl` without a name"]);
    assert_eq!(material(&import, &import.objects[0].name).color, Vec3::new(1.0, 0.5, 0.25));
    let utf16: Vec<u8> = [0xFF, 0xFE].into_iter().chain(triangle.encode_utf16().flat_map(u16::to_le_bytes)).collect();
    obj_error("utf16", &[("model.obj", &utf16)], &["UTF-16", "save it as UTF-8"]);
}

// ---------------------------------------------------------------------------------------------
// PLY: a scan-sized mesh, written here in every encoding.

/// A bumpy blob the size of the Stanford bunny (35 947 vertices): an icosphere divided six times
/// (40 962 vertices, 81 920 triangles), each vertex pushed along its direction by a few waves so
/// that the surface has the scan's small-scale relief.
fn scan_mesh() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..6 {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]).normalize());
                positions.len() as u32 - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) =
                    (midpoint(a, b, &mut positions), midpoint(b, c, &mut positions), midpoint(c, a, &mut positions));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    for p in &mut positions {
        let d = *p;
        let relief = 0.08 * (5.0 * d.x).sin() * (4.0 * d.y).sin() * (6.0 * d.z).sin()
            + 0.03 * (17.0 * d.x + 11.0 * d.y).sin() * (13.0 * d.z).cos()
            + 0.2 * d.y.max(0.0).powi(4);
        *p = d * (1.0 + relief) * Vec3::new(1.0, 0.9, 0.8);
    }
    (positions, faces)
}

#[derive(Clone, Copy)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// The PLY file of `positions` and `faces`. To cover what files in the wild vary, the big-endian
/// file stores doubles and names its index list `vertex_index` with unsigned indices.
fn ply_bytes(encoding: Encoding, positions: &[Vec3], faces: &[[u32; 3]]) -> Vec<u8> {
    let (format, scalar, list) = match encoding {
        Encoding::Ascii => ("ascii", "float", "list uchar int vertex_indices"),
        Encoding::LittleEndian => ("binary_little_endian", "float", "list uchar int vertex_indices"),
        Encoding::BigEndian => ("binary_big_endian", "double", "list uchar uint vertex_index"),
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment written by tests/obj_ply.rs\nelement vertex {}\nproperty {scalar} x\n\
         property {scalar} y\nproperty {scalar} z\nelement face {}\nproperty {list}\nend_header\n",
        positions.len(),
        faces.len()
    )
    .into_bytes();
    for p in positions {
        match encoding {
            Encoding::Ascii => out.extend(format!("{} {} {}\n", p.x, p.y, p.z).bytes()),
            Encoding::LittleEndian => p.to_array().iter().for_each(|c| out.extend(c.to_le_bytes())),
            Encoding::BigEndian => p.to_array().iter().for_each(|&c| out.extend(f64::from(c).to_be_bytes())),
        }
    }
    for f in faces {
        match encoding {
            Encoding::Ascii => out.extend(format!("3 {} {} {}\n", f[0], f[1], f[2]).bytes()),
            Encoding::LittleEndian => {
                out.push(3);
                f.iter().for_each(|&i| out.extend((i as i32).to_le_bytes()));
            }
            Encoding::BigEndian => {
                out.push(3);
                f.iter().for_each(|&i| out.extend(i.to_be_bytes()));
            }
        }
    }
    out
}

#[test]
fn ascii_and_binary_plys_give_the_same_scan() {
    let (positions, faces) = scan_mesh();
    assert_eq!((positions.len(), faces.len()), (40_962, 81_920));
    let dir = temp_dir("scan");
    let mut imports = Vec::new();
    for (name, encoding) in
        [("ascii", Encoding::Ascii), ("little", Encoding::LittleEndian), ("big", Encoding::BigEndian)]
    {
        let path = dir.join(format!("scan-{name}.ply"));
        std::fs::write(&path, ply_bytes(encoding, &positions, &faces)).unwrap();
        imports.push((name, load_ply(&path)));
    }
    let (_, ascii) = &imports[0];
    let mesh = &ascii.meshes[0];
    assert_eq!(mesh.positions, positions, "f32 printed shortest-exact reads back bit for bit");
    assert_eq!(mesh.indices, faces.concat());
    assert!(mesh.normals.iter().zip(&positions).all(|(n, p)| n.dot(p.normalize()) > 0.5), "outward normals");
    assert_eq!(ascii.objects.len(), 1);
    assert_eq!(ascii.materials[0].name, ply::DEFAULT_MATERIAL);
    assert!(ascii.warnings.is_empty(), "{:?}", ascii.warnings);
    for (name, import) in &imports[1..] {
        let other = &import.meshes[0];
        assert_eq!(other.positions, mesh.positions, "{name}-endian positions");
        assert_eq!(other.indices, mesh.indices, "{name}-endian faces");
        assert_eq!(other.normals, mesh.normals, "{name}-endian normals");
    }
}

/// A quad and a pentagon with normals, texture coordinates and colours, in ASCII.
const SMALL_PLY: &str = "ply
format ascii 1.0
comment a quad and a pentagon
element vertex 9
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float s
property float t
property uchar red
property uchar green
property uchar blue
element face 3
property list uchar int vertex_indices
property uchar flags
element edge 1
property int vertex1
property int vertex2
end_header
0 0 0 0 0 2 0 0 255 0 0
1 0 0 0 0 2 1 0 255 0 0
1 1 0 0 0 2 1 1 255 0 0
0 1 0 0 0 2 0 1 255 0 0
2 0 0 0 1 0 0 0 0 255 0
3 0 0 0 1 0 0 0 0 255 0
3.5 0 1 0 1 0 0 0 0 255 0
2.5 0 2 0 1 0 0 0 0 255 0
1.5 0 1 0 1 0 0 0 0 255 0
4 0 1 2 3 0
5 4 8 7 6 5 0
2 0 1 0
0 1
";

#[test]
fn a_small_ply_is_read_number_by_number() {
    let path = write_files("small", &[("small.ply", SMALL_PLY.as_bytes())]);
    let import = load_ply(&path);
    let mesh = &import.meshes[0];
    assert_eq!(mesh.name, "small");
    assert_eq!(mesh.positions.len(), 9);
    assert_eq!(mesh.indices, [0, 1, 2, 0, 2, 3, 4, 8, 7, 4, 7, 6, 4, 6, 5], "fans; the two-vertex face skipped");
    assert_eq!(mesh.normals[0], Vec3::Z, "given normals are normalised");
    assert_eq!(mesh.normals[4], Vec3::Y);
    assert_eq!(mesh.uvs[1], Vec2::new(1.0, 1.0), "(s, 1 − t)");
    assert_eq!(mesh.uvs[2], Vec2::new(1.0, 0.0));
    let warnings = import.warnings.join("\n");
    for expected in ["vertex.red", "face.flags", "fewer than three vertices"] {
        assert!(warnings.contains(expected), "no warning about {expected}: {warnings}");
    }
}

// ---------------------------------------------------------------------------------------------
// PLY: broken files.

const HEADER: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                      element face 1\nproperty list uchar int vertex_indices\nend_header\n";

#[test]
fn a_ply_header_that_lies_is_an_error() {
    // More vertices declared than present: the face line is read as a vertex, and then the file ends.
    let lying = HEADER.replace("element vertex 3", "element vertex 5");
    ply_error("more-vertices", format!("{lying}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").as_bytes(), &["element `vertex`"]);
    // A binary file cut short.
    let (positions, faces) = (vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
    let whole = ply_bytes(Encoding::LittleEndian, &positions, &faces);
    ply_error("cut", &whole[..whole.len() - 5], &["element `face`", "ends before the header's count"]);
    let message = ply_error("index", format!("{HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n").as_bytes(), &["face 0"]);
    assert!(message.contains("vertex 9") && message.contains("3 vertices"), "{message}");
    ply_error("negative", format!("{HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n").as_bytes(), &["vertex -1"]);
}

/// Runs `read` on another thread and fails if it has not finished within `limit`.
fn within<T: Send + 'static>(limit: std::time::Duration, read: impl FnOnce() -> T + Send + 'static) -> T {
    let (done, finished) = std::sync::mpsc::channel();
    std::thread::spawn(move || done.send(read()));
    finished.recv_timeout(limit).unwrap_or_else(|_| panic!("not finished within {limit:?}"))
}

#[test]
fn a_ply_element_without_properties_is_not_read_however_many_it_claims() {
    // Found by fuzzing (fuzz/regressions/ply/): a binary element with no properties takes no
    // bytes, so the parser's loop over its count of 10^15 read nothing, never ended, and kept
    // `mirador render` busy past 60 s.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions/ply/hang-empty-element-1e15.ply");
    let import = within(std::time::Duration::from_secs(20), move || ply::import(&path));
    let import = import.unwrap_or_else(|e| panic!("the triangle after the empty element loads: {e}"));
    assert_eq!(import.meshes[0].indices, [0, 1, 2]);
}

#[test]
fn ply_counts_the_file_cannot_hold_are_refused_before_reading() {
    // 10^15 vertices of 12 bytes in a file of a few dozen: refused by the header alone.
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000000\nproperty float x\n\
                  property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let bytes = [header.as_bytes(), &[0; 40]].concat();
    let message = ply_error("counts", &bytes, &["1000000000000000 `vertex`", "12 byte(s)", "40 bytes"]);
    assert!(message.contains("the header lies"), "{message}");
    // In ASCII a property takes at least one character: 3 vertices of 3 need 9 bytes, 1 face 1.
    let ascii = format!("{HEADER}0 0 0\n");
    ply_error("ascii-counts", ascii.as_bytes(), &["`vertex`", "cannot hold them"]);
}

#[test]
fn obj_face_indices_near_the_integer_limit_are_errors_at_their_line() {
    // Found by fuzzing (the 2 660 inputs; fuzz/regressions/obj/): tobj computes
    // `2·vt + 1` and `3·vn + 2` from a face's indices unchecked, which overflowed for a huge `vn`
    // or a relative `vt` before the first (turned into an index near 2⁶⁴): a panic inside tobj
    // where overflow checks are on, caught by the importer's last net; a wrapped offset where
    // they are off. Mirador checks each index before tobj sees it.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions/obj");
    for (file, words) in [
        ("tobj-overflow-vn-index-2e63.obj", &["line 6", "normal 9223372036854775807", "past the last `vn`"][..]),
        ("tobj-overflow-vt-relative-before-first.obj", &["line 6", "relative index -5", "only 1 come before it"]),
        // 3·(6148914691236517207 − 1) wraps to 2: a release build read the second normal's y,
        // z and the next x as this vertex's normal, without an error.
        ("tobj-overflow-vn-wraps-to-offset-2.obj", &["line 6", "normal 6148914691236517207", "past the last `vn`"]),
        // 2·(2⁶³ − 2) + 1 still fits: tobj refused this one itself, but without its line.
        (
            "vt-index-2e63-past-the-last.obj",
            &["line 6", "texture coordinates 9223372036854775807", "past the last `vt`"],
        ),
    ] {
        let path = dir.join(file);
        let message = assert_error(obj::import(&path), &path, "OBJ", words);
        assert!(!message.contains(mirador::scene::PANIC_CAUGHT), "{message}");
    }
}

#[test]
fn nan_ply_coordinates_empty_plys_and_point_clouds_are_errors() {
    // The ASCII reader refuses `nan` itself; binary files can hold any bit pattern.
    ply_error("nan-ascii", format!("{HEADER}0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n").as_bytes(), &["Line 11", "1 nan 0"]);
    let nan = ply_bytes(Encoding::LittleEndian, &[Vec3::ZERO, Vec3::new(1.0, f32::NAN, 0.0), Vec3::Y], &[[0, 1, 2]]);
    ply_error("nan", &nan, &["vertex 1", "not finite"]);
    let huge = ply_bytes(Encoding::BigEndian, &[Vec3::ZERO, Vec3::X, Vec3::Y], &[[0, 1, 2]]);
    let huge = [&huge[..huge.len() - 13 - 24], &1e300f64.to_be_bytes(), &huge[huge.len() - 13 - 16..]].concat();
    ply_error("huge", &huge, &["vertex 2", "not finite"]);
    ply_error("empty", b"", &["empty"]);
    ply_error("not-ply", b"solid cube\nfacet normal 0 0 1\n", &["header"]);
    let cloud = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
                 end_header\n0 0 0\n";
    ply_error("cloud", cloud.as_bytes(), &["no `face` element", "point cloud"]);
    let floats = HEADER.replace("list uchar int", "list uchar float");
    ply_error("floats", format!("{floats}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").as_bytes(), &["floating-point"]);
    ply_error("no-z", HEADER.replace("property float z\n", "").as_bytes(), &["`z`"]);
}

// ---------------------------------------------------------------------------------------------
// In scenes.

#[test]
fn bare_obj_and_ply_files_are_framed_and_lit_scenes() {
    let scene = Scene::load(&data("obj/teapot.obj")).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names[..2], ["teapot/body/0", "teapot/handle/0"]);
    assert_eq!(scene.lights.len(), 1, "a headlight, since OBJ has no lights");
    assert!(matches!(scene.lights[0].kind, LightKind::Directional { .. }));
    let (lo, hi) = scene.bounds().unwrap();
    assert_close3(scene.camera.center, (lo + hi) / 2.0, "the framing camera looks at the middle");

    let path = write_files("bare", &[("small.PLY", SMALL_PLY.as_bytes())]);
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.objects[0].name, "small/mesh", "the extension is matched in any case");
    assert_eq!(scene.materials[scene.objects[0].material.0].name, ply::DEFAULT_MATERIAL);
}

#[test]
fn obj_and_ply_objects_are_placed_and_may_take_a_scene_material() {
    let dir = temp_dir("objects");
    std::fs::write(dir.join("small.ply"), SMALL_PLY).unwrap();
    let text = format!(
        "[materials.gold]\ncolor = [1, 0.8, 0.3]\n\
         [[objects]]\nname = \"pot\"\ntype = \"obj\"\npath = \"{}\"\ntranslate = [10, 0, 0]\n\
         [[objects]]\ntype = \"ply\"\npath = \"small.ply\"\nmaterial = \"gold\"\nscale = 2\n",
        data("obj/teapot.obj").display()
    );
    let scene = parse(&text, &dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    let pot = &scene.objects[0];
    assert_eq!(pot.name, "pot/body/0");
    assert_close3(pot.world_from_local.transform_point3(Vec3::ZERO), Vec3::new(10.0, 0.0, 0.0), "translated");
    assert_eq!(scene.materials[pot.material.0].name, "porcelain", "the MTL's own material");
    let small = scene.objects.last().unwrap();
    assert_eq!(small.name, "ply 5/mesh", "five teapot objects before it");
    assert_eq!(scene.materials[small.material.0].name, "gold", "`material` replaces the model's own");
    assert!(scene.materials.iter().all(|m| m.name != ply::DEFAULT_MATERIAL), "the replaced one is left out");
    assert!(scene.lights.is_empty(), "a scene file's models bring no headlight");

    let error = parse("[[objects]]\ntype = \"obj\"\npath = \"m.obj\"\nlights = false\n", &dir.join("bad.toml"))
        .expect_err("lights do not apply");
    assert!(error.to_string().contains("`lights` does not apply to a obj"), "{error}");
    let error = parse("[[objects]]\ntype = \"ply\"\n", &dir.join("bad.toml")).expect_err("no path");
    assert!(error.to_string().contains("a ply object needs a `path`"), "{error}");
    let error = parse("[[objects]]\ntype = \"obj\"\npath = \"nothere.obj\"\n", &dir.join("bad.toml"))
        .expect_err("no such file");
    assert!(error.to_string().contains("bad.toml:1:1: ") && error.to_string().contains("nothere.obj"), "{error}");
}

// ---------------------------------------------------------------------------------------------
// Both renderers.

/// Renders a bare model with both renderers at 320 × 240 and compares them by FLIP (the traced
/// image the reference), after checking that the model covers a fair part of the image. Fails
/// beyond `tolerance`. The renders and the FLIP error map are written to a temporary folder, named
/// in the output, to be looked at.
fn assert_renderers_agree(path: &Path, name: &str, tolerance: common::Tolerance) {
    let mut scene = Scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    (scene.camera.width, scene.camera.height) = (320, 240);
    // The framing camera keeps the whole bounding sphere in a 16:9 view; closer in, the model
    // fills more of the 4:3 image, so that the statistics are over the model, not the background.
    let camera = &mut scene.camera;
    camera.eye = camera.center + 0.7 * (camera.eye - camera.center);
    camera.near = 0.25 * camera.eye.distance(camera.center);
    let raster = common::raster(&scene, &scene.settings);
    let traced = mirador::trace::render_image(&scene, &scene.settings);
    let difference = common::difference(&traced, &raster);
    let dir = temp_dir(name);
    raster.save(dir.join(format!("{name}-raster.png"))).unwrap();
    traced.save(dir.join(format!("{name}-traced.png"))).unwrap();
    difference.error_map.save(dir.join(format!("{name}-diff.png"))).unwrap();
    let error = common::GoldenError::from_flip(&difference.flip_errors, 320, 240);
    eprintln!(
        "{name}: FLIP mean {:.5}, worst {}×{} region {:.5}; renders in {}",
        error.flip_mean,
        common::REGION,
        common::REGION,
        error.worst_region,
        dir.display()
    );
    let covered = traced.pixels().filter(|p| p.0[..3] != [0, 0, 0]).count() as f32 / (320.0 * 240.0);
    assert!(covered > 0.15, "{name}: the model covers {:.0} % of the image", 100.0 * covered);
    let excesses = error.excesses(tolerance);
    assert!(excesses.is_empty(), "{name}: {}; see {}", excesses.join(", "), dir.display());
}

/// The teapot as a bare OBJ: framed, lit by the headlight, porcelain with a blue lid. What
/// differs: edge pixels, most of them around the spout's opening and along the base (the worst
/// 32×32 region). Measured: FLIP mean 0.0025, worst region 0.023.
#[test]
fn the_teapot_agrees_between_the_renderers() {
    let tolerance = common::Tolerance { flip_mean: 0.005, worst_region: 0.05 };
    assert_renderers_agree(&data("obj/teapot.obj"), "teapot", tolerance);
}

/// The bunny-sized scan as a bare binary PLY: 81 920 triangles with computed normals, the
/// rasterizer's interpolated normals against the tracer's (the same vertex normals, interpolated
/// by the hit's barycentric coordinates), differing at the silhouette. Measured: FLIP mean 0.0020,
/// worst region 0.016.
#[test]
fn a_scan_sized_ply_agrees_between_the_renderers() {
    let (positions, faces) = scan_mesh();
    let path = temp_dir("scan-render").join("scan.ply");
    std::fs::write(&path, ply_bytes(Encoding::LittleEndian, &positions, &faces)).unwrap();
    let tolerance = common::Tolerance { flip_mean: 0.005, worst_region: 0.05 };
    assert_renderers_agree(&path, "scan", tolerance);
}
