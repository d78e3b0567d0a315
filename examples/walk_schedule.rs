//! The lock step of the SAH BVH's walk on llvmpipe, simulated on the CPU (no GPU needed):
//!
//! ```sh
//! gpgpu-rt render scenes/dragon.toml --tracer bvh --refl-depth 0 --frames 1 \
//!     --width 512 --height 512 --aov-dir /tmp/aov -o /tmp/dragon.png
//! cargo run --release --example walk_schedule -- scenes/dragon.toml /tmp/aov
//! ```
//!
//! llvmpipe runs the 8 invocations of a SIMD group — a 4×2 block of pixels
//! (`pixelPosition` in `glsl/common/images.glsl`) — in lock step, a loop until its last lane
//! leaves it, and a loop entered by no lane once under an empty mask
//! (`glsl/bvh/traverse.glsl`). This program walks each primary ray of the AOV directory through
//! the records of [`Bvh::gpu_words`] as `traverse` does — node passes of one record, or of two
//! where the walk goes on at the next record (step 24 of `docs/design/bvh.md`), the
//! triangle loop over each entered leaf — and counts per SIMD group the passes of the node
//! loop and of the triangle loop, which are the trip counts callgrind measures per JIT block,
//! beside what the lanes would need alone. It then counts two schedules that Mesa 22.3's
//! llvmpipe makes costly, for what they could save: a speculative walk (Aila and Laine 2009) whose
//! lanes walk on past a leaf until every lane of the group has one, which needs a group vote
//! in each node pass, and a walk cut after a few passes of the outer loop whose unfinished rays
//! a second dispatch walks on, 8 to a SIMD group.
//!
//! It also weighs how evenly llvmpipe's threads share each tile's dispatch — each takes one
//! contiguous share of the work groups — with the tile's rows in the order of step 9 and in
//! that of `PixelGrid::row_stride` (step 25), a SIMD group costed by the instructions
//! callgrind counts per pass.
//!
//! Every ray's node visits and triangle tests are checked against the CPU twin
//! ([`Bvh::traverse`]); the program fails if one differs.

use std::collections::VecDeque;
use std::ops::ControlFlow;
use std::path::Path;

use anyhow::{bail, ensure, Context, Result};
use glam::Vec3;
use gpgpu_rt::accel::bvh::{block_of, BvhTree as Bvh, END, LEAF_COUNT_BITS, TRIANGLE_WORDS};
use gpgpu_rt::gl::PixelGrid;
use gpgpu_rt::reference::bvh::BlockEntry;
use gpgpu_rt::reference::intersect_triangle;
use gpgpu_rt::scene::Scene;

/// The SIMD group: 4×2 pixels.
const BLOCK: (usize, usize) = (4, 2);

/// The pixel kernels' work groups (8×8 pixels) and the default tile (`--tile 256`).
const GROUP: usize = 8;
const TILE: usize = 256;

/// A SIMD group's instructions (callgrind, the dragon's intersect1 at step 24): a node pass
/// 212, a triangle pass 249, the rest of the kernel about 1,420 (its straight-line code and
/// the record store; `docs/design/bvh.md`).
fn group_cost(c: &Counts) -> f64 {
    212.0 * c.node_passes as f64 + 249.0 * c.triangle_passes as f64 + 1420.0
}

/// An f32 `.npy` of shape [H, W, 3].
fn read_rays(path: &Path) -> Result<(usize, usize, Vec<f32>)> {
    let bytes = std::fs::read(path).with_context(|| format!("{}", path.display()))?;
    let npy = npyz::NpyFile::new(&bytes[..]).with_context(|| format!("{}", path.display()))?;
    let shape = npy.shape().to_vec();
    ensure!(
        shape.len() == 3 && shape[2] == 3,
        "{}: shape {shape:?}, not [H, W, 3]",
        path.display()
    );
    let data = npy.into_vec::<f32>()?;
    Ok((shape[0] as usize, shape[1] as usize, data))
}

/// The words of the hierarchy as the kernels read them.
struct Records<'a> {
    bvh: &'a Bvh,
    words: Vec<u32>,
    /// per octant, the texel of every node's record ([`Bvh::record_texels`])
    texels: Vec<Vec<u32>>,
}

