//! The profile of a GL implementation: every choice the program adapts to the implementation
//! it runs on, made once from [`GlInfo`]'s facts and nowhere else. `gpgpu-rt info` prints it
//! (`"profile"` in `info --json`).
//!
//! Two profiles: `llvmpipe` — Mesa's CPU rasteriser, alone or under zink over lavapipe (one
//! LLVM back end, SIMD vectors of 8 lanes in lock step, a loop limit) — and `gpu`, every other
//! implementation. `GPGPU_RT_PROFILE=gpu|llvmpipe|auto` overrides the choice, so that the
//! choices a GPU makes run, and are tested, on llvmpipe and zink. Where the `gpu` profile asks
//! for what llvmpipe cannot do at all (a loop past its limit), the design that would need it
//! refuses with a message naming the limit; it never gives a wrong image
//! ([`super::GlInfo::unkept_loop_limit`]).

use anyhow::{bail, Result};

/// The environment variable that overrides the profile (`auto`, the default, reads GL_RENDERER).
pub const PROFILE_ENV: &str = "GPGPU_RT_PROFILE";

/// The image units GL 4.5 guarantees to a compute shader (`GL_MAX_COMPUTE_IMAGE_UNIFORMS` and
/// `GL_MAX_IMAGE_UNITS` are at least 8, GL 4.6 table 23.63): the units past them are used only
/// where the implementation has them.
pub const GUARANTEED_IMAGE_UNITS: i32 = 8;

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ProfileName {
    /// A hardware GPU: no loop limit, work groups handed out as they finish, kernels built for
    /// wide SIMD groups that need not run in lock step.
    Gpu,
    /// Mesa's llvmpipe, or zink over lavapipe: 8 lanes in lock step on a CPU's cores.
    Llvmpipe,
}

impl ProfileName {
    pub fn as_str(self) -> &'static str {
        match self {
            ProfileName::Gpu => "gpu",
            ProfileName::Llvmpipe => "llvmpipe",
        }
    }
}

/// What `GPGPU_RT_PROFILE` asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileChoice {
    Auto,
    Forced(ProfileName),
}

impl ProfileChoice {
    /// `GPGPU_RT_PROFILE`, or `Auto` where it is unset or empty.
    pub fn from_env() -> Result<ProfileChoice> {
        match std::env::var(PROFILE_ENV) {
            Ok(v) => Self::parse(&v),
            Err(_) => Ok(ProfileChoice::Auto),
        }
    }

    pub fn parse(text: &str) -> Result<ProfileChoice> {
        Ok(match text.trim() {
            "" | "auto" => ProfileChoice::Auto,
            "gpu" => ProfileChoice::Forced(ProfileName::Gpu),
            "llvmpipe" => ProfileChoice::Forced(ProfileName::Llvmpipe),
            other => bail!("{PROFILE_ENV}={other}: not a profile (auto, gpu or llvmpipe)"),
        })
    }
}

/// How Mesa's llvmpipe — and lavapipe, which zink runs on in software — treat long shader
/// loops: a SIMD vector of `lanes` invocations stops every loop after `iterations` iterations
/// in total (gallivm's guard against endless loops), silently. A vector iterates while any of
/// its lanes does, so divergent nested loops cost it the sum of its lanes' iterations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct LoopLimit {
    pub iterations: u32,
    pub lanes: u32,
}

impl LoopLimit {
    /// gallivm's bound on a SIMD vector's loop iterations (Mesa 22.3, `LP_MAX_TGSI_LOOP_ITERATIONS`).
    pub const LLVMPIPE_ITERATIONS: u32 = 65535;

    /// The iterations one invocation may run, every loop counted, so that no vector reaches
    /// the limit whatever its lanes do.
    pub fn per_invocation(&self) -> u32 {
        self.iterations / self.lanes.max(1)
    }
}

