//! Klee 2016, ch. 5: the evaluation of soft shadows with the Cascaded Line Space, replicated.
//! N-tree N = 10, 3 levels counting the root (reading A of the thesis' depth 3; table 2, 3 and
//! Fig. 12 also at 4 levels, reading B); the bunny (`bunny_area.toml`) and the dragon
//! (`dragon_area.toml`: 202520 triangles — the thesis' 871k dragon is not available). Shadow
//! times exclude the primary rays, as the thesis measures them; every time is the mean over
//! the frames (the thesis: ten). "CPU" is our CPU implementation (`src/reference/linespace.rs`,
//! one thread, primary hits from the G-buffer except in Table 1); "GPU" the shadow kernel's GL
//! timer-query time. The measuring is in [`measure`], what the five share besides in
//! [`common`], the published values in [`crate::bench::published::klee`].
//!
//! - [`table1`] (`klee-table1`): primary rays, GPU rasterisation (the G-buffer pass) vs CPU ray
//!   casting.
//! - [`table2`] (`klee-table2`): CPU, bunny, 4 rays: triangle tests (`exact`, `variant1`) vs
//!   line-space lookups (`linespace`, `variant2`), at both readings of the N-tree depth, and how
//!   much of the gap to the published saving each explains.
//! - [`table3`] (`klee-table3`): CPU, bunny, CGT (`linespace`) vs DDA (`linespace-dda`),
//!   4/9/16/100 rays, and the error of each against `exact`, at both readings.
//! - [`fig12`] (`klee-fig12`): bunny, 2×2 … 10×10 rays, CPU vs GPU (FPS and seconds), and the
//!   error against `exact`, at both readings.
//! - [`fig13`] (`klee-fig13`): GPU, bunny vs dragon, 2×2 … 10×10 rays.

pub mod common;
pub mod fig12;
pub mod fig13;
pub mod measure;
pub mod table1;
pub mod table2;
pub mod table3;
