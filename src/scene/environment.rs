//! Environment maps (docs/course/08-environment-maps.md): the world beyond the scene as a radiance
//! that depends only on direction, `L_env(d)`, infinitely far away. A ray that hits nothing sees
//! `intensity · L_env(d)`; a mirror shows `kps·MPS·L_env(r)` for its reflected direction `r`.
//!
//! The radiance is a procedural [`Sky`] or an image in one of the three parameterisations the
//! seed names, each a map from direction to image coordinates `(u, v)`, `v = 0` the top row:
//!
//! - **Cube (box) map** ([`cube_face_uv`]): the direction's largest component picks one of six
//!   square faces, and the other two, divided by it, give the point on that face. Faces are in
//!   wgpu/Vulkan layer order `+X −X +Y −Y +Z −Z` and oriented as in the Vulkan/OpenGL table, so
//!   the GPU's cube texture and this code read the same texel.
//! - **Sphere map** ([`sphere_map_uv`], OpenGL's `GL_SPHERE_MAP`): the image of a mirrored ball
//!   seen orthographically along −Z; the pixel at the ball's normal `n` holds the radiance of the
//!   direction `n` reflects −Z into. It covers every direction, but the one straight behind the
//!   ball (`(0, 0, −1)`) is smeared over the whole rim.
//! - **Latitude–longitude** ([`latlong_uv`], the notes' `α = a·u, β = b·v`): longitude
//!   `α = 2π·u`, angle from +Y `β = π·v`, the equirectangular layout of photographed HDRs. Texels
//!   crowd together near the poles.
//!
//! Images are sampled bilinearly with texel centres at `(i + ½)/width`; lat–long wraps in `u`.
//! Known limit: a cube face is sampled on its own, clamped at its edges, while the GPU's cube
//! sampling is seamless across faces; the two differ only within half a texel of a face edge.

use std::f32::consts::{PI, TAU};
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::SceneError;
use crate::output::srgb_decode;

/// A linear-radiance image, row 0 at the top, texel (x, y) at `texels[y * width + x]`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvImage {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

impl EnvImage {
    /// An image whose texel `(x, y)` is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> Vec3) -> EnvImage {
        let texels = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
        EnvImage { width, height, texels }
    }

    /// The lat–long image of `radiance`, each texel the radiance towards its centre.
    pub fn latlong_from(width: u32, height: u32, radiance: impl Fn(Vec3) -> Vec3) -> EnvImage {
        EnvImage::from_fn(width, height, |x, y| {
            let uv = Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
            radiance(latlong_direction(uv))
        })
    }

    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        self.texels[(y * self.width + x) as usize]
    }

    /// The bilinear sample at `uv` (texel centres at `(i + ½)/width`): `u` wraps around when
    /// `wrap_u` (lat–long), else clamps to the edge texels, as `v` always does.
    pub fn bilinear(&self, uv: Vec2, wrap_u: bool) -> Vec3 {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // `as` saturates and maps NaN to 0: a NaN coordinate (from a zero direction) gives NaN, never
        // an index out of bounds.
        let column = |i: i64| if wrap_u { i.rem_euclid(w) } else { i.clamp(0, w - 1) };
        let row = |j: i64| j.clamp(0, h - 1);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let at = |i: i64, j: i64| self.texels[(row(j) * w + column(i)) as usize];
        let top = at(x0, y0).lerp(at(x0 + 1, y0), fx);
        let bottom = at(x0, y0 + 1).lerp(at(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
}

/// A procedural clear sky: a zenith-to-horizon gradient above, a horizon-to-ground one below,
/// and a sun disc with a soft edge. The GPU evaluates the same formula ([`Sky::radiance`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Sky {
    pub zenith: Vec3,
    pub horizon: Vec3,
    pub ground: Vec3,
    /// Unit, towards the sun.
    pub sun_direction: Vec3,
    pub sun_color: Vec3,
    /// The sun's angular radius, radians.
    pub sun_radius: f32,
}

impl Default for Sky {
    /// A day sky, the sun 50° up, to the right of and behind a camera that looks along −Z, so it
    /// lights the faces that camera sees.
    fn default() -> Sky {
        Sky {
            zenith: Vec3::new(0.25, 0.45, 0.85),
            horizon: Vec3::new(0.8, 0.85, 0.9),
            ground: Vec3::new(0.3, 0.27, 0.23),
            sun_direction: Vec3::new(0.4, 0.6, 0.3).normalize(),
            sun_color: Vec3::new(20.0, 18.0, 15.0),
            sun_radius: 1.5f32.to_radians(),
        }
    }
}

/// WGSL's `smoothstep`: `t²(3 − 2t)`, `t = clamp((x − e0)/(e1 − e0), 0, 1)`.
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Sky {
    /// With `d` normalised and `y = d.y`:
    ///
    /// ```text
    /// y ≥ 0:  c = zenith + (horizon − zenith)·(1 − y)³
    /// y < 0:  c = ground + (horizon − ground)·(1 + y)⁸
    /// c += sun_color · smoothstep(cos(1.5·sun_radius), cos(sun_radius), d·sun_direction)
    /// ```
    ///
    /// The sky fades into the horizon slowly, the ground quickly, so the horizon is a bright
    /// band; the sun is full inside its radius and fades to nothing at 1.5 radii.
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        let d = direction.normalize();
        let y = d.y;
        let mut c = if y >= 0.0 {
            self.zenith + (self.horizon - self.zenith) * (1.0 - y).powi(3)
        } else {
            self.ground + (self.horizon - self.ground) * (1.0 + y).powi(8)
        };
        let sun = smoothstep((1.5 * self.sun_radius).cos(), self.sun_radius.cos(), d.dot(self.sun_direction));
        c += self.sun_color * sun;
        c
    }
}

