//! Volume files (`src/scene/nrrd.rs`) given bad input: every problem is an error that says
//! what is wrong, header problems name their line, nothing panics, and a header that asks for a
//! huge grid is refused before anything is allocated for it.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{UVec3, Vec3};
use mirador::scene::nrrd::{Endian, RawDesc, ScalarType, read_nrrd, read_raw, write_nrrd};
use mirador::volume::Grid;

// ---------------------------------------------------------------------------------------------
// Helpers.

/// A fresh, empty folder under the system's temporary folder, unique to this process and call.
fn temp_dir(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("mirador-volume-files-{}-{n}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the temporary folder can be made");
    dir
}

/// Writes `bytes` as `name` in a fresh folder; returns its path.
fn write_file(test: &str, name: &str, bytes: &[u8]) -> PathBuf {
    let path = temp_dir(test).join(name);
    std::fs::write(&path, bytes).expect("the fixture can be written");
    path
}

/// The error reading the NRRD file made of `header` and `data`, which must contain `expected`.
fn assert_nrrd_error(test: &str, header: &str, data: &[u8], expected: &str) {
    let path = write_file(test, "volume.nrrd", &[header.as_bytes(), data].concat());
    assert_error(read_nrrd(&path), expected);
}

fn assert_error(result: Result<Grid, String>, expected: &str) {
    match result {
        Ok(grid) => panic!("expected an error containing «{expected}», read a {} grid", grid.dims),
        Err(error) => assert!(error.contains(expected), "expected «{expected}» in «{error}»"),
    }
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    encoder.write_all(bytes).unwrap();
    encoder.finish().unwrap()
}

/// A 10 × 10 × 12 `uchar` header with the given encoding.
fn uchar_header(encoding: &str) -> String {
    format!("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10 10 12\nencoding: {encoding}\n\n")
}

fn ramp_grid() -> Grid {
    let dims = UVec3::new(6, 5, 4);
    Grid::new(dims, Vec3::ONE, (0..120).map(|i| (i % 50) as f32).collect()).unwrap()
}

// ---------------------------------------------------------------------------------------------
// Data that does not match the header.

#[test]
fn a_truncated_raw_nrrd_names_both_byte_counts() {
    assert_nrrd_error(
        "truncated-raw",
        &uchar_header("raw"),
        &[7; 1000],
        "the data holds 1000 bytes, the header's 10 × 10 × 12 uchar needs 1200",
    );
    // No data at all.
    assert_nrrd_error("no-data", &uchar_header("raw"), &[], "the data holds 0 bytes");
}

#[test]
fn a_gzip_nrrd_with_too_little_data_names_both_byte_counts() {
    assert_nrrd_error(
        "short-gzip",
        &uchar_header("gzip"),
        &gzip(&[7; 1000]),
        "the data holds 1000 bytes after decompression, the header's 10 × 10 × 12 uchar needs 1200",
    );
}

#[test]
fn a_truncated_gzip_nrrd_is_refused() {
    let compressed = gzip(&(0..1200).map(|i| (i * 7 % 251) as u8).collect::<Vec<u8>>());
    let header = uchar_header("gzip");
    // Cut in the compressed data, and cut in the trailer after all the data.
    assert_nrrd_error("truncated-gzip", &header, &compressed[..compressed.len() / 2], "the gzip stream is cut short");
    assert_nrrd_error(
        "truncated-trailer",
        &header,
        &compressed[..compressed.len() - 3],
        "the gzip stream is cut short",
    );
}

#[test]
fn extra_data_is_ignored() {
    let path = write_file("extra-raw", "volume.nrrd", &[uchar_header("raw").as_bytes(), &[1; 1300]].concat());
    assert_eq!(read_nrrd(&path).unwrap().values.len(), 1200);
    let path = write_file("extra-gzip", "volume.nrrd", &[uchar_header("gzip").as_bytes(), &gzip(&[1; 5000])].concat());
    assert_eq!(read_nrrd(&path).unwrap().values.len(), 1200);
    let path =
        write_file("extra-ascii", "volume.nrrd", &[uchar_header("ascii").as_bytes(), &b"3 ".repeat(1201)].concat());
    assert_eq!(read_nrrd(&path).unwrap().values, vec![3.0; 1200]);
}

