#!/usr/bin/env python3
"""Intel Embree as the peer of `--tracer bvh`: the very same rays, the same machine.

For each scene: `gpgpu-rt render SCENE --tracer bvh --refl-depth 0 --frames 3 --width S
--height S --aov-dir D --stats D/stats.json` (the primary rays, first hits and shadow shares of
the last frame as .npy, its GPU times as JSON), `gpgpu-rt export-triangles` (the triangles in
triangle-id order) and `gpgpu-rt info --json` (light positions, shadow offset). Embree (the
`embreex` package: `pip install embreex`) builds its BVH over the same triangles and traces

- the primary rays (closest hit): Mrays/s = W·H / seconds, misses included; ours
  = W·H / gpu_ms.intersect1; first-hit agreement = pixels with the same triangle id, and
  with ties: ids differ but both hit at t within 1e-5 relative (a shared edge);
- the shadow feelers of intersect2 (any hit) from o + t·d towards every point light, where
  N·L > 0 (the kernel does not trace the others), from the shadow offset to the light: Mrays/s
  = feelers / seconds, ours = feelers / gpu_ms.intersect2; agreement with shadow.npy.

Threads: embreex's `run` loops over single rays (rtcIntersect1/rtcOccluded1, Embree's
single-ray path; it binds no packet calls) on the calling thread with the GIL released, so
one call uses one core; Embree's build (rtcCommitScene) uses all cores (TBB). The script
times Embree on 1 thread and on --threads Python threads (default: all cores) that each trace
chunks of the rays; the ratio column compares with the latter. Times are the median of
--repeats runs (best in the details); ours the median of --repeats renders (the first with the
AOVs, the others only timed), each timed in its last frame. Scenes whose render.shadows picks
the soft-shadow pipeline give their G-buffer's first hits: agreement only, no Mrays/s.

Writes a markdown table (--out, default docs/results/embree_peer.md) and the same numbers as
JSON beside it; exits 1 if a scene's first hits (ties included) agree on less than
--min-agreement percent of the pixels.

    python3 tools/embree_peer.py                       # every scene in scenes/
    python3 tools/embree_peer.py scenes/bunny.toml scenes/dragon.toml --repeats 9
    python3 tools/embree_peer.py scenes/cow.toml --tracer grid-exact --out /tmp/grid_peer.md
                                                       # any accelerator of `bench accel-compare`
"""

import argparse
import datetime
import json
import os
import platform
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

try:
    from embreex import mesh_construction, rtcore_scene
except ImportError:
    sys.exit("embree_peer.py needs the embreex package: pip install embreex")

ROOT = Path(__file__).resolve().parent.parent


def gpgpu_rt(binary, *args):
    """Run the binary; its stdout, or exit with its stderr."""
    p = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"gpgpu-rt {' '.join(map(str, args))} failed:\n{p.stderr}")
    return p.stdout


class Embree:
    """An Embree scene over triangles f32 [T,3,3], its build time, and timed queries."""

    def __init__(self, tris, robust, threads):
        self.threads = threads
        t0 = time.perf_counter()
        self.scene = rtcore_scene.EmbreeScene(robust=robust)
        mesh_construction.TriangleMesh(self.scene, tris)
        t1, c1 = time.perf_counter(), time.process_time()
        # embreex commits (builds the BVH) on the first query: one ray
        self.scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
        t2, c2 = time.perf_counter(), time.process_time()
        self.upload_ms, self.build_ms = (t1 - t0) * 1e3, (t2 - t1) * 1e3
        self.build_cores = (c2 - c1) / (t2 - t1)

    def _query(self, o, d, tfar, occluded, threads):
        """Occluded: blocked per ray; else {primID, tfar, u, v} per ray."""
        def run(sl):
            far = tfar[sl].copy()  # embreex writes tfar in place
            if occluded:
                return self.scene.run(o[sl], d[sl], dists=far, query="OCCLUDED") >= 0
            r = self.scene.run(o[sl], d[sl], dists=far, output=1)
            return {k: r[k] for k in ("primID", "tfar", "u", "v")}
        if threads == 1:
            return run(slice(None))
        # chunks of 4096 rays handed out to the threads as they finish
        chunks = [slice(k, k + 4096) for k in range(0, len(o), 4096)]
        with ThreadPoolExecutor(threads) as ex:
            parts = list(ex.map(run, chunks))
        if occluded:
            return np.concatenate(parts)
        return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}

    def timed(self, o, d, tfar, occluded, repeats):
        """The result, and per thread count (1 and `threads`) the seconds (median, best) and
        the cores it got (CPU time / wall time, summed over the repeats)."""
        times = {}
        for th in sorted({1, self.threads}):
            ts, cpu = [], time.process_time()
            for _ in range(repeats):
                t0 = time.perf_counter()
                res = self._query(o, d, tfar, occluded, th)
                ts.append(time.perf_counter() - t0)
            times[th] = (statistics.median(ts), min(ts), (time.process_time() - cpu) / sum(ts))
        return res, times


