//! The fuzz harness: one function per loader, each taking arbitrary bytes the way a user's file
//! reaches Mirador and checking what comes back. libFuzzer drives them from `fuzz_targets/` (on
//! nightly, see fuzz/README.md); `tests/fuzz_corpus.rs` replays the kept corpora and every crash
//! ever found through the same functions on stable, so a fixed crash stays fixed.
//!
//! # What counts as a failure
//!
//! Each is a panic here, which libFuzzer reports as a crash with the input that caused it:
//!
//! - a panic anywhere, a dependency's included. Under libFuzzer its panic hook aborts before
//!   Mirador's last net (`catch_unwind` around the third-party parsers) can catch anything; on
//!   stable, the net's message ([`PANIC_CAUGHT`]) is looked for in every error instead;
//! - an error that does not name the file it is about;
//! - a loaded result that breaks what the renderers rely on: an index past the last vertex, a
//!   position or normal that is not finite, attribute lists of different lengths, a reference past
//!   the end of a list, a texture whose bytes are not width × height × 4 or that is larger than the
//!   largest texture, a grid whose values are not its dimensions' product or not finite.
//!
//! Hangs and runaway allocations are libFuzzer's to report (`-timeout`, `-rss_limit_mb`,
//! `-malloc_limit_mb`); the corpus test gives each input a time limit.
//!
//! # Side files
//!
//! Formats that read a second file take it from the same input, after the line [`SIDE`]: an
//! OBJ's MTL library (`mtllib side.mtl`), a detached NRRD's data (`data file: side.raw`). Each
//! thread has a folder of its own ([`fixtures`]) laid out like `assets/`, holding small stand-ins
//! for the files the seeds name (textures, a volume, models); the side file is written into it on
//! every run, as a user's disk would hold it, so the loaders read it through their own code.
//!
//! # Inputs declined
//!
//! So that the fuzzer spends its time on parsing rather than on allocations the documentation
//! already states, the harness returns without loading:
//!
//! - images whose header declares more than [`MAX_FUZZ_PIXELS`] pixels (Mirador decodes up to
//!   32768² by design, which `tests/large_textures.rs` covers);
//! - scenes whose procedural volumes ask for more than [`MAX_FUZZ_VOXELS`] points (a 1024³
//!   field is 4 GiB by design, `docs/scene-format.md` § Limits and memory);
//! - scene text that is not UTF-8 (the scene loader refuses it when reading the file, before
//!   parsing).

use std::cell::RefCell;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::UVec3;
use mirador::scene::file::parse;
use mirador::scene::nrrd::{Endian, RawDesc, ScalarType, read_nrrd, read_raw};
use mirador::scene::{ModelImport, PANIC_CAUGHT, Scene, Shape, Texture, environment, gltf, obj, ply, texture};
use mirador::volume::Grid;
use mirador::volume::grid::voxel_count;

/// The line that separates a main file from its side file in one input.
pub const SIDE: &[u8] = b"\n%%side%%\n";

/// The most pixels an image may declare for the harness to decode it: 2048².
pub const MAX_FUZZ_PIXELS: u64 = 1 << 22;

/// The most points a scene's procedural volumes may ask for, in all: 64³.
pub const MAX_FUZZ_VOXELS: u64 = 1 << 18;

/// The largest texture side, which every loaded texture fits.
const MAX_TEXTURE_SIDE: u32 = 16384;

/// A scene file (TOML), read from `scenes/fuzz.toml` of the fixture folder.
pub fn scene_toml(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if procedural_voxels(text) > MAX_FUZZ_VOXELS {
        return;
    }
    let path = fixtures().join("scenes/fuzz.toml");
    match parse(text, &path) {
        Ok(scene) => check_scene(&scene),
        Err(error) => check_error(&error.to_string(), &path),
    }
}

/// A `.gltf` or `.glb` file (the loader tells them by the GLB magic), in `models/`.
pub fn gltf(data: &[u8]) {
    let path = fixtures().join("models/fuzz.gltf");
    match gltf::import_bytes(&path, data) {
        Ok(import) => check_import(&import),
        Err(error) => check_error(&error.to_string(), &path),
    }
}

/// An OBJ file, then after [`SIDE`] the MTL library `side.mtl` it may name.
pub fn obj(data: &[u8]) {
    let (main, side) = split_side(data);
    let dir = fixtures().join("models");
    write_side(&dir.join("side.mtl"), side);
    let path = dir.join("fuzz.obj");
    match obj::import_bytes(&path, main) {
        Ok(import) => check_import(&import),
        Err(error) => check_error(&error.to_string(), &path),
    }
}

