//! Scene files: TOML, documented field by field in `docs/scene-format.md`.
//!
//! Every value is checked while it is read, so a bad number is reported at its own line and column
//! (`showcase.toml:12:10: expected a finite number, got nan`); rules that tie several fields
//! together (a sphere needs a radius, eye ≠ center) are reported at the table they belong to.
//! Unknown fields are rejected. Paths are relative to the scene file.

pub mod copy;
mod locate;
pub mod overrides;
mod volume;

use std::collections::HashMap;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec2, Vec3};
use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use toml::Spanned;

use super::camera::{Camera, Projection};
use super::environment::{self, Environment, EnvironmentSource, Sky};
use super::gltf::{GltfCamera, GltfProjection};
use super::light::{Attenuation, Light, LightKind};
use super::material::{AlphaMode, ColorSpace, Material, ProceduralHeight, Wrap};
use super::{ModelImport, Object, Scene, SceneError, Shape, texture};
use crate::base::{MaterialId, TextureId};
use crate::settings::{Parallax, Refraction, RenderSettings};

/// Reads a scene file: TOML, or a bare model (glTF, OBJ or PLY, told by the file's extension).
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("gltf" | "glb") => return load_bare_model(path, super::gltf::import(path)?),
        Some("obj") => return load_bare_model(path, super::obj::import(path)?),
        Some("ply") => return load_bare_model(path, super::ply::import(path)?),
        _ => {}
    }
    let text = crate::files::read_to_string(path).map_err(|cause| SceneError::Io { path: path.into(), cause })?;
    parse(&text, path)
}

/// Parses scene text; `path` names the file in messages and anchors relative paths.
pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let file: SceneFile =
        toml::from_str(text).map_err(|e| Located::new(syntax_message(&e, text), e.span()).at(path, text))?;
    let mut builder = Builder::new(path, text);
    builder.build(file)
}

/// The TOML reader's message, with the key named where it names none (`duplicate key` points at
/// the key but does not say which).
fn syntax_message(error: &toml::de::Error, text: &str) -> String {
    let message = error.message();
    let key = error.span().and_then(|span| text.get(span)).map(str::trim).filter(|k| !k.is_empty());
    match key {
        Some(key) if message == "duplicate key" => format!("duplicate key `{key}`"),
        _ => message.to_string(),
    }
}

// ---------------------------------------------------------------------------------------------
// Checked values: each rejects bad input where it is read, so the error carries its location.

/// A number that must be finite (TOML allows `nan` and `inf`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Finite(f32);

impl<'de> Deserialize<'de> for Finite {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let x = f64::deserialize(d)?;
        finite(x).map(Finite).map_err(de::Error::custom)
    }
}

fn finite(x: f64) -> Result<f32, String> {
    if !x.is_finite() {
        return Err(format!("expected a finite number, got {x}"));
    }
    let y = x as f32;
    if !y.is_finite() {
        return Err(format!("{x} is too large for a 32-bit float"));
    }
    Ok(y)
}

/// A number that must be ≥ 0.
#[derive(Clone, Copy, Debug, PartialEq)]
struct NonNegative(f32);

impl<'de> Deserialize<'de> for NonNegative {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Finite(x) = Finite::deserialize(d)?;
        if x < 0.0 {
            return Err(de::Error::custom(format!("expected a number ≥ 0, got {x}")));
        }
        Ok(NonNegative(x))
    }
}

/// A fraction: a number in [0, 1] (`kt`, `kps`, coverage).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Fraction(f32);

impl<'de> Deserialize<'de> for Fraction {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Finite(x) = Finite::deserialize(d)?;
        if !(0.0..=1.0).contains(&x) {
            return Err(de::Error::custom(format!("expected a number in [0, 1], got {x}")));
        }
        Ok(Fraction(x))
    }
}

/// A number that must be > 0.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Positive(f32);

impl<'de> Deserialize<'de> for Positive {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Finite(x) = Finite::deserialize(d)?;
        if x <= 0.0 {
            return Err(de::Error::custom(format!("expected a number > 0, got {x}")));
        }
        Ok(Positive(x))
    }
}

/// Three finite numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
struct V3(Vec3);

impl<'de> Deserialize<'de> for V3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let [x, y, z] = <[f64; 3]>::deserialize(d)?;
        let v = [x, y, z].map(finite);
        match v {
            [Ok(x), Ok(y), Ok(z)] => Ok(V3(Vec3::new(x, y, z))),
            _ => Err(de::Error::custom(format!("expected three finite numbers, got [{x}, {y}, {z}]"))),
        }
    }
}

/// Two positive numbers (sizes, texture repeats).
#[derive(Clone, Copy, Debug, PartialEq)]
struct PositiveV2(Vec2);

impl<'de> Deserialize<'de> for PositiveV2 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let [x, y] = <[f64; 2]>::deserialize(d)?;
        match [x, y].map(finite) {
            [Ok(x), Ok(y)] if x > 0.0 && y > 0.0 => Ok(PositiveV2(Vec2::new(x, y))),
            _ => Err(de::Error::custom(format!("expected two finite numbers > 0, got [{x}, {y}]"))),
        }
    }
}

/// A linear RGB colour: three finite numbers ≥ 0.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rgb(Vec3);

impl<'de> Deserialize<'de> for Rgb {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let V3(c) = V3::deserialize(d)?;
        if c.min_element() < 0.0 {
            return Err(de::Error::custom(format!("colour components must be ≥ 0, got {c}")));
        }
        Ok(Rgb(c))
    }
}

