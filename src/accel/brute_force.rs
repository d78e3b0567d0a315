//! The base tracer's "accelerator" (Müller 2015, ch. 3.1, 4.1): every ray against every
//! triangle — `glsl/brute_force/intersect1.comp` (Listing 12) and `intersect2.comp`
//! (Listing 15). Nothing to build. CPU twin: `reference::brute_force`.
//!
//! Ours: where the GL implementation ends long shader loops (Mesa llvmpipe: 65535 loop
//! iterations per invocation), the triangles are split over several dispatches of each kernel,
//! at most [`TRIANGLES_PER_DISPATCH`] each, so that the kernels keep the listings' loops (one
//! triangle per iteration). intersect1 carries the closest hit so far from one dispatch to the
//! next in the colour buffer, intersect2 in the shadow flag; see the kernels' headers.

use std::any::Any;

use anyhow::{bail, Result};

use super::interface::{Accelerator, BuildContext, Entry, FrameContext, LightTarget};
use super::options::Accel;
use crate::frame::FrameStats;
use crate::gl::{GlInfo, Kernel};
use crate::scene::Scene;

pub const ENTRY: Entry = Entry {
    label: "base",
    plain: Accel::Base,
    records: false,
    variants: &[("base", Accel::Base)],
    gpu: BruteForce::create,
};

/// Triangles per dispatch where the implementation limits loops: below llvmpipe's 65535
/// iterations per invocation, with room for the few other loop iterations of a kernel.
pub const TRIANGLES_PER_DISPATCH: u32 = 60_000;

/// The triangles one dispatch tests under the profile: [`TRIANGLES_PER_DISPATCH`] where it
/// keeps a loop limit (llvmpipe), else all of them (`u32::MAX`).
pub fn triangles_per_dispatch(info: &GlInfo) -> u32 {
    info.profile
        .loop_limit
        .map_or(u32::MAX, |_| TRIANGLES_PER_DISPATCH)
}

/// Refuse what the `gpu` profile asks of an implementation with a loop limit (llvmpipe): all of
/// `triangles` in one loop, past the limit, which would cut the loop short.
fn refuse_unkept_loop_limit(info: &GlInfo, triangles: u32) -> Result<()> {
    match info.unkept_loop_limit() {
        Some(l) if triangles > TRIANGLES_PER_DISPATCH => bail!(
            "the {} profile tests all {triangles} triangles in one loop of the base tracer's \
             kernels, and this GL implementation ({}) ends loops after {} iterations; use \
             GPGPU_RT_PROFILE=auto (or llvmpipe), or a scene of at most \
             {TRIANGLES_PER_DISPATCH} triangles",
            info.profile.name.as_str(),
            info.renderer,
            l.iterations
        ),
        _ => Ok(()),
    }
}

/// The triangle ranges `first..end` of the dispatches over `count` triangles, at most `per`
/// each; one (empty) range for no triangles.
pub fn dispatch_ranges(count: u32, per: u32) -> Vec<(u32, u32)> {
    let per = per.max(1);
    let mut ranges: Vec<(u32, u32)> = (0..count.div_ceil(per))
        .map(|k| {
            (
                k * per,
                count.min(k.saturating_mul(per).saturating_add(per)),
            )
        })
        .collect();
    if ranges.is_empty() {
        ranges.push((0, 0));
    }
    ranges
}

pub struct BruteForce {
    intersect1: Kernel,
    intersect2: Kernel,
    /// The dispatches' triangle ranges; the last one ends with the last triangle.
    ranges: Vec<(u32, u32)>,
}

impl BruteForce {
    fn create(b: &BuildContext, scene: &Scene, _: &Accel) -> Result<Box<dyn Accelerator>> {
        let per = b
            .triangles_per_dispatch
            .unwrap_or_else(|| triangles_per_dispatch(b.info));
        let triangles = scene.triangle_count() as u32;
        if b.triangles_per_dispatch.is_none() {
            refuse_unkept_loop_limit(b.info, triangles)?;
        }
        Ok(Box::new(BruteForce {
            intersect1: b.kernel("brute_force/intersect1.comp", &[], "intersect1")?,
            intersect2: b.kernel("brute_force/intersect2.comp", &[], "intersect2")?,
            ranges: dispatch_ranges(triangles, per),
        }))
    }

    /// The number of dispatches per kernel and pass (light).
    pub fn dispatches(&self) -> usize {
        self.ranges.len()
    }

    /// Dispatch all ranges but the last and set the last one's: the caller sets its other
    /// uniforms and dispatches it.
    fn split(kernel: &Kernel, ranges: &[(u32, u32)], f: &mut FrameContext) {
        let set = |(first, end): (u32, u32)| {
            kernel.set_i32("firstTriangle", first as i32);
            kernel.set_i32("endTriangle", end as i32);
        };
        let (last, before) = ranges.split_last().expect("at least one range");
        for &r in before {
            set(r);
            kernel.dispatch_pixels(f.timers, f.pixels);
        }
        set(*last);
    }
}

impl Accelerator for BruteForce {
    fn build(&mut self, _: &mut FrameContext) -> Result<()> {
        Ok(())
    }

    fn closest_hit(&mut self, f: &mut FrameContext, _pass: u32) -> &Kernel {
        self.intersect1.use_program();
        Self::split(&self.intersect1, &self.ranges, f);
        &self.intersect1
    }

    fn occluded(&mut self, f: &mut FrameContext, target: &LightTarget) -> &Kernel {
        self.intersect2.use_program();
        // the dispatches before the last need the light now
        target.set_uniforms(&self.intersect2);
        Self::split(&self.intersect2, &self.ranges, f);
        &self.intersect2
    }

    fn stats(&self, _: &mut FrameStats) {}

    fn as_any(&self) -> &dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::dispatch_ranges;

    #[test]
    fn ranges_cover_every_triangle_once() {
        assert_eq!(dispatch_ranges(0, 10), vec![(0, 0)]);
        assert_eq!(dispatch_ranges(10, 10), vec![(0, 10)]);
        assert_eq!(dispatch_ranges(11, 10), vec![(0, 10), (10, 11)]);
        assert_eq!(dispatch_ranges(131_072, 60_000).len(), 3);
        assert_eq!(dispatch_ranges(7, u32::MAX), vec![(0, 7)]);
    }
}
