//! Writes Haines' sphereflake ("balls" of the Standard Procedural Databases) as a scene file, so
//! the renderers can be compared on a scene that grows: 91, 820 or 7,381 spheres.
//!
//! ```sh
//! cargo run --release --example sphereflake -- 4              # writes sphereflake-4.toml
//! cargo run --release -- render sphereflake-4.toml -o flake.png --stats
//! cargo run --release -- trace sphereflake-4.toml -o flake-traced.png --stats
//! ```

use std::path::PathBuf;

use anyhow::{Context, bail};
use mirador::scene::sphereflake::{sphere_count, sphereflake_toml};

fn main() -> anyhow::Result<()> {
    let size: u32 = match std::env::args().nth(1) {
        Some(arg) => arg.parse().with_context(|| format!("{arg}: the size is a number, 0 to 5"))?,
        None => 3,
    };
    if size > 5 {
        bail!("size {size}: at most 5 (66,430 spheres)");
    }
    let path = PathBuf::from(format!("sphereflake-{size}.toml"));
    std::fs::write(&path, sphereflake_toml(size, 1280, 720)).with_context(|| format!("{}", path.display()))?;
    println!("{}: {} spheres", path.display(), sphere_count(size));
    Ok(())
}