def mrays(n, seconds):
    return n / seconds / 1e6 if seconds > 0 else float("nan")


def edge_distance(o, d, tri):
    """Per ray, the smallest barycentric coordinate of its hit on the plane of its triangle
    (f64; about 0 on an edge)."""
    o, d, tri = o.astype(np.float64), d.astype(np.float64), tri.astype(np.float64)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p, tv = np.cross(d, e2), o - tri[:, 0]
    inv = 1 / np.einsum("ij,ij->i", e1, p)
    u = inv * np.einsum("ij,ij->i", tv, p)
    v = inv * np.einsum("ij,ij->i", d, np.cross(tv, e1))
    return np.abs(np.stack([u, v, 1 - u - v])).min(axis=0)


def primary(emb, aov, tris, repeats):
    o, d = aov["ray_origin"].reshape(-1, 3), aov["ray_direction"].reshape(-1, 3)
    ids, t = aov["triangle_id"].reshape(-1), aov["hit_t"].reshape(-1)
    far = np.full(len(o), np.inf, np.float32)
    res, times = emb.timed(o, d, far, False, repeats)
    eid, et = res["primID"], res["tfar"]
    same = eid == ids
    both = (eid >= 0) & (ids >= 0)
    with np.errstate(invalid="ignore"):  # misses have t = +inf
        dt = np.where(both, np.abs(et - t), np.inf)
    tie = ~same & both & (dt <= 1e-5 * t)
    other = np.nonzero(~same & ~tie)[0]
    # on an edge: either first hit lies within 1e-3 (barycentric) of an edge of its triangle,
    # and the other tracer's ray slipped between the two triangles of that edge
    on_edge = np.zeros(len(other), bool)
    for hit_ids in (ids[other], eid[other]):
        h = hit_ids >= 0
        on_edge[h] |= edge_distance(o[other][h], d[other][h], tris[hit_ids[h]]) < 1e-3
    n = len(o)
    return {
        "rays": n,
        "embree_s": times,
        "agree_pct": 100 * same.mean(),
        "agree_ties_pct": 100 * (same | tie).mean(),
        "ties": int(tie.sum()),
        "disagree": len(other),
        "disagree_on_edge": int(on_edge.sum()),
        "max_t_rel_same_id": float(np.max(dt[same & both] / t[same & both], initial=0.0)),
    }


def feelers(emb, aov, info, repeats):
    """intersect2's feelers: per light, from the hit point towards it where N·L > 0."""
    o, d = aov["ray_origin"].reshape(-1, 3), aov["ray_direction"].reshape(-1, 3)
    t, n = aov["hit_t"].reshape(-1), aov["normal"].reshape(-1, 3)
    hit = aov["triangle_id"].reshape(-1) >= 0
    lights = np.asarray(info["light_positions"], np.float32).reshape(-1, 3)
    off = np.float32(info["shadow_offset"])
    p = (o[hit] + t[hit, None] * d[hit]).astype(np.float32)
    rays, traced = [], []
    for light in lights:
        to_light = light - p
        dist = np.linalg.norm(to_light, axis=1).astype(np.float32)
        rd = (to_light / dist[:, None]).astype(np.float32)
        front = np.einsum("ij,ij->i", n[hit], rd) > 0
        traced.append(front)
        # the kernel accepts offset < t < light distance: start the ray at the offset
        rays.append((p[front] + off * rd[front], rd[front], dist[front] - off))
    ro, rd, far = (np.ascontiguousarray(np.concatenate(x), np.float32) for x in zip(*rays))
    blocked_traced, times = emb.timed(ro, rd, far, True, repeats)
    lit = np.zeros(hit.sum(), np.float32)
    k = 0
    for front in traced:
        unblocked = np.zeros(len(front), bool)
        unblocked[front] = ~blocked_traced[k:k + front.sum()]
        k += front.sum()
        lit += unblocked
    lit /= max(len(lights), 1)
    ours = aov["shadow"].reshape(-1)[hit]
    return {"rays": len(ro), "embree_s": times, "agree_pct": 100 * (np.abs(lit - ours) < 1e-6).mean()}


