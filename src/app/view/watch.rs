//! Live-editable kernels: watch the `--glsl-dir` folder for changes.
//!
//! The folder is polled a few times a second: every file below it (kernels, `common/`
//! pieces) is read and hashed, and any difference to the last snapshot — a file written,
//! added, removed or renamed — is reported. Hashing contents instead of comparing
//! modification times catches edits within the file system's time resolution, and an editor
//! that writes a file in several steps only causes an extra reload (a half-written kernel
//! fails to compile, the last good program keeps running, the complete file then reloads).

use std::collections::hash_map::DefaultHasher;
use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Files larger than this are not kernels; they are noted by size only.
const MAX_HASHED_BYTES: u64 = 4 << 20;
/// Directory levels below the watched folder that are looked at.
const MAX_DEPTH: usize = 8;

/// A polled folder of GLSL files.
pub struct GlslWatcher {
    dir: PathBuf,
    snapshot: BTreeMap<PathBuf, u64>,
    interval: Duration,
    last_poll: Instant,
}

impl GlslWatcher {
    /// Take the first snapshot of `dir`; later changes are reported by [`GlslWatcher::poll`].
    pub fn new(dir: &Path, interval: Duration) -> GlslWatcher {
        GlslWatcher {
            dir: dir.to_path_buf(),
            snapshot: snapshot(dir),
            interval,
            last_poll: Instant::now(),
        }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// If the poll interval has passed: the files (relative to the folder) that changed since
    /// the last snapshot, or `None` when nothing did.
    pub fn poll(&mut self) -> Option<Vec<PathBuf>> {
        if self.last_poll.elapsed() < self.interval {
            return None;
        }
        self.poll_now()
    }

    /// Compare with the folder now, regardless of the interval.
    pub fn poll_now(&mut self) -> Option<Vec<PathBuf>> {
        self.last_poll = Instant::now();
        let now = snapshot(&self.dir);
        if now == self.snapshot {
            return None;
        }
        let mut changed: Vec<PathBuf> = now
            .iter()
            .filter(|(p, h)| self.snapshot.get(*p) != Some(h))
            .map(|(p, _)| p.clone())
            .collect();
        changed.extend(
            self.snapshot
                .keys()
                .filter(|p| !now.contains_key(*p))
                .cloned(),
        );
        changed.sort();
        self.snapshot = now;
        Some(changed)
    }

    /// The time until the next poll is due (for the event loop's wake-up).
    pub fn next_poll(&self) -> Instant {
        self.last_poll + self.interval
    }
}

fn snapshot(dir: &Path) -> BTreeMap<PathBuf, u64> {
    let mut files = BTreeMap::new();
    walk(dir, dir, 0, &mut files);
    files
}

fn walk(root: &Path, dir: &Path, depth: usize, out: &mut BTreeMap<PathBuf, u64>) {
    if depth > MAX_DEPTH {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let Ok(meta) = std::fs::metadata(&path) else {
            continue;
        };
        let name = entry.file_name();
        // editors' swap and backup files are not kernels
        let name = name.to_string_lossy();
        if name.starts_with('.') || name.ends_with('~') {
            continue;
        }
        if meta.is_dir() {
            walk(root, &path, depth + 1, out);
        } else if meta.is_file() {
            let mut h = DefaultHasher::new();
            meta.len().hash(&mut h);
            if meta.len() <= MAX_HASHED_BYTES {
                if let Ok(bytes) = gpgpu_rt::scene::file::read(&path) {
                    bytes.hash(&mut h);
                }
            } else if let Ok(m) = meta.modified() {
                m.hash(&mut h);
            }
            let rel = path.strip_prefix(root).unwrap_or(&path).to_path_buf();
            out.insert(rel, h.finish());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reports_written_added_and_removed_files() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("common")).unwrap();
        std::fs::write(dir.path().join("a.comp"), "void main() {}\n").unwrap();
        std::fs::write(dir.path().join("common/b.glsl"), "// b\n").unwrap();
        let mut w = GlslWatcher::new(dir.path(), Duration::ZERO);
        assert_eq!(w.poll(), None);
        // same length, same second: only the contents differ
        std::fs::write(dir.path().join("common/b.glsl"), "// c\n").unwrap();
        assert_eq!(w.poll(), Some(vec![PathBuf::from("common/b.glsl")]));
        assert_eq!(w.poll(), None);
        std::fs::write(dir.path().join("c.comp"), "x").unwrap();
        std::fs::remove_file(dir.path().join("a.comp")).unwrap();
        assert_eq!(
            w.poll(),
            Some(vec![PathBuf::from("a.comp"), PathBuf::from("c.comp")])
        );
        // editor swap files are ignored
        std::fs::write(dir.path().join(".c.comp.swp"), "x").unwrap();
        assert_eq!(w.poll(), None);
    }

    #[test]
    fn interval_limits_polling() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = GlslWatcher::new(dir.path(), Duration::from_secs(3600));
        std::fs::write(dir.path().join("a.comp"), "x").unwrap();
        assert_eq!(w.poll(), None);
        assert_eq!(w.poll_now(), Some(vec![PathBuf::from("a.comp")]));
    }
}
