//! The kinds of rays a pipeline counts and times apart (ours; issue 15's `accel-compare`): primary
//! rays, shadow feelers towards the first light and towards the others, and reflection rays — in
//! Müller 2015's pipeline pass 0's intersect1, intersect2 of every pass and the later passes'
//! intersect1; in the streaming tracer's streaming pipeline the generation and traversal of each.
//!
//! The counter buffer holds one bank of the pipeline's counters per kind and one for the rest of
//! the frame (builds, shading). Before each dispatch or draw the host binds the kind's bank to
//! `SSBO_COUNTERS` (`glBindBufferRange`), so the kernels — which know nothing of kinds — add to
//! it; the frame's totals are the sums over the banks. The GPU timers are told the kind the same
//! way ([`GpuTimers::set_ray_kind`]).

use std::collections::BTreeMap;
use std::sync::Arc;

use anyhow::Result;

use crate::frame::{RayKindStats, RAY_KINDS};
use crate::gl::resources::{GpuTimers, Ssbo};
use crate::gl::slots::ssbo;
use crate::gl::{Gl, GlInfo};

/// A bank of the counter buffer: the work of one kind of rays, or of none.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bank {
    /// Work that is not one kind of rays': builds, shading (Müller's: eye-ray generation too).
    Frame,
    Primary,
    /// Shadow feelers towards light 0.
    ShadowFirstLight,
    /// Shadow feelers towards lights 1…n−1.
    ShadowOtherLights,
    Reflection,
}

/// The banks in buffer order.
pub const BANKS: [Bank; 5] = [
    Bank::Frame,
    Bank::Primary,
    Bank::ShadowFirstLight,
    Bank::ShadowOtherLights,
    Bank::Reflection,
];

impl Bank {
    /// The kind's name in `FrameStats::ray_kinds`; `None` for [`Bank::Frame`].
    pub fn ray_kind(self) -> Option<&'static str> {
        match self {
            Bank::Frame => None,
            Bank::Primary => Some(RAY_KINDS[0]),
            Bank::ShadowFirstLight => Some(RAY_KINDS[1]),
            Bank::ShadowOtherLights => Some(RAY_KINDS[2]),
            Bank::Reflection => Some(RAY_KINDS[3]),
        }
    }

    /// The bank of the closest-hit search of `pass`.
    pub fn closest_hit(pass: u32) -> Bank {
        match pass {
            0 => Bank::Primary,
            _ => Bank::Reflection,
        }
    }

    /// The bank of the feelers towards `light`.
    pub fn occluded(light: usize) -> Bank {
        match light {
            0 => Bank::ShadowFirstLight,
            _ => Bank::ShadowOtherLights,
        }
    }
}

/// The counter buffer, a bank per [`Bank`].
pub struct CounterBanks {
    ssbo: Ssbo,
    /// Counters per bank.
    slots: usize,
    /// Bytes from one bank to the next: the counters' 8 bytes each, rounded up to the GL's
    /// offset alignment.
    stride: usize,
}

impl CounterBanks {
    pub fn new(gl: &Arc<Gl>, info: &GlInfo, slots: usize) -> Result<CounterBanks> {
        let align = info.ssbo_offset_alignment.max(1) as usize;
        let stride = (8 * slots).div_ceil(align) * align;
        let bytes = stride * BANKS.len();
        let ssbo = Ssbo::new(gl, "counters", bytes, None, info.max_ssbo_block_size)?;
        Ok(CounterBanks {
            ssbo,
            slots,
            stride,
        })
    }

    /// Zero every bank and bind [`Bank::Frame`].
    pub fn clear(&self, gl: &Gl, timers: &mut GpuTimers) {
        self.ssbo.clear_u32(gl, 0);
        self.bind(gl, timers, Bank::Frame);
    }

    /// The kernels dispatched from now on count into `bank` and are timed under its kind.
    pub fn bind(&self, gl: &Gl, timers: &mut GpuTimers, bank: Bank) {
        let i = BANKS.iter().position(|b| *b == bank).expect("a bank");
        let bytes = 8 * self.slots;
        self.ssbo
            .bind_range(gl, ssbo::COUNTERS, i * self.stride, bytes);
        timers.set_ray_kind(bank.ray_kind());
    }

    /// Every bank's counts (64-bit, see `glsl/common/counters.glsl`), in [`BANKS`] order.
    pub fn read(&self, gl: &Gl) -> Vec<Vec<u64>> {
        let raw = self.ssbo.read_u32(gl);
        let words = self.stride / 4;
        (0..BANKS.len())
            .map(|b| {
                let bank = &raw[b * words..];
                (0..self.slots)
                    .map(|i| super::renderer::counter_value(bank, i))
                    .collect()
            })
            .collect()
    }
}

/// The statistics per ray kind: each kind bank's counts under `names` (those in `tests` count
/// ray–triangle tests), with the kind's GPU milliseconds; kinds that traced no ray and took no
/// time are left out.
pub fn ray_kind_stats(
    banks: &[Vec<u64>],
    names: &[&str],
    tests: &[&str],
    mut ms: BTreeMap<String, f64>,
) -> BTreeMap<String, RayKindStats> {
    let mut out = BTreeMap::new();
    for (bank, counts) in BANKS.iter().zip(banks) {
        let Some(kind) = bank.ray_kind() else {
            continue;
        };
        let gpu_ms = ms.remove(kind).unwrap_or(0.0);
        let counts: BTreeMap<String, u64> = names
            .iter()
            .zip(counts)
            .filter(|(_, &v)| v > 0)
            .map(|(n, &v)| (n.to_string(), v))
            .collect();
        let triangle_tests = tests.iter().filter_map(|t| counts.get(*t)).sum();
        if gpu_ms > 0.0 || !counts.is_empty() {
            let k = RayKindStats {
                gpu_ms,
                triangle_tests,
                counts,
            };
            out.insert(kind.to_string(), k);
        }
    }
    out
}
