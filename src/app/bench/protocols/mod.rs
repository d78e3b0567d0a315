//! The protocols, one file per published evaluation it replicates (its configurations, what it
//! compares, the published values it sets ours beside), what they share ([`protocol`]: the
//! [`Protocol`] and how it makes its section of `report.md`), and the registry [`protocol_of`].
//!
//! - [`thesis_5_1`], [`thesis_5_2`], [`thesis_5_3`]: Müller 2015, ch. 5.1–5.3; [`sweep`] is
//!   what the grid-resolution protocols (5.2, 5.3) share.
//! - [`klee`]: Klee 2016, Tables 1–3 and Fig. 12–13, one file each; [`klee::measure`] times
//!   its soft shadows on the GPU and the CPU.
//! - [`wagner`]: Wagner 2018, Tables A.1 and A.2.
//! - [`proximity_clouds`]: the streaming tracer, Tables 1–3.
//! - [`accel_compare`]: every accelerator under the same conditions (ours; nothing published).

pub mod accel_compare;
pub mod klee;
pub mod protocol;
pub mod proximity_clouds;
pub mod sweep;
pub mod thesis_5_1;
pub mod thesis_5_2;
pub mod thesis_5_3;
pub mod thesis_bvh;
pub mod wagner;

use crate::bench::runner::args::ProtocolId;
pub use protocol::Protocol;

/// The registry: the protocol each command-line value runs.
pub fn protocol_of(id: ProtocolId) -> &'static Protocol {
    match id {
        ProtocolId::Thesis51 => &thesis_5_1::PROTOCOL,
        ProtocolId::Thesis52 => &thesis_5_2::PROTOCOL,
        ProtocolId::Thesis53 => &thesis_5_3::PROTOCOL,
        ProtocolId::KleeTable1 => &klee::table1::KLEE_TABLE1,
        ProtocolId::KleeTable2 => &klee::table2::KLEE_TABLE2,
        ProtocolId::KleeTable3 => &klee::table3::KLEE_TABLE3,
        ProtocolId::KleeFig12 => &klee::fig12::KLEE_FIG12,
        ProtocolId::KleeFig13 => &klee::fig13::KLEE_FIG13,
        ProtocolId::WagnerA1 => &wagner::WAGNER_A1,
        ProtocolId::WagnerA2 => &wagner::WAGNER_A2,
        ProtocolId::ProximityCloudsTable1 => &proximity_clouds::PROXIMITY_CLOUDS_TABLE1,
        ProtocolId::ProximityCloudsTable2 => &proximity_clouds::PROXIMITY_CLOUDS_TABLE2,
        ProtocolId::ProximityCloudsTable3 => &proximity_clouds::PROXIMITY_CLOUDS_TABLE3,
        ProtocolId::AccelCompare => &accel_compare::ACCEL_COMPARE,
    }
}
