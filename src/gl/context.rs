//! Headless OpenGL 4.5 core context through glutin's EGL device platform.
//!
//! `Device::query_devices()` enumerates the EGL devices (Mesa's llvmpipe "software" device on a
//! machine without a GPU, the NVIDIA device on an NVIDIA machine); a display is created on the
//! chosen device, a config with an empty surface type is chosen (the default template asks for
//! window surfaces and then finds nothing), and a 4.5 core context is made current without a
//! surface. All rendering happens in our own textures and framebuffers.

use std::ffi::{c_void, CStr, CString};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context as _, Result};
use glow::HasContext;
use glutin::api::egl::{context::PossiblyCurrentContext, device::Device, display::Display};
use glutin::config::{ConfigSurfaceTypes, ConfigTemplateBuilder};
use glutin::context::{ContextApi, ContextAttributesBuilder, GlProfile, Version};
use glutin::prelude::*;

pub use super::profile::LoopLimit;
use super::profile::{Profile, ProfileChoice, ProfileName, GUARANTEED_IMAGE_UNITS};

/// Facts about the GL implementation, printed by `info` and stored in the statistics.
#[derive(Debug, Clone, serde::Serialize)]
pub struct GlInfo {
    pub vendor: String,
    pub renderer: String,
    pub version: String,
    pub glsl_version: String,
    pub egl_device: usize,
    pub egl_device_name: String,
    pub max_ssbo_block_size: i64,
    /// GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT: where a bound range of a buffer may start.
    pub ssbo_offset_alignment: i32,
    pub max_texture_size: i32,
    pub max_3d_texture_size: i32,
    /// The compute stage's own limits (their keys stay at the top level of `info --json`).
    #[serde(flatten)]
    pub compute: ComputeLimits,
    pub max_vertex_shader_storage_blocks: i32,
    pub max_image_units: i32,
    pub max_array_texture_layers: i32,
    pub timer_query_bits: i32,
    /// GL_ARB_gpu_shader_int64: 64-bit integers in the kernels (the SAH BVH's intersect1 stores
    /// a pixel's record as two 64-bit words in one store, its intersect2 the counts as one
    /// word: `glsl/bvh/records.glsl`).
    pub int64: bool,
    /// GL_ARB_shader_ballot with 64-bit integers: a SIMD group's votes as one mask (the SAH
    /// BVH's hit list reserves a SIMD group's entries with one atomic: `glsl/bvh/hit_list.glsl`).
    pub ballot: bool,
    /// Every choice adapted to this implementation ([`Profile`]), made once from the facts
    /// above (and `GPGPU_RT_PROFILE`).
    pub profile: Profile,
}

/// The limits of the compute stage (GL 4.5, table 23.63).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ComputeLimits {
    pub max_compute_work_group_count: [i32; 3],
    pub max_compute_work_group_invocations: i32,
    pub max_compute_shared_memory_size: i32,
    pub max_compute_shader_storage_blocks: i32,
    /// GL_MAX_COMPUTE_IMAGE_UNIFORMS: the image uniforms one compute kernel may declare.
    pub max_compute_image_uniforms: i32,
}

impl GlInfo {
    /// The loop limit the implementation has, whatever the profile: llvmpipe's, alone or under
    /// zink (GL_RENDERER names it, with the width of its vectors: "llvmpipe (LLVM 15.0.6, 256
    /// bits)", 8 lanes of 32 bits; 16 lanes where the width cannot be read). `None` elsewhere.
    /// The kernels keep within [`Profile::loop_limit`], which the profile chooses from this.
    pub fn implementation_loop_limit(&self) -> Option<LoopLimit> {
        if !self.renderer.contains("llvmpipe") {
            return None;
        }
        Some(LoopLimit {
            iterations: LoopLimit::LLVMPIPE_ITERATIONS,
            lanes: vector_bits(&self.renderer).map_or(16, |b| b / 32),
        })
    }

