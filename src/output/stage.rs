//! All-or-nothing writing: every output is written to a temporary file beside its target and
//! flushed to disk; only when all were written are they renamed over their targets. A staging
//! dropped before [`Staging::commit`] removes its temporary files and the folders it made.

use std::fs::{self, File};
use std::io::{BufWriter, Cursor, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use anyhow::{anyhow, Context as _, Result};
use tempfile::NamedTempFile;

use super::check::{is_stream, parent_of};
use super::interrupt;

/// Where an encoder writes: a file or a buffer (image encoders want to seek).
pub trait WriteSeek: Write + Seek {}
impl<T: Write + Seek> WriteSeek for T {}

enum Staged {
    /// A regular file: its complete new content in a temporary file beside it.
    Temp { tmp: NamedTempFile, target: PathBuf },
    /// A device or pipe (`/dev/stdout`): written in place at the commit, from memory.
    Stream { bytes: Vec<u8>, target: PathBuf },
}

/// The outputs of one command, written but not yet in place.
#[derive(Default)]
pub struct Staging {
    staged: Vec<Staged>,
    /// Folders made for the outputs, outermost first; removed again unless committed.
    created: Vec<PathBuf>,
    /// What it registered for removal on an interrupt ([`interrupt`]).
    registered: Vec<u64>,
}

impl Staging {
    pub fn new() -> Staging {
        Staging::default()
    }

    /// Make `dir` and its missing ancestors (remembered, to remove them if nothing is
    /// committed).
    pub fn create_folder(&mut self, dir: &Path) -> Result<()> {
        let missing: Vec<&Path> = dir.ancestors().take_while(|d| !d.exists()).collect();
        for d in missing.into_iter().rev() {
            if d.as_os_str().is_empty() {
                continue;
            }
            let mut r = interrupt::registry();
            fs::create_dir(d)
                .with_context(|| format!("cannot create the folder {}", d.display()))?;
            self.registered.push(r.add(d.to_path_buf(), true));
            self.created.push(d.to_path_buf());
        }
        Ok(())
    }

    /// Write `target`'s new content with `encode`, into a temporary file beside it (or into
    /// memory for a device or pipe). Errors name `target`.
    pub fn file(
        &mut self,
        target: &Path,
        encode: impl FnOnce(&mut dyn WriteSeek) -> Result<()>,
    ) -> Result<()> {
        let named = || format!("cannot write {}", target.display());
        if is_stream(target) {
            let target = target.to_path_buf();
            let mut buf = Cursor::new(Vec::new());
            encode(&mut buf).with_context(named)?;
            let bytes = buf.into_inner();
            self.staged.push(Staged::Stream { bytes, target });
            return Ok(());
        }
        let target = through_link(target);
        let tmp = {
            let mut r = interrupt::registry();
            let tmp = temp_beside(&target).with_context(named)?;
            self.registered.push(r.add(tmp.path().to_path_buf(), false));
            tmp
        };
        let mut w = BufWriter::new(tmp.as_file());
        encode(&mut w).with_context(named)?;
        w.flush().with_context(named)?;
        drop(w);
        // on disk now, so that a full disk fails here and not after the rename
        tmp.as_file().sync_all().with_context(named)?;
        self.staged.push(Staged::Temp { tmp, target });
        Ok(())
    }

    /// Put every staged file in place: the devices and pipes first (they cannot be undone,
    /// and if one fails no regular file has been replaced), then the renames.
    pub fn commit(mut self) -> Result<()> {
        let staged = std::mem::take(&mut self.staged);
        let (streams, temps): (Vec<_>, Vec<_>) = staged
            .into_iter()
            .partition(|s| matches!(s, Staged::Stream { .. }));
        // (a pipe may block: an interrupt must still find the registry free meanwhile)
        for s in streams {
            if let Staged::Stream { bytes, target } = s {
                write_stream(&target, &bytes)?;
            }
        }
        // held to the end: an interrupt waits for the renames, so it finds all or none done
        let mut registry = interrupt::registry();
        let temps = temps.into_iter().filter_map(|t| match t {
            Staged::Temp { tmp, target } => Some((tmp, target)),
            Staged::Stream { .. } => None,
        });
        let renamed = rename_all(temps.collect());
        if renamed.is_ok() {
            self.created.clear();
        }
        registry.forget(&std::mem::take(&mut self.registered));
        drop(registry); // before `self` drops, which takes it again
        renamed
    }
}

/// Rename every temporary file over its target. The old files are kept as hard links until all
/// renames succeeded; if one fails, the targets renamed before it get their old files back (or
/// are removed where there was none).
fn rename_all(temps: Vec<(NamedTempFile, PathBuf)>) -> Result<()> {
    let mut done: Vec<(PathBuf, Option<NamedTempFile<()>>)> = Vec::new();
    for (tmp, target) in temps {
        let old = keep_old(&target);
        if let Err(e) = tmp.persist(&target) {
            roll_back(done);
            let e = anyhow!(e.error);
            return Err(e.context(format!("cannot replace {}", target.display())));
        }
        done.push((target, old));
    }
    Ok(()) // the old files' links are removed as they drop
}

/// A hard link `.NAME.XXXXXX.old` to the file `target` (none where it does not exist or the
/// file system has no hard links).
fn keep_old(target: &Path) -> Option<NamedTempFile<()>> {
    let name = target.file_name()?.to_string_lossy();
    let prefix = format!(".{name}.{}", run_mark(std::process::id()));
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".old");
    let link = |p: &Path| fs::hard_link(target, p);
    fs::metadata(target).ok().filter(|m| m.is_file())?;
    b.make_in(parent_of(target), link).ok()
}

