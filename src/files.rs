//! Where the files a scene names come from: the disk; in the browser, the scenes and assets built
//! into the page and the files the person opened there (by the file picker or by dropping them,
//! `src/web/`). Every reader of scenes, models, textures, environments and volumes opens its files
//! here, so the same readers, with the same checks and messages, serve both.
//!
//! Natively only regular files are read: a device or a pipe (`/dev/zero`, a FIFO) has no end a
//! reader could wait for, so a file naming one would never load, or fill memory while trying.

use std::io::{self, BufReader};
use std::path::Path;

/// An open file: read and seek, and know its length ([`length`]).
#[cfg(not(target_arch = "wasm32"))]
pub type Opened = std::fs::File;
#[cfg(target_arch = "wasm32")]
pub type Opened = io::Cursor<std::rc::Rc<[u8]>>;

/// Reads a whole file (natively, a regular one).
pub fn read(path: &Path) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    io::Read::read_to_end(&mut open(path)?, &mut bytes)?;
    Ok(bytes)
}

/// Reads a whole file of UTF-8 text.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_to_string(path: &Path) -> io::Result<String> {
    std::fs::read_to_string(path)
}
#[cfg(target_arch = "wasm32")]
pub fn read_to_string(path: &Path) -> io::Result<String> {
    String::from_utf8(read(path)?)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "stream did not contain valid UTF-8"))
}

/// An image reader of the file, its format guessed from the extension and then from the bytes,
/// as `image::ImageReader::open` guesses it.
pub fn image_reader(path: &Path) -> io::Result<image::ImageReader<BufReader<Opened>>> {
    let mut reader = image::ImageReader::new(BufReader::new(open(path)?));
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    reader.with_guessed_format()
}

/// The file's length in bytes.
pub fn length(file: &Opened) -> io::Result<u64> {
    #[cfg(not(target_arch = "wasm32"))]
    return Ok(file.metadata()?.len());
    #[cfg(target_arch = "wasm32")]
    return Ok(file.get_ref().len() as u64);
}

/// Opens a file for reading; natively it must be a regular file (or a link to one).
#[cfg(not(target_arch = "wasm32"))]
pub fn open(path: &Path) -> io::Result<Opened> {
    check_regular(path)?;
    std::fs::File::open(path)
}

/// An error unless `path` is a regular file (or a link to one): see the module's header.
#[cfg(not(target_arch = "wasm32"))]
pub fn check_regular(path: &Path) -> io::Result<()> {
    if std::fs::metadata(path)?.is_file() {
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        "not a regular file (a folder, a device or a pipe); Mirador reads files",
    ))
}

#[cfg(target_arch = "wasm32")]
pub use in_memory::{add, check_regular, open, opened};

/// Whether `path` is not there at all: what a model's importer may warn about and draw without
/// (a file that is there but is no regular file, or cannot be read, is an error of its reader).
pub fn is_missing(path: &Path) -> bool {
    check_regular(path).is_err_and(|e| e.kind() == io::ErrorKind::NotFound)
}

