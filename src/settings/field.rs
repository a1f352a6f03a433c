//! A setting's one description, written beside its field.
//!
//! `section!` declares a section of settings: its struct (serde's `default` and
//! `deny_unknown_fields`, so a scene file or `--set` may name any of its keys and no other), its
//! `Default`, and a static [`Field`] per field. The field's doc comment is its meaning; an optional
//! `#[values(…)]` line under it states the numbers it accepts, their unit and the viewer's slider
//! ([`Values`]). `choices!` declares an enum setting: spelled as serde writes it, each variant's
//! doc comment the help of that choice.
//!
//! Nothing else states what a setting means or accepts. `RenderSettings::validate` walks these
//! descriptions ([`walk`]); `settings_doc` turns them into the viewer's tooltips and the settings
//! table of docs/scene-format.md, which a test keeps equal to the file.

/// One setting (or a section of them), as its section declares it.
#[derive(Debug)]
pub struct Field {
    /// Its name in its section, as serde, `--set` and scene files spell it.
    pub name: &'static str,
    /// Its doc comment, line by line: what it changes, in the course's terms (Markdown).
    pub doc: &'static [&'static str],
    /// The numbers it accepts, their unit, the viewer's slider.
    pub values: Values,
    /// What its type is: a switch, a number, a choice or a section.
    pub kind: Kind,
}

impl Field {
    /// The meaning as one line of Markdown: the doc comment's lines joined.
    pub fn meaning(&self) -> String {
        self.doc.iter().map(|line| line.trim()).filter(|line| !line.is_empty()).collect::<Vec<_>>().join(" ")
    }
}

/// What a field's type makes of it.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// `bool`.
    Switch,
    /// An integer type; `signed: false` for the unsigned ones, which accept no value below 0.
    Integer { signed: bool },
    /// `f32`.
    Number,
    /// An enum declared by `choices!`: its values, spelled as serde writes them.
    Choice(fn() -> Vec<Choice>),
    /// A nested section and its fields.
    Section(&'static [Field]),
}

/// One value an enum setting can take.
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    /// As serde writes it: the value of `--set key="value"`.
    pub value: String,
    /// The variant's doc comment, when it has one.
    pub help: Option<String>,
}

/// The choices of an enum, spelled as serde writes them, with each variant's doc comment (as clap
/// reads it: one paragraph, without its final period).
pub fn choices_of<T: clap::ValueEnum + serde::Serialize>() -> Vec<Choice> {
    T::value_variants()
        .iter()
        .filter_map(|variant| {
            let value = match toml::Value::try_from(variant) {
                Ok(toml::Value::String(name)) => name,
                _ => return None,
            };
            let help = variant.to_possible_value().and_then(|p| p.get_help().map(|h| h.to_string()));
            Some(Choice { value, help })
        })
        .collect()
}

/// Which numbers a setting accepts. Every one of them is finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Accepts {
    /// Any finite value of the field's type.
    Any,
    /// `low ≤ x ≤ high`.
    Closed(f64, f64),
    /// `low < x ≤ high`.
    OpenClosed(f64, f64),
    /// `x ≥ low`.
    AtLeast(f64),
    /// `x > low`.
    Above(f64),
}

/// The numbers a setting accepts, their unit, and the range the viewer's slider offers. Written
/// under a field's doc comment as `#[values(closed(0.05, 8.0).unit("voxels"))]`: the calls are
/// the `const` builders below, applied to [`Values::ANY`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Values {
    pub accepts: Accepts,
    /// What the number counts (`"texels"`), where it is not a plain factor or count.
    pub unit: Option<&'static str>,
    /// The slider, where it differs from the accepted range or that range is open.
    slider: Option<(f64, f64)>,
}

impl Values {
    /// Any finite value of the field's type: every switch, choice and section, and the numbers
    /// that state no range.
    pub const ANY: Values = Values { accepts: Accepts::Any, unit: None, slider: None };

    /// `low ≤ x ≤ high`.
    pub const fn closed(self, low: f64, high: f64) -> Values {
        Values { accepts: Accepts::Closed(low, high), ..self }
    }

    /// `low < x ≤ high`.
    pub const fn open_closed(self, low: f64, high: f64) -> Values {
        Values { accepts: Accepts::OpenClosed(low, high), ..self }
    }

    /// `x ≥ low`.
    pub const fn at_least(self, low: f64) -> Values {
        Values { accepts: Accepts::AtLeast(low), ..self }
    }

    /// `x > low`.
    pub const fn above(self, low: f64) -> Values {
        Values { accepts: Accepts::Above(low), ..self }
    }

    pub const fn unit(self, unit: &'static str) -> Values {
        Values { unit: Some(unit), ..self }
    }

    /// The range of the viewer's slider, for numbers whose accepted range is open or too wide to
    /// drag through; it must lie within the accepted values.
    pub const fn slider(self, low: f64, high: f64) -> Values {
        Values { slider: Some((low, high)), ..self }
    }

