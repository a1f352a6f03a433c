//! `mirador copy SCENE DIR`: a scene file and every file it reads, copied into a folder a
//! student owns, so an exercise is done on the copy and the course stays as it was.
//!
//! The files are the ones loading the scene found ([`super::locate::recording`]): textures,
//! environment maps, models, volumes. A model brings the files it names itself (an OBJ's MTL
//! libraries and their texture maps, a glTF's buffers and images). Each lands under the folder
//! at the path the scene gave it with its leading `..` steps dropped
//! (`../../textures/checker.png` → `textures/checker.png`), and the copy of the scene names it
//! so: the folder reads nothing outside itself, which is checked by loading the copy (a copy that
//! would still read a file from outside, named by an absolute path or with `..` further in, is
//! refused and taken back). Nothing already in the folder is overwritten.

use std::path::{Component, Path, PathBuf};

use super::locate;

/// What [`copy`] wrote, relative to the folder: the scene first.
pub struct Copied {
    pub files: Vec<PathBuf>,
}

/// Copies the scene at `scene` and the files it reads into `dir`.
pub fn copy(scene: &Path, dir: &Path) -> Result<Copied, String> {
    let text = std::fs::read_to_string(scene).map_err(|e| format!("{}: {e}", scene.display()))?;
    let found = files_read(scene)?;
    let name = scene.file_name().ok_or_else(|| format!("{}: not a file", scene.display()))?;
    let mut plan: Vec<(PathBuf, PathBuf)> = Vec::new();
    let mut rewritten = text.clone();
    for (relative, source) in &found {
        let target = inside(relative).ok_or_else(|| {
            format!(
                "{}: `{relative}` is named by an absolute path or with `..` inside it, so it has no place in the \
                 folder: copy it by hand",
                scene.display()
            )
        })?;
        let written = target.to_string_lossy().replace('\\', "/");
        if written != *relative {
            for quote in ['"', '\''] {
                rewritten =
                    rewritten.replace(&format!("{quote}{relative}{quote}"), &format!("{quote}{written}{quote}"));
            }
        }
        for (from, to) in with_dependencies(source, &target)? {
            match plan.iter().find(|(_, t)| *t == to) {
                Some((other, _)) if *other != from => {
                    return Err(format!(
                        "{}: {} and {} would both be copied to {}: copy them by hand",
                        scene.display(),
                        other.display(),
                        from.display(),
                        to.display()
                    ));
                }
                Some(_) => {}
                None => plan.push((from, to)),
            }
        }
    }
    let mut files = vec![PathBuf::from(name)];
    files.extend(plan.iter().map(|(_, to)| to.clone()));
    if let Some(taken) = files.iter().find(|f| dir.join(f).exists()) {
        return Err(format!(
            "{}: already exists; nothing was copied (copy into a new folder)",
            dir.join(taken).display()
        ));
    }
    let written = write(&plan, dir, name, &rewritten);
    // The copy must read nothing outside the folder; otherwise it is taken back.
    let outside = written.and_then(|()| {
        let read = files_read(&dir.join(name))?;
        let dir = std::fs::canonicalize(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        Ok(read.into_iter().find(|(_, found)| std::fs::canonicalize(found).map_or(true, |f| !f.starts_with(&dir))))
    });
    match outside {
        Ok(None) => Ok(Copied { files }),
        Ok(Some((relative, found))) => {
            remove(&files, dir);
            Err(format!(
                "{}: the copy would still read `{relative}` from {}; nothing was copied",
                scene.display(),
                found.display()
            ))
        }
        Err(e) => {
            remove(&files, dir);
            Err(e)
        }
    }
}

/// Writes the files of `plan` and the rewritten scene into `dir`.
fn write(plan: &[(PathBuf, PathBuf)], dir: &Path, name: &std::ffi::OsStr, scene: &str) -> Result<(), String> {
    for (from, to) in plan {
        let to = dir.join(to);
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        }
        std::fs::copy(from, &to).map_err(|e| format!("copying {} to {}: {e}", from.display(), to.display()))?;
    }
    crate::output::write_atomically(scene.as_bytes(), &dir.join(name))
        .map_err(|e| format!("{}: {e}", dir.join(name).display()))
}

