//! GLSL program loading: kernels embedded in the binary (or read from `--glsl-dir`), a small
//! `#include "file"` preprocessor, `#define` injection, and compile/link errors that name the
//! GLSL file and line.
//!
//! The assembled source keeps a map from each of its lines to (file, line), so a driver
//! message such as `0:17(5): error: ...` (Mesa) or `0(17) : error ...` (NVIDIA) is mapped back
//! to `glsl/common/intersect.glsl:3`. (A line map rather than `#line L FILE`: Mesa drops the
//! file number in its semantic errors.)

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context as _, Result};
use glow::HasContext;

use super::context::Gl;
pub use super::defines::Defines;
use super::resources::Owned;

/// The kernel files compiled into the binary, keyed by their path below `glsl/` (every file
/// of the folder: see `build.rs`).
pub const EMBEDDED: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/embedded_glsl.rs"));

/// The environment variable that, when no `--glsl-dir` is given, names a folder to read the
/// kernels from instead of the embedded copies.
pub const GLSL_DIR_ENV: &str = "GPGPU_RT_GLSL_DIR";

/// Where kernel sources come from.
#[derive(Debug, Clone, Default)]
pub struct ShaderSource {
    /// `None`: the embedded copies; `Some(dir)`: files read from `dir` (the `--glsl-dir` option).
    pub dir: Option<PathBuf>,
}

impl ShaderSource {
    pub fn from_dir(dir: Option<PathBuf>) -> Result<Self> {
        if let Some(d) = &dir {
            if !d.is_dir() {
                bail!("--glsl-dir {}: not a directory", d.display());
            }
        }
        Ok(ShaderSource { dir })
    }

    /// The folder the kernels are read from: `dir`, else the environment variable
    /// [`GLSL_DIR_ENV`] when set and non-empty (so that a test binary or the CLI runs edited
    /// kernels without recompiling, e.g. for `scripts/mutants.sh`), else none (embedded).
    pub fn effective_dir(&self) -> Option<PathBuf> {
        self.dir.clone().or_else(|| {
            std::env::var_os(GLSL_DIR_ENV)
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
        })
    }

    /// The text of one kernel file.
    pub fn read(&self, name: &str) -> Result<String> {
        match &self.effective_dir() {
            Some(dir) => {
                let path = dir.join(name);
                crate::scene::file::read_text(&path)
                    .map_err(|e| anyhow!("cannot read GLSL file {}: {e}", path.display()))
            }
            None => EMBEDDED
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, s)| s.to_string())
                .ok_or_else(|| anyhow!("no embedded GLSL file {name}")),
        }
    }

    /// How `name` is shown in messages: its path below `--glsl-dir`, or `glsl/NAME` when embedded.
    pub fn display_name(&self, name: &str) -> String {
        match &self.effective_dir() {
            Some(dir) => dir.join(name).display().to_string(),
            None => format!("glsl/{name}"),
        }
    }

    /// Assemble `name` with its includes, the binding slots of [`super::slots`] and the given
    /// defines. Returns the text and, for
    /// every line of it, the file and line it came from.
    pub fn assemble(&self, name: &str, defines: &Defines) -> Result<(String, LineMap)> {
        let mut map = LineMap::default();
        let mut out = String::new();
        map.push("<generated header>", 1);
        out.push_str("#version 450 core\n");
        // the binding slots of gl::slots, then the program's own defines
        let mut all = super::slots::defines();
        all.0.extend(defines.0.clone());
        for (i, (k, v)) in all.0.iter().enumerate() {
            out.push_str(&format!("#define {k} {v}\n"));
            map.push("<generated header>", i + 2);
        }
        self.include(name, &mut out, &mut map, &mut Vec::new())?;
        Ok((out, map))
    }

    fn include(
        &self,
        name: &str,
        out: &mut String,
        map: &mut LineMap,
        stack: &mut Vec<String>,
    ) -> Result<()> {
        if stack.iter().any(|s| s == name) {
            bail!("#include cycle: {} -> {name}", stack.join(" -> "));
        }
        let text = self.read(name)?;
        let display = self.display_name(name);
        stack.push(name.to_string());
        for (lineno, line) in text.lines().enumerate() {
            let trimmed = line.trim_start();
            if let Some(rest) = trimmed.strip_prefix("#include") {
                let target = rest.trim().trim_matches('"');
                if target.is_empty() {
                    bail!(
                        "{}:{}: malformed #include",
                        self.display_name(name),
                        lineno + 1
                    );
                }
                let dir = Path::new(name).parent().unwrap_or(Path::new(""));
                let target = dir.join(target).to_string_lossy().replace('\\', "/");
                self.include(&normalize(&target), out, map, stack)
                    .with_context(|| {
                        format!("included from {}:{}", self.display_name(name), lineno + 1)
                    })?;
            } else {
                if trimmed.starts_with("#version") {
                    // the header carries the version
                    out.push('\n');
                } else {
                    out.push_str(line);
                    out.push('\n');
                }
                map.push(&display, lineno + 1);
            }
        }
        stack.pop();
        Ok(())
    }
}

