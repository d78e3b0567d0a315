//! The soft-shadow settings a scene file may give (`[render] shadows`, `light_samples`) and
//! `render --shadows`/`--light-samples` take: how the shadow rays of Klee 2016's pipeline are
//! answered, and how many. GPU-free, so the scene parser and the renderer share them.

use serde::Serialize;

/// `render --shadows`: how the shadow rays are answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowMode {
    /// The packet traversal down to the leaves with real triangle tests (line spaces only
    /// skip empty shafts): the reference (Table 2, "Schnitttests mit Dreiecken").
    Exact,
    /// The packet traversal (coherent grid traversal, Algorithm 1–4); at the last depth with
    /// line spaces the bit decides a hit (the thesis' approximation).
    Linespace,
    /// Every ray alone with a 3D-DDA through the N-tree, same line-space termination (Table 3).
    LinespaceDda,
    /// Table 2's "Variante 1" as the thesis defines it: `exact` without our near-origin rule —
    /// every node with children, the one holding the rays' origin included, is descended only
    /// when Algorithm 2 finds a set bit; one more level is traversed and the leaves' triangles
    /// are tested ("Traversierung einer weiteren Ebene, sowie der Verwendung von Schnitttests").
    Variant1,
    /// Table 2's "Variante 2" as the thesis defines it: `linespace` without our near-origin
    /// rule — at the last depth with line spaces a set bit is a hit for every node, the one
    /// holding the origin included; the deepest level is never visited, no triangle is tested
    /// ("die tiefste Ebene des N-tree [muss] nicht traversiert werden").
    Variant2,
    /// Ours, the fast path: `linespace`'s answer (the same shadow values) for less work — the
    /// nodes away from the origin (line-space lookups) are walked first and the nodes near it
    /// (exact triangle tests) only for the rays still unblocked, and a leaf's triangle is
    /// skipped for the whole packet when the origin and the light's four corners lie on one
    /// side of its plane (no ray of the packet can cross it).
    LinespaceFast,
}

impl ShadowMode {
    /// SHADOW_MODE of the kernel.
    pub fn kernel_mode(self) -> u32 {
        match self {
            ShadowMode::Exact => 0,
            ShadowMode::Linespace => 1,
            ShadowMode::LinespaceDda => 2,
            ShadowMode::Variant1 => 3,
            ShadowMode::Variant2 => 4,
            ShadowMode::LinespaceFast => 5,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            ShadowMode::Exact => "exact",
            ShadowMode::Linespace => "linespace",
            ShadowMode::LinespaceDda => "linespace-dda",
            ShadowMode::Variant1 => "variant1",
            ShadowMode::Variant2 => "variant2",
            ShadowMode::LinespaceFast => "linespace-fast",
        }
    }
    /// Does the mode descend (and test exactly) the nodes near the rays' origin instead of
    /// asking their line space? Ours (`exact`, `linespace`, `linespace-dda`); the thesis'
    /// variants do not.
    pub fn near_origin_rule(self) -> bool {
        !matches!(self, ShadowMode::Variant1 | ShadowMode::Variant2)
    }
    /// Does a set line-space bit at the last depth with line spaces count as a hit?
    pub fn bit_is_hit(self) -> bool {
        matches!(
            self,
            ShadowMode::Linespace | ShadowMode::Variant2 | ShadowMode::LinespaceFast
        )
    }
    /// Does the mode walk the nodes away from the origin first and cull triangles per packet
    /// (`linespace-fast`)?
    pub fn fast_path(self) -> bool {
        self == ShadowMode::LinespaceFast
    }
}

/// `render --klee-shading`: how the shadow value lights a pixel (phase 2 of Fig. 7).
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum, Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum KleeShading {
    /// Ours: diffuse · (ambient + light colour · s · max(N·L, 0)), N·L towards the light's
    /// centre: the light's colour and angle show, and a fully shadowed pixel keeps the ambient.
    #[default]
    Lit,
    /// Fig. 7 as printed: the shadow value s times the diffuse colour (black in full shadow).
    Fig7,
}

/// Parse `UxV` (e.g. `5x5`) light samples.
pub fn parse_samples(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}`: expected UxV, e.g. 5x5"))?;
    let a: u32 = a
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: expected UxV, e.g. 5x5"))?;
    let b: u32 = b
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: expected UxV, e.g. 5x5"))?;
    if !(1..=10).contains(&a) || !(1..=10).contains(&b) {
        return Err(format!(
            "`{s}`: 1x1 to 10x10 samples (the thesis uses 2x2 to 10x10)"
        ));
    }
    Ok((a, b))
}
