//! The one way an input file is read (issue 33, class 1): it must be a regular file (a FIFO
//! would block the open or the read forever, `/dev/zero` never ends, a folder is no text), its
//! length is checked against the host's memory before a byte is read
//! ([`super::budget::check_file`]), and the read stops at that length, so a file that grows
//! while it is read cannot take more than was estimated.

use std::fs::{File, Metadata, OpenOptions};
use std::io::Read;
use std::path::Path;

use super::budget;

/// What kind of file `m` is, for a refusal ("a FIFO", "a character device", …).
fn kind(m: &Metadata) -> &'static str {
    let t = m.file_type();
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// An error unless `m` is a regular file.
fn regular(m: &Metadata) -> Result<(), String> {
    if m.is_file() {
        Ok(())
    } else {
        Err(format!(
            "is {}; only regular files are read (their length is known before they are read)",
            kind(m)
        ))
    }
}

/// Open `path` for reading without blocking on a FIFO (a FIFO swapped in after the check
/// is then refused by the check of the open file).
fn open(path: &Path) -> std::io::Result<File> {
    let mut o = OpenOptions::new();
    o.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NONBLOCK);
    }
    o.open(path)
}

/// The bytes of the regular file `path`, within the host's memory. The error is a sentence
/// without the path (the caller names the file and its role).
pub fn read(path: &Path) -> Result<Vec<u8>, String> {
    let (file, len) = open_regular(path)?;
    budget::check_file(len)?;
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(len.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > len {
        return Err(format!(
            "grew past its length of {len} bytes while it was read"
        ));
    }
    Ok(bytes)
}

/// [`read`] as UTF-8 text.
pub fn read_text(path: &Path) -> Result<String, String> {
    String::from_utf8(read(path)?).map_err(|e| format!("is not UTF-8 text ({e})"))
}

/// A regular file opened for streaming (a gzip member is decompressed as it is read; the
/// caller bounds what it takes), with its length.
pub fn open_regular(path: &Path) -> Result<(File, u64), String> {
    regular(&std::fs::metadata(path).map_err(|e| e.to_string())?)?;
    let file = open(path).map_err(|e| e.to_string())?;
    let meta = file.metadata().map_err(|e| e.to_string())?;
    regular(&meta)?;
    Ok((file, meta.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_folders_and_fifos_are_refused_without_blocking() {
        let d = tempfile::tempdir().unwrap();
        for (p, k) in [
            (Path::new("/dev/zero"), "a character device"),
            (d.path(), "a folder"),
        ] {
            let e = read(p).unwrap_err();
            assert!(e.contains(k), "{}: {e}", p.display());
        }
        let fifo = d.path().join("f");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(read(&fifo).unwrap_err().contains("a FIFO"));
        let f = d.path().join("t.txt");
        std::fs::write(&f, "abc").unwrap();
        assert_eq!(read_text(&f).unwrap(), "abc");
    }
}
