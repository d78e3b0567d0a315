//! The base tracer's "accelerator" (Müller 2015, ch. 3.1, 4.1): every ray against every
//! triangle — `glsl/brute_force/intersect1.comp` (Listing 12) and `intersect2.comp`
//! (Listing 15). Nothing to build. CPU twin: `reference::brute_force`.

use std::any::Any;

use anyhow::Result;

use super::{Accelerator, BuildContext, Entry, FrameContext, GridOptions, TracerKind};
use crate::frame::FrameStats;
use crate::gl::Kernel;
use crate::reference::{self, CpuAccelerator};
use crate::scene::Scene;

pub const ENTRY: Entry = Entry {
    tracer: TracerKind::Base,
    grid_variant: None,
    label: "base",
    gpu: BruteForce::create,
    cpu: |scene, _| -> Result<Box<dyn CpuAccelerator>> {
        Ok(Box::new(reference::brute_force::BruteForce::new(
            scene.world_triangles(),
        )))
    },
};

pub struct BruteForce {
    intersect1: Kernel,
    intersect2: Kernel,
}

impl BruteForce {
    fn create(b: &BuildContext, _: &Scene, _: &GridOptions) -> Result<Box<dyn Accelerator>> {
        Ok(Box::new(BruteForce {
            intersect1: b.kernel("brute_force/intersect1.comp", &[], "intersect1")?,
            intersect2: b.kernel("brute_force/intersect2.comp", &[], "intersect2")?,
        }))
    }
}

impl Accelerator for BruteForce {
    fn build(&mut self, _: &mut FrameContext) -> Result<()> {
        Ok(())
    }

    fn closest_hit(&mut self, _: &mut FrameContext, _pass: u32) -> &Kernel {
        self.intersect1.use_program();
        &self.intersect1
    }

    fn any_hit(&mut self, _: &mut FrameContext, _light: usize) -> &Kernel {
        self.intersect2.use_program();
        &self.intersect2
    }

    fn stats(&self, _: &mut FrameStats) {}

    fn as_any(&self) -> &dyn Any {
        self
    }
}
