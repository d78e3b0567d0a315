//! The checks every output path gets before any GPU work: a format the command writes, a
//! folder that exists (or can be made) and takes new files, and no other output or input of the
//! command at the same file.

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

/// What a file holds; its name must end in one of the format's extensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The colour image: PNG or JPEG, chosen by the extension (`view --screenshot`).
    Image,
    /// The colour image as `render -o` writes it: PNG, JPEG or OpenEXR (linear float).
    ColorImage,
    /// OpenEXR (`--aov-format exr`).
    Exr,
    /// A NumPy array (`--aov-dir`, `export-triangles -o`).
    Npy,
    /// JSON (`--stats`).
    Json,
}

impl Format {
    /// The extensions (lower case) of the format.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Format::Image => &["png", "jpg", "jpeg"],
            Format::ColorImage => &["png", "jpg", "jpeg", "exr"],
            Format::Exr => &["exr"],
            Format::Npy => &["npy"],
            Format::Json => &["json"],
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Format::Image => "a PNG or JPEG image",
            Format::ColorImage => "a PNG, JPEG or OpenEXR image",
            Format::Exr => "an OpenEXR image",
            Format::Npy => "a NumPy array",
            Format::Json => "JSON",
        }
    }
}

/// An output file of a command: the option that names it, the path and its format.
#[derive(Debug, Clone)]
pub struct Target {
    pub option: String,
    pub path: PathBuf,
    pub format: Format,
    /// The file goes into a folder the command makes when it is missing (`--aov-dir`).
    pub in_new_folder: bool,
}

impl Target {
    /// An output file `path` named by `option`, in a folder that must exist.
    pub fn file(option: &str, path: &Path, format: Format) -> Target {
        Target {
            option: option.to_string(),
            path: path.to_path_buf(),
            format,
            in_new_folder: false,
        }
    }

    /// The files `names` in the folder `dir` named by `option`, made when missing.
    pub fn in_folder(option: &str, dir: &Path, names: &[&str], format: Format) -> Vec<Target> {
        let target = |name: &&str| Target {
            in_new_folder: true,
            ..Target::file(option, &dir.join(name), format)
        };
        names.iter().map(target).collect()
    }

    fn name(&self) -> String {
        format!("{} {}", self.option, self.path.display())
    }
}

/// An input file of a command (the scene, a model, a texture), which no output may replace.
#[derive(Debug, Clone)]
pub struct Input {
    pub path: PathBuf,
    /// What it is, for the message: "the scene file", "a model of the scene", …
    pub role: String,
}