/// The files built into the browser's page, by their paths in the source tree: every file under
/// `assets/` but the READMEs and the [`FETCHED`] ones (`tests/web.rs` checks the lists), and the
/// model a course scene borrows from the tests. [`builtin_bytes`] holds their bytes, in the browser build only.
macro_rules! builtin_files {
    ($($path:literal),* $(,)?) => {
        pub const BUILTIN: &[&str] = &[$($path),*];

        /// The bytes of the [`BUILTIN`] files.
        #[cfg(target_arch = "wasm32")]
        pub fn builtin_bytes() -> [(&'static str, &'static [u8]); BUILTIN.len()] {
            [$(($path, include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/", $path)))),*]
        }
    };
}

builtin_files!(
    "assets/environments/sky.hdr",
    "assets/labs/bump/lab.toml",
    "assets/labs/environment-maps/lab.toml",
    "assets/labs/mipmaps/lab.toml",
    "assets/labs/parallax/lab.toml",
    "assets/labs/planar-mirrors/lab.toml",
    "assets/labs/refraction/lab.toml",
    "assets/labs/shadow-map/lab.toml",
    "assets/labs/transparency/lab.toml",
    "assets/labs/volumes/lab.toml",
    "assets/scenes/bumps.toml",
    "assets/scenes/course/acceleration-teapot.toml",
    "assets/scenes/course/aliasing-edges.toml",
    "assets/scenes/course/bump-fields.toml",
    "assets/scenes/course/camera-orthographic.toml",
    "assets/scenes/course/camera-perspective.toml",
    "assets/scenes/course/displacement-plane.toml",
    "assets/scenes/course/displacement-sphere.toml",
    "assets/scenes/course/environment-ball.toml",
    "assets/scenes/course/illumination-ambient.toml",
    "assets/scenes/course/illumination-terms.toml",
    "assets/scenes/course/mipmaps-floor.toml",
    "assets/scenes/course/mirror-pair.toml",
    "assets/scenes/course/shadows-bias.toml",
    "assets/scenes/course/shadows-methods.toml",
    "assets/scenes/course/transparency-order.toml",
    "assets/scenes/course/transparency-refraction.toml",
    "assets/scenes/course/volume-isosurface.toml",
    "assets/scenes/course/volume-phantom.toml",
    "assets/scenes/course/whitted-depth.toml",
    "assets/scenes/environment.toml",
    "assets/scenes/mirrors.toml",
    "assets/scenes/refraction.toml",
    "assets/scenes/seed-simple.toml",
    "assets/scenes/shadows.toml",
    "assets/scenes/showcase.toml",
    "assets/scenes/transparency.toml",
    "assets/scenes/volume.toml",
    "assets/textures/checker.png",
    "assets/textures/cobbles-height.png",
    "tests/data/obj/teapot.mtl",
);

/// The files the page fetches beside its module when it starts, rather than carrying them: the
/// largest (the phantom is 0.2 MB that compression cannot shrink, the teapot 0.07 MB compressed),
/// which only a few scenes name. web/build.sh copies them into the page's folder at the same
/// paths; web/files.js fetches them, and the page's scene and lab menus wait for them.
pub const FETCHED: &[&str] = &["assets/volumes/phantom.nrrd", "tests/data/obj/teapot.obj"];

/// The browser's files: a map from a normalized path (`assets/scenes/showcase.toml`,
/// `opened/model.glb`) to the file's bytes, filled at start with the built-in assets and then by
/// every file the person opens.
#[cfg(target_arch = "wasm32")]
mod in_memory {
    use std::cell::RefCell;
    use std::collections::HashMap;
    use std::io;
    use std::path::{Component, Path, PathBuf};
    use std::rc::Rc;

    thread_local! {
        static FILES: RefCell<HashMap<PathBuf, Rc<[u8]>>> = RefCell::new(HashMap::new());
    }

    /// `a/b/../c` → `a/c`, without asking a file system: paths in scene files are relative to the
    /// scene's folder.
    fn normalized(path: &Path) -> PathBuf {
        let mut out = PathBuf::new();
        for component in path.components() {
            match component {
                Component::ParentDir => {
                    out.pop();
                }
                Component::Normal(part) => out.push(part),
                Component::CurDir | Component::RootDir | Component::Prefix(_) => {}
            }
        }
        out
    }

    /// The files the person opened, by their names under `opened/`: what the page's tracer
    /// workers need besides the built-in assets.
    pub fn opened() -> Vec<(String, Rc<[u8]>)> {
        FILES.with(|files| {
            files
                .borrow()
                .iter()
                .filter_map(|(path, bytes)| {
                    let name = path.strip_prefix("opened").ok()?;
                    Some((name.to_string_lossy().into_owned(), bytes.clone()))
                })
                .collect()
        })
    }

    /// Adds (or replaces) a file.
    pub fn add(path: &Path, bytes: Vec<u8>) {
        FILES.with(|files| files.borrow_mut().insert(normalized(path), bytes.into()));
    }

    pub fn open(path: &Path) -> io::Result<super::Opened> {
        let found = FILES.with(|files| files.borrow().get(&normalized(path)).cloned());
        let bytes = found.ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::NotFound,
                "no such file among the page's built-in assets and the files opened (open every file the scene names together)",
            )
        })?;
        Ok(io::Cursor::new(bytes))
    }

    pub fn check_regular(path: &Path) -> io::Result<()> {
        open(path).map(|_| ())
    }
}