    /// The implementation's loop limit where the profile's kernels do not keep within it (the
    /// `gpu` profile on llvmpipe or zink): the designs whose loops may pass it check their work
    /// against it and refuse, naming it, rather than give an image cut short.
    pub fn unkept_loop_limit(&self) -> Option<LoopLimit> {
        match self.profile.loop_limit {
            Some(_) => None,
            None => self.implementation_loop_limit(),
        }
    }

    /// Whether GL_RENDERER names one of Mesa's CPU rasterisers (llvmpipe, alone or under zink
    /// over lavapipe; softpipe): a fact for the profile's automatic choice and for reports.
    pub fn is_software_rasteriser(&self) -> bool {
        let r = &self.renderer;
        r.contains("llvmpipe") || r.contains("softpipe") || r.contains("lavapipe")
    }

    /// The same facts under the profile `choice` (the tests run the GPU's choices on llvmpipe
    /// this way, as `GPGPU_RT_PROFILE` does for the program).
    pub fn with_profile(&self, choice: ProfileChoice) -> GlInfo {
        let mut info = self.clone();
        info.profile = self.choose_profile(choice);
        info
    }

    /// The profile of this implementation as `choice` asks for it.
    pub fn choose_profile(&self, choice: ProfileChoice) -> Profile {
        let software = self.is_software_rasteriser();
        let (name, forced) = match choice {
            ProfileChoice::Auto if software => (ProfileName::Llvmpipe, false),
            ProfileChoice::Auto => (ProfileName::Gpu, false),
            ProfileChoice::Forced(n) => (n, true),
        };
        let units = self
            .max_image_units
            .min(self.compute.max_compute_image_uniforms);
        match name {
            ProfileName::Llvmpipe => Profile {
                name,
                forced,
                loop_limit: Some(self.implementation_loop_limit().unwrap_or(LoopLimit {
                    iterations: LoopLimit::LLVMPIPE_ITERATIONS,
                    lanes: 16,
                })),
                prefetch_rays: true,
                dispatch_threads: super::profile::llvmpipe_threads(),
                linespace_build_on_gpu: false,
                hit_list_ballot: self.ballot,
                record_store_64: self.int64,
                image_units: units,
            },
            ProfileName::Gpu => Profile {
                name,
                forced,
                loop_limit: None,
                prefetch_rays: false,
                dispatch_threads: 1,
                linespace_build_on_gpu: true,
                hit_list_ballot: self.ballot,
                record_store_64: self.int64,
                image_units: match software {
                    true => units.min(GUARANTEED_IMAGE_UNITS),
                    false => units,
                },
            },
        }
    }

    /// The most work groups of one dimension a dispatch may have (`GL_MAX_COMPUTE_WORK_GROUP_COUNT`
    /// of x, at least 65535 by GL 4.6 §19): the GPU-written commands of work lists keep within
    /// it (`MAX_GROUPS_X` in `glsl/common/work_lists.glsl`).
    pub fn max_groups_x(&self) -> u32 {
        self.compute.max_compute_work_group_count[0].max(1) as u32
    }
}

/// The vector width llvmpipe names in its GL_RENDERER ("… 256 bits)").
fn vector_bits(renderer: &str) -> Option<u32> {
    let head = renderer
        .split(" bits")
        .next()
        .filter(|h| h.len() < renderer.len())?;
    let n = head.rsplit([' ', ',', '(']).next()?;
    n.parse::<u32>().ok().filter(|&b| b >= 32)
}

/// An EGL device's name, else its vendor.
fn device_name(d: &Device) -> &str {
    d.name().or(d.vendor()).unwrap_or("unnamed EGL device")
}

/// The EGL devices as `info` lists them: index and name (or vendor; Mesa's software device has
/// neither).
pub fn egl_devices() -> Vec<String> {
    Device::query_devices()
        .map(|devices| {
            devices
                .enumerate()
                .map(|(i, d)| format!("{i}: {}", device_name(&d)))
                .collect()
        })
        .unwrap_or_default()
}