/// The entry point of every 8×8 block of the image (`glsl/bvh/entry.comp`, step 26 of
/// `docs/design/bvh.md`), the blocks in GL's order (rows from the bottom).
struct Entries {
    blocks: Vec<Option<BlockEntry>>,
    width: usize,
    height: usize,
}

impl Entries {
    fn new(bvh: &Bvh, (width, height): (usize, usize), o: &[f32], d: &[f32]) -> Entries {
        let blocks = bvh.block_entries((width as u32, height as u32), |x, y| {
            let i = 3 * ((height - 1 - y as usize) * width + x as usize);
            let v = |a: &[f32]| Vec3::new(a[i], a[i + 1], a[i + 2]);
            Some((v(o), v(d)))
        });
        Entries {
            blocks,
            width,
            height,
        }
    }

    /// The entry of the pixel in column x, row `row` of the AOVs (from the top).
    fn at(&self, x: usize, row: usize) -> Option<BlockEntry> {
        let y = (self.height - 1 - row) as u32;
        self.blocks[block_of(self.width as u32, x as u32, y)]
    }
}

impl Records<'_> {
    /// The texel of index `texel` (zeros past the buffer, as imageLoad reads them).
    fn texel(&self, texel: i32) -> [u32; 4] {
        let at = 4 * texel as usize;
        match self.words.get(at..at + 4) {
            Some(w) => [w[0], w[1], w[2], w[3]],
            None => [0; 4],
        }
    }
}

/// One invocation: its ray, where its walk stands and what it has done.
struct Lane {
    ro: Vec3,
    rd: Vec3,
    grid_a: Vec3,
    grid_b: Vec3,
    node: i32,
    end: i32,
    limit: f32,
    best: u32,
    /// leaf references entered and not yet tested
    pending: VecDeque<i32>,
    nodes: u64,
    tests: u64,
    /// node passes this lane took part in
    passes: u64,
    /// its block's entry point (`None`: it walks from its root)
    entry: Option<BlockEntry>,
}

impl Lane {
    fn new(records: &Records, ro: Vec3, rd: Vec3, entry: Option<BlockEntry>) -> Lane {
        let safe = |d: f32| if d.abs() < 1e-20 { 1e-20 } else { d };
        let inv = Vec3::new(1.0 / safe(rd.x), 1.0 / safe(rd.y), 1.0 / safe(rd.z));
        let octant = (0..3)
            .map(|a| ((inv[a] < 0.0) as usize) << a)
            .sum::<usize>();
        let grid = records.bvh.grid.ray(ro, inv);
        let (root, n) = (
            records.bvh.root_texel(octant) as i32,
            records.bvh.nodes.len(),
        );
        // the walk of traverse.glsl: from the entry's record to the texel after its subtree if
        // the ray is of the entry's octant, else the whole octant's copy
        let texel = |k: i32| records.texels[octant][if k == END { n } else { k as usize }] as i32;
        let (node, end) = match entry {
            Some(e) if e.octant == octant => (texel(e.node), texel(e.stop)),
            _ => (root, root + n as i32),
        };
        Lane {
            ro,
            rd,
            grid_a: grid.a,
            grid_b: grid.b,
            node,
            end,
            limit: f32::INFINITY,
            best: u32::MAX,
            pending: VecDeque::new(),
            nodes: 0,
            tests: 0,
            passes: 0,
            entry,
        }
    }

    fn walking(&self) -> bool {
        self.node < self.end
    }

    /// `boxEntered` of traverse.glsl.
    fn entered(&self, r: [u32; 4]) -> bool {
        let q = |v: u32| (v & 0xffff) as f32;
        let near = Vec3::new(q(r[0]), q(r[0] >> 16), q(r[1]));
        let far = Vec3::new(q(r[1] >> 16), q(r[2]), q(r[2] >> 16));
        let (tn, tf) = (
            near * self.grid_a + self.grid_b,
            far * self.grid_a + self.grid_b,
        );
        let bits = |t: f32| t.to_bits() as i32;
        let t_near = bits(tn.x).max(bits(tn.y)).max(bits(tn.z)).max(0);
        let t_far = bits(tf.x)
            .min(bits(tf.y))
            .min(bits(tf.z))
            .min(bits(self.limit));
        t_near <= t_far
    }