/// A student's lab file: the first byte picks the lab (of Mirador's eight), the rest is the file,
/// as `mirador lab check` reads it. What must hold: no panic in the student's names put apart,
/// loops guarded, signatures compared, and naga's checks of every module; each problem placed on
/// one of the file's own lines; the isolated text maps every offset back inside the file. Seeds:
/// every lab's stub and answer key (`corpus/lab_source/`), which the dictionary's WGSL tokens
/// mutate by dropping, swapping and repeating.
pub fn lab_source(data: &[u8]) {
    let Some((&choice, rest)) = data.split_first() else { return };
    let Ok(text) = std::str::from_utf8(rest) else { return };
    let labs = mirador::lab::catalog();
    let lab = &labs[choice as usize % labs.len()];
    let lines = text.lines().count().max(1) as u32;
    for problem in mirador::lab::source::problems(lab, text) {
        assert!(!problem.message.is_empty(), "a problem without a message");
        if let Some(line) = problem.line {
            assert!(line >= 1 && line <= lines + 1, "problem on line {line} of a {lines}-line file");
        }
        let _ = problem.display(&lab.file);
    }
    let isolated = mirador::lab::source::isolated(lab, text);
    // Every place a compiler can name (a character's start) maps to one of the file's.
    for offset in (0..isolated.text.len()).filter(|&offset| isolated.text.is_char_boundary(offset)) {
        if let Some(original) = isolated.original(offset) {
            assert!(original <= text.len() && text.is_char_boundary(original), "offset {offset} maps to {original}");
        }
    }
    let _ = mirador::lab::source::untouched_slots(lab, text);
}

/// A PLY file, ASCII or binary.
pub fn ply(data: &[u8]) {
    let path = fixtures().join("models/fuzz.ply");
    match ply::import_bytes(&path, data) {
        Ok(import) => check_import(&import),
        Err(error) => check_error(&error.to_string(), &path),
    }
}

/// A NRRD file (attached raw, gzip or ascii data, or a detached header), then after [`SIDE`] the
/// detached data file `side.raw` it may name.
pub fn nrrd(data: &[u8]) {
    let (main, side) = split_side(data);
    let dir = fixtures().join("volumes");
    write_side(&dir.join("side.raw"), side);
    let path = dir.join("fuzz.nrrd");
    write_side(&path, main);
    match read_nrrd(&path) {
        Ok(grid) => check_grid(&grid),
        // The volume loader's messages leave naming the file to the scene loader, which puts
        // the path in front; there is nothing to check here but the panic net.
        Err(error) => check_error(&error, Path::new("")),
    }
}

/// A headerless raw volume: the first six bytes describe it (three sizes, each 2 + byte % 14;
/// the sample type, ScalarType::ALL[byte % 8]; the byte order, little when even; the bytes to
/// skip, byte % 16), the rest is the file.
pub fn raw_volume(data: &[u8]) {
    let Some((desc, file)) = data.split_first_chunk::<6>() else { return };
    let size = |byte: u8| 2 + u32::from(byte % 14);
    let desc = RawDesc {
        dims: UVec3::new(size(desc[0]), size(desc[1]), size(desc[2])),
        scalar: ScalarType::ALL[usize::from(desc[3] % 8)],
        spacing: glam::Vec3::ONE,
        endian: if desc[4] % 2 == 0 { Endian::Little } else { Endian::Big },
        header_bytes: u64::from(desc[5] % 16),
    };
    let path = fixtures().join("volumes/fuzz.raw");
    write_side(&path, file);
    match read_raw(&path, &desc) {
        Ok(grid) => {
            assert_eq!(grid.dims, desc.dims, "a raw grid has the dimensions it was read with");
            check_grid(&grid);
        }
        Err(error) => check_error(&error, Path::new("")),
    }
}