/// Resolve `a/../b` in include paths.
fn normalize(path: &str) -> String {
    let mut parts: Vec<&str> = Vec::new();
    for p in path.split('/') {
        match p {
            ".." => {
                parts.pop();
            }
            "." | "" => {}
            p => parts.push(p),
        }
    }
    parts.join("/")
}

/// For every line of an assembled source: the file and line it came from.
#[derive(Debug, Clone, Default)]
pub struct LineMap(Vec<(String, usize)>);

impl LineMap {
    fn push(&mut self, file: &str, line: usize) {
        self.0.push((file.to_string(), line));
    }

    /// The origin of assembled line `line` (1-based).
    pub fn origin(&self, line: usize) -> Option<(&str, usize)> {
        self.0
            .get(line.checked_sub(1)?)
            .map(|(f, l)| (f.as_str(), *l))
    }

    pub fn files(&self) -> impl Iterator<Item = &str> {
        self.0.iter().map(|(f, _)| f.as_str())
    }
}

/// Rewrite a driver's compile log so every `N:LINE(` / `N(LINE)` prefix names the file.
pub fn map_log(log: &str, map: &LineMap) -> String {
    let mut out = String::new();
    for line in log.lines() {
        out.push_str(&map_line(line, map).unwrap_or_else(|| line.to_string()));
        out.push('\n');
    }
    out
}

fn map_line(line: &str, map: &LineMap) -> Option<String> {
    let t = line.trim_start();
    let digits: String = t.chars().take_while(|c| c.is_ascii_digit()).collect();
    if digits.is_empty() {
        return None;
    }
    let rest = &t[digits.len()..];
    let (lineno, tail) = if let Some(r) = rest.strip_prefix(':') {
        // Mesa: "0:12(5): error: ..."
        let n: String = r.chars().take_while(|c| c.is_ascii_digit()).collect();
        (n.clone(), r[n.len()..].to_string())
    } else if let Some(r) = rest.strip_prefix('(') {
        // NVIDIA: "0(12) : error C0000: ..."
        let n: String = r.chars().take_while(|c| c.is_ascii_digit()).collect();
        (n.clone(), r[n.len()..].trim_start_matches(')').to_string())
    } else {
        return None;
    };
    let (name, origin) = map.origin(lineno.parse().ok()?)?;
    Some(format!("{name}:{origin}{tail}"))
}

/// `GPGPU_RT_DUMP_GLSL=DIR`: every stage's assembled source (includes expanded, defines
/// injected: what the driver compiles, so its line numbers are the driver's) is written to
/// DIR/NAME, a second version of the same file as NAME.2, and so on.
fn dump_source(name: &str, text: &str) {
    let Some(dir) = std::env::var_os("GPGPU_RT_DUMP_GLSL") else {
        return;
    };
    let dir = Path::new(&dir);
    // `thesis_grid/intersect1.comp` -> `thesis_grid.intersect1.comp`
    let file = name.replace(['/', '\\'], ".");
    let mut path = dir.join(&file);
    let mut k = 2;
    while path.exists() {
        if crate::scene::file::read_text(&path).is_ok_and(|t| t == text) {
            return;
        }
        path = dir.join(format!("{file}.{k}"));
        k += 1;
    }
    if let Err(e) = std::fs::create_dir_all(dir).and_then(|_| std::fs::write(&path, text)) {
        log::warn!("GPGPU_RT_DUMP_GLSL: cannot write {}: {e}", path.display());
    }
}