def measure(scene, a, work):
    d = work / scene.stem
    d.mkdir(parents=True, exist_ok=True)
    stats_file = d / "stats.json"
    ray_tracer = not soft_shadow_scene(scene)
    # the soft-shadow pipeline: its first hits only (one frame, one light sample)
    # Wagner's megakernel has no reflection passes to turn off
    no_reflection = ["--refl-depth", "0"] if a.bvh_variant == "sah" else []
    pipeline_args = ([*tracer_args(a), *no_reflection, "--frames", a.frames] if ray_tracer
                     else ["--light-samples", "1x1"])
    cmd = ["render", scene, *pipeline_args, "--width", a.size,
           "--height", a.size, "--aov-dir", d, "--stats", stats_file, "-o", d / "image.png"]
    gpgpu_rt(a.bin, *cmd)
    gpgpu_rt(a.bin, "export-triangles", scene, "-o", d / "tris.npy")
    info = json.loads(gpgpu_rt(a.bin, "info", scene, "--json"))
    stats = json.loads(stats_file.read_text())
    aov = {f.stem: np.load(f) for f in d.glob("*.npy") if f.stem != "tris"}
    tris = np.ascontiguousarray(np.load(d / "tris.npy"), np.float32)
    emb = Embree(tris, a.robust, a.threads)
    r = {"scene": str(scene.relative_to(ROOT) if scene.is_relative_to(ROOT) else scene),
         "size": f"{a.size}×{a.size}", "triangles": len(tris), "tracer": stats["tracer"],
         "variant": a.bvh_variant if ray_tracer else None,
         "embree_build_ms": emb.build_ms, "embree_upload_ms": emb.upload_ms,
         "embree_build_cores": emb.build_cores,
         "bvh_build_ms": stats.get("bvh_build_ms", stats.get("grid_build_ms")), "gl_renderer": stats["renderer"],
         "primary": primary(emb, aov, tris, a.repeats)}
    if ray_tracer:
        # the megakernel times primary rays and feelers together: agreement only
        timed = a.bvh_variant == "sah"
        runs = [stats] + rerun(a, scene, pipeline_args, d) if timed else []
        if timed:
            r["primary"]["ours_ms"] = median_of(runs, lambda s: s["gpu_ms"]["intersect1"])
            r["primary"]["kind_ms"] = median_of(runs, lambda s: kind_ms(s, "primary"))
        if info["lights"] > 0:
            r["feelers"] = feelers(emb, aov, info, a.repeats)
            if timed:
                r["feelers"]["ours_ms"] = median_of(runs, lambda s: s["gpu_ms"]["intersect2"])
                r["feelers"]["kind_ms"] = median_of(
                    runs, lambda s: kind_ms(s, "shadow_first_light", "shadow_other_lights"))
    return r


def rerun(a, scene, pipeline_args, d):
    """The statistics of a.repeats - 1 more renders of the scene (no AOVs), so that ours are
    medians of a.repeats renders as Embree's are of a.repeats runs."""
    out = []
    for k in range(1, a.repeats):
        f = d / f"stats{k}.json"
        gpgpu_rt(a.bin, "render", scene, *pipeline_args, "--width", a.size, "--height", a.size,
                 "--stats", f, "-o", d / f"image{k}.png")
        out.append(json.loads(f.read_text()))
    return out


def kind_ms(stats, *kinds):
    """The GPU time of the named ray kinds of one render (None if it has none of them)."""
    got = [stats.get("ray_kinds", {}).get(k, {}).get("gpu_ms") for k in kinds]
    got = [g for g in got if g is not None]
    return sum(got) if got else None


def median_of(runs, value):
    values = [v for v in map(value, runs) if v is not None]
    return statistics.median(values) if values else None