/// Where the radiance comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSource {
    Sky(Sky),
    /// A latitude–longitude image ([`latlong_uv`]), 2:1.
    LatLong(EnvImage),
    /// Six square faces of equal size, in [`CUBE_FACES`] order.
    Cube(Box<[EnvImage; 6]>),
    /// A sphere map ([`sphere_map_uv`]) for a camera looking along world −Z with +Y up, so view
    /// space is world space: the image's centre holds the radiance from +Z (behind that camera),
    /// its rim the radiance from −Z.
    Sphere(EnvImage),
}

impl EnvironmentSource {
    /// The radiance from `direction` (not necessarily unit).
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        match self {
            EnvironmentSource::Sky(sky) => sky.radiance(direction),
            EnvironmentSource::LatLong(image) => image.bilinear(latlong_uv(direction), true),
            EnvironmentSource::Cube(faces) => {
                let (face, uv) = cube_face_uv(direction);
                faces[face].bilinear(uv, false)
            }
            EnvironmentSource::Sphere(image) => image.bilinear(sphere_map_uv(direction), false),
        }
    }
}

/// The scene's environment: the radiance of rays that hit nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub source: EnvironmentSource,
    /// Scales the source's radiance (≥ 0).
    pub intensity: f32,
    /// The file it came from, for messages; `None` for a sky or an environment built in code.
    pub path: Option<PathBuf>,
}

impl Environment {
    /// `intensity × source` towards `direction`, which need not be unit (but not zero).
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        self.intensity * self.source.radiance(direction)
    }
}

// ---------------------------------------------------------------------------------------------
// The three parameterisations, each with its inverse.

/// Cube faces in wgpu/Vulkan layer order: layer `i` of a cube texture is face `CUBE_FACES[i]`.
pub const CUBE_FACES: [&str; 6] = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"];

/// The cube face `d` points into and the point on it, `v = 0` the face image's top row.
///
/// The major axis is the component of largest magnitude; on a tie X wins over Y, Y over Z (a
/// direction through a cube edge or corner lies on both faces' borders, and both give it). Then,
/// by the Vulkan/OpenGL table,
///
/// ```text
/// face  sc   tc   ma        u = (sc/|ma| + 1)/2
/// +X    −z   −y   x         v = (tc/|ma| + 1)/2
/// −X    +z   −y   x
/// +Y    +x   +z   y
/// −Y    +x   −z   y
/// +Z    +x   −y   z
/// −Z    −x   −y   z
/// ```
///
/// The table is left-handed: the four side faces are upright (+Y at the top), but each face seen
/// from inside the cube is mirrored left to right, as in every cube map made for OpenGL, Vulkan
/// or Direct3D.
pub fn cube_face_uv(d: Vec3) -> (usize, Vec2) {
    let a = d.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 { (0, -d.z, -d.y, a.x) } else { (1, d.z, -d.y, a.x) }
    } else if a.y >= a.z {
        if d.y >= 0.0 { (2, d.x, d.z, a.y) } else { (3, d.x, -d.z, a.y) }
    } else if d.z >= 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    (face, Vec2::new((sc / ma + 1.0) / 2.0, (tc / ma + 1.0) / 2.0))
}