/// A current GL context. Dropping it releases the context.
pub struct GlContext {
    pub gl: Arc<Gl>,
    pub info: GlInfo,
    _context: PossiblyCurrentContext,
    _display: Display,
}

impl GlContext {
    /// Open a headless GL 4.5 core context. `device`: the index of the EGL device to use; `None`
    /// picks the first device that gives a 4.5 core context — of the driver `GPGPU_RT_DRIVER`
    /// names, where it names one ([`super::driver`]).
    pub fn headless(device: Option<usize>) -> Result<GlContext> {
        let driver = super::driver::apply_from_env()?;
        let choice = ProfileChoice::from_env()?;
        let devices: Vec<Device> = Device::query_devices()
            .map_err(|e| {
                anyhow!(
                    "no EGL device platform available ({e}); install Mesa's EGL \
                     (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri) or the NVIDIA driver"
                )
            })?
            .collect();
        if devices.is_empty() {
            bail!("EGL reports no devices; install libegl-mesa0 (llvmpipe) or a GPU driver");
        }
        let describe = |i: usize, d: &Device| format!("device {i} ({})", device_name(d));
        let candidates: Vec<usize> = match device {
            Some(i) if i < devices.len() => vec![i],
            Some(i) => bail!(
                "--device {i}: there are only {} EGL devices: {}",
                devices.len(),
                devices
                    .iter()
                    .enumerate()
                    .map(|(i, d)| describe(i, d))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            None => (0..devices.len()).collect(),
        };
        let mut failures = Vec::new();
        for i in candidates {
            match Self::open(&devices[i], i, choice) {
                Ok(ctx) if driver.matches(&ctx.info.renderer) => return Ok(ctx),
                Ok(ctx) => failures.push(format!(
                    "{}: {}, not {}",
                    describe(i, &devices[i]),
                    ctx.info.renderer,
                    driver.name()
                )),
                Err(e) => failures.push(format!("{}: {e:#}", describe(i, &devices[i]))),
            }
        }
        let what = match driver {
            super::driver::Driver::Auto => "an OpenGL 4.5 core context".to_string(),
            d => format!(
                "an OpenGL 4.5 core context of {} (--driver {} or {}={}{})",
                d.name(),
                d.name(),
                super::driver::DRIVER_ENV,
                d.name(),
                match d {
                    super::driver::Driver::Zink => "; zink needs mesa-vulkan-drivers",
                    _ => "",
                }
            ),
        };
        let inherited = super::driver::conflicting_variables(driver);
        let cause = match inherited.is_empty() {
            true => String::new(),
            false => format!(
                "\nthe environment sets {}, which loads another driver: unset it",
                inherited.join(" and ")
            ),
        };
        bail!(
            "no EGL device gives {what}:\n  {}{cause}",
            failures.join("\n  ")
        )
    }

    fn open(device: &Device, index: usize, choice: ProfileChoice) -> Result<GlContext> {
        // (eglInitialize sets up Mesa's screen, which names the renderer: under the lock too)
        let held = gl_strings_lock();
        // SAFETY: no native display handle is passed; the device comes from query_devices.
        let display = unsafe { Display::with_device(device, None) }
            .map_err(|e| anyhow!("cannot create an EGL display: {e}"))?;
        drop(held);
        let template = ConfigTemplateBuilder::new()
            .with_surface_type(ConfigSurfaceTypes::empty())
            .build();
        // SAFETY: the template is valid for this display.
        let config = unsafe { display.find_configs(template) }
            .map_err(|e| anyhow!("no EGL config: {e}"))?
            .next()
            .ok_or_else(|| anyhow!("no surfaceless EGL config"))?;
        let attributes = ContextAttributesBuilder::new()
            .with_context_api(ContextApi::OpenGl(Some(Version::new(4, 5))))
            .with_profile(GlProfile::Core)
            .with_debug(gl_debug_requested())
            .build(None);
        let held = gl_strings_lock();
        // SAFETY: the config belongs to this display.
        let context = unsafe { display.create_context(&config, &attributes) }
            .map_err(|e| anyhow!("cannot create a GL 4.5 core context: {e}"))?;
        let context = context
            .make_current_surfaceless()
            .map_err(|e| anyhow!("cannot make the context current without a surface: {e}"))?;
        drop(held);
        // SAFETY: the context is current; symbols come from its display.
        let gl = unsafe { load_gl(|name| display.get_proc_address(name), "the context") }?;
        let name = device.name().or(device.vendor()).unwrap_or("");
        let info = query_info(&gl, index, name, choice);
        Ok(GlContext {
            gl: Arc::new(gl),
            info,
            _context: context,
            _display: display,
        })
    }
}

/// Load the GL functions of the current context (debug output as requested) and check that it
/// is 4.5 core; `what` names the context in the error ("the window's context").
///
/// # Safety
/// A GL context must be current and `get_proc_address` must be its display's.
pub unsafe fn load_gl(get_proc_address: impl Fn(&CStr) -> *const c_void, what: &str) -> Result<Gl> {
    let load = |name: &str| {
        let name = CString::new(name).expect("GL symbol names have no NUL");
        get_proc_address(&name)
    };
    // SAFETY: as this function's contract: the context is current, the symbols its own.
    let mut gl = unsafe { Gl::load(load) }?;
    gl.enable_debug_output_if_requested();
    let version = gl.version();
    if (version.major, version.minor) < (4, 5) || version.is_embedded {
        bail!(
            "{what} is OpenGL {}.{}{}, 4.5 core is needed",
            version.major,
            version.minor,
            if version.is_embedded { " ES" } else { "" }
        );
    }
    Ok(gl)
}

/// One lock for every GL string query and every context creation in the process. Mesa 22.3's
/// zink formats GL_RENDERER into one static buffer at every query (`zink_get_name`), so a query
/// in another thread at the same moment reads it half rewritten — "" or "\0ink (…" (glibc's
/// snprintf clears the first byte before it writes) — and a context was taken for one of
/// another driver ("device 0: , not zink", about one run in six of a test file whose threads
/// made their contexts together; four threads of `tests/gl_strings.rs` read it torn 14,289
/// times in 800,000 queries without the lock). Context creation takes the lock too: Mesa
/// reads the name while it sets up a context.
static GL_STRINGS: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn gl_strings_lock() -> std::sync::MutexGuard<'static, ()> {
    // a panic while held leaves nothing half done: the lock guards Mesa's buffer, not ours
    GL_STRINGS.lock().unwrap_or_else(|e| e.into_inner())
}

