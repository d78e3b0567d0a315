//! Klee 2016, ch. 5 (B.Sc. thesis, Koblenz, 2016): the published times of Tables 1–3 and what
//! Fig. 12 and 13 show, in seconds unless said otherwise.

/// Table 1 (seconds): scene, GPU, CPU (the dragon: 871k triangles).
pub const TABLE1: [(&str, f64, f64); 2] = [
    ("bunny", 0.000993448, 0.178985),
    ("dragon", 0.00189566, 0.197976),
];
/// Table 2 (seconds, CPU, bunny, 4 rays): triangle tests, line-space lookups.
pub const TABLE2: [(&str, f64); 2] = [
    ("triangle tests", 6.064665),
    ("line-space lookups", 0.448443),
];
/// Table 3 (seconds, CPU, bunny): rays, CGT, DDA.
pub const TABLE3: [(u32, f64, f64); 4] = [
    (4, 0.628609, 0.356825),
    (9, 0.867256, 0.550786),
    (16, 1.18496, 0.829777),
    (100, 4.82775, 3.88766),
];
/// Fig. 12 — the GPU takes 86 % less time than the CPU at every sample count.
pub const FIG12_GPU_SAVING: f64 = 0.86;
/// Fig. 13 — the dragon (871k) takes 3 % longer than the bunny at 4 rays, 22 % at 100.
pub const FIG13_DRAGON_EXTRA: [(u32, f64); 2] = [(4, 0.03), (100, 0.22)];
