//! Mirador's FLIP (`flip-rs`, pure Rust: `src/compare/`) against NVIDIA's C++ implementation, on
//! Mirador's own images: the raster and traced images of three scenes (`tests/data/flip/`, drawn
//! at 160×90 by `mirador render` and `mirador trace`). The figures below were recorded with the
//! `nv-flip` crate (NVIDIA's C++ FLIP, which Mirador used before) on these very files; on the
//! machine that recorded them the two error maps were identical bit for bit. Here they must agree
//! to a few units of f32 rounding, so that a change of the pinned crate that moved FLIP would fail.

use std::path::Path;

/// `(scene, nv-flip's mean, nv-flip's largest pixel error, nv-flip's pixels with an error)`, the
/// traced image as the reference and the raster image as the test, 67 pixels per degree.
const RECORDED: &[(&str, f32, f32, usize)] = &[
    ("showcase", 0.030858697, 0.30865023, 14400),
    ("mirrors", 0.03889769, 0.2677307, 14400),
    ("aliasing-edges", 0.026102506, 0.30118307, 11474),
];

fn image(name: &str) -> image::RgbaImage {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/flip").join(name);
    image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgba8()
}

#[test]
fn flip_is_nvidias_on_mirador_s_images() {
    for &(scene, mean, max, nonzero) in RECORDED {
        let traced = image(&format!("{scene}-traced.png"));
        let raster = image(&format!("{scene}-raster.png"));
        let d = mirador::compare::difference(&traced, &raster).expect("the same size");
        let largest = d.flip_errors.iter().copied().fold(0.0f32, f32::max);
        let with_error = d.flip_errors.iter().filter(|&&e| e > 0.0).count();
        assert!((d.flip_mean - mean).abs() <= 1e-6, "{scene}: mean {} against NVIDIA's {mean}", d.flip_mean);
        assert!((largest - max).abs() <= 1e-5, "{scene}: largest {largest} against NVIDIA's {max}");
        assert_eq!(with_error, nonzero, "{scene}: pixels with an error");
    }
}