/// The unit direction through point `uv` of cube face `face` (`0..6`, [`CUBE_FACES`]): the
/// inverse of [`cube_face_uv`].
pub fn cube_direction(face: usize, uv: Vec2) -> Vec3 {
    let (sc, tc) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    let d = match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        5 => Vec3::new(-sc, -tc, -1.0),
        _ => panic!("cube face {face} is not one of 0..6"),
    };
    d.normalize()
}

/// Sphere-map coordinates of a view-space reflection vector (OpenGL's `GL_SPHERE_MAP`: viewer
/// looking along −Z, +Y up), normalised first:
///
/// ```text
/// m = 2·sqrt(rx² + ry² + (rz + 1)²),  s = rx/m + ½,  t = ry/m + ½,  uv = (s, 1 − t)
/// ```
///
/// `(s, t)` is the point of the ball whose normal is halfway between `r` and +Z (towards the
/// viewer). `r = (0, 0, −1)`, straight away from the viewer, is the whole rim; it is given the
/// rim's top point, `(½, 0)`.
pub fn sphere_map_uv(r_view: Vec3) -> Vec2 {
    let r = r_view.normalize();
    let m = 2.0 * (r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0)).sqrt();
    if m < 1e-12 {
        return Vec2::new(0.5, 0.0);
    }
    Vec2::new(r.x / m + 0.5, 0.5 - r.y / m)
}

/// The unit view-space direction sphere-map point `uv` holds, or `None` outside the ball (the
/// unit disk): the inverse of [`sphere_map_uv`]. With `x = 2u − 1`, `y = 1 − 2v`, the ball's
/// normal is `n = (x, y, sqrt(1 − x² − y²))` and the view ray −Z reflects to
/// `r = (2·nz·nx, 2·nz·ny, 2·nz² − 1)`.
pub fn sphere_map_direction(uv: Vec2) -> Option<Vec3> {
    let (x, y) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    let rho2 = x * x + y * y;
    if rho2 > 1.0 {
        return None;
    }
    let nz = (1.0 - rho2).sqrt();
    Some(Vec3::new(2.0 * nz * x, 2.0 * nz * y, 2.0 * nz * nz - 1.0))
}

/// Lat–long coordinates of a direction (normalised first): `β = acos(d.y)` from +Y, longitude
/// `α = atan2(−d.x, d.z)` in `[0, 2π)`, `uv = (α/2π, β/π)`. The image's centre (`u = ½`) looks
/// along −Z, `u` grows towards +X, and the top row is straight up.
pub fn latlong_uv(d: Vec3) -> Vec2 {
    let d = d.normalize();
    let beta = d.y.clamp(-1.0, 1.0).acos();
    let mut alpha = (-d.x).atan2(d.z);
    if alpha < 0.0 {
        alpha += TAU;
    }
    Vec2::new(alpha / TAU, beta / PI)
}

/// The unit direction of lat–long point `uv`, the inverse of [`latlong_uv`]: with `α = 2π·u`,
/// `β = π·v`, `d = (−sin β·sin α, cos β, sin β·cos α)`.
pub fn latlong_direction(uv: Vec2) -> Vec3 {
    let (alpha, beta) = (TAU * uv.x, PI * uv.y);
    Vec3::new(-beta.sin() * alpha.sin(), beta.cos(), beta.sin() * alpha.cos())
}

// ---------------------------------------------------------------------------------------------
// Cube faces laid out in one image.

/// Where each face sits in an image of faces: (column, row) in face units, in [`CUBE_FACES`] order.
type FaceCells = [(u32, u32); 6];

/// Where each face sits in a horizontal cross, in face units (column, row):
///
/// ```text
///        +Y
///    −X  +Z  +X  −Z
///        −Y
/// ```
///
/// Each face's edges meet its neighbours' across the cross's seams, folded back into a cube.
const HORIZONTAL_CROSS: FaceCells = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];

/// The vertical cross (3 × 4 faces): the horizontal one with −Z moved below −Y, turned 180° so
/// that its edge meets −Y's.
const VERTICAL_CROSS: FaceCells = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (1, 3)];