    /// `nodePass` of traverse.glsl (`pair`: step 24's second record), an entered leaf queued.
    fn node_pass(&mut self, records: &Records, pair: bool) {
        self.passes += 1;
        let r0 = records.texel(self.node);
        let e0 = self.entered(r0);
        let second = pair && (r0[3] as i32 >= 0) == e0 && self.node + 1 < self.end;
        let (entered, reference) = if second {
            self.nodes += 1;
            self.node += 1;
            let r1 = records.texel(self.node);
            (self.entered(r1), r1[3] as i32)
        } else {
            (e0, r0[3] as i32)
        };
        self.nodes += 1;
        let inner = reference >= 0;
        if entered && !inner {
            self.pending.push_back(reference);
        }
        self.node = if !entered && inner {
            reference
        } else {
            self.node + 1
        };
    }

    /// Test the triangle of leaf entry `slot` (intersect1's triangleHit: the closest hit, ties
    /// to the lower id).
    fn test(&mut self, records: &Records, slot: usize) {
        let at = records.bvh.triangle_base() + TRIANGLE_WORDS * slot;
        self.hit(records.bvh, records.words[at + 3]);
    }

    fn hit(&mut self, bvh: &Bvh, id: u32) {
        self.tests += 1;
        let [v0, v1, v2] = bvh.triangles()[id as usize];
        if let Some((t, _, _)) = intersect_triangle(self.ro, self.rd, v0, v1, v2) {
            if t < self.limit || (t == self.limit && id < self.best) {
                (self.limit, self.best) = (t, id);
            }
        }
    }
}

/// A leaf reference's entries of `Bvh::tris`.
fn leaf_slots(reference: i32) -> std::ops::Range<usize> {
    let code = (-1 - reference) as usize;
    let first = code >> LEAF_COUNT_BITS;
    first..first + (code & ((1 << LEAF_COUNT_BITS) - 1))
}

/// Passes of a SIMD group's loops, summed over the groups.
#[derive(Default)]
struct Counts {
    groups: u64,
    node_passes: u64,
    triangle_passes: u64,
    empty_triangle_passes: u64,
    outer_passes: u64,
    /// per entry k of the node loop (k ≥ 3 together): passes, lane passes, lanes entering
    loops: [[u64; 3]; 4],
    /// the longest lane's node passes
    longest: u64,
}

/// The node loop of today's walk: until every lane has entered a leaf or ended its walk (at
/// least one pass).
fn node_loop(group: &mut [Lane], records: &Records, pair: bool, k: usize, c: &mut Counts) {
    let mut active: Vec<bool> = group.iter().map(Lane::walking).collect();
    let entry = &mut c.loops[k.min(3)];
    entry[2] += active.iter().filter(|&&a| a).count() as u64;
    loop {
        c.node_passes += 1;
        entry[0] += 1;
        for (lane, a) in group.iter_mut().zip(active.iter_mut()).filter(|(_, a)| **a) {
            entry[1] += 1;
            lane.node_pass(records, pair);
            *a = lane.walking() && lane.pending.is_empty();
        }
        if !active.contains(&true) {
            return;
        }
    }
}

/// The triangle loop: each lane tests its first pending leaf (at least one pass).
fn triangle_loop(group: &mut [Lane], records: &Records, c: &mut Counts) {
    let leaves: Vec<_> = group
        .iter_mut()
        .map(|l| l.pending.pop_front().map_or(0..0, leaf_slots))
        .collect();
    let passes = leaves.iter().map(|s| s.len() as u64).max().unwrap_or(0);
    for (lane, slots) in group.iter_mut().zip(leaves) {
        slots.for_each(|s| lane.test(records, s));
    }
    c.triangle_passes += passes.max(1);
    c.empty_triangle_passes += (passes == 0) as u64;
}