/// Put the old files of `done` back (best effort: this runs after an error).
fn roll_back(done: Vec<(PathBuf, Option<NamedTempFile<()>>)>) {
    for (target, old) in done.into_iter().rev() {
        let _ = match old {
            Some(old) => old.persist(&target).map(|_| ()).map_err(|e| e.error),
            None => fs::remove_file(&target),
        };
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        let mut registry = interrupt::registry();
        // the temporary files first (removed as they drop), then the folders made for them
        self.staged.clear();
        for d in self.created.iter().rev() {
            let _ = fs::remove_dir(d);
        }
        registry.forget(&self.registered);
    }
}

/// The file a symbolic link `path` points to (written there, the link kept), else `path`.
fn through_link(path: &Path) -> PathBuf {
    let link = fs::symlink_metadata(path).is_ok_and(|m| m.is_symlink());
    match link.then(|| fs::canonicalize(path)) {
        Some(Ok(p)) => p,
        _ => path.to_path_buf(),
    }
}

/// What names a staged file as this process's: `gpgpu-rt-PID.` after the target's name.
fn run_mark(pid: u32) -> String {
    format!("{RUN_MARK}{pid}.")
}

const RUN_MARK: &str = "gpgpu-rt-";

/// The process that staged the file `name` (`.NAME.gpgpu-rt-PID.XXXXXX.tmp` or `.old`).
fn stager_of(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?;
    if !(rest.ends_with(".tmp") || rest.ends_with(".old")) {
        return None;
    }
    let (_, after) = rest.rsplit_once(RUN_MARK)?;
    after.split_once('.')?.0.parse().ok()
}

/// Is the process `pid` still running? (Where it cannot be told, yes: nothing is removed.)
fn alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return true;
        };
        // signal 0 checks only; ESRCH: no such process
        let r = unsafe { libc::kill(pid, 0) };
        r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Remove from `dir` the staged files of runs that were killed before they could (SIGKILL, a
/// power cut): each carries its process id, and a process that no longer runs will not commit
/// it. Once per folder and process.
fn sweep_litter(dir: &Path) {
    static SWEPT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    let mut swept = SWEPT.lock().unwrap_or_else(|e| e.into_inner());
    if swept.iter().any(|d| d == dir) {
        return;
    }
    swept.push(dir.to_path_buf());
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let dead = stager_of(&name.to_string_lossy())
            .is_some_and(|pid| pid != std::process::id() && !alive(pid));
        if dead && e.file_type().is_ok_and(|t| t.is_file()) {
            let _ = fs::remove_file(e.path());
        }
    }
}

/// A temporary file `.NAME.gpgpu-rt-PID.XXXXXX.tmp` beside `target`, with `target`'s
/// permissions if it exists, else those of a new file (0666 less the umask).
fn temp_beside(target: &Path) -> Result<NamedTempFile> {
    let name = target.file_name().unwrap_or_default().to_string_lossy();
    sweep_litter(parent_of(target));
    let prefix = format!(".{name}.{}", run_mark(std::process::id()));
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(fs::Permissions::from_mode(0o666));
    }
    let dir = parent_of(target);
    let tmp = b
        .tempfile_in(dir)
        .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
    if let Ok(m) = fs::metadata(target) {
        tmp.as_file().set_permissions(m.permissions())?;
    }
    Ok(tmp)
}

fn write_stream(target: &Path, bytes: &[u8]) -> Result<()> {
    let named = || format!("cannot write {}", target.display());
    let mut f = File::options()
        .write(true)
        .open(target)
        .with_context(named)?;
    f.write_all(bytes).with_context(named)?;
    f.flush().with_context(named)
}