/// The folder of `path` ("." for a bare file name).
pub fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A file under `/dev/` (`/dev/stdout` even when it is redirected to a file, `/dev/full`), or
/// one that exists and is neither a regular file nor a folder (a pipe): written in place, since
/// there is nothing to keep.
pub fn is_stream(path: &Path) -> bool {
    path.starts_with("/dev/") || fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Check `targets`, each alone and against each other, before anything is rendered.
pub fn check(targets: &[Target]) -> Result<()> {
    for t in targets {
        check_one(t)?;
    }
    for (i, a) in targets.iter().enumerate() {
        if let Some(b) = targets[i + 1..]
            .iter()
            .find(|b| same_file(&a.path, &b.path))
        {
            bail!(
                "{} and {} are the same file: each output needs its own",
                a.name(),
                b.name()
            );
        }
    }
    for a in targets {
        if let Some(b) = targets.iter().find(|b| folder_of(&a.path, &b.path)) {
            bail!(
                "{} would be a file, but {} puts a file inside it: it cannot be both",
                a.name(),
                b.name()
            );
        }
    }
    Ok(())
}

/// `file` is a folder above `other` (an `-o x.png` where `--aov-dir x.png` writes files).
fn folder_of(file: &Path, other: &Path) -> bool {
    let file = canonical(file);
    canonical(other).ancestors().skip(1).any(|d| d == file)
}

/// Refuse any target that is one of `inputs`.
pub fn refuse_inputs(targets: &[Target], inputs: &[Input]) -> Result<()> {
    for t in targets {
        if let Some(i) = inputs.iter().find(|i| same_file(&t.path, &i.path)) {
            bail!(
                "{} is {} ({}), an input of this command: refusing to overwrite it",
                t.name(),
                i.role,
                i.path.display()
            );
        }
    }
    Ok(())
}

fn check_one(t: &Target) -> Result<()> {
    if is_stream(&t.path) {
        return Ok(());
    }
    // `y.png/` names a folder: the path's own file name ignores the slash
    if t.path
        .as_os_str()
        .to_string_lossy()
        .ends_with(std::path::MAIN_SEPARATOR)
    {
        bail!(
            "{}: ends in {}, so it names a folder, not a file",
            t.name(),
            std::path::MAIN_SEPARATOR
        );
    }
    match fs::metadata(&t.path) {
        Ok(m) if m.is_dir() => bail!("{}: is a folder, not a file", t.name()),
        // renaming over it would succeed: its mode is the owner's wish to keep it
        Ok(m) if m.permissions().readonly() => bail!("{}: is read-only, not replaced", t.name()),
        _ => {}
    }
    check_extension(t)?;
    let dir = parent_of(&t.path);
    if t.in_new_folder {
        check_folder(&t.option, dir)
    } else if !dir.is_dir() {
        bail!("{}: the folder {} does not exist", t.name(), dir.display())
    } else {
        probe(&t.name(), dir)
    }
}

fn check_extension(t: &Target) -> Result<()> {
    let ext = t.path.extension().and_then(|e| e.to_str());
    let ext = ext.map(str::to_ascii_lowercase).unwrap_or_default();
    let allowed = t.format.extensions();
    if !allowed.contains(&ext.as_str()) {
        let list: Vec<String> = allowed.iter().map(|e| format!(".{e}")).collect();
        let list = match list.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        };
        let name = t.path.file_name().unwrap_or_default().to_string_lossy();
        let got = if !ext.is_empty() {
            format!("not `.{ext}`")
        } else if name.starts_with('.') && !name[1..].contains('.') {
            format!("`{name}` has no extension: a name that begins with its only dot is all name")
        } else {
            format!("`{name}` has no extension")
        };
        bail!(
            "{}: {} writes {}, so the file name must end in {list} ({got})",
            t.name(),
            t.option,
            t.format.describe(),
        );
    }
    Ok(())
}

/// A folder named by `option` that the command makes when missing: it is a folder and takes
/// new files, or its nearest existing ancestor is and does.
pub fn check_folder(option: &str, dir: &Path) -> Result<()> {
    let name = format!("{option} {}", dir.display());
    let mut existing = dir;
    while !existing.exists() {
        match existing.parent() {
            Some(p) if !p.as_os_str().is_empty() => existing = p,
            _ => existing = Path::new("."),
        }
    }
    if !existing.is_dir() {
        bail!("{name}: {} is not a folder", existing.display());
    }
    probe(&name, existing)
}

/// Create and remove a file in `dir`: the only sure test that it takes new files.
fn probe(name: &str, dir: &Path) -> Result<()> {
    let probe = tempfile::Builder::new()
        .prefix(".gpgpu-rt-probe.")
        .tempfile_in(dir);
    match probe {
        Ok(_) => Ok(()),
        Err(e) => bail!("{name}: cannot create files in {}: {e}", dir.display()),
    }
}

/// Whether `a` and `b` name the same file: the same canonical path (links and `..` resolved,
/// for files that do not exist yet through their folder), or the same device and inode (hard
/// links).
pub fn same_file(a: &Path, b: &Path) -> bool {
    if canonical(a) == canonical(b) {
        return true;
    }
    matches!((inode(a), inode(b)), (Some(x), Some(y)) if x == y)
}

fn canonical(path: &Path) -> PathBuf {
    if let Ok(p) = fs::canonicalize(path) {
        return p;
    }
    match (path.parent(), path.file_name()) {
        (Some(_), Some(name)) => canonical(parent_of(path)).join(name),
        _ => std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
    }
}

#[cfg(unix)]
fn inode(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn inode(_path: &Path) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_file_through_dots_links_and_missing_files() {
        let d = tempfile::tempdir().unwrap();
        let a = d.path().join("a.json");
        std::fs::write(&a, "{}").unwrap();
        std::fs::create_dir(d.path().join("sub")).unwrap();
        assert!(same_file(&a, &d.path().join("sub/../a.json")));
        std::fs::hard_link(&a, d.path().join("b.json")).unwrap();
        assert!(same_file(&a, &d.path().join("b.json")));
        let missing = d.path().join("new.png");
        assert!(same_file(&missing, &d.path().join(".").join("new.png")));
        assert!(!same_file(&missing, &a));
    }
}
