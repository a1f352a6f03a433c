//! Known answers for the camera of docs/course/01-camera.md: the rasterizer's matrices and the ray
//! tracer's primary rays describe the same camera, so a point lands on the pixel whose centre ray
//! hits it.

mod common;

use glam::{Vec2, Vec3};
use mirador::scene::camera::CameraError;
use mirador::scene::{Camera, Projection};

fn seed_camera() -> Camera {
    common::load("scenes/seed-simple.toml").camera
}

fn orthographic() -> Camera {
    Camera { projection: Projection::Orthographic, ortho_height: 120.0, width: 320, height: 200, ..seed_camera() }
}

/// A deterministic spread of points inside the view volume of `camera`.
fn points_in_view(camera: &Camera) -> Vec<Vec3> {
    let frame = camera.frame();
    let mut points = Vec::new();
    for i in 0..7 {
        for j in 0..5 {
            for depth in [0.1, 0.5, 0.9] {
                let (x, y) = (0.05 + 0.9 * i as f32 / 6.0, 0.05 + 0.9 * j as f32 / 4.0);
                let d = camera.near + depth * (camera.far - camera.near);
                let ray = camera.ray_through(x * camera.width as f32, y * camera.height as f32);
                let along = d / ray.direction.dot(-frame.ze).max(1e-6);
                points.push(ray.at(if camera.projection == Projection::Perspective { along } else { d }));
            }
        }
    }
    points
}

#[test]
fn seed_simple_window_follows_the_notes() {
    let camera = seed_camera();
    // h = 2·near·tan(fovy/2) = 2·30·tan 45° = 60, and the image is square.
    let (w, h) = camera.window();
    assert!((h - 60.0).abs() < 1e-4 && (w - 60.0).abs() < 1e-4, "window {w}×{h}");
    let frame = camera.frame();
    let ze = Vec3::new(100.0, 40.0, 40.0).normalize();
    assert!(frame.ze.abs_diff_eq(ze, 1e-6));
    assert!(frame.xe.abs_diff_eq(Vec3::Y.cross(ze).normalize(), 1e-6));
    // The image centre (115, 115) is the point eye − near·ze, straight ahead.
    let centre = camera.window_point(115.0, 115.0);
    assert!(centre.abs_diff_eq(camera.eye - 30.0 * ze, 1e-4), "{centre}");
    // Pixel (0, 0)'s centre is half a pixel (60/230/2) in from the window's top-left corner.
    let corner = camera.eye - 30.0 * frame.ze - 30.0 * frame.xe + 30.0 * frame.ye;
    let half = 60.0 / 230.0 / 2.0;
    assert!(camera.window_point(0.5, 0.5).abs_diff_eq(corner + half * frame.xe - half * frame.ye, 1e-4));
}

#[test]
fn a_projected_point_lies_on_the_centre_ray_of_its_pixel() {
    for camera in [seed_camera(), orthographic()] {
        for p in points_in_view(&camera) {
            let projected = camera.project(p).expect("the point is in front of the camera");
            assert!((0.0..=1.0).contains(&projected.z), "depth {} outside [0, 1]", projected.z);
            let ray = camera.ray_through(projected.x, projected.y);
            let t = (p - ray.origin).dot(ray.direction);
            let miss = (ray.at(t) - p).length();
            assert!(miss < 1e-4 * (p - camera.eye).length(), "{:?}: ray misses {p} by {miss}", camera.projection);
        }
    }
}

#[test]
fn pixel_centres_project_to_half_integers() {
    for camera in [seed_camera(), orthographic()] {
        for (i, j) in [(0, 0), (17, 3), (camera.width - 1, camera.height - 1)] {
            let ray = camera.primary_ray(i, j);
            let p = ray.at(camera.near * 2.0);
            let projected = camera.project(p).expect("in front");
            let expected = Vec2::new(i as f32 + 0.5, j as f32 + 0.5);
            assert!(
                projected.truncate().abs_diff_eq(expected, 2e-3),
                "{:?}: {projected} vs {expected}",
                camera.projection
            );
        }
    }
}

#[test]
fn depth_is_zero_at_near_and_one_at_far() {
    for camera in [seed_camera(), orthographic()] {
        let ahead = -camera.frame().ze;
        let at_near = camera.project(camera.eye + camera.near * ahead).unwrap();
        let at_far = camera.project(camera.eye + camera.far * ahead).unwrap();
        assert!(at_near.z.abs() < 1e-5 && (at_far.z - 1.0).abs() < 1e-5, "{at_near} {at_far}");
    }
}

#[test]
fn degenerate_cameras_are_rejected() {
    let good = seed_camera();
    let cases = [
        (Camera { center: good.eye, ..good.clone() }, CameraError::EyeAtCenter),
        (Camera { up: good.eye - good.center, ..good.clone() }, CameraError::UpParallelToView),
        (Camera { fovy_degrees: 180.0, ..good.clone() }, CameraError::FieldOfView(180.0)),
        (Camera { near: 0.0, ..good.clone() }, CameraError::ClipDistances { near: 0.0, far: 230.0 }),
        (Camera { width: 0, ..good.clone() }, CameraError::EmptyImage { width: 0, height: 230 }),
        (Camera { eye: Vec3::new(f32::NAN, 0.0, 0.0), ..good.clone() }, CameraError::NotFinite),
    ];
    for (camera, expected) in cases {
        assert_eq!(camera.validate(), Err(expected));
    }
    assert_eq!(good.validate(), Ok(()));
}

/// End to end on the GPU: a small glowing sphere drawn by the rasterizer lights the pixels around
/// the point the CPU camera projects its centre to.
#[test]
fn the_rasterizer_puts_a_point_where_the_camera_projects_it() {
    let text = r#"
        [camera]
        eye = [100, 40, 40]
        center = [0, 0, 0]
        fovy = 90
        near = 30
        far = 230
        width = 230
        height = 180
        [world]
        ambient = [0, 0, 0]
        [materials.glow]
        color = [0, 0, 0]
        emission = [1, 1, 1]
        [[objects]]
        type = "sphere"
        center = [-20, 25, -30]
        radius = 3
        material = "glow"
    "#;
    let scene = mirador::scene::file::parse(text, std::path::Path::new("dot.toml")).unwrap();
    let image = common::raster(&scene, &scene.settings);
    let (mut sum, mut weight) = (Vec2::ZERO, 0.0);
    for (x, y, p) in image.enumerate_pixels() {
        let w = f32::from(p[0]) / 255.0;
        sum += w * Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        weight += w;
    }
    assert!(weight > 12.0, "the sphere covers a few pixels, found weight {weight}");
    let centroid = sum / weight;
    let expected = scene.camera.project(Vec3::new(-20.0, 25.0, -30.0)).unwrap().truncate();
    assert!(centroid.abs_diff_eq(expected, 0.25), "lit pixels centre on {centroid}, camera projects to {expected}");
}
