//! The hybrid (docs/course/12-error-budget.md): any of the rasterizer's approximations swapped for
//! its traced counterpart inside the raster frame, per pixel of every view, so that what each
//! approximation costs can be measured (`mirador budget`).
//!
//! **The approximations table.** Each approximation with a traced counterpart is one row of
//! `approximations!` below, and everything the program knows of it comes from that row: its
//! switch in [`HybridSettings`] (with the switch's documentation), the sections of the settings
//! the viewer shows the switch in, when a scene makes the approximation at all, what the raster
//! frame leaves out while it is traced, how many layers of a view's traced image its term fills,
//! the budget's name and sentence for it; and, numbered from the row's place, its bit in the
//! frame's `traced` uniform (`Frame::traced` in the WGSL) and its first layer, which
//! `crate::shaders::constants` writes into the WGSL. What stays by hand is what no table can say: the tracer's term
//! (`crate::trace::terms`), the shading's branch that reads it (`shaders/common/surface.wgsl`)
//! and the frame's phases. A new traced approximation is a row, a term and a branch.

use super::field::section;
use crate::RenderSettings;

/// What a scene holds that decides which approximations it makes (`crate::scene::Scene::facts`):
/// the settings cannot see the scene, so the scene says this much of itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneFacts {
    /// How many lights it has.
    pub lights: usize,
    /// Whether some object's material reflects (`kps > 0`).
    pub reflective: bool,
    /// Whether some object's material is transparent (`kt > 0` or blended).
    pub transparent: bool,
    /// Whether some object's material has a colour texture.
    pub textured: bool,
    /// Whether some object's material has a height field (a height map or a procedural one).
    pub heights: bool,
}

/// One of the rasterizer's approximations with a traced counterpart: a row of the table.
#[derive(Debug)]
pub struct Approximation {
    /// Its one name: the switch `hybrid.NAME`, the WGSL's `TRACED_NAME` bit and
    /// `TRACED_NAME_LAYER`.
    pub name: &'static str,
    /// What the budget's report calls it.
    pub budget: &'static str,
    /// What the rasterizer does, and what replaces it: the budget's sentence.
    pub swap: &'static str,
    /// The sections of `RenderSettings` whose approximation it replaces: the viewer's panel shows
    /// the switch in each, as the section's traced choice.
    pub sections: &'static [&'static str],
    /// Whether a scene (its facts, with its settings) makes this approximation anywhere.
    pub in_use: fn(&SceneFacts, &RenderSettings) -> bool,
    /// What the raster frame leaves out while the term is traced (the term takes its place).
    pub replaces: fn(&mut RenderSettings),
    /// How many layers of a view's traced image the term fills.
    pub layers: u32,
}