/// `glGetString(name)` of the current context, whole whatever other threads query
/// ([`GL_STRINGS`]).
pub fn gl_string(gl: &Gl, name: u32) -> String {
    let _held = gl_strings_lock();
    // SAFETY: a plain query on the current context.
    unsafe { gl.get_parameter_string(name) }
}

/// Query the facts of `GlInfo` on a current context (headless or a window's); `device` and
/// `device_name` name where the context comes from.
pub fn query_info(gl: &Gl, device: usize, device_name: &str, choice: ProfileChoice) -> GlInfo {
    // SAFETY: plain queries on a current context.
    let mut info = unsafe {
        let int = |p: u32| gl.get_parameter_i32(p);
        let indexed = |p: u32, i: u32| gl.get_parameter_indexed_i32(p, i);
        let mut timer_bits = 0i32;
        (gl.get_query_iv)(glow::TIME_ELAPSED, QUERY_COUNTER_BITS, &mut timer_bits);
        let extensions = gl.supported_extensions();
        GlInfo {
            vendor: gl_string(gl, glow::VENDOR),
            renderer: gl_string(gl, glow::RENDERER),
            version: gl_string(gl, glow::VERSION),
            glsl_version: gl_string(gl, glow::SHADING_LANGUAGE_VERSION),
            egl_device: device,
            egl_device_name: device_name.to_string(),
            max_ssbo_block_size: gl.get_parameter_i64(glow::MAX_SHADER_STORAGE_BLOCK_SIZE),
            ssbo_offset_alignment: int(glow::SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT),
            max_texture_size: int(glow::MAX_TEXTURE_SIZE),
            max_3d_texture_size: int(glow::MAX_3D_TEXTURE_SIZE),
            compute: ComputeLimits {
                max_compute_work_group_count: [
                    indexed(glow::MAX_COMPUTE_WORK_GROUP_COUNT, 0),
                    indexed(glow::MAX_COMPUTE_WORK_GROUP_COUNT, 1),
                    indexed(glow::MAX_COMPUTE_WORK_GROUP_COUNT, 2),
                ],
                max_compute_work_group_invocations: int(glow::MAX_COMPUTE_WORK_GROUP_INVOCATIONS),
                max_compute_shared_memory_size: int(glow::MAX_COMPUTE_SHARED_MEMORY_SIZE),
                max_compute_shader_storage_blocks: int(glow::MAX_COMPUTE_SHADER_STORAGE_BLOCKS),
                max_compute_image_uniforms: int(glow::MAX_COMPUTE_IMAGE_UNIFORMS),
            },
            max_vertex_shader_storage_blocks: int(glow::MAX_VERTEX_SHADER_STORAGE_BLOCKS),
            max_image_units: int(glow::MAX_IMAGE_UNITS),
            max_array_texture_layers: int(glow::MAX_ARRAY_TEXTURE_LAYERS),
            timer_query_bits: timer_bits,
            int64: extensions.contains("GL_ARB_gpu_shader_int64"),
            ballot: extensions.contains("GL_ARB_gpu_shader_int64")
                && extensions.contains("GL_ARB_shader_ballot"),
            profile: Profile::UNSET,
        }
    };
    info.profile = info.choose_profile(choice);
    info
}

