//! Which OpenGL implementation answers: `--driver` on the command line, or the environment
//! variable [`DRIVER_ENV`] (which the tests honour too). Mesa reads its own variables when it
//! loads a driver, so they are set here before the process's first EGL call
//! ([`GlContext::headless`](super::GlContext::headless) calls [`apply_from_env`] first).

use std::sync::OnceLock;

use anyhow::{anyhow, bail, Context as _, Result};

/// `GPGPU_RT_DRIVER=zink` (or `llvmpipe`, or `auto`): the driver to ask for.
pub const DRIVER_ENV: &str = "GPGPU_RT_DRIVER";

/// The drivers a user can ask for by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Driver {
    /// The first EGL device that gives a 4.5 core context (an NVIDIA GPU where there is one,
    /// else Mesa's default, llvmpipe).
    Auto,
    /// Mesa's llvmpipe: OpenGL on the CPU.
    Llvmpipe,
    /// Mesa's zink: OpenGL on Vulkan (lavapipe on a machine without a GPU; Debian:
    /// mesa-vulkan-drivers).
    Zink,
}

impl Driver {
    pub fn name(self) -> &'static str {
        match self {
            Driver::Auto => "auto",
            Driver::Llvmpipe => "llvmpipe",
            Driver::Zink => "zink",
        }
    }

    /// Whether a context whose GL_RENDERER is `renderer` is this driver.
    pub fn matches(self, renderer: &str) -> bool {
        match self {
            Driver::Auto => true,
            Driver::Llvmpipe => renderer.starts_with("llvmpipe"),
            Driver::Zink => renderer.starts_with("zink"),
        }
    }

    fn parse(text: &str) -> Result<Driver> {
        <Driver as clap::ValueEnum>::from_str(text.trim(), true)
            .map_err(|_| anyhow!("{DRIVER_ENV}={text}: not a driver (auto, llvmpipe or zink)"))
    }
}

/// The driver [`DRIVER_ENV`] names (auto where it is unset or empty), with Mesa's variables
/// for it set — once per process, before any EGL call.
pub fn apply_from_env() -> Result<Driver> {
    static CHOSEN: OnceLock<Result<Driver, String>> = OnceLock::new();
    CHOSEN
        .get_or_init(|| {
            let text = std::env::var(DRIVER_ENV).unwrap_or_default();
            let driver = if text.is_empty() {
                Ok(Driver::Auto)
            } else {
                Driver::parse(&text)
            };
            driver
                .and_then(|d| set_mesa_variables(d).map(|()| d))
                .map_err(|e| format!("{e:#}"))
        })
        .clone()
        .map_err(|e| anyhow!(e))
}

/// Mesa's variables for `driver`, where the user has not set them already.
fn set_mesa_variables(driver: Driver) -> Result<()> {
    let set_default = |key: &str, value: &str| {
        if std::env::var_os(key).is_none() {
            std::env::set_var(key, value);
        }
    };
    match driver {
        Driver::Auto => {}
        Driver::Llvmpipe => {
            set_default("LIBGL_ALWAYS_SOFTWARE", "1");
            set_default("GALLIUM_DRIVER", "llvmpipe");
        }
        Driver::Zink => {
            set_default("MESA_LOADER_DRIVER_OVERRIDE", "zink");
            set_default("GALLIUM_DRIVER", "zink");
            set_default("LIBGL_ALWAYS_SOFTWARE", "1");
            if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
                std::env::set_var("XDG_RUNTIME_DIR", runtime_dir()?);
            }
        }
    }
    Ok(())
}

/// Mesa's variables from the environment that keep `driver` from being loaded (set before this
/// program ran: [`set_mesa_variables`] leaves a user's value as it is), as `NAME=value`.
pub fn conflicting_variables(driver: Driver) -> Vec<String> {
    let wanted: &[(&str, &str)] = match driver {
        Driver::Auto => &[],
        Driver::Llvmpipe => &[
            ("GALLIUM_DRIVER", "llvmpipe"),
            ("MESA_LOADER_DRIVER_OVERRIDE", ""),
        ],
        Driver::Zink => &[
            ("GALLIUM_DRIVER", "zink"),
            ("MESA_LOADER_DRIVER_OVERRIDE", "zink"),
        ],
    };
    let value = |k: &str| std::env::var(k).ok().filter(|v| !v.is_empty());
    wanted
        .iter()
        .filter_map(|(k, want)| {
            let v = value(k)?;
            (v != *want).then(|| format!("{k}={v}"))
        })
        .collect()
}

/// A folder of our own, mode 700, for `XDG_RUNTIME_DIR` (Vulkan's loader and zink look there).
fn runtime_dir() -> Result<std::path::PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, PermissionsExt};
    // SAFETY: getuid has no preconditions.
    let uid = unsafe { libc::getuid() };
    let dir = std::env::temp_dir().join(format!("gpgpu-rt-xdg-{uid}"));
    if !dir.is_dir() {
        std::fs::DirBuilder::new()
            .mode(0o700)
            .create(&dir)
            .with_context(|| format!("cannot make {} for XDG_RUNTIME_DIR", dir.display()))?;
    }
    let meta = std::fs::metadata(&dir)?;
    if meta.permissions().mode() & 0o077 != 0 {
        bail!(
            "{} (for XDG_RUNTIME_DIR) is open to other users; remove it or set XDG_RUNTIME_DIR",
            dir.display()
        );
    }
    Ok(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drivers_match_their_renderers() {
        assert!(Driver::Zink.matches("zink (llvmpipe (LLVM 15.0.6, 256 bits))"));
        assert!(!Driver::Llvmpipe.matches("zink (llvmpipe (LLVM 15.0.6, 256 bits))"));
        assert!(Driver::Llvmpipe.matches("llvmpipe (LLVM 15.0.6, 256 bits)"));
        assert!(Driver::Auto.matches("NVIDIA H200/PCIe/SSE2"));
        assert_eq!(Driver::parse("Zink").unwrap(), Driver::Zink);
        let e = Driver::parse("nouveau").unwrap_err().to_string();
        assert!(
            e.contains("GPGPU_RT_DRIVER=nouveau") && e.contains("zink"),
            "{e}"
        );
    }
}