/// Today's walk (glsl/bvh/traverse.glsl), at most `outer` passes of its outer loop.
fn walk(group: &mut [Lane], records: &Records, pair: bool, outer: usize, c: &mut Counts) {
    for k in 0..outer {
        c.outer_passes += 1;
        node_loop(group, records, pair, k, c);
        triangle_loop(group, records, c);
        if !group.iter().any(Lane::walking) {
            return;
        }
    }
}

/// The speculative walk: a node pass while a walking lane has no pending leaf (a vote), each
/// walking lane with fewer than `cap` pending leaves stepping on; then each lane's first
/// pending leaf is tested.
fn speculative(group: &mut [Lane], records: &Records, cap: usize, c: &mut Counts) {
    while group.iter().any(|l| l.walking() || !l.pending.is_empty()) {
        c.outer_passes += 1;
        while group.iter().any(|l| l.walking() && l.pending.is_empty()) {
            c.node_passes += 1;
            for lane in group.iter_mut() {
                if lane.walking() && lane.pending.len() < cap {
                    lane.node_pass(records, true);
                }
            }
        }
        triangle_loop(group, records, c);
    }
}

/// Each SIMD group of the image's primary rays, walking from their blocks' entries or (`None`)
/// from the root.
fn groups(
    records: &Records,
    (width, height): (usize, usize),
    (o, d): (&[f32], &[f32]),
    entries: Option<&Entries>,
) -> Vec<Vec<Lane>> {
    let ray = |x: usize, y: usize| {
        let i = 3 * (y * width + x);
        let v = |a: &[f32]| Vec3::new(a[i], a[i + 1], a[i + 2]);
        Lane::new(records, v(o), v(d), entries.and_then(|e| e.at(x, y)))
    };
    let mut out = Vec::new();
    for by in (0..height).step_by(BLOCK.1) {
        for bx in (0..width).step_by(BLOCK.0) {
            let lanes = (by..(by + BLOCK.1).min(height))
                .flat_map(|y| (bx..(bx + BLOCK.0).min(width)).map(move |x| (x, y)))
                .map(|(x, y)| ray(x, y));
            out.push(lanes.collect());
        }
    }
    out
}

/// Every ray's node visits and tests against the CPU twin's: the number that differ.
fn check_twin(bvh: &Bvh, groups: &[Vec<Lane>]) -> usize {
    let mut differ = 0;
    for lane in groups.iter().flatten() {
        let mut twin = Lane {
            pending: VecDeque::new(),
            limit: f32::INFINITY,
            best: u32::MAX,
            tests: 0,
            ..*lane
        };
        let (entry, ro, rd) = (lane.entry.as_ref(), lane.ro, lane.rd);
        let nodes = bvh.traverse_from(entry, ro, rd, 0.0, f32::INFINITY, |ids| {
            ids.iter().for_each(|&id| twin.hit(bvh, id));
            ControlFlow::Continue(twin.limit)
        });
        differ +=
            (nodes != lane.nodes || twin.tests != lane.tests || twin.best != lane.best) as usize;
    }
    differ
}

fn per_group(n: u64, c: &Counts) -> f64 {
    n as f64 / c.groups as f64
}

fn report_walk(name: &str, all: &[Vec<Lane>], c: &Counts) {
    let rays = all.iter().map(Vec::len).sum::<usize>() as f64;
    let lane_passes: u64 = all.iter().flatten().map(|l| l.passes).sum();
    let nodes: u64 = all.iter().flatten().map(|l| l.nodes).sum();
    let tests: u64 = all.iter().flatten().map(|l| l.tests).sum();
    println!(
        "{name}: node loop {:.2} passes per SIMD group (its longest lane alone {:.2}, lanes' mean {:.2}; {:.2} nodes per ray, {:.2} per lane pass); triangle loop {:.2} passes ({:.2} with no lane testing; {:.3} tests per ray); outer loop {:.2}",
        per_group(c.node_passes, c),
        per_group(c.longest, c),
        lane_passes as f64 / rays,
        nodes as f64 / rays,
        nodes as f64 / lane_passes as f64,
        per_group(c.triangle_passes, c),
        per_group(c.empty_triangle_passes, c),
        tests as f64 / rays,
        per_group(c.outer_passes, c),
    );
}