/// The six faces as one horizontal cross, `4s × 3s` for faces of side `s`, black where there is no
/// face: the cube unfolded, for looking at.
pub fn unfold_cross(faces: &[EnvImage; 6]) -> EnvImage {
    let s = faces[0].width;
    let mut cross = EnvImage { width: 4 * s, height: 3 * s, texels: vec![Vec3::ZERO; (12 * s * s) as usize] };
    for (face, &(column, row)) in faces.iter().zip(HORIZONTAL_CROSS.iter()) {
        for y in 0..s {
            for x in 0..s {
                cross.texels[((row * s + y) * 4 * s + column * s + x) as usize] = face.texel(x, y);
            }
        }
    }
    cross
}

/// The six faces of a horizontal cross (4:3), a vertical cross (3:4, −Z at the bottom turned
/// 180°), or a strip of the faces in [`CUBE_FACES`] order, side by side (6:1) or stacked (1:6).
/// Any other shape is an error saying why.
pub fn fold_cross(image: &EnvImage) -> Result<Box<[EnvImage; 6]>, String> {
    let (w, h) = (image.width, image.height);
    // (columns, rows, cells) of each layout.
    let layouts: [(u32, u32, FaceCells); 4] = [
        (4, 3, HORIZONTAL_CROSS),
        (3, 4, VERTICAL_CROSS),
        (6, 1, [(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (5, 0)]),
        (1, 6, [(0, 0), (0, 1), (0, 2), (0, 3), (0, 4), (0, 5)]),
    ];
    let Some(&(columns, _, cells)) = layouts.iter().find(|(c, r, _)| w * r == h * c && w % c == 0 && w > 0) else {
        return Err(format!(
            "the image is {w}×{h}; a cube map in one image must be a horizontal cross (4:3), a vertical \
             cross (3:4) or a strip of six faces (6:1 or 1:6), its sides divisible into square faces"
        ));
    };
    let s = w / columns;
    let face = |index: usize| {
        let (column, row) = cells[index];
        let turned = columns == 3 && index == 5;
        EnvImage::from_fn(s, s, |x, y| {
            let (x, y) = if turned { (s - 1 - x, s - 1 - y) } else { (x, y) };
            image.texel(column * s + x, row * s + y)
        })
    };
    Ok(Box::new(std::array::from_fn(face)))
}

// ---------------------------------------------------------------------------------------------
// Loading images.

/// Decodes an environment image: `.hdr` (and any floating-point format) as linear radiance,
/// 8- and 16-bit formats (PNG, JPEG) as sRGB, decoded to linear. Size and memory limits are the
/// textures' ([`super::texture::decode`]); an image over the largest texture is downscaled with a
/// warning. Non-finite and negative texels are repaired to 0 with a warning ([`from_image`]).
pub fn load_image(path: &Path) -> Result<EnvImage, SceneError> {
    let error = |message: String| SceneError::Texture { path: path.to_path_buf(), message };
    super::check_regular_file(path).map_err(|e| error(format!("cannot open: {e}")))?;
    let reader = crate::files::image_reader(path).map_err(|e| error(format!("cannot read: {e}")))?;
    Ok(from_image(path, super::texture::decode(reader).map_err(error)?))
}

/// Converts a decoded image to linear radiance (see [`load_image`]); `path` names it in warnings.
/// A large image is downscaled in its own format first, so that the 32-bit float copy is made
/// of the smaller image.
pub fn from_image(path: &Path, image: image::DynamicImage) -> EnvImage {
    let linear = matches!(image, image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_));
    let (width, height) = (image.width(), image.height());
    let image = match super::texture::fitted_size(width, height) {
        Some((w, h)) => {
            log::warn!(
                "{}: the environment image is {width}×{height}, larger than the largest texture; downscaled to \
                 {w}×{h}",
                path.display()
            );
            super::texture::downscaled(image, w, h)
        }
        None => image,
    };
    let rgb = image.into_rgb32f();
    let (width, height) = rgb.dimensions();
    let mut texels: Vec<Vec3> = rgb
        .pixels()
        .map(|p| {
            let c = Vec3::from_array(p.0);
            if linear { c } else { c.to_array().map(srgb_decode).into() }
        })
        .collect();
    repair(path, &mut texels);
    EnvImage { width, height, texels }
}

