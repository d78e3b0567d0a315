//! Host memory that input-controlled allocations will take, estimated and checked **before**
//! they are made (issue 14, class 1): a model file's length, the triangles a procedural
//! object or a file gives. A refusal names the object and the limit; no input reaches an
//! allocation failure.
//!
//! The limit is the host's available memory (`MemAvailable` of `/proc/meminfo`), or
//! `GPGPU_RT_MEMORY_LIMIT` (bytes, or with a `K`, `M` or `G` suffix) when it is set; without
//! either (not Linux) only the fixed caps apply ([`super::MAX_PROCEDURAL_TRIANGLES`]).

/// Host bytes of one triangle of a [`super::Mesh`]: three positions, normals and colours of 12
/// bytes, three texture coordinates of 8, one material id of 4.
pub const MESH_TRIANGLE_BYTES: u64 = 3 * (12 + 12 + 12 + 8) + 4;

/// Copies of the triangles made on their way to the GPU (the mesh, the world-space attributes
/// or the vertex arrays of the upload, the world triangles of the accelerators and their
/// CPU structures).
pub const TRIANGLE_COPIES: u64 = 4;

/// A model file read and parsed takes at most this many times its length (the text, the
/// parser's arrays, its per-element maps for PLY).
pub const FILE_FACTOR: u64 = 16;

/// The environment variable that sets the limit instead of the host's available memory.
pub const LIMIT_VAR: &str = "GPGPU_RT_MEMORY_LIMIT";

/// The limit and where it comes from, `None` when unknown.
pub fn host_limit() -> Option<(u64, &'static str)> {
    if let Ok(v) = std::env::var(LIMIT_VAR) {
        return parse_bytes(&v).map(|b| (b, LIMIT_VAR));
    }
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some((kib.saturating_mul(1024), "the host's available memory"))
}

/// `"123"`, `"64K"`, `"512M"`, `"2G"`, `"1T"` as bytes; `KB`/`KiB` and the like mean the same
/// (powers of 1024, as `MemAvailable` counts).
pub fn parse_bytes(s: &str) -> Option<u64> {
    let s = s.trim();
    let lower = s.to_ascii_lowercase();
    // "KiB" needs its K; a lone "B" means bytes
    let (number, needs_unit) = match lower.strip_suffix("ib") {
        Some(n) => (n, true),
        None => (lower.strip_suffix('b').unwrap_or(&lower), false),
    };
    let (digits, shift) = match number.char_indices().last()? {
        (i, 'k') => (&number[..i], 10),
        (i, 'm') => (&number[..i], 20),
        (i, 'g') => (&number[..i], 30),
        (i, 't') => (&number[..i], 40),
        _ if !needs_unit => (number, 0),
        _ => return None,
    };
    let digits = digits.trim();
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse::<u64>().ok()?.checked_mul(1 << shift)
}

/// An error when `GPGPU_RT_MEMORY_LIMIT` is set but is not a size (checked once at the start
/// of every command: a limit that does not parse must not silently mean no limit).
pub fn check_limit_var() -> Result<(), String> {
    match std::env::var(LIMIT_VAR) {
        Err(std::env::VarError::NotPresent) => Ok(()),
        Ok(v) if parse_bytes(&v).is_some_and(|b| b > 0) => Ok(()),
        Ok(v) => Err(format!(
            "{LIMIT_VAR}={v:?} is not a positive size (bytes, or with K, M, G or T for powers of \
             1024, e.g. 512M)"
        )),
        Err(e) => Err(format!("{LIMIT_VAR}: {e}")),
    }
}

/// `bytes` as "12.3 MiB".
pub fn human(bytes: u64) -> String {
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < units.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{v:.1} {}", units[u])
    }
}

/// `what` would take `bytes` of host memory: an error when that is more than the limit.
pub fn check_host(what: &str, bytes: u64) -> Result<(), String> {
    check_against(what, bytes, host_limit())
}