const QUERY_COUNTER_BITS: u32 = 0x8864;

type ClearBufferDataFn = unsafe extern "system" fn(u32, u32, u32, u32, *const c_void);
type ClearTexImageFn = unsafe extern "system" fn(u32, i32, u32, u32, *const c_void);
type GetQueryIvFn = unsafe extern "system" fn(u32, u32, *mut i32);
type GetQueryObjectU64Fn = unsafe extern "system" fn(u32, u32, *mut u64);
type TexBufferFn = unsafe extern "system" fn(u32, u32, u32);

/// The GL functions: glow's, plus the few GL 4.4/4.5 entry points glow does not wrap
/// (`glClearBufferData` — the thesis clears its grid lists with it every frame —,
/// `glClearTexImage` and `glGetQueryiv`).
pub struct Gl {
    glow: glow::Context,
    /// The barrier bits not issued since the last pass that ran shaders ([`super::sync`]).
    pending_barriers: std::sync::atomic::AtomicU32,
    pub(super) clear_buffer_data: ClearBufferDataFn,
    pub(super) clear_tex_image: ClearTexImageFn,
    get_query_iv: GetQueryIvFn,
    get_query_object_u64: GetQueryObjectU64Fn,
    tex_buffer: TexBufferFn,
}

impl std::ops::Deref for Gl {
    type Target = glow::Context;
    fn deref(&self) -> &glow::Context {
        &self.glow
    }
}

/// `GPGPU_RT_GL_DEBUG=1` (any value but empty or `0`): a debug context whose messages
/// (GL 4.3 / KHR_debug output) are logged — errors at `error`, the rest at `warn` (compiler,
/// performance and portability notes) or `debug` (notifications; `RUST_LOG=debug` shows them).
pub fn gl_debug_requested() -> bool {
    std::env::var("GPGPU_RT_GL_DEBUG").is_ok_and(|v| !v.is_empty() && v != "0")
}