#[test]
fn a_corrupt_gzip_stream_is_refused() {
    let header = uchar_header("gzip");
    let data: Vec<u8> = (0..1200).map(|i| (i * 7 % 251) as u8).collect();
    assert_nrrd_error("not-gzip", &header, &data, "the gzip data is corrupt");

    // A wrong checksum in the trailer.
    let mut compressed = gzip(&data);
    let crc = compressed.len() - 8;
    compressed[crc] ^= 0xff;
    assert_nrrd_error("bad-crc", &header, &compressed, "the gzip data is corrupt");

    // Any byte of the compressed data flipped: an error, never a panic. (Or, rarely, a grid: a
    // flip can make the stream decode to more bytes than the header needs, and the extra is not
    // decompressed, so the checksum after it is never reached.)
    let compressed = gzip(&data);
    let mut refused = 0;
    for at in 10..compressed.len() {
        let mut flipped = compressed.clone();
        flipped[at] ^= 0x55;
        let path = write_file("flipped", "volume.nrrd", &[header.as_bytes(), &flipped].concat());
        match read_nrrd(&path) {
            Ok(grid) => assert_eq!(grid.values.len(), 1200),
            Err(_) => refused += 1,
        }
    }
    assert!(refused * 10 > (compressed.len() - 10) * 9, "{refused} of {} flips refused", compressed.len() - 10);
}

#[test]
fn every_prefix_of_a_file_is_refused_without_panicking() {
    let dir = temp_dir("prefixes");
    for gzip in [false, true] {
        let path = dir.join("whole.nrrd");
        write_nrrd(&path, &ramp_grid(), ScalarType::I16, gzip).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        for length in 0..bytes.len() {
            let cut = dir.join("cut.nrrd");
            std::fs::write(&cut, &bytes[..length]).unwrap();
            assert!(read_nrrd(&cut).is_err(), "gzip {gzip}: {length} of {} bytes", bytes.len());
        }
    }
}

#[test]
fn a_raw_file_must_match_its_dimensions_exactly() {
    let desc = RawDesc {
        dims: UVec3::splat(10),
        scalar: ScalarType::U8,
        spacing: Vec3::ONE,
        endian: Endian::Little,
        header_bytes: 0,
    };
    let small = write_file("raw-small", "volume.raw", &[0; 999]);
    assert_error(read_raw(&small, &desc), "the file holds 999 bytes, a 10 × 10 × 10 uint8 grid needs 1000");
    let large = write_file("raw-large", "volume.raw", &[0; 1001]);
    assert_error(read_raw(&large, &desc), "the file holds 1001 bytes, a 10 × 10 × 10 uint8 grid needs 1000");
    let with_header = RawDesc { header_bytes: 16, scalar: ScalarType::U16, ..desc.clone() };
    assert_error(
        read_raw(&large, &with_header),
        "the file holds 1001 bytes, a 16-byte header and a 10 × 10 × 10 uint16 grid need 2016",
    );
    let exact = write_file("raw-exact", "volume.raw", &[3; 1000]);
    assert_eq!(read_raw(&exact, &desc).unwrap().values, vec![3.0; 1000]);
    assert_error(read_raw(&exact.with_extension("missing"), &desc), "cannot open the file");
}

// ---------------------------------------------------------------------------------------------
// Header problems.

#[test]
fn an_unsupported_type_names_its_line() {
    let header = "NRRD0004\ntype: complex\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n";
    assert_nrrd_error("type", header, &[0; 8], "line 2: unknown type `complex` (Mirador reads uint8, int8,");
    let header = "NRRD0004\ndimension: 3\ntype: long long\nsizes: 2 2 2\nencoding: raw\n\n";
    assert_nrrd_error("type-64", header, &[0; 64], "line 3: unsupported type `long long`");
    let header = "NRRD0004\ndimension: 3\ntype: block\nblock size: 4\nsizes: 2 2 2\nencoding: raw\n\n";
    assert_nrrd_error("type-block", header, &[0; 32], "line 3: unknown type `block`");
}

#[test]
fn an_unsupported_encoding_lists_the_ones_read() {
    for encoding in ["bzip2", "hex"] {
        assert_nrrd_error(
            "encoding",
            &uchar_header(encoding),
            &[0; 1200],
            &format!("line 5: unsupported encoding `{encoding}` (Mirador reads raw, gzip and ascii"),
        );
    }
    assert_nrrd_error("encoding", &uchar_header("zip"), &[0; 1200], "line 5: unknown encoding `zip`");
}

#[test]
fn a_dimension_other_than_3_is_refused() {
    let header = "NRRD0004\ntype: float\ndimension: 4\nsizes: 2 2 2 3\nendian: little\nencoding: raw\n\n";
    assert_nrrd_error("dimension-4", header, &[0; 96], "line 3: dimension is 4, but Mirador reads 3-D scalar volumes");
    let header = "NRRD0001\ntype: uchar\ndimension: 2\nsizes: 8 8\nencoding: raw\n\n";
    assert_nrrd_error("dimension-2", header, &[0; 64], "line 3: dimension is 2");
}