/// An image file (PNG, JPEG or Radiance HDR, told by its content), decoded as a texture and as an
/// environment map (lat–long, and folded into a cube when its shape is a cross or a strip), by the
/// functions `texture::load` and `environment::load_image` call.
pub fn image(data: &[u8]) {
    let guessed = || image::ImageReader::new(Cursor::new(data)).with_guessed_format().expect("reading memory");
    // An unreadable header goes on to the decoder, which must say so.
    if let Ok((width, height)) = guessed().into_dimensions()
        && u64::from(width) * u64::from(height) > MAX_FUZZ_PIXELS
    {
        return;
    }
    let path = Path::new("fuzz.image");
    let decoded = match texture::decode(guessed()) {
        Ok(decoded) => decoded,
        Err(error) => return check_error(&error, Path::new("")),
    };
    check_texture(&texture::from_image(path, decoded.clone(), mirador::scene::ColorSpace::Srgb));
    let environment = environment::from_image(path, decoded);
    assert_eq!(environment.texels.len() as u64, u64::from(environment.width) * u64::from(environment.height));
    assert!(
        environment.texels.iter().all(|t| t.is_finite() && t.min_element() >= 0.0),
        "environment texels are repaired to finite, non-negative radiance"
    );
    if let Ok(faces) = environment::fold_cross(&environment) {
        let side = faces[0].width;
        assert!(faces.iter().all(|f| f.width == side && f.height == side), "six square faces of one size");
    }
}

// ---------------------------------------------------------------------------------------------
// Checks.

/// An error must name its file (when it has one) and must not come from the panic net.
pub fn check_error(message: &str, path: &Path) {
    assert!(!message.contains(PANIC_CAUGHT), "a panic was caught instead of checked for: {message}");
    let name = path.display().to_string();
    assert!(message.contains(&name), "the error does not name {name}: {message}");
}

fn check_import(import: &ModelImport) {
    for (i, mesh) in import.meshes.iter().enumerate() {
        check_mesh(mesh, &format!("mesh {i}"));
    }
    for texture in &import.textures {
        check_texture(texture);
    }
    for material in &import.materials {
        for id in [material.texture, material.height_map, material.normal_map].into_iter().flatten() {
            assert!(id.0 < import.textures.len(), "material `{}` names texture {}", material.name, id.0);
        }
    }
    for object in &import.objects {
        assert!(object.mesh < import.meshes.len(), "object `{}` names mesh {}", object.name, object.mesh);
        assert!(
            object.material < import.materials.len(),
            "object `{}` names material {}",
            object.name,
            object.material
        );
        assert!(object.world_from_local.is_finite(), "object `{}` has a transform that is not finite", object.name);
    }
}

fn check_mesh(mesh: &mirador::scene::Mesh, what: &str) {
    let n = mesh.positions.len();
    assert_eq!(mesh.normals.len(), n, "{what}: one normal per position");
    assert_eq!(mesh.uvs.len(), n, "{what}: one uv per position");
    assert!(mesh.tangents.is_empty() || mesh.tangents.len() == n, "{what}: tangents for none or all");
    assert!(!mesh.indices.is_empty() && mesh.indices.len().is_multiple_of(3), "{what}: whole triangles");
    assert!(mesh.indices.iter().all(|&i| (i as usize) < n), "{what}: an index past the last vertex");
    assert!(mesh.positions.iter().all(|p| p.is_finite()), "{what}: a position that is not finite");
    assert!(mesh.normals.iter().all(|v| v.is_finite()), "{what}: a normal that is not finite");
    assert!(mesh.uvs.iter().all(|v| v.is_finite()), "{what}: a uv that is not finite");
}

fn check_texture(texture: &Texture) {
    let (w, h) = (texture.width, texture.height);
    assert!(w > 0 && h > 0 && w <= MAX_TEXTURE_SIDE && h <= MAX_TEXTURE_SIDE, "texture {w}×{h}");
    assert_eq!(texture.rgba8.len() as u64, u64::from(w) * u64::from(h) * 4, "texture {w}×{h} bytes");
}

fn check_grid(grid: &Grid) {
    assert_eq!(grid.values.len() as u64, voxel_count(grid.dims), "one value per grid point");
    assert!(grid.values.iter().all(|v| v.is_finite()), "grid values are finite");
    assert!(grid.spacing.is_finite() && grid.spacing.min_element() > 0.0, "grid spacing {}", grid.spacing);
}