/// A scale: one number for all three axes, or three.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Scale(Vec3);

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ScaleVisitor;
        impl<'de> Visitor<'de> for ScaleVisitor {
            type Value = Vec3;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or an array of three numbers")
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Vec3, E> {
                finite(x).map(Vec3::splat).map_err(E::custom)
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<Vec3, E> {
                self.visit_f64(x as f64)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Vec3, A::Error> {
                V3::deserialize(de::value::SeqAccessDeserializer::new(seq)).map(|V3(v)| v)
            }
        }
        let v = d.deserialize_any(ScaleVisitor)?;
        if v.cmpeq(Vec3::ZERO).any() {
            return Err(de::Error::custom(format!("a scale of zero flattens the object, got {v}")));
        }
        Ok(Scale(v))
    }
}

// ---------------------------------------------------------------------------------------------
// The file's shape.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: Option<Spanned<CameraDesc>>,
    #[serde(default)]
    world: WorldDesc,
    settings: Option<Spanned<RenderSettings>>,
    #[serde(default)]
    materials: std::collections::BTreeMap<String, Spanned<MaterialDesc>>,
    #[serde(default)]
    lights: Vec<Spanned<LightDesc>>,
    #[serde(default)]
    objects: Vec<Spanned<ObjectDesc>>,
    #[serde(default)]
    volumes: Vec<Spanned<volume::VolumeDesc>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDesc {
    eye: V3,
    center: V3,
    up: Option<V3>,
    fovy: Option<Finite>,
    near: Option<Finite>,
    far: Option<Finite>,
    width: Option<u32>,
    height: Option<u32>,
    projection: Option<Projection>,
    ortho_height: Option<Finite>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct WorldDesc {
    ambient: Option<Rgb>,
    background: Option<Rgb>,
    environment: Option<Spanned<EnvironmentDesc>>,
}

/// `[world.environment]`: exactly one source, and an intensity.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentDesc {
    sky: Option<SkyDesc>,
    latlong: Option<String>,
    cube: Option<[String; 6]>,
    cross: Option<String>,
    sphere: Option<String>,
    intensity: Option<NonNegative>,
}

/// `sky = { … }`: every key optional, `sun_radius` in degrees.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SkyDesc {
    zenith: Option<Rgb>,
    horizon: Option<Rgb>,
    ground: Option<Rgb>,
    sun_direction: Option<Spanned<V3>>,
    sun_color: Option<Rgb>,
    sun_radius: Option<Spanned<Finite>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialDesc {
    color: Option<Rgb>,
    texture: Option<String>,
    wrap: Option<WrapDesc>,
    ka: Option<NonNegative>,
    kd: Option<NonNegative>,
    ks: Option<NonNegative>,
    specular_color: Option<Rgb>,
    shininess: Option<NonNegative>,
    emission: Option<Rgb>,
    mirror: Option<Fraction>,
    mirror_color: Option<Rgb>,
    transmission: Option<Fraction>,
    transmission_color: Option<Rgb>,
    ior: Option<Positive>,
    height_map: Option<String>,
    height_field: Option<Spanned<HeightFieldDesc>>,
    bump_scale: Option<Finite>,
    normal_map: Option<String>,
    normal_scale: Option<Finite>,
    alpha: Option<Fraction>,
    alpha_mode: Option<AlphaModeName>,
    alpha_cutoff: Option<Spanned<Fraction>>,
}

/// `alpha_mode = "opaque" | "mask" | "blend"`, glTF's `alphaMode`.
#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "snake_case")]
enum AlphaModeName {
    Opaque,
    Mask,
    Blend,
}

impl AlphaModeName {
    /// The name the file uses for this mode, for messages.
    fn name(self) -> &'static str {
        match self {
            AlphaModeName::Opaque => "opaque",
            AlphaModeName::Mask => "mask",
            AlphaModeName::Blend => "blend",
        }
    }
}

/// `wrap = "clamp"` for both axes, or `wrap = ["repeat", "mirror"]` for u and v.
#[derive(Deserialize)]
#[serde(untagged)]
enum WrapDesc {
    Both(WrapName),
    PerAxis([WrapName; 2]),
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "snake_case")]
enum WrapName {
    Repeat,
    Clamp,
    Mirror,
}

impl From<WrapName> for Wrap {
    fn from(name: WrapName) -> Wrap {
        match name {
            WrapName::Repeat => Wrap::Repeat,
            WrapName::Clamp => Wrap::Clamp,
            WrapName::Mirror => Wrap::Mirror,
        }
    }
}

/// `height_field = { type = "sine", frequency = [8, 4], amplitude = 0.02 }` or
/// `{ type = "noise", seed = 7, cells = 4, octaves = 3, amplitude = 0.02 }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeightFieldDesc {
    #[serde(rename = "type")]
    kind: HeightFieldType,
    frequency: Option<PositiveV2>,
    amplitude: Option<Finite>,
    seed: Option<u32>,
    cells: Option<u32>,
    octaves: Option<u32>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "snake_case")]
enum HeightFieldType {
    Sine,
    Noise,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "snake_case")]
enum LightType {
    Point,
    Directional,
    Spot,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightDesc {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: LightType,
    position: Option<V3>,
    direction: Option<V3>,
    color: Option<Rgb>,
    intensity: Option<NonNegative>,
    attenuation: Option<Attenuation>,
    inner_angle: Option<NonNegative>,
    outer_angle: Option<NonNegative>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "snake_case")]
