//! Memory stays bounded: for each loader, a small file whose header (or counts, or indices)
//! claims far more than it holds is refused, and the largest single allocation made while it is
//! read stays within the bound `docs/scene-format.md` § Limits and memory states for that loader.
//!
//! Allocations are counted by a global allocator that remembers, per thread, the largest block
//! asked for since the last reset; the loaders read on the calling thread, so what another test
//! allocates at the same time is not counted.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use mirador::scene::file::parse;
use mirador::scene::nrrd::read_nrrd;
use mirador::scene::{gltf, obj, ply};

struct Largest;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(size: usize) {
    // `try_with`: the thread-local may already be gone while a thread is torn down.
    let _ = LARGEST.try_with(|largest| largest.set(largest.get().max(size)));
}

// SAFETY: every call is passed on to the system allocator unchanged; only sizes are noted.
unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Largest = Largest;

/// The result of `read` and the largest block allocated on this thread while it ran.
fn largest_allocation<T>(read: impl FnOnce() -> T) -> (T, usize) {
    LARGEST.with(|largest| largest.set(0));
    let result = read();
    (result, LARGEST.with(Cell::get))
}

const MIB: usize = 1 << 20;

fn scratch(name: &str, bytes: &[u8]) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("mirador-memory-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("a scratch file");
    path
}

#[test]
fn a_ply_header_claiming_a_billion_vertices_is_refused_before_allocating() {
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty double x\n\
                  property double y\nproperty double z\nelement face 2000000000\n\
                  property list uchar uint vertex_indices\nend_header\n";
    let bytes = [header.as_bytes(), &[0u8; 200]].concat();
    let (result, largest) = largest_allocation(|| ply::import_bytes(Path::new("billion.ply"), &bytes));
    let message = result.expect_err("the file cannot hold its counts").to_string();
    assert!(message.contains("cannot hold them"), "{message}");
    assert!(largest < 64 * 1024, "the refusal allocated {largest} bytes at once");
}

#[test]
fn ply_memory_grows_with_the_file_not_with_its_header() {
    // A header that tells the truth: 20 000 vertices and faces, read in full. The largest block
    // is one of the element lists, a bounded multiple of the file's own size.
    let (n, faces) = (20_000u32, 19_998u32);
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty float x\nproperty float y\n\
         property float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    for i in 0..n {
        let angle = i as f32 * 0.001;
        [angle.cos(), angle.sin(), i as f32 * 1e-3].iter().for_each(|c| bytes.extend(c.to_le_bytes()));
    }
    for i in 0..faces {
        bytes.push(3);
        [0, i + 1, i + 2].iter().for_each(|&v| bytes.extend((v as i32).to_le_bytes()));
    }
    let (result, largest) = largest_allocation(|| ply::import_bytes(Path::new("fan.ply"), &bytes));
    result.expect("the fan loads");
    eprintln!("PLY: {largest} bytes at once for a {}-byte file", bytes.len());
    assert!(largest <= 8 * bytes.len(), "{largest} bytes at once for a {}-byte file", bytes.len());
}

#[test]
fn obj_memory_grows_with_the_text() {
    // 20 000 triangles over 10 002 vertices, each face with its own texture coordinates: tobj's
    // lists and Mirador's mesh grow with the statements the text holds.
    let mut text = String::new();
    for i in 0..10_002 {
        text += &format!("v {i} {} 0\nvt 0.5 {}\n", i % 2, i % 3);
    }
    for i in 1..=10_000 {
        text += &format!("f {i}/{i} {}/{} {}/{}\nf {i} {} {}\n", i + 1, i + 1, i + 2, i + 2, i + 2, i + 1);
    }
    let (result, largest) = largest_allocation(|| obj::import_bytes(Path::new("strip.obj"), text.as_bytes()));
    result.expect("the strip loads");
    eprintln!("OBJ: {largest} bytes at once for {} bytes of text", text.len());
    assert!(largest <= 16 * text.len(), "{largest} bytes at once for {} bytes of text", text.len());
}

#[test]
fn obj_indices_past_the_file_are_refused_by_the_scan() {
    // tobj keeps a `Vec` per face; Mirador's scan refuses indices no statement backs before tobj
    // sees them (see fuzz/regressions/obj/).
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4000000000\n";
    let (result, largest) = largest_allocation(|| obj::import_bytes(Path::new("far.obj"), text.as_bytes()));
    let message = result.expect_err("vertex 4e9 is not in the file").to_string();
    assert!(message.contains("line 4") && message.contains("past the last `v`"), "{message}");
    assert!(largest < 64 * 1024, "{largest} bytes at once");
}

