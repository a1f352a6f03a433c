//! The hybrid (docs/course/12-error-budget.md): any of the rasterizer's approximations swapped for
//! its traced counterpart inside the raster frame, per pixel of every view, so that what each
//! approximation costs can be measured (`mirador budget`).

use super::field::section;

section! {
    /// Terms of the raster frame taken from the ray tracer instead, each in place of the
    /// approximation that makes it. The traced term is computed at the first opaque surface along
    /// each pixel's ray of each view (the main camera, mirrored cameras, cube faces); a fragment
    /// of another surface there (a silhouette the two renderers draw a pixel apart, a transparent
    /// surface) keeps the rasterizer's own.
    #[derive(Copy, Eq)]
    pub struct HybridSettings {
        /// The visibility `V_i` of each shadowed light from shadow rays, in place of shadow maps
        /// or projected polygons.
        shadows: bool = false,
        /// The mirror term `kps·MPS·L(r)` with `L(r)` traced (the tracer's whole recursion along
        /// the reflected ray), in place of the mirrored cameras of planar mirrors and the
        /// environment maps of curved ones (glass still reads the maps: its reflection and
        /// refraction are transmission's to swap).
        reflections: bool = false,
        /// What transparent surfaces let through, traced (`α·((1 − F)·kt·MT·L(t) + F·kt·MT·L(r))
        /// + (1 − α)·L(behind)`), in place of sorted blending and the screen-space refraction:
        /// the frame draws transparent surfaces as opaque ones, each adding its traced share.
        transmission: bool = false,
        /// The surface colour `C` filtered as the tracer filters it (its mip level from a ray
        /// cone), in place of trilinear filtering from screen derivatives. The swap goes the
        /// tracer's way: neither filter is exact, the tracer's is the reference's.
        textures: bool = false,
    }
}

/// Each technique's section of `RenderSettings` whose approximation a switch of the hybrid
/// replaces, and that switch: the viewer's panel shows the switch in the section as its traced
/// choice.
pub const TRACED_CHOICES: [(&str, &str); 5] = [
    ("shadows", "shadows"),
    ("mirrors", "reflections"),
    ("environment", "reflections"),
    ("transparency", "transmission"),
    ("textures", "textures"),
];

impl HybridSettings {
    /// Whether any term is traced.
    pub fn any(&self) -> bool {
        self.shadows || self.reflections || self.transmission || self.textures
    }
}

#[cfg(test)]
mod tests {
    use super::TRACED_CHOICES;
    use crate::RenderSettings;

    #[test]
    fn each_traced_choice_names_a_section_and_a_switch_of_the_hybrid() {
        let table = toml::Table::try_from(RenderSettings::default()).expect("the settings serialise");
        for (section, switch) in TRACED_CHOICES {
            assert!(table.get(section).is_some_and(toml::Value::is_table), "no section `{section}`");
            let mut settings = RenderSettings::default();
            settings.set(&format!("hybrid.{switch}=true")).unwrap_or_else(|e| panic!("{e}"));
            assert!(settings.hybrid.any(), "`hybrid.{switch}` switched nothing on");
        }
    }
}