enum ObjectType {
    Sphere,
    Box,
    Plane,
    Torus,
    RoundedBox,
    Gltf,
    Obj,
    Ply,
}

impl ObjectType {
    /// The name the file uses for this type, for messages.
    fn name(self) -> &'static str {
        match self {
            ObjectType::Sphere => "sphere",
            ObjectType::Box => "box",
            ObjectType::Plane => "plane",
            ObjectType::Torus => "torus",
            ObjectType::RoundedBox => "rounded_box",
            ObjectType::Gltf => "gltf",
            ObjectType::Obj => "obj",
            ObjectType::Ply => "ply",
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectDesc {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: ObjectType,
    material: Option<Spanned<String>>,
    center: Option<V3>,
    radius: Option<Positive>,
    min: Option<V3>,
    max: Option<V3>,
    size: Option<PositiveV2>,
    major_radius: Option<Positive>,
    minor_radius: Option<Positive>,
    half_extents: Option<V3>,
    uv_scale: Option<PositiveV2>,
    path: Option<String>,
    lights: Option<bool>,
    camera: Option<bool>,
    translate: Option<V3>,
    rotate: Option<V3>,
    scale: Option<Scale>,
}

// ---------------------------------------------------------------------------------------------
// Errors with a place.

/// A message with an optional byte range in the file, turned into line and column at the end.
struct Located {
    message: String,
    span: Option<Range<usize>>,
}

impl Located {
    fn new(message: impl Into<String>, span: Option<Range<usize>>) -> Located {
        Located { message: message.into(), span }
    }

    fn at(self, path: &Path, text: &str) -> SceneError {
        match self.span {
            Some(span) => {
                let (line, column) = line_column(text, span.start);
                SceneError::Syntax { path: path.into(), line, column, message: self.message }
            }
            None => SceneError::Invalid { path: path.into(), message: self.message },
        }
    }
}

/// 1-based line and column (in characters) of a byte offset.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

// ---------------------------------------------------------------------------------------------
// From the file's shape to a Scene.

struct Builder<'a> {
    path: &'a Path,
    text: &'a str,
    dir: PathBuf,
    scene: Scene,
    material_ids: HashMap<String, MaterialId>,
    texture_ids: HashMap<(PathBuf, bool), TextureId>,
}

impl<'a> Builder<'a> {
    fn new(path: &'a Path, text: &'a str) -> Builder<'a> {
        Builder {
            path,
            text,
            dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            scene: empty_scene(path),
            material_ids: HashMap::new(),
            texture_ids: HashMap::new(),
        }
    }

    fn error(&self, message: impl Into<String>, span: Range<usize>) -> SceneError {
        Located::new(message, Some(span)).at(self.path, self.text)
    }

    fn build(&mut self, file: SceneFile) -> Result<Scene, SceneError> {
        if let Some(settings) = file.settings {
            let span = settings.span();
            settings.get_ref().validate().map_err(|e| self.error(format!("[settings]: {e}"), span))?;
            self.scene.settings = settings.into_inner();
        }
        self.scene.ambient = file.world.ambient.map_or(Vec3::splat(0.1), |Rgb(c)| c);
        self.scene.background = file.world.background.map_or(Vec3::ZERO, |Rgb(c)| c);
        if let Some(environment) = file.world.environment {
            let span = environment.span();
            if file.world.background.is_some() {
                let message = "give [world] either a `background` or an `environment`, not both";
                return Err(self.error(message, span));
            }
            self.scene.environment = Some(self.environment(environment.into_inner(), span)?);
        }
        self.materials(file.materials)?;
        for light in file.lights {
            let span = light.span();
            let light = self.light(light.into_inner(), span)?;
            self.scene.lights.push(light);
        }
        let mut gltf_camera = None;
        for object in file.objects {
            let span = object.span();
            if let Some(camera) = self.object(object.into_inner(), span.clone())? {
                gltf_camera.get_or_insert((camera, span));
            }
        }
        for volume in file.volumes {
            let span = volume.span();
            self.volume(volume.into_inner(), span)?;
        }
        let table_camera = match file.camera {
            Some(desc) => {
                let span = desc.span();
                let camera = camera_from(desc.into_inner());
                camera.validate().map_err(|e| self.error(format!("[camera]: {e}"), span))?;
                Some(camera)
            }
            None => None,
        };
        self.scene.camera = match (table_camera, gltf_camera) {
            (Some(camera), None) => camera,
            // A model's camera takes the view; the [camera] table still sets the image size.
            (table, Some((gltf, span))) => {
                let (width, height) = table.map_or((1280, 720), |c| (c.width, c.height));
                let camera = camera_from_gltf(&gltf, width, height, self.scene.bounds());
                camera.validate().map_err(|e| self.error(format!("glTF camera `{}`: {e}", gltf.name), span))?;
                camera
            }
            (None, None) => {
                let camera = frame_scene(&self.scene);
                camera.validate().map_err(|e| SceneError::Invalid {
                    path: self.path.into(),
                    message: format!("the camera framing the scene (the file has no [camera]): {e}"),
                })?;
                camera
            }
        };
        Ok(std::mem::replace(&mut self.scene, empty_scene(self.path)))
    }

