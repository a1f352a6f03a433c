//! The browser build in `cargo test`: what CI can check without a browser (the full browser test
//! is `bash web/test.sh`, tests/web_page.rs). The library must keep compiling for
//! `wasm32-unknown-unknown`, and the page must carry every asset a built-in scene may name.

use std::path::Path;
use std::process::Command;

/// Every file under assets/ but the READMEs is built into the page (`files::BUILTIN`) or fetched by
/// it (`files::FETCHED`), and every name in the lists exists: a scene added without its texture, or a list left behind, fails here
/// rather than in a browser.
#[test]
fn the_page_carries_every_asset() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut on_disk = Vec::new();
    let mut folders = vec![root.join("assets")];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else if path.file_name().is_some_and(|n| n != "README.md") {
                on_disk.push(path.strip_prefix(root).unwrap().to_str().unwrap().to_string());
            }
        }
    }
    on_disk.sort();
    let files = || mirador::files::BUILTIN.iter().chain(mirador::files::FETCHED);
    let mut in_page: Vec<String> = files().filter(|p| p.starts_with("assets/")).map(|p| p.to_string()).collect();
    in_page.sort();
    assert_eq!(in_page, on_disk, "src/files.rs's lists (built in and fetched) and assets/ differ");
    for path in files() {
        assert!(root.join(path).is_file(), "{path} is in the page but is not a file");
    }
    for path in mirador::files::FETCHED {
        assert!(!mirador::files::BUILTIN.contains(path), "{path} is both built in and fetched");
    }
}

/// `cargo check` of the library for the browser, in a target folder of its own (the outer `cargo
/// test` holds its own). Needs rustup's wasm32 standard library: README's install line adds it,
/// and `.ci/run` does.
#[test]
fn the_library_compiles_for_the_browser() {
    let target_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web-check");
    // Both of the page's modules: WebGPU's, and WebGL2's without WebGPU (web/build.sh).
    for features in [&[][..], &["--no-default-features", "--features=webgl2"]] {
        let output = Command::new(env!("CARGO"))
            .args(["check", "--locked", "--lib", "--target", "wasm32-unknown-unknown", "--message-format", "short"])
            .args(features)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("CARGO_TARGET_DIR", &target_dir)
            .output()
            .expect("running cargo");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            !stderr.contains("can't find crate for `core`") && !stderr.contains("target may not be installed"),
            "the wasm32-unknown-unknown standard library is missing: `rustup target add wasm32-unknown-unknown` \
             (README's install line)\n{stderr}"
        );
        let module = if features.is_empty() { "WebGPU" } else { "WebGL2" };
        assert!(output.status.success(), "the library does not compile for the browser ({module}):\n{stderr}");
        assert!(!stderr.contains("warning:"), "the browser build warns ({module}):\n{stderr}");
    }
}
