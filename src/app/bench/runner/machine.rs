//! The machine a benchmark ran on: GL implementation, CPU, operating system, time.

use serde::{Deserialize, Serialize};

use gpgpu_rt::gl::GlInfo;

/// What `report.md` states about the machine.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Machine {
    pub gl_vendor: String,
    pub gl_renderer: String,
    pub gl_version: String,
    pub glsl_version: String,
    pub egl_device: String,
    pub cpu: String,
    pub logical_cpus: usize,
    pub os: String,
    /// UTC, ISO 8601.
    pub date: String,
    pub gpgpu_rt_version: String,
}

impl Machine {
    pub fn describe(info: &GlInfo) -> Machine {
        Machine {
            gl_vendor: info.vendor.clone(),
            gl_renderer: info.renderer.clone(),
            gl_version: info.version.clone(),
            glsl_version: info.glsl_version.clone(),
            egl_device: if info.egl_device_name.is_empty() {
                format!("{}", info.egl_device)
            } else {
                format!("{} ({})", info.egl_device, info.egl_device_name)
            },
            ..Machine::host()
        }
    }

    /// This host without a GL implementation (`--list`, `bench merge`): CPU, OS, date.
    pub fn host() -> Machine {
        let none = || "none (nothing measured)".to_string();
        Machine {
            gl_vendor: none(),
            gl_renderer: none(),
            gl_version: none(),
            glsl_version: none(),
            egl_device: none(),
            cpu: cpu_model().unwrap_or_else(|| std::env::consts::ARCH.to_string()),
            logical_cpus: std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            os: os_description(),
            date: utc_now(),
            gpgpu_rt_version: gpgpu_rt::VERSION.to_string(),
        }
    }

    /// True for Mesa's software rasterizers, whose timings only make sense as ratios.
    pub fn is_software(&self) -> bool {
        let r = self.gl_renderer.to_lowercase();
        r.contains("llvmpipe") || r.contains("softpipe") || r.contains("lavapipe")
    }
}

fn cpu_model() -> Option<String> {
    let text = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    text.lines()
        .find(|l| {
            l.starts_with("model name") || l.starts_with("Hardware") || l.starts_with("cpu model")
        })
        .and_then(|l| l.split_once(':'))
        .map(|(_, v)| v.trim().to_string())
}

fn os_description() -> String {
    let release = std::fs::read_to_string("/proc/sys/kernel/osrelease")
        .map(|s| format!(" {}", s.trim()))
        .unwrap_or_default();
    let pretty = std::fs::read_to_string("/etc/os-release")
        .ok()
        .and_then(|t| {
            t.lines()
                .find_map(|l| l.strip_prefix("PRETTY_NAME="))
                .map(|v| format!(", {}", v.trim_matches('"')))
        });
    format!(
        "{}{}{}",
        std::env::consts::OS,
        release,
        pretty.unwrap_or_default()
    )
}

/// The current time as `YYYY-MM-DDThh:mm:ssZ` (no calendar crate needed for this one line).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    format_utc(secs)
}

/// Format seconds since the Unix epoch (days → civil date after H. Hinnant's algorithm).
pub fn format_utc(secs: i64) -> String {
    let days = secs.div_euclid(86_400);
    let rem = secs.rem_euclid(86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + (m <= 2) as i64;
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::format_utc;

    #[test]
    fn formats_known_dates() {
        assert_eq!(format_utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(format_utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(format_utc(1_700_000_000), "2023-11-14T22:13:20Z");
    }
}