    fn materials(
        &mut self,
        tables: std::collections::BTreeMap<String, Spanned<MaterialDesc>>,
    ) -> Result<(), SceneError> {
        for (name, desc) in tables {
            let span = desc.span();
            let material = self.material(&name, desc.into_inner(), span)?;
            self.material_ids.insert(name, MaterialId(self.scene.materials.len()));
            self.scene.materials.push(material);
        }
        Ok(())
    }

    fn material(&mut self, name: &str, d: MaterialDesc, span: Range<usize>) -> Result<Material, SceneError> {
        let base = Material::default();
        let texture = d.texture.map(|p| self.texture(&p, ColorSpace::Srgb, span.clone())).transpose()?;
        let height_map = d.height_map.map(|p| self.texture(&p, ColorSpace::Linear, span.clone())).transpose()?;
        let normal_map = d.normal_map.map(|p| self.texture(&p, ColorSpace::Linear, span.clone())).transpose()?;
        let height_field = match d.height_field {
            Some(field) => {
                let span = field.span();
                if height_map.is_some() {
                    return Err(self.error("give a material either a `height_map` or a `height_field`, not both", span));
                }
                Some(self.height_field(field.into_inner(), span)?)
            }
            None => None,
        };
        let mode = d.alpha_mode.unwrap_or(AlphaModeName::Opaque);
        let alpha_mode = match (mode, d.alpha_cutoff) {
            (AlphaModeName::Mask, cutoff) => {
                AlphaMode::Mask { cutoff: cutoff.map_or(AlphaMode::DEFAULT_CUTOFF, |c| c.into_inner().0) }
            }
            (_, Some(cutoff)) => {
                let message = format!(
                    "`alpha_cutoff` applies only to alpha_mode = \"mask\", and this material's is \"{}\"",
                    mode.name()
                );
                return Err(self.error(message, cutoff.span()));
            }
            (AlphaModeName::Blend, None) => AlphaMode::Blend,
            (AlphaModeName::Opaque, None) => AlphaMode::Opaque,
        };
        Ok(Material {
            name: name.into(),
            color: d.color.map_or(base.color, |Rgb(c)| c),
            texture,
            wrap: match d.wrap {
                Some(WrapDesc::Both(w)) => [w.into(); 2],
                Some(WrapDesc::PerAxis([u, v])) => [u.into(), v.into()],
                None => base.wrap,
            },
            ka: d.ka.map_or(base.ka, |NonNegative(x)| x),
            kd: d.kd.map_or(base.kd, |NonNegative(x)| x),
            ks: d.ks.map_or(base.ks, |NonNegative(x)| x),
            specular_color: d.specular_color.map_or(base.specular_color, |Rgb(c)| c),
            shininess: d.shininess.map_or(base.shininess, |NonNegative(x)| x),
            emission: d.emission.map_or(base.emission, |Rgb(c)| c),
            mirror: d.mirror.map_or(base.mirror, |Fraction(x)| x),
            mirror_color: d.mirror_color.map_or(base.mirror_color, |Rgb(c)| c),
            transmission: d.transmission.map_or(base.transmission, |Fraction(x)| x),
            transmission_color: d.transmission_color.map_or(base.transmission_color, |Rgb(c)| c),
            ior: d.ior.map_or(base.ior, |Positive(x)| x),
            height_map,
            height_field,
            bump_scale: d.bump_scale.map_or(base.bump_scale, |Finite(x)| x),
            normal_map,
            normal_scale: d.normal_scale.map_or(base.normal_scale, |Finite(x)| x),
            alpha: d.alpha.map_or(base.alpha, |Fraction(x)| x),
            alpha_mode,
        })
    }

    fn height_field(&self, d: HeightFieldDesc, span: Range<usize>) -> Result<ProceduralHeight, SceneError> {
        let fail = |message: String| self.error(message, span.clone());
        let amplitude = d.amplitude.map_or(0.05, |Finite(a)| a);
        match d.kind {
            HeightFieldType::Sine => {
                if d.seed.is_some() || d.cells.is_some() || d.octaves.is_some() {
                    return Err(fail("`seed`, `cells` and `octaves` apply to a noise field, not a sine".into()));
                }
                Ok(ProceduralHeight::Sine {
                    frequency: d.frequency.map_or(Vec2::splat(8.0), |PositiveV2(f)| f),
                    amplitude,
                })
            }
            HeightFieldType::Noise => {
                if d.frequency.is_some() {
                    return Err(fail("`frequency` applies to a sine field; a noise field has `cells`".into()));
                }
                let (cells, octaves) = (d.cells.unwrap_or(4), d.octaves.unwrap_or(3));
                if !(1..=1024).contains(&cells) || !(1..=8).contains(&octaves) {
                    return Err(fail(format!(
                        "a noise field needs 1 ≤ cells ≤ 1024 and 1 ≤ octaves ≤ 8, got {cells} and {octaves}"
                    )));
                }
                Ok(ProceduralHeight::Noise { seed: d.seed.unwrap_or(0), cells, octaves, amplitude })
            }
        }
    }

    fn texture(&mut self, relative: &str, space: ColorSpace, span: Range<usize>) -> Result<TextureId, SceneError> {
        let (path, looked) = locate::locate(&self.dir, relative);
        let key = (path.clone(), space == ColorSpace::Srgb);
        if let Some(&id) = self.texture_ids.get(&key) {
            return Ok(id);
        }
        let texture =
            texture::load(&path, space).map_err(|e| self.error(locate::with_places(e.to_string(), &looked), span))?;
        let id = TextureId(self.scene.textures.len());
        self.scene.textures.push(texture);
        self.texture_ids.insert(key, id);
        Ok(id)
    }