/// GL debug messages of type error received so far (all contexts of the process).
static GL_DEBUG_ERRORS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// How many GL debug messages of type error the debug output has reported (0 without
/// [`gl_debug_requested`]).
pub fn gl_debug_errors() -> u64 {
    GL_DEBUG_ERRORS.load(std::sync::atomic::Ordering::Relaxed)
}

impl Gl {
    /// With [`gl_debug_requested`], route the context's debug messages to the log,
    /// synchronously (the message comes from the call that caused it).
    pub fn enable_debug_output_if_requested(&mut self) {
        if !gl_debug_requested() {
            return;
        }
        // SAFETY: state changes and a callback registration on the current context.
        unsafe {
            self.glow.enable(glow::DEBUG_OUTPUT);
            self.glow.enable(glow::DEBUG_OUTPUT_SYNCHRONOUS);
            self.glow
                .debug_message_callback(|source, kind, id, severity, message| {
                    let what = format!(
                        "GL debug (source {source:#x}, type {kind:#x}, id {id}, severity {severity:#x}): \
                         {message}"
                    );
                    if kind == glow::DEBUG_TYPE_ERROR {
                        GL_DEBUG_ERRORS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    }
                    match (kind, severity) {
                        (glow::DEBUG_TYPE_ERROR, _) => log::error!("{what}"),
                        (_, glow::DEBUG_SEVERITY_NOTIFICATION) => log::debug!("{what}"),
                        _ => log::warn!("{what}"),
                    }
                });
        }
        log::info!("GL debug output enabled (GPGPU_RT_GL_DEBUG)");
    }

    /// # Safety
    /// A GL context must be current and `load` must return its entry points.
    pub unsafe fn load(load: impl Fn(&str) -> *const c_void) -> Result<Gl> {
        let get = |name: &str| {
            let p = load(name);
            if p.is_null() {
                Err(anyhow!("the GL implementation lacks {name}"))
            } else {
                Ok(p)
            }
        };
        let clear_buffer_data = get("glClearBufferData")?;
        let clear_tex_image = get("glClearTexImage")?;
        let get_query_iv = get("glGetQueryiv")?;
        let get_query_object_u64 = get("glGetQueryObjectui64v")?;
        let tex_buffer = get("glTexBuffer")?;
        Ok(Gl {
            glow: glow::Context::from_loader_function(|n| load(n)),
            // SAFETY: the pointers are the named GL entry points with these signatures.
            pending_barriers: std::sync::atomic::AtomicU32::new(super::barrier_bits::ALL),
            clear_buffer_data: std::mem::transmute::<*const c_void, ClearBufferDataFn>(
                clear_buffer_data,
            ),
            clear_tex_image: std::mem::transmute::<*const c_void, ClearTexImageFn>(clear_tex_image),
            get_query_iv: std::mem::transmute::<*const c_void, GetQueryIvFn>(get_query_iv),
            get_query_object_u64: std::mem::transmute::<*const c_void, GetQueryObjectU64Fn>(
                get_query_object_u64,
            ),
            tex_buffer: std::mem::transmute::<*const c_void, TexBufferFn>(tex_buffer),
        })
    }

    /// The pending barrier bits of `kinds`, taken: they are issued by the caller
    /// ([`super::sync::before`]).
    pub(crate) fn take_pending_barriers(&self, kinds: u32) -> u32 {
        use std::sync::atomic::Ordering;
        self.pending_barriers.fetch_and(!kinds, Ordering::Relaxed) & kinds
    }