/// Sets NaN, infinite and negative texel components to 0, which would otherwise spread through
/// bilinear filtering and every mirror that sees them; warns with their count.
fn repair(path: &Path, texels: &mut [Vec3]) {
    let (mut non_finite, mut negative) = (0usize, 0usize);
    for texel in texels.iter_mut() {
        if !texel.is_finite() {
            non_finite += 1;
        } else if texel.min_element() < 0.0 {
            negative += 1;
        } else {
            continue;
        }
        *texel = Vec3::from_array(texel.to_array().map(|c| if c.is_finite() && c > 0.0 { c } else { 0.0 }));
    }
    if non_finite > 0 {
        log::warn!("{}: {non_finite} texels are NaN or infinite; their bad components are set to 0", path.display());
    }
    if negative > 0 {
        log::warn!("{}: {negative} texels are negative; their negative components are set to 0", path.display());
    }
}

/// A lat–long image from a file; its aspect must be 2:1.
pub fn load_latlong(path: &Path) -> Result<EnvImage, SceneError> {
    let image = load_image(path)?;
    if image.width != 2 * image.height {
        return Err(SceneError::Texture {
            path: path.into(),
            message: format!(
                "a lat–long environment must be twice as wide as tall (2:1), got {}×{}",
                image.width, image.height
            ),
        });
    }
    Ok(image)
}

/// A sphere map from a file; it must be square.
pub fn load_sphere(path: &Path) -> Result<EnvImage, SceneError> {
    let image = load_image(path)?;
    if image.width != image.height {
        return Err(SceneError::Texture {
            path: path.into(),
            message: format!("a sphere map must be square, got {}×{}", image.width, image.height),
        });
    }
    Ok(image)
}

/// A cube map from six files in [`CUBE_FACES`] order: square faces of one size.
pub fn load_cube(paths: &[PathBuf; 6]) -> Result<Box<[EnvImage; 6]>, SceneError> {
    let mut faces = Vec::with_capacity(6);
    for (i, path) in paths.iter().enumerate() {
        let face = load_image(path)?;
        let bad = |message: String| SceneError::Texture { path: path.clone(), message };
        if face.width != face.height {
            return Err(bad(format!("cube face {} must be square, got {}×{}", CUBE_FACES[i], face.width, face.height)));
        }
        if let Some(first) = faces.first().map(|f: &EnvImage| f.width).filter(|&s| s != face.width) {
            return Err(bad(format!(
                "cube face {} is {}×{}, but face {} is {first}×{first}; all six must be the same size",
                CUBE_FACES[i], face.width, face.height, CUBE_FACES[0]
            )));
        }
        faces.push(face);
    }
    Ok(Box::new(faces.try_into().expect("six paths give six faces")))
}

