//! The settings table of docs/scene-format.md is generated from the settings' own descriptions
//! (`src/settings/`, through `mirador::settings_doc::scene_format_table`): this test fails when
//! the file's table differs from them, and with `MIRADOR_BLESS=1` writes the generated table
//! into the file, between its two marker comments, leaving the prose around it alone.

use std::path::Path;

const BEGIN: &str = concat!(
    "<!-- settings table: generated from src/settings/ by ",
    "`MIRADOR_BLESS=1 cargo test --test settings_docs`; edit the settings, not this table -->"
);
const END: &str = "<!-- end of the generated settings table -->";

#[test]
fn the_scene_format_table_matches_the_settings() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scene-format.md");
    let text = std::fs::read_to_string(&path).expect("docs/scene-format.md is readable");
    let (before, rest) = text.split_once(BEGIN).unwrap_or_else(|| panic!("{} has no line `{BEGIN}`", path.display()));
    let (table, after) = rest.split_once(END).unwrap_or_else(|| panic!("{} has no line `{END}`", path.display()));
    let generated = format!("\n{}", mirador::settings_doc::scene_format_table());
    if table == generated {
        return;
    }
    if std::env::var_os("MIRADOR_BLESS").is_some() {
        std::fs::write(&path, format!("{before}{BEGIN}{generated}{END}{after}"))
            .expect("docs/scene-format.md is writable");
        eprintln!("wrote the settings table of {}", path.display());
        return;
    }
    let first_difference = table
        .lines()
        .zip(generated.lines())
        .find(|(written, made)| written != made)
        .map(|(written, made)| format!("the file has\n  {written}\nthe settings give\n  {made}"))
        .unwrap_or_else(|| "the tables differ in length".into());
    panic!(
        "the settings table of docs/scene-format.md differs from the settings' descriptions; {first_difference}\n\
         Edit the descriptions in src/settings/, then run `MIRADOR_BLESS=1 cargo test --test settings_docs` \
         and commit the rewritten table."
    );
}