/// Every SIMD group through `schedule`; the lanes after it and the counts.
fn run(
    mut all: Vec<Vec<Lane>>,
    mut schedule: impl FnMut(&mut [Lane], &mut Counts),
) -> (Vec<Vec<Lane>>, Counts) {
    let mut c = Counts {
        groups: all.len() as u64,
        ..Counts::default()
    };
    for group in &mut all {
        schedule(group, &mut c);
        c.longest += group.iter().map(|l| l.passes).max().unwrap_or(0);
    }
    (all, c)
}

/// The walk from the root with one and with two records per node pass, and today's, from the
/// blocks' entries; each ray checked against the twin.
fn report_today(
    records: &Records,
    from_root: impl Fn() -> Vec<Vec<Lane>>,
    fresh: impl Fn() -> Vec<Vec<Lane>>,
) -> Result<()> {
    for (name, pair, today) in [
        (
            "from the root, one record per node pass (step 23)",
            false,
            false,
        ),
        (
            "from the root, two records per node pass (step 24)",
            true,
            false,
        ),
        (
            "from the blocks' entries, two records per node pass (step 26)",
            true,
            true,
        ),
    ] {
        let lanes = if today { fresh() } else { from_root() };
        let (all, c) = run(lanes, |g, c| walk(g, records, pair, usize::MAX, c));
        report_walk(name, &all, &c);
        for (k, [passes, lane_passes, entering]) in c.loops.iter().enumerate().filter(|_| today) {
            println!(
                "  node loop {k}{}: {:.2} passes per group, {:.2} lanes entering, lane utilisation {:.2}",
                if k == 3 { " and later" } else { "" },
                per_group(*passes, &c),
                per_group(*entering, &c),
                *lane_passes as f64 / (8.0 * *passes as f64)
            );
        }
        let differ = check_twin(records.bvh, &all);
        ensure!(
            differ == 0,
            "{differ} rays' node visits, tests or hits differ from the CPU twin's"
        );
    }
    println!("checked: every ray's node visits, triangle tests and hit equal the CPU twin's");
    Ok(())
}

/// The walk cut after `outer` passes of the outer loop, the unfinished rays walked on 8 to a
/// SIMD group.
fn report_cut(records: &Records, all: Vec<Vec<Lane>>, outer: usize) {
    let rays = all.iter().map(Vec::len).sum::<usize>();
    let (all, mut c) = run(all, |g, c| walk(g, records, true, outer, c));
    let mut rest: Vec<Lane> = all.into_iter().flatten().filter(Lane::walking).collect();
    let (first_nodes, first_triangles) = (c.node_passes, c.triangle_passes);
    rest.chunks_mut(8)
        .for_each(|g| walk(g, records, true, usize::MAX, &mut c));
    println!(
        "cut after {outer} outer passes: {:.2} node and {:.2} triangle passes per SIMD group, then {} rays ({:.1} %) walk on in {} SIMD groups: {:.2} and {:.2} more per first group",
        per_group(first_nodes, &c),
        per_group(first_triangles, &c),
        rest.len(),
        100.0 * rest.len() as f64 / rays as f64,
        rest.len().div_ceil(8),
        per_group(c.node_passes - first_nodes, &c),
        per_group(c.triangle_passes - first_triangles, &c),
    );
}

