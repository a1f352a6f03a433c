//! Environment maps for curved mirrors, and the world drawn as the background (docs/course/08-environment-maps.md).

use super::field::{choices, section};

section! {
    /// Environment mapping (materials with `kps > 0` that are not planar mirrors) in the
    /// rasterizer.
    #[derive(Copy)]
    pub struct EnvironmentSettings {
        /// Curved mirrors (objects with `mirror` > 0 that are not flat) add `kps·MPS·L(r)` to
        /// their illumination model, `L(r)` looked up in an environment map. Off, they show their
        /// model alone. The world's `[world.environment]` is the background either way.
        enabled: bool = true,
        /// Where the reflected direction `r = 2(n·v)n − v` is looked up: a cube's face and texel, a
        /// sphere map (in view space), or longitude and latitude.
        map: EnvironmentMap = EnvironmentMap::Cube,
        /// With the `cube` map, each curved mirror (the first 8) gets a cube drawn from its
        /// centre: six 90° views of the rest of the scene with the techniques that are on, so it
        /// reflects its neighbours; wrong for what is near (parallax), and a neighbour's cube is a
        /// frame old. Off: the world's cube alone.
        dynamic: bool = true,
        /// Texels on a side of each cube face the renderer makes; sphere maps are twice,
        /// latitude–longitude maps four times as wide.
        #[values(closed(16.0, 2048.0).unit("texels"))]
        cube_size: u32 = 256,
        /// Draw the dynamic cubes again every `refresh` frames; 0: only when something they see
        /// changes (objects, materials, lights, settings; not the camera).
        #[values(unit("frames").slider(0.0, 600.0))]
        refresh: u32 = 0,
        /// Where a dynamic cube's lookup assumes the reflected (or refracted) ray ends: infinitely
        /// far (the course's rule: only the direction counts), or on a proxy of the scene, so
        /// what is near lines up with the tracer (parallax correction).
        parallax: Parallax = Parallax::Infinite,
        /// Whose view the sphere map is made for: the first frame's camera, or every frame's.
        sphere_view: SphereView = SphereView::Fixed,
        /// Teaching views over the frame (see `environment.inset`): the cube map unfolded as a
        /// cross, the sphere map, or the latitude–longitude map.
        view: EnvironmentView = EnvironmentView::Off,
        /// Draw the teaching view in the frame's lower-right corner (40 % of its width, at the
        /// map's aspect) with the scene around it; in the viewer, the latitude–longitude view
        /// then marks the reflected direction `r` of the surface under the cursor (the view ray
        /// itself over the background). Off: over the whole frame, letterboxed.
        inset: bool = true,
    }
}

choices! {
    /// Which map the rasterizer looks curved mirrors' reflections up in.
    pub enum EnvironmentMap {
        /// The six faces of a cube around the object: `r` picks the face and the texel
        /// (seamless).
        Cube,
        /// One image of a mirror ball seen along −Z in view space (OpenGL's sphere map).
        Sphere,
        /// Longitude and latitude of `r` (`α = a·u`, `β = b·v`), with explicit gradients.
        Latlong,
    }
}

choices! {
    /// Where the lookup of a dynamic cube assumes the ray ends
    /// (docs/course/08-environment-maps.md#parallax).
    pub enum Parallax {
        /// Infinitely far: the cube is read along the ray's direction `r` alone.
        Infinite,
        /// On the scene's ground, the plane through its lowest point: a ray going down is read
        /// along the direction from the cube's centre to where it meets the plane; a ray going up
        /// along `r`.
        Ground,
        /// On the box around the scene: every ray is read along the direction from the cube's
        /// centre to where it leaves the box (a room's walls).
        Box,
    }
}

choices! {
    /// Whose view a sphere map is made for.
    pub enum SphereView {
        /// Made once, for the camera of the first frame: turn the camera and the reflections turn
        /// with it (the map belongs to one view direction).
        Fixed,
        /// Made again for every frame's camera.
        Follow,
    }
}

choices! {
    /// What the environment technique shows.
    pub enum EnvironmentView {
        /// The scene.
        Off,
        /// The cube map of the first curved mirror (or the world's) unfolded as a cross.
        Cross,
        /// The sphere map, as an image.
        Sphere,
        /// The latitude–longitude map, as an image.
        Latlong,
    }
}
