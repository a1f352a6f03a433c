//! The fuzz corpora, replayed on stable: every input kept in `fuzz/corpus/<target>/` (minimized
//! by `cargo fuzz cmin`, a subset kept) and every input that ever crashed, hung or ran away with
//! memory, kept in `fuzz/regressions/<target>/`, goes through the same harness function the
//! libFuzzer target calls (`fuzz/src/lib.rs`), with its checks: no panic (here: no error from the
//! loaders' panic net), errors that name the file, loaded results the renderers can use. Each
//! target's inputs must all finish within [`LIMIT`], so a hang that came back fails instead of
//! stalling the run. See fuzz/README.md for running the fuzzers themselves (nightly).

#[path = "../fuzz/src/lib.rs"]
mod harness;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

/// The time one target's inputs get, all together, in a debug build.
const LIMIT: Duration = Duration::from_secs(60);

/// The inputs of `target`: its corpus and its regressions, sorted by name.
fn inputs(target: &str) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut files = Vec::new();
    for kind in ["corpus", "regressions"] {
        let Ok(entries) = std::fs::read_dir(root.join(kind).join(target)) else { continue };
        files.extend(entries.map(|e| e.expect("a corpus entry").path()).filter(|p| p.is_file()));
    }
    files.sort();
    files
}

/// Runs every input of `target` through `run` on a worker thread, failing with the input's name
/// if one panics or if they take longer than [`LIMIT`].
fn replay(target: &'static str, run: fn(&[u8])) {
    let files = inputs(target);
    assert!(!files.is_empty(), "fuzz/corpus/{target}/ has no inputs");
    let current = Arc::new(Mutex::new(PathBuf::new()));
    let (done, finished) = mpsc::channel();
    let worker = {
        let current = Arc::clone(&current);
        let files = files.clone();
        std::thread::spawn(move || {
            let start = Instant::now();
            for file in &files {
                *current.lock().expect("no panic while holding the name") = file.clone();
                run(&std::fs::read(file).expect("a corpus file can be read"));
            }
            done.send(start.elapsed()).expect("the test waits for the worker");
        })
    };
    match finished.recv_timeout(LIMIT) {
        Ok(took) => eprintln!("{target}: {} inputs in {took:.2?}", files.len()),
        Err(mpsc::RecvTimeoutError::Timeout) => {
            panic!(
                "{target}: still running after {LIMIT:?}, on {}",
                current.lock().unwrap_or_else(|e| e.into_inner()).display()
            )
        }
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            let _ = worker.join();
            panic!("{target}: the harness failed on {}", current.lock().unwrap_or_else(|e| e.into_inner()).display())
        }
    }
}

#[test]
fn scene_toml_corpus() {
    replay("scene_toml", harness::scene_toml);
}

#[test]
fn gltf_corpus() {
    replay("gltf", harness::gltf);
}

#[test]
fn obj_corpus() {
    replay("obj", harness::obj);
}

#[test]
fn ply_corpus() {
    replay("ply", harness::ply);
}

#[test]
fn nrrd_corpus() {
    replay("nrrd", harness::nrrd);
}

#[test]
fn raw_volume_corpus() {
    replay("raw_volume", harness::raw_volume);
}

#[test]
fn image_corpus() {
    replay("image", harness::image);
}

#[test]
fn lab_source_corpus() {
    replay("lab_source", harness::lab_source);
}

#[test]
fn the_harness_splits_side_files_and_catches_what_it_should() {
    assert_eq!(harness::split_side(b"a\n%%side%%\nb\n%%side%%\nc"), (&b"a"[..], &b"b\n%%side%%\nc"[..]));
    assert_eq!(harness::split_side(b"no side"), (&b"no side"[..], &b""[..]));
    // An OBJ whose face names a vertex past the last is an error naming the file: the harness
    // accepts it. One it must refuse: a caught panic, as the net words it.
    harness::obj(b"v 0 0 0\nf 1 2 3\n");
    let caught = std::panic::catch_unwind(|| {
        harness::check_error(
            &format!("x.obj: OBJ: malformed file ({}: boom)", mirador::scene::PANIC_CAUGHT),
            Path::new("x.obj"),
        )
    });
    assert!(caught.is_err(), "a message from the panic net fails the harness");
}