/// How evenly llvmpipe's `threads` threads share each tile's dispatch (each takes one
/// contiguous share of its work groups in the order x, then y), the tile's rows taken in the
/// order `row(y, rows)` (`pixelPosition`): the work over `threads` times the slowest share,
/// summed over the tiles. Costs per SIMD group by [`group_cost`], in the order of [`groups`].
fn share_efficiency(
    costs: &[f64],
    (width, height): (usize, usize),
    threads: usize,
    row: impl Fn(u32, u32) -> u32,
) -> f64 {
    let block_cols = width.div_ceil(BLOCK.0);
    let mut shares = std::collections::HashMap::<(usize, usize), Vec<f64>>::new();
    for (i, cost) in costs.iter().enumerate() {
        let (px, py) = ((i % block_cols) * BLOCK.0, (i / block_cols) * BLOCK.1);
        let (tx, ty) = (px / TILE, py / TILE);
        let cols = TILE.min(width - tx * TILE).div_ceil(GROUP);
        let rows = TILE.min(height - ty * TILE).div_ceil(GROUP) as u32;
        let tile_row = ((py % TILE) / GROUP) as u32;
        let y = (0..rows).find(|&y| row(y, rows) == tile_row);
        let linear = y.expect("a row map is one-to-one") as usize * cols + (px % TILE) / GROUP;
        let share = (linear / (cols * rows as usize / threads).max(1)).min(threads - 1);
        shares.entry((tx, ty)).or_insert_with(|| vec![0.0; threads])[share] += cost;
    }
    let slowest: f64 = shares
        .values()
        .map(|s| s.iter().copied().fold(0.0, f64::max))
        .sum();
    costs.iter().sum::<f64>() / (threads as f64 * slowest)
}

/// The threads' shares of the step-24 walk with the rows in the order of step 9 and of step 25.
fn report_shares(records: &Records, fresh: impl Fn() -> Vec<Vec<Lane>>, size: (usize, usize)) {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    if threads < 2 {
        return;
    }
    let costs: Vec<f64> = fresh()
        .into_iter()
        .map(|mut group| {
            let mut c = Counts::default();
            walk(&mut group, records, true, usize::MAX, &mut c);
            group_cost(&c)
        })
        .collect();
    // step 9: y·s mod rows, s the integer nearest rows/φ that is coprime to the rows
    let step9 = |y: u32, rows: u32| {
        let coprime =
            |s: u32| (2..=s.min(rows)).all(|d| !s.is_multiple_of(d) || !rows.is_multiple_of(d));
        let start = (rows as f64 * 0.618_033_988_75).round().max(1.0) as u32;
        y * (start..)
            .find(|&s| coprime(s))
            .expect("rows + 1 is coprime")
            % rows
    };
    let step25 = |y: u32, rows: u32| {
        PixelGrid::tile_row(y, rows, PixelGrid::row_stride(rows, threads as u32))
    };
    println!(
        "{threads} threads' shares of each {TILE}² tile (a SIMD group's instructions: 212 a node pass, 249 a triangle pass, 1,420 the rest): {:.3} of the even split with the rows of step 9, {:.3} with those of step 25",
        share_efficiency(&costs, size, threads, step9),
        share_efficiency(&costs, size, threads, step25)
    );
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, aov] = &args[..] else {
        bail!("usage: walk_schedule SCENE.toml AOV_DIR (the primary rays of `render --aov-dir`)");
    };
    let scene = Scene::load(Path::new(scene))?;
    let (height, width, origin) = read_rays(&Path::new(aov).join("ray_origin.npy"))?;
    let (h2, w2, direction) = read_rays(&Path::new(aov).join("ray_direction.npy"))?;
    ensure!(
        (h2, w2) == (height, width),
        "{aov}: ray_origin and ray_direction differ in shape"
    );
    let bvh = Bvh::new(scene.world_triangles());
    let records = Records {
        bvh: &bvh,
        words: bvh.gpu_words(),
        texels: (0..8).map(|o| bvh.record_texels(o)).collect(),
    };
    let rays = (&origin[..], &direction[..]);
    let entries = Entries::new(&bvh, (width, height), &origin, &direction);
    let from_root = || groups(&records, (width, height), rays, None);
    let fresh = || groups(&records, (width, height), rays, Some(&entries));
    println!(
        "{} primary rays ({width}×{height}) in SIMD groups of {}×{}, {} triangles, {} nodes",
        width * height,
        BLOCK.0,
        BLOCK.1,
        bvh.triangles().len(),
        bvh.nodes.len()
    );
    report_today(&records, from_root, fresh)?;
    report_shares(&records, fresh, (width, height));
    for cap in [2, 3] {
        let (all, c) = run(fresh(), |g, c| speculative(g, &records, cap, c));
        let name = format!("speculative, up to {cap} pending leaves, a vote per node pass");
        report_walk(&name, &all, &c);
    }
    for outer in [2, 3] {
        report_cut(&records, fresh(), outer);
    }
    Ok(())
}
