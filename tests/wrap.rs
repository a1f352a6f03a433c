//! Texture wrap modes (glTF's wrapS / wrapT): texture coordinates outside [0, 1] repeat, clamp to
//! the edge, or mirror, alike in both renderers.

mod common;

use std::path::Path;

use mirador::scene::Wrap;
use mirador::scene::file::parse;

fn data(relative: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(relative).display().to_string()
}

#[test]
fn gltf_samplers_give_the_material_its_wrap_modes() {
    let import = mirador::scene::gltf::import(Path::new(&data("gltf/wrapped.gltf"))).unwrap();
    assert_eq!(import.materials[0].wrap, [Wrap::Clamp, Wrap::Mirror]);
    let plain = mirador::scene::gltf::import(Path::new(&data("gltf/normal_mapped.gltf"))).unwrap();
    assert_eq!(plain.materials[0].wrap, [Wrap::Repeat, Wrap::Repeat], "no sampler means repeat");
}

#[test]
fn wrap_index_known_answers() {
    let n = 4;
    let repeat: Vec<i64> = (-5..9).map(|i| Wrap::Repeat.index(i, n)).collect();
    let clamp: Vec<i64> = (-5..9).map(|i| Wrap::Clamp.index(i, n)).collect();
    let mirror: Vec<i64> = (-5..9).map(|i| Wrap::Mirror.index(i, n)).collect();
    assert_eq!(repeat, vec![3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]);
    assert_eq!(clamp, vec![0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3]);
    assert_eq!(mirror, vec![3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]);
    // A side that is not a power of two takes the remainder's other road.
    let repeat: Vec<i64> = (-5..9).map(|i| Wrap::Repeat.index(i, 3)).collect();
    assert_eq!(repeat, vec![1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2]);
    for n in 1..=17 {
        assert!((-70..70).all(|i| Wrap::Repeat.index(i, n) == i.rem_euclid(n)), "repeat over {n} texels");
    }
}

/// A plane whose texture coordinates run over [0, 3]²: the ramp texture repeats, stretches its
/// edge texels, or mirrors, and the rasterizer and the tracer show the same. The ramp's hard
/// seams make FLIP (an edge-sensitive metric) report about 0.02 for differences of one or two
/// 8-bit levels there (PSNR about 57 dB), so agreement is judged by PSNR here.
#[test]
fn wrap_modes_agree_between_the_renderers() {
    let mut images = Vec::new();
    for wrap in [r#""repeat""#, r#""clamp""#, r#""mirror""#, r#"["clamp", "mirror"]"#] {
        let text = format!(
            r#"
            [camera]
            eye = [0, 5, 0.001]
            center = [0, 0, 0]
            fovy = 45
            near = 0.1
            far = 20
            width = 120
            height = 120
            [world]
            ambient = [1, 1, 1]
            [materials.ramp]
            color = [1, 1, 1]
            kd = 1
            texture = "{}"
            wrap = {wrap}
            [[objects]]
            type = "plane"
            size = [4, 4]
            uv_scale = [3, 3]
            material = "ramp"
            "#,
            data("textures/ramp.png")
        );
        let scene = parse(&text, Path::new("wrap.toml")).unwrap_or_else(|e| panic!("{e}"));
        let raster = common::raster(&scene, &scene.settings);
        let traced = mirador::trace::render_image(&scene, &scene.settings);
        let difference = common::difference(&traced, &raster);
        assert!(
            difference.psnr_db > 45.0 && difference.flip_mean < 0.03,
            "wrap {wrap}: PSNR {} dB, FLIP {}",
            difference.psnr_db,
            difference.flip_mean
        );
        images.push(raster);
    }
    // Every mode draws a different image.
    for a in 0..images.len() {
        for b in a + 1..images.len() {
            let flip = common::difference(&images[a], &images[b]).flip_mean;
            assert!(flip > 0.02, "modes {a} and {b} look alike ({flip})");
        }
    }
}