/// The staging of a [`Batch`] in progress, which [`write_file`] stages into.
static BATCH: Mutex<Option<Staging>> = Mutex::new(None);

fn batch() -> MutexGuard<'static, Option<Staging>> {
    BATCH.lock().unwrap_or_else(|e| e.into_inner())
}

/// Every file [`write_file`] writes while a batch is open is staged, not put in place: a
/// command that writes many files as it goes (the bench's CSVs, plots, frames and report)
/// commits them together at its end, or, dropping the batch, leaves every old file as it was
/// (a bench run that measured nothing must not replace one that did).
pub struct Batch(());

impl Batch {
    pub fn begin() -> Batch {
        *batch() = Some(Staging::new());
        Batch(())
    }

    /// Put every staged file in place.
    pub fn commit(self) -> Result<()> {
        let staged = batch().take();
        staged.map_or(Ok(()), Staging::commit)
    }

    /// Put every file staged so far in place and go on staging into a new staging (a long
    /// command keeps what it finished: an interrupt removes only what came after).
    pub fn commit_so_far(&self) -> Result<()> {
        let mut b = batch();
        let done = b.replace(Staging::new());
        drop(b); // the commit takes the interrupt registry, which a staging's files take first
        done.map_or(Ok(()), Staging::commit)
    }

    /// Put in place only the staged files that replace nothing; the others are discarded.
    pub fn commit_new_files(self) -> Result<()> {
        let Some(mut s) = batch().take() else {
            return Ok(());
        };
        s.staged.retain(|f| match f {
            Staged::Temp { target, .. } => fs::symlink_metadata(target).is_err(),
            Staged::Stream { .. } => false,
        });
        s.commit()
    }
}

impl Drop for Batch {
    fn drop(&mut self) {
        // the staged files are removed as the staging drops
        let staged = batch().take();
        drop(staged);
    }
}

/// Write the single file `target` with `encode`: into a temporary file, then renamed over it
/// (or staged into the open [`Batch`]).
pub fn write_file(
    target: &Path,
    encode: impl FnOnce(&mut dyn WriteSeek) -> Result<()>,
) -> Result<()> {
    if let Some(s) = batch().as_mut() {
        return s.file(target, encode);
    }
    let mut s = Staging::new();
    s.file(target, encode)?;
    s.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rename that fails (a folder appeared at the second target after staging) puts the first
    /// target's old file back and removes the new file where there was none.
    #[test]
    fn a_failed_rename_restores_the_renamed_files() {
        let d = tempfile::tempdir().unwrap();
        let (a, b, c) = (
            d.path().join("a.txt"),
            d.path().join("b.txt"),
            d.path().join("c.txt"),
        );
        fs::write(&a, "old a").unwrap();
        let mut s = Staging::new();
        for p in [&a, &c, &b] {
            s.file(p, |w| Ok(w.write_all(b"new")?)).unwrap();
        }
        fs::create_dir_all(b.join("in-the-way")).unwrap();
        let e = s.commit().unwrap_err();
        assert!(format!("{e:#}").contains("cannot replace"), "{e:#}");
        assert_eq!(fs::read_to_string(&a).unwrap(), "old a");
        assert!(!c.exists());
        let mut names: Vec<_> = fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        names.sort();
        assert_eq!(names, ["a.txt", "b.txt"]);
    }

    /// A staged file of a process that no longer runs (killed before it could remove it) is
    /// removed by the next staging in its folder; one of a running process and files of other
    /// names stay.
    #[test]
    fn staged_files_of_a_killed_run_are_swept() {
        let d = tempfile::tempdir().unwrap();
        let mut gone = std::process::Command::new("true").spawn().unwrap();
        gone.wait().unwrap(); // its id names no process now (reaped)
        let dead = format!(".report.md.{}abc123.tmp", run_mark(gone.id()));
        let dead_old = format!(".a.csv.{}xyz789.old", run_mark(gone.id()));
        let running = format!(".report.md.{}abc123.tmp", run_mark(1));
        let other = ".notes.tmp".to_string();
        for n in [&dead, &dead_old, &running, &other] {
            fs::write(d.path().join(n), "x").unwrap();
        }
        assert_eq!(stager_of(&dead), Some(gone.id()));
        assert_eq!(stager_of(&other), None);
        write_file(&d.path().join("new.txt"), |w| Ok(w.write_all(b"new")?)).unwrap();
        let mut names: Vec<String> = fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let mut want = vec![other, running, "new.txt".to_string()];
        want.sort();
        assert_eq!(names, want);
    }
}