/// A cube map from one image: a cross or a strip ([`fold_cross`]).
pub fn load_cross(path: &Path) -> Result<Box<[EnvImage; 6]>, SceneError> {
    fold_cross(&load_image(path)?).map_err(|message| SceneError::Texture { path: path.into(), message })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` directions spread evenly over the sphere (a Fibonacci lattice), off the axes.
    fn directions(n: usize) -> impl Iterator<Item = Vec3> {
        let golden = PI * (3.0 - 5f32.sqrt());
        (0..n).map(move |i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
    }

    fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
        a.abs_diff_eq(b, eps)
    }

    #[test]
    fn each_axis_looks_at_its_face_centre() {
        let axes = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
        for (face, axis) in axes.into_iter().enumerate() {
            assert_eq!(cube_face_uv(3.0 * axis), (face, Vec2::splat(0.5)), "{}", CUBE_FACES[face]);
            assert!(close(cube_direction(face, Vec2::splat(0.5)), axis, 1e-6));
        }
    }

    #[test]
    fn cube_texels_by_hand() {
        // +X face: sc = −z, tc = −y, so its top-left corner (0, 0) is where z and y are +1.
        assert!(close(cube_direction(0, Vec2::ZERO), Vec3::ONE.normalize(), 1e-6));
        // +Y face: sc = +x, tc = +z: top-left is (−1, 1, −1), bottom-right (1, 1, 1).
        assert!(close(cube_direction(2, Vec2::ZERO), Vec3::new(-1.0, 1.0, -1.0).normalize(), 1e-6));
        assert!(close(cube_direction(2, Vec2::ONE), Vec3::ONE.normalize(), 1e-6));
        // −Z face: sc = −x, tc = −y: u grows towards −x, the face seen from inside is upright.
        assert!(close(cube_direction(5, Vec2::new(1.0, 0.5)), Vec3::new(-1.0, 0.0, -1.0).normalize(), 1e-6));
        // +Z: halfway to the right edge and a quarter from the top.
        let (face, uv) = cube_face_uv(Vec3::new(0.5, 0.5, 1.0));
        assert_eq!(face, 4);
        assert!(uv.abs_diff_eq(Vec2::new(0.75, 0.25), 1e-6), "{uv}");
    }

    #[test]
    fn cube_edges_and_corners_sit_on_face_borders_and_round_trip() {
        // Ties go X, then Y, then Z.
        let cases = [
            (Vec3::new(1.0, 1.0, 0.0), 0, Vec2::new(0.5, 0.0)),
            (Vec3::new(1.0, 1.0, 1.0), 0, Vec2::new(0.0, 0.0)),
            (Vec3::new(-1.0, 1.0, -1.0), 1, Vec2::new(0.0, 0.0)),
            (Vec3::new(0.0, -1.0, 1.0), 3, Vec2::new(0.5, 0.0)),
            (Vec3::new(0.0, 1.0, -1.0), 2, Vec2::new(0.5, 0.0)),
        ];
        for (d, face, uv) in cases {
            let (f, got) = cube_face_uv(d);
            assert_eq!(f, face, "{d}");
            assert!(got.abs_diff_eq(uv, 1e-6), "{d}: {got} vs {uv}");
            assert!(close(cube_direction(f, got), d.normalize(), 1e-6), "{d}");
        }
        // On a tie the other face gives the same direction from its own border.
        assert!(close(cube_direction(2, Vec2::new(1.0, 0.5)), Vec3::new(1.0, 1.0, 0.0).normalize(), 1e-6));
        assert!(close(cube_direction(4, Vec2::new(1.0, 0.0)), Vec3::ONE.normalize(), 1e-6));
    }

    #[test]
    fn cube_direction_inverts_cube_face_uv() {
        for d in directions(2000) {
            let d = d * 2.5;
            let (face, uv) = cube_face_uv(d);
            assert!(uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all(), "{d}: {uv}");
            assert!(close(cube_direction(face, uv), d.normalize(), 1e-5), "{d}");
        }
    }

    #[test]
    fn texels_across_the_cross_seams_look_the_same_way() {
        let s = 8;
        let faces: [EnvImage; 6] = std::array::from_fn(|face| {
            EnvImage::from_fn(s, s, |x, y| {
                cube_direction(face, Vec2::new((x as f32 + 0.5) / s as f32, (y as f32 + 0.5) / s as f32))
            })
        });
        let cross = unfold_cross(&faces);
        assert_eq!((cross.width, cross.height), (4 * s, 3 * s));
        assert_eq!(cross.texel(0, 0), Vec3::ZERO, "outside the cross is black");
        // Each texel holds its own direction: any two side by side across a face border inside
        // the cross are one texel apart on the cube, far less than a face (90°) apart.
        let texel_angle = 2.0 * (1.0 / s as f32).atan();
        let mut seams = 0;
        for y in 0..cross.height {
            for x in 0..cross.width {
                let a = cross.texel(x, y);
                for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                    if nx >= cross.width || ny >= cross.height {
                        continue;
                    }
                    let b = cross.texel(nx, ny);
                    if a == Vec3::ZERO || b == Vec3::ZERO {
                        continue;
                    }
                    if nx % s == 0 && nx != x || ny % s == 0 && ny != y {
                        seams += 1;
                    }
                    assert!(a.angle_between(b) < 1.01 * texel_angle, "({x}, {y}) → ({nx}, {ny})");
                }
            }
        }
        assert_eq!(seams, 5 * s, "+Z meets +Y, −Y, −X and +X inside the cross, and +X meets −Z");
        let folded = fold_cross(&cross).unwrap();
        assert_eq!(*folded, faces);
    }

    #[test]
    fn vertical_crosses_and_strips_fold_to_the_same_faces() {
        let s = 3;
        let faces: [EnvImage; 6] =
            std::array::from_fn(|f| EnvImage::from_fn(s, s, |x, y| Vec3::new(f as f32, x as f32, y as f32)));
        let strip = EnvImage::from_fn(6 * s, s, |x, y| faces[(x / s) as usize].texel(x % s, y));
        let column = EnvImage::from_fn(s, 6 * s, |x, y| faces[(y / s) as usize].texel(x, y % s));
        let horizontal = unfold_cross(&faces);
        let vertical = EnvImage::from_fn(3 * s, 4 * s, |x, y| {
            if y >= 3 * s {
                // −Z below −Y, turned 180°.
                if (s..2 * s).contains(&x) { faces[5].texel(2 * s - 1 - x, 4 * s - 1 - y) } else { Vec3::ZERO }
            } else {
                horizontal.texel(x, y)
            }
        });
        for image in [strip, column, vertical] {
            assert_eq!(*fold_cross(&image).unwrap(), faces, "{}×{}", image.width, image.height);
        }
        let odd = EnvImage::from_fn(5, 3, |_, _| Vec3::ZERO);
        assert!(fold_cross(&odd).unwrap_err().contains("5×3"));
    }

    #[test]
    fn sphere_map_known_values() {
        assert!(sphere_map_uv(Vec3::Z).abs_diff_eq(Vec2::splat(0.5), 1e-6));
        // r = (1, 0, 0): m = 2·√2, s = ½ + 1/(2√2) ≈ 0.853553, t = ½.
        let expected = Vec2::new(0.5 + 1.0 / (2.0 * 2f32.sqrt()), 0.5);
        assert!(sphere_map_uv(Vec3::X).abs_diff_eq(expected, 1e-6));
        // r = (0, 1, 0) is up, so above the centre: v < ½.
        assert!(sphere_map_uv(Vec3::Y).abs_diff_eq(Vec2::new(0.5, 0.5 - 1.0 / (2.0 * 2f32.sqrt())), 1e-6));
        assert_eq!(sphere_map_direction(Vec2::new(0.0, 0.0)), None, "corners are outside the ball");
        assert!(close(sphere_map_direction(Vec2::new(0.5, 0.0)).unwrap(), Vec3::NEG_Z, 1e-6), "the rim");
    }

    #[test]
    fn sphere_map_direction_inverts_sphere_map_uv() {
        for d in directions(2000).filter(|d| d.z > -0.99) {
            let uv = sphere_map_uv(3.0 * d);
            let back = sphere_map_direction(uv).unwrap();
            assert!(close(back, d, 1e-4), "{d} → {uv} → {back}");
        }
    }

    #[test]
    fn latlong_known_values_and_round_trip() {
        assert!(close(latlong_direction(Vec2::new(0.5, 0.5)), Vec3::NEG_Z, 1e-6), "the centre looks along −Z");
        assert!(close(latlong_direction(Vec2::new(0.75, 0.5)), Vec3::X, 1e-6), "u grows towards +X");
        assert!(close(latlong_direction(Vec2::new(0.0, 0.5)), Vec3::Z, 1e-6));
        assert!(close(latlong_direction(Vec2::new(0.3, 0.0)), Vec3::Y, 1e-6), "the top row is up");
        assert!(latlong_uv(Vec3::NEG_Z).abs_diff_eq(Vec2::new(0.5, 0.5), 1e-6));
        for d in directions(2000) {
            let uv = latlong_uv(2.0 * d);
            assert!((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y), "{uv}");
            assert!(close(latlong_direction(uv), d, 1e-5), "{d}");
        }
        // Either side of the seam at u = 0 = 1 lie neighbouring directions, and sampling wraps.
        let a = latlong_direction(Vec2::new(0.001, 0.5));
        let b = latlong_direction(Vec2::new(0.999, 0.5));
        assert!(a.angle_between(b) < 0.013, "{a} {b}");
        let image = EnvImage::from_fn(4, 2, |x, _| Vec3::splat(x as f32));
        // Halfway between the last column's centre and the first's (wrapped): (3 + 0)/2.
        assert!(close(image.bilinear(Vec2::new(0.0, 0.5), true), Vec3::splat(1.5), 1e-6));
        assert!(close(image.bilinear(Vec2::new(0.0, 0.5), false), Vec3::ZERO, 1e-6), "clamped");
    }

    #[test]
    fn bilinear_reads_texel_centres_exactly_and_blends_between() {
        let image = EnvImage::from_fn(4, 4, |x, y| Vec3::new(x as f32, y as f32, 1.0));
        assert_eq!(image.bilinear(Vec2::new(1.5 / 4.0, 2.5 / 4.0), false), Vec3::new(1.0, 2.0, 1.0));
        assert!(close(image.bilinear(Vec2::new(0.5, 0.5), false), Vec3::new(1.5, 1.5, 1.0), 1e-6));
        assert!(close(image.bilinear(Vec2::new(1.0, 1.0), false), Vec3::new(3.0, 3.0, 1.0), 1e-6));
        // A NaN coordinate (a zero direction) is NaN radiance, not an index out of bounds.
        assert!(image.bilinear(Vec2::NAN, true).is_nan() && image.bilinear(Vec2::NAN, false).is_nan());
        assert!(
            Environment { source: EnvironmentSource::LatLong(image), intensity: 1.0, path: None }
                .radiance(Vec3::ZERO)
                .is_nan()
        );
    }

    #[test]
    fn sky_known_values() {
        let sky = Sky { sun_direction: Vec3::new(1.0, 1.0, 0.0).normalize(), ..Sky::default() };
        assert!(close(sky.radiance(Vec3::Y * 2.0), sky.zenith, 1e-6), "straight up is the zenith");
        assert!(close(sky.radiance(Vec3::NEG_Z), sky.horizon, 1e-6), "level is the horizon");
        assert!(close(sky.radiance(Vec3::NEG_Y), sky.ground, 1e-6), "straight down is the ground");
        // Halfway up (y = ½): zenith + (horizon − zenith)/8.
        let half_up = Vec3::new(0.0, 0.5, -(0.75f32).sqrt());
        assert!(close(sky.radiance(half_up), sky.zenith + (sky.horizon - sky.zenith) / 8.0, 1e-5));
        // Towards the sun: the sky there plus the full sun.
        let y = sky.sun_direction.y;
        let under_sun = sky.zenith + (sky.horizon - sky.zenith) * (1.0 - y).powi(3);
        assert!(close(sky.radiance(sky.sun_direction), under_sun + sky.sun_color, 1e-4));
        // At 1.5 sun radii the sun is gone; where the cosine is halfway between those of 1 and
        // 1.5 radii, half of it is there.
        let away = Vec3::Z.cross(sky.sun_direction).normalize();
        let sky_only = |angle: f32| {
            let d = sky.sun_direction * angle.cos() + away * angle.sin();
            (d, sky.zenith + (sky.horizon - sky.zenith) * (1.0 - d.y).powi(3))
        };
        let r = sky.sun_radius;
        let (d, c) = sky_only(1.5 * r + 1e-3);
        assert!(close(sky.radiance(d), c, 1e-4), "no sun beyond 1.5 radii");
        let (d, c) = sky_only((((1.5 * r).cos() + r.cos()) / 2.0).acos());
        assert!(close(sky.radiance(d), c + 0.5 * sky.sun_color, 2e-2), "half the sun");
        assert!((smoothstep(0.0, 1.0, 0.5) - 0.5).abs() < 1e-7 && smoothstep(0.0, 1.0, 2.0) == 1.0);
    }

    #[test]
    fn environment_scales_by_intensity() {
        let environment = Environment { source: EnvironmentSource::Sky(Sky::default()), intensity: 2.0, path: None };
        assert!(close(environment.radiance(Vec3::Y), 2.0 * Sky::default().zenith, 1e-6));
    }

    #[test]
    fn non_finite_and_negative_texels_are_set_to_zero() {
        let mut hdr = image::Rgb32FImage::from_pixel(4, 2, image::Rgb([1.0, 2.0, 3.0]));
        hdr.put_pixel(1, 0, image::Rgb([f32::NAN, 0.5, 0.5]));
        hdr.put_pixel(2, 1, image::Rgb([f32::INFINITY, -1.0, 0.5]));
        hdr.put_pixel(3, 1, image::Rgb([-2.0, 0.25, 0.5]));
        let image = from_image(Path::new("nan.hdr"), image::DynamicImage::ImageRgb32F(hdr));
        assert_eq!(image.texel(1, 0), Vec3::new(0.0, 0.5, 0.5));
        assert_eq!(image.texel(2, 1), Vec3::new(0.0, 0.0, 0.5));
        assert_eq!(image.texel(3, 1), Vec3::new(0.0, 0.25, 0.5));
        assert_eq!(image.texel(0, 0), Vec3::new(1.0, 2.0, 3.0), "HDR texels are linear, kept as they are");
        let png = image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(2, 1, image::Rgb([255, 188, 0])));
        let image = from_image(Path::new("srgb.png"), png);
        assert!(close(image.texel(0, 0), Vec3::new(1.0, srgb_decode(188.0 / 255.0), 0.0), 1e-6), "8-bit is sRGB");
    }
}