    /// The viewer's slider: the stated one, else the accepted range where it is closed.
    pub fn slider_range(&self) -> Option<(f64, f64)> {
        match (self.slider, self.accepts) {
            (Some(range), _) => Some(range),
            (None, Accepts::Closed(low, high)) => Some((low, high)),
            _ => None,
        }
    }

    /// Whether `x` is accepted; `Err` holds the rule it breaks (`must lie in 3..=4096`). `round`
    /// turns a bound into the field's own precision (an `f32` is compared with `f32` bounds), so
    /// a bound written in the source is always accepted.
    pub fn check(&self, x: f64, round: fn(f64) -> f64) -> Result<(), String> {
        let unit = self.unit.map(|u| format!(" {u}")).unwrap_or_default();
        let (accepted, rule) = match self.accepts {
            Accepts::Any => (x.is_finite(), "must be finite".to_string()),
            Accepts::Closed(low, high) => {
                (round(low) <= x && x <= round(high), format!("must lie in {low}..={high}{unit}"))
            }
            Accepts::OpenClosed(low, high) => {
                (round(low) < x && x <= round(high), format!("must lie in ({low}, {high}]{unit}"))
            }
            Accepts::AtLeast(low) => (x.is_finite() && x >= round(low), format!("must be a finite number ≥ {low}")),
            Accepts::Above(0.0) => (x.is_finite() && x > 0.0, "must be positive".to_string()),
            Accepts::Above(low) => (x.is_finite() && x > round(low), format!("must be a finite number > {low}")),
        };
        if accepted { Ok(()) } else { Err(rule) }
    }

    /// The accepted values and unit in words, for the documentation and the tooltips (`0.05 to 8
    /// voxels`); `None` for any value without a unit.
    pub fn summary(&self) -> Option<String> {
        let unit = self.unit.map(|u| format!(" {u}")).unwrap_or_default();
        match self.accepts {
            Accepts::Any => self.unit.map(|u| format!("in {u}")),
            Accepts::Closed(low, high) => Some(format!("{low} to {high}{unit}")),
            Accepts::OpenClosed(low, high) => Some(format!("above {low}, at most {high}{unit}")),
            Accepts::AtLeast(low) => Some(format!("at least {low}{unit}")),
            Accepts::Above(low) => Some(format!("above {low}{unit}")),
        }
    }
}

/// A type a setting can have, described statically (for the [`Field`] tables).
pub trait SettingType {
    const KIND: Kind;
}

/// A setting's value, for walking the settings themselves.
pub trait SettingValue {
    /// Checks the value against what its field accepts; `Err` holds the rule it breaks and the
    /// value (`must lie in 3..=4096, got 2`).
    fn check(&self, values: &Values) -> Result<(), String>;
    /// The value as TOML writes it (`true`, `0.5`, `"clamp"`); empty for a section.
    fn toml(&self) -> String;
    /// A section's fields, in the order of its [`Field`] table; nothing for a single value.
    fn fields(&self) -> Vec<&dyn SettingValue> {
        Vec::new()
    }
}

impl SettingType for bool {
    const KIND: Kind = Kind::Switch;
}

impl SettingValue for bool {
    fn check(&self, _: &Values) -> Result<(), String> {
        Ok(())
    }
    fn toml(&self) -> String {
        self.to_string()
    }
}

macro_rules! integer_settings {
    ($($ty:ty: $signed:literal),*) => {$(
        impl SettingType for $ty {
            const KIND: Kind = Kind::Integer { signed: $signed };
        }

        impl SettingValue for $ty {
            fn check(&self, values: &Values) -> Result<(), String> {
                values.check(*self as f64, |bound| bound).map_err(|rule| format!("{rule}, got {self}"))
            }
            fn toml(&self) -> String {
                self.to_string()
            }
        }
    )*};
}

integer_settings!(u16: false, u32: false, u64: false, i32: true);

impl SettingType for f32 {
    const KIND: Kind = Kind::Number;
}

impl SettingValue for f32 {
    fn check(&self, values: &Values) -> Result<(), String> {
        values.check(*self as f64, |bound| bound as f32 as f64).map_err(|rule| format!("{rule}, got {self}"))
    }
    /// With a decimal point, as TOML writes a float: `1.0`, `0.99`.
    fn toml(&self) -> String {
        if self.fract() == 0.0 { format!("{self:.1}") } else { self.to_string() }
    }
}