#[test]
fn sizes_must_be_three_numbers_of_at_least_2() {
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nencoding: raw\nsizes: 10 10\n\n";
    assert_nrrd_error("sizes-count", header, &[0; 100], "line 5: sizes has 2 numbers but dimension is 3");
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10 0 10\nencoding: raw\n\n";
    assert_nrrd_error(
        "sizes-zero",
        header,
        &[],
        "line 4: a grid needs at least 2 points on every axis, got 10 × 0 × 10",
    );
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10 -3 10\nencoding: raw\n\n";
    assert_nrrd_error("sizes-negative", header, &[], "line 4: sizes: `-3` is not a whole number");
}

#[test]
fn huge_sizes_are_refused_before_allocation() {
    let header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nendian: little\nencoding: gzip\n\n";
    assert_nrrd_error(
        "huge",
        header,
        &gzip(&[0; 64]),
        "line 4: a 100000 × 100000 × 100000 grid is larger than Mirador reads (2048 points per axis, 1073741824 in all)",
    );
    // Every axis within 2048, the product not; and numbers past u64.
    let header = "NRRD0004\ntype: double\ndimension: 3\nsizes: 2048 2048 2048\nendian: little\nencoding: raw\n\n";
    assert_nrrd_error("huge-product", header, &[0; 64], "a 2048 × 2048 × 2048 grid is larger than Mirador reads");
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 99999999999999999999 2 2\nencoding: raw\n\n";
    assert_nrrd_error("huge-number", header, &[0; 64], "line 4: sizes: `99999999999999999999` is not a whole number");
    // A grid Mirador accepts, with next to no data: refused from the file's size, not after
    // allocating 4 GiB.
    let header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 1024 1024 1024\nendian: little\nencoding: raw\n\n";
    assert_nrrd_error(
        "lying-raw",
        header,
        &[0; 64],
        "the data holds 64 bytes, the header's 1024 × 1024 × 1024 float needs 4294967296",
    );

    let desc = RawDesc {
        dims: UVec3::splat(100_000),
        scalar: ScalarType::F64,
        spacing: Vec3::ONE,
        endian: Endian::Little,
        header_bytes: 0,
    };
    let path = write_file("huge-raw", "volume.raw", &[0; 64]);
    assert_error(read_raw(&path, &desc), "a 100000 × 100000 × 100000 grid is larger than Mirador reads");
}

#[test]
fn spacings_must_be_positive_and_finite() {
    for (spacings, expected) in [
        ("1 -1 1", "line 5: the y spacing is `-1`; spacings must be positive and finite"),
        ("0 1 1", "line 5: the x spacing is `0`; spacings must be positive and finite"),
        ("1 1 nan", "line 5: the z spacing is `nan`; spacings must be positive and finite"),
        ("1 1 inf", "line 5: the z spacing is `inf`"),
        ("1 1", "line 5: spacings has 2 entries but dimension is 3"),
        ("1 one 1", "line 5: spacings: `one` is not a number"),
    ] {
        let header =
            format!("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspacings: {spacings}\nencoding: raw\n\n");
        assert_nrrd_error("spacings", &header, &[0; 8], expected);
    }
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace directions: (1,0,0) (0,1,0) (0,0,nan)\nencoding: raw\n\n";
    assert_nrrd_error(
        "directions-nan",
        header,
        &[0; 8],
        "line 5: space directions: the z axis's vector has length NaN",
    );
    let header =
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace directions: (1,0,0) (0,1,0)\nencoding: raw\n\n";
    assert_nrrd_error("directions-count", header, &[0; 8], "line 5: space directions has 2 entries but dimension is 3");
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace directions: (1,0,0) (0,1,0) [0,0,1]\nencoding: raw\n\n";
    assert_nrrd_error(
        "directions-syntax",
        header,
        &[0; 8],
        "line 5: space directions: expected a vector `(x,y,z)` or `none`",
    );

    // A raw file's spacing is checked by the grid.
    let desc = RawDesc {
        dims: UVec3::splat(2),
        scalar: ScalarType::U8,
        spacing: Vec3::new(1.0, 0.0, 1.0),
        endian: Endian::Little,
        header_bytes: 0,
    };
    let path = write_file("raw-spacing", "volume.raw", &[0; 8]);
    assert_error(read_raw(&path, &desc), "spacing must be positive and finite");
}

#[test]
fn a_nan_voxel_is_named() {
    let mut values = [1.0f32; 8];
    values[5] = f32::NAN;
    let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nendian: little\nencoding: raw\n\n";
    assert_nrrd_error("nan-voxel", header, &data, "voxel (1, 0, 1) is NaN (values must be finite)");
    let header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: text\n\n";
    assert_nrrd_error("nan-ascii", header, b"0 0 0 -inf 0 0 0 0", "voxel (1, 1, 0) is -inf");
}