fn check_scene(scene: &Scene) {
    for (i, mesh) in scene.meshes.iter().enumerate() {
        check_mesh(mesh, &format!("mesh {i}"));
    }
    for texture in &scene.textures {
        check_texture(texture);
    }
    for material in &scene.materials {
        for id in [material.texture, material.height_map, material.normal_map].into_iter().flatten() {
            assert!(id.0 < scene.textures.len(), "material `{}` names texture {}", material.name, id.0);
        }
    }
    for object in &scene.objects {
        assert!(object.material.0 < scene.materials.len(), "object `{}` names a missing material", object.name);
        if let Shape::Mesh(index) = object.shape {
            assert!(index < scene.meshes.len(), "object `{}` names mesh {index}", object.name);
        }
        assert!(object.world_from_local.is_finite(), "object `{}` has a transform that is not finite", object.name);
    }
    for volume in &scene.volumes {
        check_grid(&volume.grid);
        assert!(volume.grid.values.iter().all(|v| (0.0..=1.0).contains(v)), "volume `{}` is normalized", volume.name);
        assert!(volume.material.0 < scene.materials.len(), "volume `{}` names a missing material", volume.name);
        assert!(volume.world_from_local.is_finite(), "volume `{}` has a transform that is not finite", volume.name);
    }
    scene.camera.validate().expect("a loaded scene's camera is valid");
}

// ---------------------------------------------------------------------------------------------
// Inputs.

/// The input before [`SIDE`], and what follows it (empty without one).
pub fn split_side(data: &[u8]) -> (&[u8], &[u8]) {
    match data.windows(SIDE.len()).position(|w| w == SIDE) {
        Some(at) => (&data[..at], &data[at + SIDE.len()..]),
        None => (data, &[]),
    }
}

/// Writes a side file, replacing the previous run's, so that every run sees only its own input.
fn write_side(path: &Path, bytes: &[u8]) {
    std::fs::write(path, bytes).expect("the fixture folder can be written");
}

/// The points the text's `[[volumes]]` procedural fields ask for, added up; 0 when the text is not
/// TOML (the loader then refuses it anyway).
fn procedural_voxels(text: &str) -> u64 {
    let Ok(table) = text.parse::<toml::Table>() else { return 0 };
    let Some(volumes) = table.get("volumes").and_then(toml::Value::as_array) else { return 0 };
    let side = |value: &toml::Value| value.as_integer().map_or(0, |n| n.clamp(0, 1 << 20) as u64);
    volumes
        .iter()
        .filter_map(|volume| volume.get("field"))
        .map(|field| match field.get("resolution") {
            None => 64 * 64 * 64,
            Some(toml::Value::Array(sides)) => sides.iter().map(side).product(),
            Some(cube) => side(cube).pow(3),
        })
        .fold(0u64, u64::saturating_add)
}

/// The small files the seeds name, built once per thread in a folder of the thread's own:
/// `scenes/` (where scene text is read from), `textures/` (the repository's textures), `volumes/`
/// (a 6³ NRRD standing in for `phantom.nrrd`), `models/` (a glTF triangle, an OBJ and a PLY).
pub fn fixtures() -> PathBuf {
    thread_local! {
        static DIR: RefCell<Option<PathBuf>> = const { RefCell::new(None) };
    }
    DIR.with(|dir| dir.borrow_mut().get_or_insert_with(make_fixtures).clone())
}

fn make_fixtures() -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("mirador-fuzz-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let files: [(&str, &[u8]); 9] = [
        ("textures/checker.png", include_bytes!("../../assets/textures/checker.png")),
        ("textures/cobbles-height.png", include_bytes!("../../assets/textures/cobbles-height.png")),
        ("textures/ramp.png", include_bytes!("../../tests/data/textures/ramp.png")),
        ("textures/tilted-normal.png", include_bytes!("../../tests/data/textures/tilted-normal.png")),
        ("volumes/phantom.nrrd", &small_nrrd()),
        ("models/triangle.glb", include_bytes!("../../tests/data/gltf/triangle.glb")),
        ("models/quad.obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"),
        ("models/triangle.ply", SMALL_PLY),
        ("scenes/.keep", b""),
    ];
    for (name, bytes) in files {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().expect("a file in a folder")).expect("the fixture folder can be made");
        std::fs::write(&path, bytes).expect("the fixture folder can be written");
    }
    dir
}

const SMALL_PLY: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

/// A 6³ grid of `uchar` (a ball of 200 in a field of 10), raw-encoded.
fn small_nrrd() -> Vec<u8> {
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 6 6 6\nspacings: 1 1 1\nencoding: raw\n\n";
    let mut bytes = header.as_bytes().to_vec();
    for z in 0..6i32 {
        for y in 0..6i32 {
            for x in 0..6i32 {
                let r2 = (2 * x - 5).pow(2) + (2 * y - 5).pow(2) + (2 * z - 5).pow(2);
                bytes.push(if r2 < 30 { 200 } else { 10 });
            }
        }
    }
    bytes
}