/// Calls `visit` with every setting under `fields` (a section before its own settings), its
/// dotted key (`shadows.map_size`, after `prefix`) and its value in `values`, stopping at the
/// first error.
pub fn walk<E>(
    fields: &'static [Field],
    values: &dyn SettingValue,
    prefix: &str,
    visit: &mut impl FnMut(&str, &'static Field, &dyn SettingValue) -> Result<(), E>,
) -> Result<(), E> {
    let children = values.fields();
    debug_assert_eq!(children.len(), fields.len(), "`section!` lists every field once");
    for (field, value) in fields.iter().zip(children) {
        let key = if prefix.is_empty() { field.name.to_string() } else { format!("{prefix}.{}", field.name) };
        visit(&key, field, value)?;
        if let Kind::Section(inner) = field.kind {
            walk(inner, value, &key, visit)?;
        }
    }
    Ok(())
}

/// The field at the dotted path `key` under `fields`.
pub fn find(fields: &'static [Field], key: &str) -> Option<&'static Field> {
    let (first, rest) = match key.split_once('.') {
        Some((first, rest)) => (first, Some(rest)),
        None => (key, None),
    };
    let field = fields.iter().find(|f| f.name == first)?;
    match (rest, field.kind) {
        (None, _) => Some(field),
        (Some(rest), Kind::Section(inner)) => find(inner, rest),
        (Some(_), _) => None,
    }
}

/// Declares a section of settings and describes each of its fields once.
///
/// ```ignore
/// section! {
///     /// The section's own documentation.
///     #[derive(Copy)]
///     pub struct VolumeSettings {
///         /// What the setting changes, in the course's terms (its meaning everywhere).
///         #[values(closed(0.05, 8.0).unit("voxels"))]
///         step: f32 = 0.5,
///         …
///     }
/// }
/// ```
///
/// Every field has a doc comment, then optionally `#[values(…)]` (calls of [`Values`]' builders),
/// then `name: Type = default`. The struct derives `Clone, Debug, PartialEq, Serialize,
/// Deserialize` (add others with `#[derive]`); its fields are public; `Default` gives each its
/// default; `VolumeSettings::FIELDS` describes them, in declaration order. A field without a doc
/// comment does not compile.
macro_rules! section {
    (@values) => { $crate::settings::field::Values::ANY };
    (@values $($builders:tt)+) => { $crate::settings::field::Values::ANY.$($builders)+ };
    (
        $(#[$attr:meta])*
        pub struct $name:ident {
            $(
                $(#[doc = $doc:literal])+
                $(#[values($($builders:tt)+)])?
                $field:ident: $ty:ty = $default:expr
            ),+ $(,)?
        }
    ) => {
        $(#[$attr])*
        #[derive(Clone, Debug, PartialEq, ::serde::Serialize, ::serde::Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name {
            $( $(#[doc = $doc])+ pub $field: $ty, )+
        }

        impl Default for $name {
            fn default() -> Self {
                $name { $( $field: $default, )+ }
            }
        }

        impl $name {
            /// Each field's description, in declaration order.
            pub const FIELDS: &'static [$crate::settings::field::Field] = &[$(
                $crate::settings::field::Field {
                    name: stringify!($field),
                    doc: &[$($doc),+],
                    values: $crate::settings::field::section!(@values $($($builders)+)?),
                    kind: <$ty as $crate::settings::field::SettingType>::KIND,
                },
            )+];
        }

        impl $crate::settings::field::SettingType for $name {
            const KIND: $crate::settings::field::Kind = $crate::settings::field::Kind::Section(Self::FIELDS);
        }

        impl $crate::settings::field::SettingValue for $name {
            fn check(&self, _: &$crate::settings::field::Values) -> Result<(), String> {
                Ok(())
            }
            fn toml(&self) -> String {
                String::new()
            }
            fn fields(&self) -> Vec<&dyn $crate::settings::field::SettingValue> {
                vec![$(&self.$field),+]
            }
        }
    };
}

/// Declares an enum setting: `Copy`, compared, serialized in `snake_case` (the spelling of scene
/// files and `--set`) and a `clap::ValueEnum`, whose variants' doc comments are the help of each
/// choice in the viewer and the documentation.
macro_rules! choices {
    (
        $(#[$attr:meta])*
        pub enum $name:ident {
            $( $(#[$variant_attr:meta])* $variant:ident ),+ $(,)?
        }
    ) => {
        $(#[$attr])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, ::serde::Serialize, ::serde::Deserialize, ::clap::ValueEnum)]
        #[serde(rename_all = "snake_case")]
        pub enum $name {
            $( $(#[$variant_attr])* $variant, )+
        }

        impl $crate::settings::field::SettingType for $name {
            const KIND: $crate::settings::field::Kind =
                $crate::settings::field::Kind::Choice($crate::settings::field::choices_of::<$name>);
        }

        impl $crate::settings::field::SettingValue for $name {
            fn check(&self, _: &$crate::settings::field::Values) -> Result<(), String> {
                Ok(())
            }
            fn toml(&self) -> String {
                ::toml::Value::try_from(self).map(|v| v.to_string()).unwrap_or_default()
            }
        }
    };
}

pub(crate) use {choices, section};