    /// The pending barrier bits, left pending.
    pub(crate) fn peek_pending_barriers(&self) -> u32 {
        self.pending_barriers
            .load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Every barrier bit pending again: a pass ran shaders ([`super::sync::after_pass`]).
    pub(crate) fn set_all_barriers_pending(&self) {
        use std::sync::atomic::Ordering;
        self.pending_barriers
            .store(super::barrier_bits::ALL, Ordering::Relaxed);
    }

    /// `glTexBuffer(GL_TEXTURE_BUFFER, format, buffer)` on the texture bound to
    /// GL_TEXTURE_BUFFER (glow does not wrap it): the node pool of the line-space tracer.
    pub fn tex_buffer(&self, format: u32, buffer: glow::Buffer) {
        // SAFETY: plain GL call with a buffer name of this context.
        unsafe { (self.tex_buffer)(glow::TEXTURE_BUFFER, format, buffer.0.get()) }
    }

    /// The 64-bit result of a query (`GL_QUERY_RESULT`, waits for it): nanoseconds for
    /// `GL_TIME_ELAPSED`. (A 32-bit result would wrap after 4.3 s, which a brute-force frame
    /// on llvmpipe exceeds.)
    pub fn query_result_u64(&self, query: glow::Query) -> u64 {
        let mut v = 0u64;
        // SAFETY: v outlives the call.
        unsafe { (self.get_query_object_u64)(query.0.get(), glow::QUERY_RESULT, &mut v) };
        v
    }
}

/// The name of a `glGetError` code.
pub fn gl_error_name(code: u32) -> &'static str {
    match code {
        glow::INVALID_ENUM => "GL_INVALID_ENUM",
        glow::INVALID_VALUE => "GL_INVALID_VALUE",
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION",
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION",
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY",
        glow::STACK_UNDERFLOW => "GL_STACK_UNDERFLOW",
        glow::STACK_OVERFLOW => "GL_STACK_OVERFLOW",
        _ => "GL error",
    }
}

/// Check `glGetError` after a step and name the step.
pub fn check_error(gl: &Gl, what: &str) -> Result<()> {
    // SAFETY: glGetError on a current context.
    let err = unsafe { gl.get_error() };
    if err != glow::NO_ERROR {
        let name = gl_error_name(err);
        return Err(anyhow!("{name} (0x{err:04x}) after {what}")).context("OpenGL call failed");
    }
    Ok(())
}

/// Check `glGetError` right after allocating `what` of `bytes`: an error, above all
/// GL_OUT_OF_MEMORY, says what was being allocated and how large.
pub fn check_alloc(gl: &Gl, what: &str, bytes: u64) -> Result<()> {
    // SAFETY: glGetError on a current context.
    let err = unsafe { gl.get_error() };
    if err == glow::NO_ERROR {
        return Ok(());
    }
    Err(anyhow!("{}", alloc_error(err, what, bytes)))
}

/// The message of [`check_alloc`] for the error `err`.
pub fn alloc_error(err: u32, what: &str, bytes: u64) -> String {
    let size = crate::scene::budget::human(bytes);
    let name = gl_error_name(err);
    if err == glow::OUT_OF_MEMORY {
        format!(
            "{name} (0x{err:04x}): the GL implementation has no memory for {what} of {size} \
             ({bytes} bytes)"
        )
    } else {
        format!("{name} (0x{err:04x}) while allocating {what} of {size} ({bytes} bytes)")
    }
}

#[cfg(test)]
mod tests {
    use super::vector_bits;

    #[test]
    fn llvmpipe_vector_width_is_read_from_the_renderer() {
        assert_eq!(vector_bits("llvmpipe (LLVM 15.0.6, 256 bits)"), Some(256));
        assert_eq!(
            vector_bits("zink (llvmpipe (LLVM 15.0.6, 512 bits))"),
            Some(512)
        );
        assert_eq!(vector_bits("llvmpipe (LLVM 15.0.6)"), None);
        assert_eq!(vector_bits("NVIDIA H200/PCIe/SSE2"), None);
    }
}
