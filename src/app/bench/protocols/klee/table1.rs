//! `klee-table1` (Klee 2016, Table 1): the primary rays, GPU rasterisation (the G-buffer pass)
//! vs CPU ray casting, on the bunny and the dragon.

use anyhow::Result;

use super::common::{klee, Measured, SCENES};
use super::measure::{Row, Setup};
use crate::bench::common::format::{num, ratio, table};
use crate::bench::protocols::protocol::Protocol;
use crate::bench::published::klee as published;
use crate::bench::runner::config::Sizing;
use crate::bench::runner::units::Units;
use crate::bench::runner::Bench;
use gpgpu_rt::scene::ShadowMode;

pub const KLEE_TABLE1: Protocol = Protocol {
    name: "klee-table1",
    title: "primary rays: GPU rasterisation vs CPU ray casting (Klee 2016, Table 1)",
    run: |p, bench| klee(p, bench, table1),
    units: Units::Whole,
};

/// Table 1: per scene, the G-buffer pass on the GPU and the primary rays cast on the CPU.
fn table1(bench: &mut Bench, s: Sizing) -> Result<Measured> {
    let mut rows = Vec::new();
    for (scene, label) in SCENES {
        let mut st = Setup::new(bench, scene, s, 3)?;
        let gpu = st.gpu(bench, ShadowMode::Linespace, 2, 2)?.gbuffer;
        rows.push(Row::new(label, "primary", "GPU", 1, gpu));
        rows.push(Row::new(label, "primary", "CPU", 1, st.cpu_primary()));
    }
    let mut lines = Vec::new();
    for ((label, p_gpu, p_cpu), pair) in published::TABLE1.into_iter().zip(rows.chunks(2)) {
        let (gpu, cpu) = (pair[0].m.mean_s, pair[1].m.mean_s);
        let [p_ratio, ours_ratio] = [p_cpu / p_gpu, cpu / gpu].map(|r| ratio(Some(r)));
        lines.push(vec![format!("GPU {label}"), num(p_gpu), num(gpu)]);
        lines.push(vec![format!("CPU {label}"), num(p_cpu), num(cpu)]);
        lines.push(vec![format!("CPU / GPU {label}"), p_ratio, ours_ratio]);
    }
    let markdown = table(&["variant", "published (s)", "ours (s)"], &lines)
        + "\nGPU: the G-buffer pass (rasterisation into the FBO). CPU: a hierarchical 3D-DDA through the \
           N-tree testing the leaves' triangles. The thesis' dragon had 871k triangles, ours 202520.\n";
    Ok(Measured::table(rows, markdown))
}