def tracer_args(a):
    """The render options of the tracer measured: --tracer bvh (either variant), or another
    accelerator of Müller 2015's pipeline (base, the grids at --grid auto) on the same rays."""
    if a.tracer == "bvh":
        return ["--tracer", "bvh", "--bvh-variant", a.bvh_variant]
    if a.tracer == "base":
        return ["--tracer", "base"]
    variant, _, pc = a.tracer.partition("+")
    return ["--tracer", "grid", "--grid", "auto", "--grid-variant", variant.split("-")[1],
            *(["--proximity-clouds"] if pc else [])]


def tracer_label(a):
    """`--tracer bvh --bvh-variant sah`, `--tracer grid-exact+pc`: the title's name."""
    return f"--tracer bvh --bvh-variant {a.bvh_variant}" if a.tracer == "bvh" else f"--tracer {a.tracer}"


def soft_shadow_scene(scene):
    """Whether the scene's render.shadows picks the soft-shadow pipeline (no --tracer)."""
    return "shadows" in tomllib.loads(scene.read_text()).get("render", {})


def fmt(x, digits=2):
    return "—" if x is None else f"{x:.{digits}f}"


def rate_cells(m, threads):
    """Embree Mrays/s on 1 and on `threads` threads (medians), ours, ours/Embree, and ours
    over the whole ray kind (the kernel with the dispatches that serve it)."""
    e1 = mrays(m["rays"], m["embree_s"][1][0])
    en = mrays(m["rays"], m["embree_s"][threads][0])
    ours = mrays(m["rays"], m["ours_ms"] / 1e3) if "ours_ms" in m else None
    kind = mrays(m["rays"], m["kind_ms"] / 1e3) if m.get("kind_ms") else None
    return [fmt(e1), fmt(en), fmt(ours), fmt(ours / en if ours else None, 3), fmt(kind)]


def label(r):
    """Why a row has no speed of ours: the soft-shadow G-buffer, or Wagner's megakernel."""
    if "ours_ms" in r["primary"]:
        return ""
    return " (megakernel)" if r["variant"] == "wagner" else " (G-buffer)"