    fn environment(&self, d: EnvironmentDesc, span: Range<usize>) -> Result<Environment, SceneError> {
        let fail = |message: String| self.error(message, span.clone());
        let given: Vec<&str> = [
            ("sky", d.sky.is_some()),
            ("latlong", d.latlong.is_some()),
            ("cube", d.cube.is_some()),
            ("cross", d.cross.is_some()),
            ("sphere", d.sphere.is_some()),
        ]
        .into_iter()
        .filter_map(|(key, present)| present.then_some(key))
        .collect();
        if given.len() != 1 {
            let got = if given.is_empty() { "none".to_string() } else { format!("`{}`", given.join("`, `")) };
            return Err(fail(format!(
                "[world.environment] needs exactly one of `sky`, `latlong`, `cube`, `cross`, `sphere`; got {got}"
            )));
        }
        // An image's own problems name the image; they are placed at the environment's table,
        // with every place a missing one was looked for.
        let mut looked = Vec::new();
        let mut locate = |relative: &str| {
            let (path, places) = locate::locate(&self.dir, relative);
            looked.extend(places);
            path
        };
        let (source, path) = if let Some(sky) = d.sky {
            (Ok(EnvironmentSource::Sky(self.sky(sky)?)), None)
        } else if let Some(relative) = d.latlong {
            let path = locate(&relative);
            (environment::load_latlong(&path).map(EnvironmentSource::LatLong), Some(path))
        } else if let Some(relatives) = d.cube {
            let paths = relatives.map(|r| locate(&r));
            (environment::load_cube(&paths).map(EnvironmentSource::Cube), Some(paths[0].clone()))
        } else if let Some(relative) = d.cross {
            let path = locate(&relative);
            (environment::load_cross(&path).map(EnvironmentSource::Cube), Some(path))
        } else if let Some(relative) = d.sphere {
            let path = locate(&relative);
            (environment::load_sphere(&path).map(EnvironmentSource::Sphere), Some(path))
        } else {
            unreachable!("exactly one source was checked above")
        };
        let source = source.map_err(|e| fail(locate::with_places(e.to_string(), &looked)))?;
        Ok(Environment { source, intensity: d.intensity.map_or(1.0, |NonNegative(x)| x), path })
    }

    fn sky(&self, d: SkyDesc) -> Result<Sky, SceneError> {
        let base = Sky::default();
        let sun_direction = match d.sun_direction {
            Some(v) => {
                let span = v.span();
                let V3(direction) = v.into_inner();
                direction.try_normalize().ok_or_else(|| self.error("`sun_direction` is the zero vector", span))?
            }
            None => base.sun_direction,
        };
        let sun_radius = match d.sun_radius {
            Some(r) => {
                let span = r.span();
                let Finite(degrees) = r.into_inner();
                if !(degrees > 0.0 && degrees < 90.0) {
                    return Err(self.error(format!("sun_radius must be > 0 and < 90 degrees, got {degrees}"), span));
                }
                degrees.to_radians()
            }
            None => base.sun_radius,
        };
        Ok(Sky {
            zenith: d.zenith.map_or(base.zenith, |Rgb(c)| c),
            horizon: d.horizon.map_or(base.horizon, |Rgb(c)| c),
            ground: d.ground.map_or(base.ground, |Rgb(c)| c),
            sun_direction,
            sun_color: d.sun_color.map_or(base.sun_color, |Rgb(c)| c),
            sun_radius,
        })
    }

    fn light(&self, d: LightDesc, span: Range<usize>) -> Result<Light, SceneError> {
        let fail = |message: String| self.error(message, span.clone());
        let kind_name = format!("{:?}", d.kind).to_lowercase();
        let direction = |v: Option<V3>| -> Result<Vec3, SceneError> {
            let V3(v) = v.ok_or_else(|| fail(format!("a {kind_name} light needs a `direction`")))?;
            v.try_normalize().ok_or_else(|| fail("the light's direction is the zero vector".into()))
        };
        let position = |v: Option<V3>| -> Result<Vec3, SceneError> {
            v.map(|V3(p)| p).ok_or_else(|| fail(format!("a {kind_name} light needs a `position`")))
        };
        let unused = |present: bool, field: &str| -> Result<(), SceneError> {
            if present { Err(fail(format!("`{field}` does not apply to a {kind_name} light"))) } else { Ok(()) }
        };
        let kind = match d.kind {
            LightType::Point => {
                unused(d.direction.is_some(), "direction")?;
                unused(d.inner_angle.is_some() || d.outer_angle.is_some(), "inner_angle/outer_angle")?;
                LightKind::Point { position: position(d.position)? }
            }
            LightType::Directional => {
                unused(d.position.is_some(), "position")?;
                unused(d.inner_angle.is_some() || d.outer_angle.is_some(), "inner_angle/outer_angle")?;
                unused(d.attenuation.is_some(), "attenuation")?;
                LightKind::Directional { direction: direction(d.direction)? }
            }
            LightType::Spot => {
                let inner = d.inner_angle.map_or(20.0, |NonNegative(a)| a);
                let outer = d.outer_angle.map_or(30.0, |NonNegative(a)| a);
                if !(inner <= outer && outer < 180.0) {
                    return Err(fail(format!(
                        "spot angles must satisfy inner ≤ outer < 180°, got inner = {inner}, outer = {outer}"
                    )));
                }
                LightKind::Spot {
                    position: position(d.position)?,
                    direction: direction(d.direction)?,
                    inner: inner.to_radians(),
                    outer: outer.to_radians(),
                }
            }
        };
        Ok(Light {
            name: d.name.unwrap_or_else(|| format!("light {}", self.scene.lights.len())),
            kind,
            color: d.color.map_or(Vec3::ONE, |Rgb(c)| c),
            intensity: d.intensity.map_or(1.0, |NonNegative(x)| x),
            attenuation: d.attenuation.unwrap_or_default(),
        })
    }