/// Declares the approximations table: one row per approximation, `name: Variant { … }` with the
/// switch's documentation above it. Generates [`HybridSettings`] (a `bool` switch a row, through
/// `section!`), [`Traced`] (a variant a row, numbered by the row's place) and [`APPROXIMATIONS`].
macro_rules! approximations {
    (
        $(
            $(#[doc = $doc:literal])+
            $name:ident: $variant:ident {
                budget: $budget:literal,
                swap: $swap:literal,
                sections: $sections:expr,
                in_use: $in_use:expr,
                replaces: $replaces:expr,
                layers: $layers:expr $(,)?
            }
        ),+ $(,)?
    ) => {
        section! {
            /// Terms of the raster frame taken from the ray tracer instead, each in place of the
            /// approximation that makes it (a row of the approximations table,
            /// `src/settings/hybrid.rs`). The traced term is computed at the first opaque surface
            /// along each pixel's ray of each view (the main camera, mirrored cameras, cube
            /// faces); a fragment of another surface there (a silhouette the two renderers draw a
            /// pixel apart, a transparent surface) keeps the rasterizer's own.
            #[derive(Copy, Eq)]
            pub struct HybridSettings {
                $( $(#[doc = $doc])+ $name: bool = false, )+
            }
        }

        /// An approximation of the table, by its row.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Traced {
            $( $variant, )+
        }

        /// Every approximation with a traced counterpart, in the order the budget reports them.
        pub const APPROXIMATIONS: &[Approximation] = &[$(
            Approximation {
                name: stringify!($name),
                budget: $budget,
                swap: $swap,
                sections: $sections,
                in_use: $in_use,
                replaces: $replaces,
                layers: $layers,
            },
        )+];

        impl Traced {
            /// Every row, in order.
            pub const ALL: &[Traced] = &[$(Traced::$variant),+];

            /// Whether `hybrid` traces this term.
            pub fn is_on(self, hybrid: &HybridSettings) -> bool {
                match self {
                    $( Traced::$variant => hybrid.$name, )+
                }
            }

            /// Its switch in `hybrid`.
            pub fn switch(self, hybrid: &mut HybridSettings) -> &mut bool {
                match self {
                    $( Traced::$variant => &mut hybrid.$name, )+
                }
            }
        }
    };
}

approximations! {
    /// The visibility `V_i` of each shadowed light from shadow rays, in place of shadow maps
    /// or projected polygons.
    shadows: Shadows {
        budget: "shadows",
        swap: "shadow maps or projected polygons → shadow rays from the visible surface",
        sections: &["shadows"],
        in_use: |scene, settings| settings.shadows.enabled && scene.lights > 0,
        replaces: |_| {},
        // A layer for each of the rasterizer's shadowed lights.
        layers: super::MAX_SHADOWED_LIGHTS as u32,
    },
    /// The mirror term `kps·MPS·L(r)` with `L(r)` traced (the tracer's whole recursion along
    /// the reflected ray), in place of the mirrored cameras of planar mirrors and the
    /// environment maps of curved ones (glass still reads the maps: its reflection and
    /// refraction are transmission's to swap).
    reflections: Reflections {
        budget: "reflections",
        swap: "mirrored cameras and environment maps → the traced L(r)",
        sections: &["mirrors", "environment"],
        in_use: |scene, _| scene.reflective,
        // The environment maps stay: glass reads them, and the opaque surfaces the terms were
        // traced on skip their lookup.
        replaces: |settings| settings.mirrors.enabled = false,
        layers: 1,
    },
    /// What transparent surfaces let through, traced (`α·((1 − F)·kt·MT·L(t) + F·kt·MT·L(r))
    /// + (1 − α)·L(behind)`), in place of sorted blending and the screen-space refraction:
    /// the frame draws transparent surfaces as opaque ones, each adding its traced share.
    transmission: Transmission {
        budget: "transmission",
        swap: "sorted blending and screen-space refraction → the traced transmission",
        sections: &["transparency"],
        in_use: |scene, _| scene.transparent,
        replaces: |settings| settings.transparency.enabled = false,
        layers: 1,
    },
    /// The surface colour `C` filtered as the tracer filters it (its mip level from a ray
    /// cone), in place of trilinear filtering from screen derivatives. The swap goes the
    /// tracer's way: neither filter is exact, the tracer's is the reference's.
    textures: Textures {
        budget: "texture filtering",
        swap: "trilinear from screen derivatives → the tracer's ray-cone filtering",
        sections: &["textures"],
        in_use: |scene, _| scene.textured,
        replaces: |_| {},
        // `C` shares the surface layer (layer 0) with the object every term is traced on.
        layers: 0,
    },
    /// The lights past the fourth, traced: the rasterizer shadows four lights and draws the
    /// others (up to its sixteen) as if nothing stood in their way; traced, their whole direct
    /// term `Σ V_i·S_i ⊗ (ka·C + kd·C·max(0, n·l) + ks·Sc·max(0, r·v)^e)` comes from the tracer,
    /// shadow rays and all.
    lights: Lights {
        budget: "lights past the fourth",
        swap: "the lights past the fourth drawn unshadowed → their light traced, shadow rays and all",
        sections: &[],
        in_use: |scene, settings| settings.shadows.enabled && scene.lights > super::MAX_SHADOWED_LIGHTS,
        replaces: |_| {},
        layers: 1,
    },
    /// The height fields' relief made as the displaced surface `p + k·f·n` (displacement
    /// mapping, `bump.method = "displacement"`), in place of bump or parallax mapping, which
    /// shade the smooth surface. Its counterpart is no traced term but geometry: the scene is
    /// made again, displaced, for both renderers (`crate::texture::displacement`), and the
    /// budget's reference is the tracer's image of the displaced surface.
    relief: Relief {
        budget: "bump and parallax mapping",
        swap: "the smooth surface shaded as if bumped (or with the view ray marched) → the displaced surface",
        sections: &["bump"],
        in_use: |scene, settings| {
            scene.heights && settings.bump.enabled && settings.bump.method != super::BumpMethod::Displacement
        },
        replaces: |settings| settings.bump.method = super::BumpMethod::Displacement,
        layers: 0,
    },
}

/// The layer of a view's traced image that holds the surface colour `C` and the object + 1 the
/// terms were traced on (0: none): every row's layers follow it.
pub const SURFACE_LAYER: u32 = 0;

/// How many layers a view's traced image has: the surface's, then each row's.
pub const TRACED_LAYERS: u32 = first_layer(APPROXIMATIONS.len());

/// The first layer of row `index`'s term: after the surface layer and every earlier row's.
const fn first_layer(index: usize) -> u32 {
    let (mut layer, mut row) = (SURFACE_LAYER + 1, 0);
    while row < index {
        layer += APPROXIMATIONS[row].layers;
        row += 1;
    }
    layer
}

impl Traced {
    /// Its row of the table.
    pub const fn row(self) -> &'static Approximation {
        &APPROXIMATIONS[self as usize]
    }

    /// Its bit in the frame's `traced` uniform (`TRACED_NAME` in the WGSL).
    pub const fn bit(self) -> u32 {
        1 << self as u32
    }

    /// The first layer of a view's traced image its term fills (`TRACED_NAME_LAYER`).
    pub const fn layer(self) -> u32 {
        first_layer(self as usize)
    }
}

/// A set of traced terms: the bits of [`Traced::bit`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct TracedSet(pub u32);

impl TracedSet {
    /// The set of `terms`.
    pub fn of(terms: &[Traced]) -> TracedSet {
        TracedSet(terms.iter().fold(0, |bits, t| bits | t.bit()))
    }

    /// Whether `term` is in the set.
    pub fn contains(self, term: Traced) -> bool {
        self.0 & term.bit() != 0
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
}

impl HybridSettings {
    /// The terms traced.
    pub fn traced(&self) -> TracedSet {
        let on: Vec<Traced> = Traced::ALL.iter().copied().filter(|t| t.is_on(self)).collect();
        TracedSet::of(&on)
    }

    /// Whether any term is traced.
    pub fn any(&self) -> bool {
        !self.traced().is_empty()
    }

    /// The settings the rasterizer's own passes draw with: what each traced term replaces left
    /// out. `None` when that is nothing.
    pub fn raster_settings(&self, settings: &RenderSettings) -> Option<RenderSettings> {
        let mut raster = settings.clone();
        for term in Traced::ALL.iter().filter(|t| t.is_on(self)) {
            (term.row().replaces)(&mut raster);
        }
        (raster != *settings).then_some(raster)
    }

    /// The switch of the section `section` shows as its traced choice, if any.
    pub fn choice_of(section: &str) -> Option<&'static str> {
        APPROXIMATIONS.iter().find(|a| a.sections.contains(&section)).map(|a| a.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_rows_sections_are_sections_and_its_switch_is_the_hybrids() {
        let table = toml::Table::try_from(RenderSettings::default()).expect("the settings serialise");
        for (row, term) in APPROXIMATIONS.iter().zip(Traced::ALL) {
            for section in row.sections {
                assert!(table.get(*section).is_some_and(toml::Value::is_table), "no section `{section}`");
                assert_eq!(HybridSettings::choice_of(section), Some(row.name));
            }
            let mut settings = RenderSettings::default();
            settings.set(&format!("hybrid.{}=true", row.name)).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(settings.hybrid.traced(), TracedSet(term.bit()), "`hybrid.{}`", row.name);
            assert_eq!(term.row().name, row.name);
        }
    }

    #[test]
    fn bits_and_layers_are_numbered_from_the_rows() {
        assert_eq!(Traced::Shadows.bit(), 1);
        assert_eq!(Traced::Relief.bit(), 1 << (APPROXIMATIONS.len() - 1));
        assert_eq!(Traced::Shadows.layer(), SURFACE_LAYER + 1);
        for pair in Traced::ALL.windows(2) {
            assert_eq!(pair[1].layer(), pair[0].layer() + pair[0].row().layers);
        }
        let last = Traced::ALL[Traced::ALL.len() - 1];
        assert_eq!(TRACED_LAYERS, last.layer() + last.row().layers);
    }
}