/// Every adaptation to the GL implementation, one field each.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Profile {
    pub name: ProfileName,
    /// Whether `GPGPU_RT_PROFILE` chose the profile (else GL_RENDERER did).
    pub forced: bool,
    /// The loop limit the kernels keep within: the brute-force tracer's triangles per dispatch
    /// (`accel::brute_force`), Klee 2016's `LOOP_BUDGET` (`klee2016::shadow_pass`). `None`:
    /// one dispatch over every triangle, no budget.
    pub loop_limit: Option<LoopLimit>,
    /// The SAH BVH's intersect1 loads the next work group's rays ahead (`PREFETCH_RAYS`,
    /// `glsl/bvh/intersect1_main.glsl`): latency hiding for a CPU that runs the work groups of
    /// a thread one after another; a GPU hides latency with other warps.
    pub prefetch_rays: bool,
    /// The threads among which the implementation splits a dispatch's work groups in
    /// contiguous shares (the row shuffle, [`super::PixelGrid::row_stride`]); 1 on a GPU, which
    /// hands work groups out as they finish.
    pub dispatch_threads: u32,
    /// `--linespace-build auto` builds Klee 2016's line spaces on the GPU (on llvmpipe the CPU
    /// build is faster: its kernels run on the same cores).
    pub linespace_build_on_gpu: bool,
    /// The SAH BVH's hit list reserves a subgroup's entries with one atomic through
    /// GL_ARB_shader_ballot (`HIT_LIST_BALLOT`, `glsl/bvh/evaluate_hit.comp`), where the
    /// implementation has it with 64-bit integers; else a work group's shared counter.
    pub hit_list_ballot: bool,
    /// The SAH BVH's kernels store a pixel's record as two 64-bit words in one store
    /// (`RECORD_STORE_64`, `glsl/bvh/records.glsl`), where the implementation has
    /// GL_ARB_gpu_shader_int64; else as 32-bit words.
    pub record_store_64: bool,
    /// The image units a compute kernel may bind: units `0..image_units` (the least of
    /// `GL_MAX_IMAGE_UNITS` and `GL_MAX_COMPUTE_IMAGE_UNIFORMS`, so that a kernel with an image
    /// at each unit it binds stays within both). The `gpu` profile forced on a software
    /// rasteriser keeps to the 8 GL guarantees, so that the paths of a GPU that has only those
    /// (NVIDIA reports 8) run there.
    pub image_units: i32,
}

impl Profile {
    /// A placeholder while the facts it is made from are read ([`super::context::query_info`]).
    pub(crate) const UNSET: Profile = Profile {
        name: ProfileName::Gpu,
        forced: false,
        loop_limit: None,
        prefetch_rays: false,
        dispatch_threads: 1,
        linespace_build_on_gpu: false,
        hit_list_ballot: false,
        record_store_64: false,
        image_units: GUARANTEED_IMAGE_UNITS,
    };

    /// `info`'s lines for the profile: the name and how it was chosen, then each choice.
    pub fn describe(&self) -> Vec<String> {
        let how = match self.forced {
            true => PROFILE_ENV.to_string(),
            false => "GL_RENDERER".to_string(),
        };
        let limit = match self.loop_limit {
            Some(l) => format!(
                "{} iterations per SIMD vector of {} lanes",
                l.iterations, l.lanes
            ),
            None => "none".into(),
        };
        let yes = |b: bool| if b { "yes" } else { "no" };
        vec![
            format!("profile: {} (chosen by {how})", self.name.as_str()),
            format!("  loop limit kept: {limit}"),
            format!("  ray prefetch: {}", yes(self.prefetch_rays)),
            format!(
                "  dispatch threads (row shuffle): {}",
                self.dispatch_threads
            ),
            format!(
                "  line-space build (auto): {}",
                if self.linespace_build_on_gpu {
                    "GPU"
                } else {
                    "CPU"
                }
            ),
            format!(
                "  hit list: {}",
                if self.hit_list_ballot {
                    "ballot"
                } else {
                    "shared counter"
                }
            ),
            format!("  64-bit record stores: {}", yes(self.record_store_64)),
            format!("  compute image units: {}", self.image_units),
        ]
    }
}

/// llvmpipe's compute threads as Mesa 22.3 counts them (`lp_screen.c`: `LP_NUM_THREADS`, else
/// the CPUs where there are more than one — we take those of
/// `std::thread::available_parallelism` — and at most `LP_MAX_THREADS`: we cap at 16, the bound
/// of older releases, where later ones allow 32; with 0 the calling thread runs them all). A
/// count that misses Mesa's changes only how evenly the shares are loaded.
pub(crate) fn llvmpipe_threads() -> u32 {
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get() as u32);
    let threads = std::env::var("LP_NUM_THREADS")
        .ok()
        .and_then(|v| v.trim().parse::<u32>().ok())
        .unwrap_or(if cpus > 1 { cpus } else { 0 });
    threads.clamp(1, 16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_choice_is_parsed_and_a_wrong_one_named() {
        assert_eq!(ProfileChoice::parse("").unwrap(), ProfileChoice::Auto);
        assert_eq!(
            ProfileChoice::parse(" gpu").unwrap(),
            ProfileChoice::Forced(ProfileName::Gpu)
        );
        let e = ProfileChoice::parse("nvidia").unwrap_err().to_string();
        assert!(
            e.contains("GPGPU_RT_PROFILE=nvidia") && e.contains("gpu"),
            "{e}"
        );
    }
}