    /// Adds one `[[objects]]` entry; a glTF model may bring a camera, returned for the caller.
    fn object(&mut self, d: ObjectDesc, span: Range<usize>) -> Result<Option<GltfCamera>, SceneError> {
        let fail = |message: String| self.error(message, span.clone());
        let kind_name = d.kind.name();
        let fields: [(&str, bool); 13] = [
            ("major_radius", d.major_radius.is_some()),
            ("minor_radius", d.minor_radius.is_some()),
            ("half_extents", d.half_extents.is_some()),
            ("center", d.center.is_some()),
            ("radius", d.radius.is_some()),
            ("min", d.min.is_some()),
            ("max", d.max.is_some()),
            ("size", d.size.is_some()),
            ("uv_scale", d.uv_scale.is_some()),
            ("path", d.path.is_some()),
            ("lights", d.lights.is_some()),
            ("camera", d.camera.is_some()),
            ("material", d.material.is_some()),
        ];
        let allowed: &[&str] = match d.kind {
            ObjectType::Sphere => &["center", "radius", "material"],
            ObjectType::Box => &["min", "max", "material"],
            ObjectType::Plane => &["size", "uv_scale", "material"],
            ObjectType::Torus => &["major_radius", "minor_radius", "material"],
            ObjectType::RoundedBox => &["half_extents", "radius", "material"],
            ObjectType::Gltf => &["path", "lights", "camera", "material"],
            ObjectType::Obj | ObjectType::Ply => &["path", "material"],
        };
        if let Some((field, _)) = fields.iter().find(|(f, present)| *present && !allowed.contains(f)) {
            return Err(fail(format!("`{field}` does not apply to a {kind_name}")));
        }
        let world_from_local = transform(d.translate, d.rotate, d.scale);
        let name = d.name.unwrap_or_else(|| format!("{kind_name} {}", self.scene.objects.len()));
        let shape = match d.kind {
            ObjectType::Sphere => Shape::Sphere {
                center: d.center.map_or(Vec3::ZERO, |V3(c)| c),
                radius: d.radius.map_or(1.0, |Positive(r)| r),
            },
            ObjectType::Box => {
                let (Some(V3(min)), Some(V3(max))) = (d.min, d.max) else {
                    return Err(fail("a box needs `min` and `max` corners".into()));
                };
                if !min.cmplt(max).all() {
                    return Err(fail(format!("a box needs min < max on every axis, got min = {min}, max = {max}")));
                }
                Shape::Cuboid { min, max }
            }
            ObjectType::Plane => Shape::Plane {
                size: d.size.map_or(Vec2::ONE, |PositiveV2(s)| s),
                uv_scale: d.uv_scale.map_or(Vec2::ONE, |PositiveV2(s)| s),
            },
            ObjectType::Torus => {
                let major = d.major_radius.map_or(1.0, |Positive(r)| r);
                let minor = d.minor_radius.map_or(0.25, |Positive(r)| r);
                if minor >= major {
                    return Err(fail(format!("a torus needs minor_radius < major_radius, got {minor} and {major}")));
                }
                Shape::Torus { major, minor }
            }
            ObjectType::RoundedBox => {
                let half = d.half_extents.map_or(Vec3::splat(0.5), |V3(h)| h);
                if half.min_element() < 0.0 {
                    return Err(fail(format!("half_extents must be ≥ 0, got {half}")));
                }
                Shape::RoundedBox { half, radius: d.radius.map_or(0.1, |Positive(r)| r) }
            }
            ObjectType::Gltf => {
                let relative = d.path.ok_or_else(|| fail("a gltf object needs a `path`".into()))?;
                let (file, looked) = locate::locate(&self.dir, &relative);
                let import =
                    super::gltf::import(&file).map_err(|e| fail(locate::with_places(e.to_string(), &looked)))?;
                let camera = d.camera.unwrap_or(false).then(|| import.cameras.first().cloned()).flatten();
                let material = d.material.map(|m| self.named_material(m)).transpose()?;
                add_model(&mut self.scene, import, world_from_local, d.lights.unwrap_or(true), &name, material);
                return Ok(
                    camera.map(|c| GltfCamera { world_from_camera: world_from_local * c.world_from_camera, ..c })
                );
            }
            ObjectType::Obj | ObjectType::Ply => {
                let article = if d.kind == ObjectType::Obj { "an" } else { "a" };
                let relative = d.path.ok_or_else(|| fail(format!("{article} {kind_name} object needs a `path`")))?;
                let (file, looked) = locate::locate(&self.dir, &relative);
                let import = match d.kind {
                    ObjectType::Obj => super::obj::import(&file),
                    _ => super::ply::import(&file),
                };
                let import = import.map_err(|e| fail(locate::with_places(e.to_string(), &looked)))?;
                let material = d.material.map(|m| self.named_material(m)).transpose()?;
                add_model(&mut self.scene, import, world_from_local, false, &name, material);
                return Ok(None);
            }
        };
        let material = match d.material {
            Some(m) => self.named_material(m)?,
            None => self.default_material(),
        };
        self.scene.objects.push(Object { name, shape, material, world_from_local });
        Ok(None)
    }