/// Removes what a failed copy wrote (`files`, relative to `dir`); the folders stay.
fn remove(files: &[PathBuf], dir: &Path) {
    for file in files {
        let _ = std::fs::remove_file(dir.join(file));
    }
}

/// The files loading the scene at `scene` reads, as the scene names each and where it was
/// found (beside the scene, or in Mirador's own files).
pub fn files_read(scene: &Path) -> Result<Vec<(String, PathBuf)>, String> {
    let (loaded, found) = locate::recording(|| super::load(scene));
    loaded.map_err(|e| e.to_string())?;
    Ok(found)
}

/// `relative` with its leading `..` and `.` steps dropped: where the copy keeps the file. `None`
/// for a path that would not stay in the folder: absolute, or with `..` further in.
fn inside(relative: &str) -> Option<PathBuf> {
    let rest: Vec<Component> = Path::new(relative)
        .components()
        .skip_while(|c| matches!(c, Component::ParentDir | Component::CurDir))
        .collect();
    let plain = !rest.is_empty() && rest.iter().all(|c| matches!(c, Component::Normal(_)));
    plain.then(|| rest.iter().collect())
}

/// The file at `source`, to be kept at `target`, and the files it names itself, each kept at the
/// same place relative to it.
fn with_dependencies(source: &Path, target: &Path) -> Result<Vec<(PathBuf, PathBuf)>, String> {
    let mut out = vec![(source.to_path_buf(), target.to_path_buf())];
    let (from_dir, to_dir) = (source.parent().unwrap_or(Path::new("")), target.parent().unwrap_or(Path::new("")));
    let extension = source.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let named: Vec<String> = match extension.as_deref() {
        Some("obj") => {
            let mut named = Vec::new();
            for library in lines_naming(source, &["mtllib"])? {
                let mtl = from_dir.join(&library);
                if mtl.is_file() {
                    let maps =
                        lines_naming(&mtl, &["map_kd", "map_ka", "map_ks", "map_bump", "bump", "map_d", "norm"])?;
                    let mtl_dir = Path::new(&library).parent().unwrap_or(Path::new(""));
                    named.extend(maps.iter().map(|m| mtl_dir.join(m).to_string_lossy().into_owned()));
                }
                named.push(library);
            }
            named
        }
        Some("gltf") => gltf_uris(source)?,
        _ => Vec::new(),
    };
    // A file the model names beside or below itself keeps its place relative to the model; one
    // named elsewhere (`../maps/wood.png`, an absolute path) is left where it is.
    for relative in named {
        let from = from_dir.join(&relative);
        let kept = inside(&relative).filter(|kept| kept.as_os_str().len() == Path::new(&relative).as_os_str().len());
        if let Some(kept) = kept.filter(|_| from.is_file()) {
            out.push((from, to_dir.join(kept)));
        }
    }
    Ok(out)
}

/// The last word of each line of `path` that starts with one of `keys` (case aside).
fn lines_naming(path: &Path, keys: &[&str]) -> Result<Vec<String>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    Ok(text
        .lines()
        .filter_map(|line| {
            let mut words = line.split_whitespace();
            let key = words.next()?.to_ascii_lowercase();
            keys.contains(&key.as_str()).then(|| words.last().map(str::to_owned)).flatten()
        })
        .collect())
}

/// The relative `uri`s of a glTF file's buffers and images (not the `data:` ones inside it).
fn gltf_uris(path: &Path) -> Result<Vec<String>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let uris = ["buffers", "images"]
        .iter()
        .filter_map(|key| json.get(key)?.as_array())
        .flatten()
        .filter_map(|item| item.get("uri")?.as_str())
        .filter(|uri| !uri.starts_with("data:"))
        .map(str::to_owned)
        .collect();
    Ok(uris)
}