def report(results, a, command, load):
    th = a.threads
    flags = "robust (RTC_SCENE_FLAG_ROBUST)" if a.robust else "default flags (not robust)"
    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text()
                .splitlines() if line.startswith("model name")), platform.processor())
    lines = [
        f"# Embree as the peer of `{tracer_label(a)}`: the same rays on "
        "the same machine", "",
        *([f"**{a.note}**", ""] if a.note else []),
        f"- command: `{command}`",
        f"- date: {datetime.date.today().isoformat()}; machine: {cpu}, {os.cpu_count()} cores "
        f"(load average {load[0]} before, {load[1]} after); ours on "
        f"`{results[0]['gl_renderer']}` (all cores)",
        f"- Embree: embreex {embreex_version()}, {flags}; rtcIntersect1/rtcOccluded1 per ray "
        f"(embreex binds no packet calls), 1 thread per call: the {th}-thread column splits "
        f"the rays over {th} Python threads; build = rtcCommitScene (multi-threaded, TBB)",
        f"- Mrays/s: rays / seconds, medians of {a.repeats} Embree runs; ours medians of "
        f"{a.repeats} renders, each timed in the last of its {a.frames} frames (W·H / "
        "gpu_ms.intersect1; feelers / gpu_ms.intersect2). "
        "Agreement: same triangle id / with ties (ids differ, t within 1e-5 relative)",
        "- ours, whole kind: the rays over the GPU time of their ray kind (`ray_kinds`): for "
        "`--tracer bvh` intersect1 with the hit evaluation (`evaluate_hit`, Listings 13–14) and "
        "the addition of its per-pixel counts (`pixel_counts`), which the BVH runs as kernels "
        "of their own; intersect2 with its counts", "",
        "## Primary rays (closest hit)", "",
        f"| scene | size | triangles | Embree build ms | our build ms (BVH or grid) | Embree Mrays/s "
        f"(1 thread) | Embree Mrays/s ({th} threads) | ours Mrays/s | ours/Embree | "
        "ours Mrays/s, whole kind | first-hit agreement % (ids / with ties) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        m = r["primary"]
        lines.append("| " + " | ".join([
            f"`{r['scene']}`" + label(r), r["size"],
            str(r["triangles"]), fmt(r["embree_build_ms"], 1), fmt(r["bvh_build_ms"], 1),
            *rate_cells(m, th), f"{m['agree_pct']:.4f} / {m['agree_ties_pct']:.4f}"]) + " |")
    lines += ["", "## Shadow feelers (any hit, intersect2)", "",
              f"| scene | feelers | Embree Mrays/s (1 thread) | Embree Mrays/s ({th} threads) "
              "| ours Mrays/s | ours/Embree | ours Mrays/s, whole kind | shadow agreement % (hit pixels) |",
              "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        if "feelers" in r:
            m = r["feelers"]
            lines.append("| " + " | ".join([f"`{r['scene']}`", str(m["rays"]),
                                            *rate_cells(m, th), f"{m['agree_pct']:.4f}"]) + " |")
    lines += ["", "## Details", "",
              "| scene | Embree upload ms (embreex copy) | cores Embree got: build, "
              f"{th}-thread rays (CPU / wall time) | Embree best Mrays/s ({th} threads) | ties "
              "| other disagreements (on a shared edge) | max relative t difference, same id |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        m = r["primary"]
        lines.append(f"| `{r['scene']}` | {r['embree_upload_ms']:.1f} | "
                     f"{r['embree_build_cores']:.2f}, {m['embree_s'][th][2]:.2f} | "
                     f"{mrays(m['rays'], m['embree_s'][th][1]):.2f} | {m['ties']} | "
                     f"{m['disagree']} ({m['disagree_on_edge']}) | {m['max_t_rel_same_id']:.1e} |")
    lines += ["", "On a shared edge: one tracer's first hit lies on an edge of its triangle "
              "(within 1e-3, barycentric), and the other's ray slipped between the two triangles "
              "of that edge by a rounding error and went on to a farther one. Neither test is "
              "watertight: Algorithm 1 (Möller–Trumbore without an epsilon, the thesis' test) "
              "and Embree without its robust mode.", ""]
    return "\n".join(lines)


def embreex_version():
    from importlib.metadata import version
    return version("embreex")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", nargs="*", type=Path, help="default: every scenes/*.toml")
    ap.add_argument("--bin", type=Path, default=ROOT / "target/release/gpgpu-rt")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--repeats", type=int, default=5, help="Embree runs per query and thread count")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--robust", action="store_true", help="Embree's robust mode (slower)")
    ap.add_argument("--min-agreement", type=float, default=99.9)
    ap.add_argument("--tracer", choices=["bvh", "base", "grid-thesis", "grid-exact",
                                         "grid-exact+pc"], default="bvh",
                    help="the accelerator measured (Müller 2015's pipeline; grids at --grid auto): "
                         "places every accelerator of `bench accel-compare` against Embree")
    ap.add_argument("--bvh-variant", choices=["sah", "wagner"], default="sah",
                    help="wagner: Wagner 2018's megakernel (agreement only: it times primary "
                    "rays and feelers as one kernel)")
    ap.add_argument("--out", type=Path, default=ROOT / "docs/results/embree_peer.md")
    ap.add_argument("--work", type=Path, help="keep the AOVs here (default: a temporary folder)")
    ap.add_argument("--note", default="", help="a line printed above the tables")
    a = ap.parse_args()
    if not a.bin.exists():
        sys.exit(f"{a.bin} not found: cargo build --release (or --bin)")
    first = [ROOT / "scenes/bunny.toml", ROOT / "scenes/dragon.toml"]
    scenes = [s.resolve() for s in a.scenes] or first + sorted(
        s for s in (ROOT / "scenes").glob("*.toml") if s not in first)
    command = shlex.join(["python3", "tools/embree_peer.py", *sys.argv[1:]])
    load = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory() as tmp:
        work = a.work or Path(tmp)
        results = []
        for s in scenes:
            r = measure(s, a, work)
            m = r["primary"]
            print(f"{r['scene']}: agreement {m['agree_pct']:.4f} % "
                  f"({m['agree_ties_pct']:.4f} % with ties)", file=sys.stderr)
            results.append(r)
    load.append(os.getloadavg()[0])
    load = [f"{x:.1f}" for x in load]
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(report(results, a, command, load))
    a.out.with_suffix(".json").write_text(json.dumps(results, indent=1) + "\n")
    print(a.out.read_text())
    bad = [r["scene"] for r in results if r["primary"]["agree_ties_pct"] < a.min_agreement]
    if bad:
        sys.exit(f"first hits agree on less than {a.min_agreement} % of the pixels: {bad}")


if __name__ == "__main__":
    main()