    /// The material an object's `material` field names.
    fn named_material(&mut self, name: Spanned<String>) -> Result<MaterialId, SceneError> {
        // `default` names the implicit default material, defined or not.
        if name.get_ref() == "default" && !self.material_ids.contains_key("default") {
            return Ok(self.default_material());
        }
        self.material_ids.get(name.get_ref()).copied().ok_or_else(|| {
            let known: Vec<&str> = self.material_ids.keys().map(String::as_str).collect();
            self.error(format!("no material named `{}` (known: {})", name.get_ref(), known.join(", ")), name.span())
        })
    }

    fn default_material(&mut self) -> MaterialId {
        *self.material_ids.entry("default".into()).or_insert_with(|| {
            self.scene.materials.push(Material::default());
            MaterialId(self.scene.materials.len() - 1)
        })
    }
}

/// Appends an imported model, placed by `world_from_root`, re-indexing its meshes, materials and
/// textures. With `material`, every object of the model is drawn in that scene material instead,
/// and the model's own materials and textures are left out.
fn add_model(
    scene: &mut Scene,
    import: ModelImport,
    world_from_root: Mat4,
    with_lights: bool,
    name: &str,
    material: Option<MaterialId>,
) {
    let (mesh_base, material_base, texture_base) = (scene.meshes.len(), scene.materials.len(), scene.textures.len());
    scene.meshes.extend(import.meshes);
    if material.is_none() {
        scene.textures.extend(import.textures);
        scene.materials.extend(import.materials.into_iter().map(|mut m| {
            m.texture = m.texture.map(|TextureId(i)| TextureId(i + texture_base));
            m.height_map = m.height_map.map(|TextureId(i)| TextureId(i + texture_base));
            m.normal_map = m.normal_map.map(|TextureId(i)| TextureId(i + texture_base));
            m
        }));
    }
    scene.objects.extend(import.objects.into_iter().map(|o| Object {
        name: format!("{name}/{}", o.name),
        shape: Shape::Mesh(mesh_base + o.mesh),
        material: material.unwrap_or(MaterialId(material_base + o.material)),
        world_from_local: world_from_root * o.world_from_local,
    }));
    if with_lights {
        scene.lights.extend(import.lights.into_iter().map(|mut light| {
            light.kind = match light.kind {
                LightKind::Point { position } => {
                    LightKind::Point { position: world_from_root.transform_point3(position) }
                }
                LightKind::Directional { direction } => {
                    LightKind::Directional { direction: world_from_root.transform_vector3(direction).normalize() }
                }
                LightKind::Spot { position, direction, inner, outer } => LightKind::Spot {
                    position: world_from_root.transform_point3(position),
                    direction: world_from_root.transform_vector3(direction).normalize(),
                    inner,
                    outer,
                },
            };
            light
        }));
    }
}

/// `translate · rotate(z·y·x) · scale`: scale first, then rotate about X, Y, Z in that order
/// (degrees), then translate.
fn transform(translate: Option<V3>, rotate: Option<V3>, scale: Option<Scale>) -> Mat4 {
    let t = translate.map_or(Vec3::ZERO, |V3(t)| t);
    let r = rotate.map_or(Vec3::ZERO, |V3(r)| r);
    let s = scale.map_or(Vec3::ONE, |Scale(s)| s);
    let rotation = Quat::from_rotation_z(r.z.to_radians())
        * Quat::from_rotation_y(r.y.to_radians())
        * Quat::from_rotation_x(r.x.to_radians());
    Mat4::from_scale_rotation_translation(s, rotation, t)
}

fn camera_from(d: CameraDesc) -> Camera {
    Camera {
        eye: d.eye.0,
        center: d.center.0,
        up: d.up.map_or(Vec3::Y, |V3(u)| u),
        fovy_degrees: d.fovy.map_or(60.0, |Finite(x)| x),
        near: d.near.map_or(0.1, |Finite(x)| x),
        far: d.far.map_or(1000.0, |Finite(x)| x),
        width: d.width.unwrap_or(1280),
        height: d.height.unwrap_or(720),
        projection: d.projection.unwrap_or(Projection::Perspective),
        ortho_height: d.ortho_height.map_or(10.0, |Finite(x)| x),
    }
}

/// A glTF camera as the course's camera. glTF gives no target, so `center` is put on the view
/// axis at the depth of the scene's centre (`bounds`): the viewer orbits around the model, and
/// shadow maps fitted to the view reach as far as the model does.
fn camera_from_gltf(c: &GltfCamera, width: u32, height: u32, bounds: Option<(Vec3, Vec3)>) -> Camera {
    let eye = c.world_from_camera.transform_point3(Vec3::ZERO);
    let forward = c.world_from_camera.transform_vector3(Vec3::NEG_Z);
    let depth = bounds.map_or(1.0, |(lo, hi)| ((lo + hi) / 2.0 - eye).dot(forward.normalize_or_zero()));
    let forward = forward * if depth.is_finite() && depth > 0.0 { depth / forward.length() } else { 1.0 };
    let up = c.world_from_camera.transform_vector3(Vec3::Y);
    let (projection, fovy_degrees, near, far, ortho_height) = match c.projection {
        GltfProjection::Perspective { yfov_radians, znear, zfar } => {
            (Projection::Perspective, yfov_radians.to_degrees(), znear, zfar.unwrap_or(znear * 1e4), 1.0)
        }
        GltfProjection::Orthographic { ymag, znear, zfar } => (Projection::Orthographic, 60.0, znear, zfar, 2.0 * ymag),
    };
    Camera { eye, center: eye + forward, up, fovy_degrees, near, far, width, height, projection, ortho_height }
}

