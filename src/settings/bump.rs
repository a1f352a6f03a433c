//! Bump mapping from height fields, and normal maps (docs/course/04-bump-mapping.md).

use super::field::{choices, section};

section! {
    /// Bump mapping and normal maps, in both renderers.
    #[derive(Copy)]
    pub struct BumpSettings {
        /// Bump mapping and normal maps: the shading normal perturbed by the height field's slope
        /// (or read from the normal map); off, surfaces are shaded with the geometric normal `n`.
        enabled: bool = true,
        /// What the height field `f(u, v)` changes, in both renderers: the shading normal alone
        /// (bump mapping: the silhouette and the shadows stay the smooth surface's), the point
        /// shaded as well (parallax mapping: the view ray marched through the relief, which hides
        /// itself), or the surface itself, `p + k·f·n`, made as triangles (displacement mapping:
        /// the silhouette, the self-shadows and what hides what are the relief's).
        method: BumpMethod = BumpMethod::Normal,
        /// Displacement's tessellation: the longest edge of the displaced triangles, in steps of
        /// the height field (texels of a height map; a 64th of a sine's period, a 16th of the
        /// finest noise cell). Smaller follows more detail with more triangles (at most two
        /// million in a scene: past that the level is lowered, and said).
        #[values(closed(0.25, 64.0).unit("texels").slider(0.25, 16.0))]
        displacement_texels: f32 = 2.0,
        /// How the rasterizer tessellates displacement: on the GPU every frame, each edge split
        /// until its pieces are under `edge_pixels` on screen (and under `displacement_texels` of
        /// the field), or the uniform mesh the tracer draws. WebGL2 has no compute shaders and
        /// always draws the uniform mesh.
        tessellation: Tessellation = Tessellation::Adaptive,
        /// Adaptive tessellation's longest edge on screen, in pixels: smaller follows the
        /// silhouette more closely with more triangles (at most two million: past that the
        /// edges are made longer, and said).
        #[values(closed(0.5, 64.0).unit("px").slider(0.5, 32.0))]
        edge_pixels: f32 = 4.0,
        /// Where the rasterizer's tangents `t_u = ∂p/∂u`, `t_v = ∂p/∂v` come from (the tracer
        /// uses the third source, the analytic surface).
        tangents: TangentSource = TangentSource::Derivatives,
        /// Multiplies every material's bump scale `k` (`bump_scale`) in
        /// `du = k·(f(u+Δ) − f(u−Δ))/2Δ`: the relief's depth; negative inverts it.
        #[values(slider(-8.0, 8.0))]
        scale: f32 = 1.0,
        /// The finite-difference step `Δ`, in texels of the height map: small follows detail,
        /// large smooths it. For a procedural field, in units of its own step: a 64th of a sine's
        /// period, a 16th of the finest noise cell.
        #[values(open_closed(0.0, 64.0).unit("texels").slider(0.05, 64.0))]
        delta_texels: f32 = 1.0,
        /// For procedural height fields, the closed-form gradient instead of finite differences,
        /// so the two can be compared.
        analytic: bool = false,
        /// Teaching view instead of the shaded colour: the perturbed normal `n'` or the tangent
        /// `t_u` as colour.
        view: BumpView = BumpView::Off,
    }
}

choices! {
    /// What a height field changes.
    pub enum BumpMethod {
        /// Bump mapping: the shading normal perturbed by the field's slope, the surface unmoved.
        Normal,
        /// Parallax occlusion mapping: the flat surface shaded, at each point, as the point of
        /// the displaced surface the view ray meets first (the relief hides itself; the outline
        /// and the shadows stay flat).
        Parallax,
        /// Displacement mapping: the surface moved by `k·f(u, v)` along its normal, as geometry.
        Displacement,
    }
}

choices! {
    /// How the rasterizer makes displacement's triangles.
    pub enum Tessellation {
        /// In a compute shader, every frame the view changes: each edge of the object's mesh split
        /// by its length on screen, neighbours of different levels joined without cracks.
        Adaptive,
        /// The mesh displacement made once for both renderers: every triangle split alike, by
        /// the height field's texels.
        Uniform,
    }
}

choices! {
    /// What the bump-mapping teaching view shows instead of the shaded colour.
    pub enum BumpView {
        /// The shaded image.
        Off,
        /// The (perturbed) shading normal as colour: `0.5 + 0.5·n`.
        Normals,
        /// The tangent `t_u` as colour the same way: the frame the bumps are built in.
        Tangents,
        /// The shaded image with the rasterizer's mesh triangles' edges drawn over it: how finely
        /// displacement tessellated the relief (and any model's own mesh).
        Tessellation,
    }
}

choices! {
    /// Where the rasterizer's tangents `t_u`, `t_v` come from (docs/course/04-bump-mapping.md names three
    /// sources; the tracer uses the third, the analytic surface).
    pub enum TangentSource {
        /// Constant per triangle, from how position and texture coordinates change across it
        /// (screen-space derivatives): true-length `∂p/∂u`, `∂p/∂v`.
        Derivatives,
        /// Per vertex and interpolated: the file's tangents, or MikkTSpace's; unit length, so `k`
        /// reads as relief per unit of texture coordinate rather than per unit of surface.
        PerVertex,
    }
}