/// Shader stages that compiled with messages (warnings) in their info log, all contexts of the
/// process. (A stage taken from the driver's shader cache is not compiled and has no log.)
static COMPILER_MESSAGES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// How many shader stages compiled with warnings so far (they are logged at `warn`).
pub fn compiler_messages() -> u64 {
    COMPILER_MESSAGES.load(std::sync::atomic::Ordering::Relaxed)
}

/// One stage of a program: kind (glow::COMPUTE_SHADER, ...) and file name below `glsl/`.
/// Compiler warnings are logged (file and line mapped like errors) and counted. The program
/// and its stages are owned: whatever fails, nothing is left behind.
pub fn compile_program(
    gl: &Arc<Gl>,
    source: &ShaderSource,
    stages: &[(u32, &str)],
    defines: &Defines,
) -> Result<Owned<glow::Program>> {
    // SAFETY: GL object creation and queries on a current context, of objects we own.
    unsafe {
        let program = Owned::new(gl, gl.create_program().map_err(|e| anyhow!(e))?);
        let mut shaders = Vec::new();
        for &(kind, name) in stages {
            let (text, lines) = source.assemble(name, defines)?;
            dump_source(name, &text);
            let shader = Owned::new(gl, gl.create_shader(kind).map_err(|e| anyhow!(e))?);
            gl.shader_source(shader.raw(), &text);
            gl.compile_shader(shader.raw());
            if !gl.get_shader_compile_status(shader.raw()) {
                let log = map_log(&gl.get_shader_info_log(shader.raw()), &lines);
                bail!(
                    "GLSL compile error in {}:\n{log}",
                    source.display_name(name)
                );
            }
            let log = gl.get_shader_info_log(shader.raw());
            if !log.trim().is_empty() {
                COMPILER_MESSAGES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                log::warn!(
                    "GLSL compiler messages for {}:\n{}",
                    source.display_name(name),
                    map_log(&log, &lines).trim_end()
                );
            }
            gl.attach_shader(program.raw(), shader.raw());
            shaders.push(shader);
        }
        gl.link_program(program.raw());
        // the stages are deleted as they drop, detached: the program no longer needs them
        for s in &shaders {
            gl.detach_shader(program.raw(), s.raw());
        }
        if !gl.get_program_link_status(program.raw()) {
            let log = gl.get_program_info_log(program.raw());
            let names: Vec<String> = stages.iter().map(|(_, n)| source.display_name(n)).collect();
            bail!("GLSL link error in {}:\n{log}", names.join(" + "));
        }
        Ok(program)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_lines_name_files() {
        let mut map = LineMap::default();
        map.push("<generated header>", 1);
        for l in 1..=20 {
            map.push("glsl/a.comp", l);
        }
        for l in 1..=5 {
            map.push("glsl/common/b.glsl", l);
        }
        assert_eq!(
            map_line("0:23(5): error: `x' undeclared", &map).unwrap(),
            "glsl/common/b.glsl:2(5): error: `x' undeclared"
        );
        assert_eq!(
            map_line("0(12) : error C0000: syntax error", &map).unwrap(),
            "glsl/a.comp:11 : error C0000: syntax error"
        );
        assert!(map_line("warning: nothing", &map).is_none());
    }

    #[test]
    fn includes_are_resolved_and_numbered() {
        let src = ShaderSource::default();
        let (text, map) = src
            .assemble("brute_force/intersect1.comp", &Defines::new().set("FOO", 3))
            .unwrap();
        assert!(text.starts_with("#version 450 core\n#define FOO 3\n"));
        assert!(map.files().any(|f| f == "glsl/common/intersect.glsl"));
        assert!(!text.contains("#include"));
        assert_eq!(text.lines().count(), map.0.len());
        // an assembled line maps back to the same text in its file
        let k = text
            .lines()
            .position(|l| l.contains("bool intersectTriangle("))
            .unwrap();
        let (f, l) = map.origin(k + 1).unwrap();
        assert_eq!(f, "glsl/common/intersect.glsl");
        let orig = EMBEDDED
            .iter()
            .find(|(n, _)| *n == "common/intersect.glsl")
            .unwrap()
            .1;
        assert!(orig
            .lines()
            .nth(l - 1)
            .unwrap()
            .contains("bool intersectTriangle("));
    }
}