/// A camera that sees the whole scene from above and to the front-right, for files without one.
pub fn frame_scene(scene: &Scene) -> Camera {
    let (lo, hi) = scene.bounds().unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)));
    let center = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(1e-3);
    let fovy: f32 = 45.0;
    let distance = 1.1 * radius / (fovy.to_radians() / 2.0).sin();
    let eye = center + distance * Vec3::new(0.6, 0.45, 1.0).normalize();
    Camera {
        eye,
        center,
        up: Vec3::Y,
        fovy_degrees: fovy,
        near: (distance - radius).max(distance * 1e-3),
        far: distance + 2.0 * radius,
        width: 1280,
        height: 720,
        projection: Projection::Perspective,
        ortho_height: 2.0 * radius,
    }
}

fn empty_scene(path: &Path) -> Scene {
    Scene {
        source: Some(path.to_path_buf()),
        camera: Camera {
            eye: Vec3::Z,
            center: Vec3::ZERO,
            up: Vec3::Y,
            fovy_degrees: 60.0,
            near: 0.1,
            far: 100.0,
            width: 1280,
            height: 720,
            projection: Projection::Perspective,
            ortho_height: 10.0,
        },
        ambient: Vec3::splat(0.1),
        background: Vec3::ZERO,
        environment: None,
        lights: Vec::new(),
        materials: Vec::new(),
        textures: Vec::new(),
        meshes: Vec::new(),
        objects: Vec::new(),
        volumes: Vec::new(),
        displaced: Vec::new(),
        settings: RenderSettings::default(),
    }
}

/// The world a bare model with its own (physical) lights is shown in: a uniform grey of this
/// radiance, as ambient light and background. glTF carries no world; this is the one Blender's
/// start-up file has, so a model exported from Blender looks as its author saw it there (the
/// ambient term has no occlusion, where Blender's world light is shadowed).
pub const PHYSICAL_WORLD: f32 = 0.0509;

/// A bare model: its own camera if it has one, else one framing it; its own lights if it has
/// any (then in [`PHYSICAL_WORLD`]), else a white directional light from over the viewer's
/// shoulder. OBJ and PLY files have neither, so they always get the framing camera and the light.
///
/// A model is made for renderers that weight glass by Fresnel and bend light through it, so its
/// glass gets both by default (docs/scene-format.md, "A bare model as the scene"):
/// `terms.fresnel`, refraction through the environment cubes, and those cubes read with the
/// ground as their proxy (a scene file keeps the course's defaults: neither, and infinitely far).
fn load_bare_model(path: &Path, import: ModelImport) -> Result<Scene, SceneError> {
    let mut scene = empty_scene(path);
    scene.settings.terms.fresnel = true;
    scene.settings.transparency.refraction = Refraction::Environment;
    scene.settings.environment.parallax = Parallax::Ground;
    if !import.lights.is_empty() {
        scene.ambient = Vec3::splat(PHYSICAL_WORLD);
        scene.background = Vec3::splat(PHYSICAL_WORLD);
    }
    let camera = import.cameras.first().cloned();
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("model").to_string();
    add_model(&mut scene, import, Mat4::IDENTITY, true, &name, None);
    scene.camera = match camera {
        Some(c) => camera_from_gltf(&c, 1280, 720, scene.bounds()),
        None => frame_scene(&scene),
    };
    scene.camera.validate().map_err(|e| SceneError::Invalid { path: path.into(), message: format!("camera: {e}") })?;
    if scene.lights.is_empty() {
        let frame = scene.camera.frame();
        scene.lights.push(Light {
            name: "headlight".into(),
            kind: LightKind::Directional { direction: (-frame.ze - 0.5 * frame.ye + 0.3 * frame.xe).normalize() },
            color: Vec3::ONE,
            intensity: 1.0,
            attenuation: Attenuation::None,
        });
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_count_characters_from_one() {
        let text = "a = 1\nbé = nan\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, text.find("nan").unwrap()), (2, 6));
    }

    #[test]
    fn transform_scales_then_rotates_x_y_z_then_translates() {
        let m = transform(
            Some(V3(Vec3::new(1.0, 2.0, 3.0))),
            Some(V3(Vec3::new(0.0, 90.0, 0.0))),
            Some(Scale(Vec3::splat(2.0))),
        );
        // +x scaled to 2, turned 90° about y to −z, moved by (1, 2, 3).
        assert!(m.transform_point3(Vec3::X).abs_diff_eq(Vec3::new(1.0, 2.0, 1.0), 1e-5));
        let m = transform(None, Some(V3(Vec3::new(90.0, 90.0, 0.0))), None);
        // X first: +y → +z; then Y: +z → +x.
        assert!(m.transform_point3(Vec3::Y).abs_diff_eq(Vec3::X, 1e-5));
    }
}