/// [`check_host`] against a given limit (`None`: no limit known).
pub fn check_against(what: &str, bytes: u64, limit: Option<(u64, &str)>) -> Result<(), String> {
    match limit {
        Some((avail, source)) if bytes > avail => Err(format!(
            "{what} would take about {} of host memory, more than the {} of {source}",
            human(bytes),
            human(avail)
        )),
        _ => Ok(()),
    }
}

/// `what`, whose size `decided_by` (an option, or the scene) sets, would take `bytes` of host
/// memory: an error naming both when that is more than the limit. Every structure a scene or
/// an option sizes is estimated through here before it is allocated.
pub fn reserve(what: &str, decided_by: &str, bytes: u64) -> Result<(), String> {
    Tracker::new(what, decided_by).add(bytes)
}

/// A build that allocates as it goes (a tree whose size shows only while it is built): each
/// step adds its bytes before it allocates them, and the running total is checked against
/// the limit taken once at the start.
pub struct Tracker {
    what: String,
    decided_by: String,
    limit: Option<(u64, &'static str)>,
    total: u64,
}

impl Tracker {
    pub fn new(what: &str, decided_by: &str) -> Tracker {
        Tracker {
            what: what.to_string(),
            decided_by: decided_by.to_string(),
            limit: host_limit(),
            total: 0,
        }
    }

    /// Add `bytes` about to be allocated; an error when the total passes the limit.
    pub fn add(&mut self, bytes: u64) -> Result<(), String> {
        self.total = self.total.saturating_add(bytes);
        check_against(&self.what, self.total, self.limit)
            .map_err(|e| format!("{e} ({} decides its size)", self.decided_by))
    }

    /// The bytes added so far.
    pub fn total(&self) -> u64 {
        self.total
    }
}

/// `triangles` of `what`, with the copies made for the GPU, within the host's memory.
pub fn check_triangles(what: &str, triangles: u64) -> Result<(), String> {
    check_triangles_against(what, triangles, host_limit())
}

/// [`check_triangles`] against a limit taken once (a scene's objects, one after another).
pub fn check_triangles_against(
    what: &str,
    triangles: u64,
    limit: Option<(u64, &str)>,
) -> Result<(), String> {
    let bytes = triangles.saturating_mul(MESH_TRIANGLE_BYTES * TRIANGLE_COPIES);
    check_against(&format!("{what}: {triangles} triangles"), bytes, limit)
}

/// A model file of `len` bytes, read and parsed, within the host's memory.
pub fn check_file(len: u64) -> Result<(), String> {
    check_host(
        &format!("reading this {} file", human(len)),
        len.saturating_mul(FILE_FACTOR),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_print() {
        assert_eq!(parse_bytes("2G"), Some(2 << 30));
        assert_eq!(parse_bytes("64 k"), Some(64 << 10));
        assert_eq!(parse_bytes("100"), Some(100));
        assert_eq!(parse_bytes("x"), None);
        assert_eq!(parse_bytes("1KB"), Some(1 << 10));
        assert_eq!(parse_bytes("3 MiB"), Some(3 << 20));
        assert_eq!(parse_bytes("7b"), Some(7));
        for bad in ["-5", "abc", "", "K", "1.5G", "5iB", "+3"] {
            assert_eq!(parse_bytes(bad), None, "{bad}");
        }
        assert_eq!(parse_bytes("99999999999999G"), None);
        assert_eq!(human(3 << 29), "1.5 GiB");
    }

    #[test]
    fn a_refusal_names_the_object_and_the_limit() {
        let e = check_against("floor", 3 << 30, Some((1 << 30, "X"))).unwrap_err();
        assert!(e.contains("floor") && e.contains("3.0 GiB") && e.contains("1.0 GiB of X"));
        assert!(check_against("floor", 1 << 30, Some((1 << 30, "X"))).is_ok());
        assert!(check_against("floor", u64::MAX, None).is_ok());
    }
}