#[test]
fn a_multi_byte_type_needs_an_endian() {
    let header = "NRRD0004\ntype: int16\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n";
    assert_nrrd_error(
        "no-endian",
        header,
        &[0; 16],
        "no `endian` field in the header (a file of 2-byte `int16` samples",
    );
    let header = "NRRD0004\ntype: int16\ndimension: 3\nsizes: 2 2 2\nendian: middle\nencoding: raw\n\n";
    assert_nrrd_error("bad-endian", header, &[0; 16], "line 5: unknown endian `middle` (accepted: little, big)");
}

#[test]
fn required_fields_are_named_when_missing() {
    let full = ["type: uchar", "dimension: 3", "sizes: 2 2 2", "encoding: raw"];
    for (missing, name) in full.iter().zip(["type", "dimension", "sizes", "encoding"]) {
        let lines: Vec<&str> = full.iter().copied().filter(|line| line != missing).collect();
        let header = format!("NRRD0004\n{}\n\n", lines.join("\n"));
        assert_nrrd_error("required", &header, &[0; 8], &format!("no `{name}` field in the header"));
    }
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nsizes: 2 2 2\nencoding: raw\n\n";
    assert_nrrd_error("twice", header, &[0; 8], "line 5: a second `sizes` field (the first is on line 4)");
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes 2 2 2\nencoding: raw\n\n";
    assert_nrrd_error("not-a-field", header, &[0; 8], "line 4: `sizes 2 2 2` is neither a `field: value` line");
}

#[test]
fn a_file_that_is_not_nrrd_is_refused() {
    let dir = temp_dir("png");
    let png = dir.join("image.png");
    image::RgbaImage::new(4, 4).save(&png).unwrap();
    assert_error(read_nrrd(&png), "not a NRRD file: it starts with `\\x89PNG`, not with a NRRD magic");
    let empty = write_file("empty", "empty.nrrd", &[]);
    assert_error(read_nrrd(&empty), "not a NRRD file: it is empty");
    let newer = write_file("newer", "newer.nrrd", b"NRRD0006\ntype: uchar\n");
    assert_error(read_nrrd(&newer), "unsupported NRRD version `NRRD0006` (Mirador reads NRRD0001 to NRRD0005)");
    let binary = write_file("binary", "binary.nrrd", &[b"NRRD0004\n".as_slice(), &[b'x'; 100_000]].concat());
    assert_error(read_nrrd(&binary), "line 2 is longer than 65536 bytes");
    assert_error(read_nrrd(&dir.join("missing.nrrd")), "cannot open the file");
}

#[test]
fn a_header_without_its_blank_line_has_no_data() {
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw";
    assert_nrrd_error("no-ending", header, &[], "the header does not end with a blank line, so no data follows it");
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n";
    assert_nrrd_error("no-blank", header, &[], "the header does not end with a blank line");
    // The data straight after the last field, without the blank line: its first line is read as
    // a header line.
    assert_nrrd_error("data-in-header", header, &[0xff, 0x80, 7, 9, 10, 11, 12, 13], "line 6: `");
}

#[test]
fn a_missing_detached_data_file_is_named() {
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: voxels.raw\n";
    let path = write_file("detached", "volume.nhdr", header.as_bytes());
    let missing = path.with_file_name("voxels.raw");
    assert_error(read_nrrd(&path), &format!("data file {}: cannot open it", missing.display()));
    // A data file that is too short is named too.
    std::fs::write(&missing, [0; 7]).unwrap();
    assert_error(
        read_nrrd(&path),
        &format!("data file {}: the data holds 7 bytes, the header's 2 × 2 × 2 uchar needs 8", missing.display()),
    );
}

#[test]
fn writing_over_a_folder_fails_cleanly() {
    let dir = temp_dir("write");
    std::fs::create_dir_all(dir.join("taken.nrrd")).unwrap();
    let error = write_nrrd(&dir.join("taken.nrrd"), &ramp_grid(), ScalarType::U8, false).unwrap_err();
    assert!(error.starts_with("cannot write the file"), "{error}");
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|entry| entry.unwrap().file_name()).collect();
    assert_eq!(leftovers, ["taken.nrrd"], "no temporary file is left behind");
    let inconsistent = Grid { values: vec![0.0; 3], ..ramp_grid() };
    let error = write_nrrd(&dir.join("bad.nrrd"), &inconsistent, ScalarType::U8, false).unwrap_err();
    assert_eq!(error, "a 6 × 5 × 4 grid needs 120 values, it has 3");
    assert!(!Path::new(&dir.join("bad.nrrd")).exists());
}