#[test]
fn a_gltf_accessor_claiming_a_billion_elements_is_refused_before_allocating() {
    // One triangle's 36-byte buffer, read by an accessor of a billion VEC3s.
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":1000000000,"type":"VEC3",
            "min":[0,0,0],"max":[1,1,0]}]}"#;
    let (result, largest) = largest_allocation(|| gltf::import_bytes(Path::new("billion.gltf"), json.as_bytes()));
    let message = result.expect_err("the view holds 3 of them").to_string();
    assert!(message.contains("past the end of the view"), "{message}");
    assert!(largest < 64 * 1024, "{largest} bytes at once");
}

#[test]
fn gltf_primitives_reading_one_buffer_over_and_over_are_stopped_by_the_budget() {
    // 999 vertices (11 988 bytes) and 2000 primitives that each read all of them: 2000 meshes of
    // 36 kB, 72 MB from a file of 80 kB, past the budget of 32 × 11 988 bytes + 16 MiB.
    let vertices: Vec<u8> =
        (0..999).flat_map(|i: u32| [i as f32, (i % 7) as f32, (i % 13) as f32]).flat_map(f32::to_le_bytes).collect();
    let primitives = vec![r#"{"attributes":{"POSITION":0}}"#; 2000].join(",");
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{primitives}]}}],
        "buffers":[{{"byteLength":11988,"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":11988}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":999,"type":"VEC3",
            "min":[0,0,0],"max":[999,6,12]}}]}}"#,
        base64(&vertices)
    );
    let (result, largest) = largest_allocation(|| gltf::import_bytes(Path::new("echo.gltf"), json.as_bytes()));
    let message = match result {
        Ok(import) => panic!("the budget should stop it; {} meshes were built", import.meshes.len()),
        Err(e) => e.to_string(),
    };
    assert!(message.contains("32 times the bytes of its buffers") && message.contains("over and over"), "{message}");
    assert!(largest < MIB, "{largest} bytes at once");
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk.iter().enumerate().fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for i in 0..=chunk.len() {
            out.push(ALPHABET[(n >> (18 - 6 * i) & 63) as usize] as char);
        }
    }
    out
}

#[test]
fn a_nrrd_header_claiming_a_gigavoxel_is_bounded_by_its_data() {
    // Raw: the file's size is checked against the header's before anything is allocated.
    let raw = "NRRD0004\ntype: float\ndimension: 3\nsizes: 1024 1024 1024\nendian: little\nencoding: raw\n\n";
    let path = scratch("giga-raw.nrrd", &[raw.as_bytes(), &[0; 400]].concat());
    let (result, largest) = largest_allocation(|| read_nrrd(&path));
    assert!(result.expect_err("400 bytes are not 4 GiB").contains("needs 4294967296"));
    assert!(largest < 64 * 1024, "raw: {largest} bytes at once");
    // Gzip: the size is known only by decompressing, so the values are reserved up to 16 Mi
    // samples (64 MiB) and grow only as data arrives.
    let gzip = raw.replace("encoding: raw", "encoding: gzip");
    let mut compressed = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    std::io::Write::write_all(&mut compressed, &[0; 4000]).expect("compressing memory");
    let path = scratch("giga-gzip.nrrd", &[gzip.as_bytes(), &compressed.finish().expect("gzip")].concat());
    let (result, largest) = largest_allocation(|| read_nrrd(&path));
    assert!(result.expect_err("4000 bytes are not 4 GiB").contains("after decompression"));
    assert!(largest <= 64 * MIB, "gzip: {largest} bytes at once");
}

#[test]
fn a_scene_asking_for_more_than_a_gigavoxel_field_is_refused_before_sampling() {
    let text = "[[volumes]]\nfield = { type = \"sphere\", resolution = [2048, 2048, 300] }\n";
    let (result, largest) = largest_allocation(|| parse(text, Path::new("huge-field.toml")));
    let message = result.expect_err("over MAX_VOXELS").to_string();
    assert!(message.contains("larger than Mirador reads"), "{message}");
    assert!(largest < 64 * 1024, "{largest} bytes at once");
}

#[test]
fn an_image_header_over_the_side_limit_is_refused_before_decoding() {
    // A PNG header of 40000 × 1, and an empty first data chunk (the decoder reads up to it).
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(40000u32.to_be_bytes());
    ihdr.extend(1u32.to_be_bytes());
    ihdr.extend([8, 6, 0, 0, 0]);
    for chunk in [&ihdr[..], b"IDAT"] {
        png.extend((chunk.len() as u32 - 4).to_be_bytes());
        png.extend(chunk);
        png.extend(crc32(chunk).to_be_bytes());
    }
    let path = scratch("wide.png", &png);
    let (result, largest) =
        largest_allocation(|| mirador::scene::texture::load(&path, mirador::scene::ColorSpace::Srgb));
    let message = result.expect_err("wider than 32768").to_string();
    assert!(message.contains("40000×1"), "{message}");
    assert!(largest < MIB, "{largest} bytes at once");
}

/// The CRC-32 PNG chunks end with (ISO-HDLC, reflected 0xEDB88320).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}
