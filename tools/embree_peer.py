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
  = feelers / seconds, ours = feelers / gpu_ms.intersect2; agreement with shadow.npy;
- the whole frame: our GPU time of every kernel of the frame (`gpu_ms_total`: the image
  clears, transform, eye rays, searches, hit evaluation, counts, shading) against Embree's
  time for the primary rays
  plus the feelers, with each kernel's share of ours; for `--tracer bvh --bvh-variant sah`
  also the frame with the fused pass (the default; each pass in one kernel), rendered in the
  same rounds.

Threads: embreex's `run` loops over single rays (rtcIntersect1/rtcOccluded1, Embree's
single-ray path; it binds no packet calls) on the calling thread with the GIL released, so
one call uses one core; Embree's build (rtcCommitScene) uses all cores (TBB). The script
times Embree on 1 thread (this process) and on --threads worker processes (default: all
cores), each with an Embree scene of its own, tracing its share of the rays (chunks of 4096,
every --threads-th) after a common barrier, timed from the first start to the last end —
processes, as Python threads that each trace chunks share the GIL between their calls (two
got about 1.5 of the two cores here, two processes 1.6–2); the ratio column compares with
them. Times are the median of --repeats runs (best in the details); ours the median of
--repeats renders (the first with the AOVs, the others only timed), each timed in its last
frame. The two sides take turns: each of our renders is followed by one Embree run of every
query at each thread count, --repeats rounds, so that a drift of the machine's speed meets
both; a column gives ours over Embree's of the same round (median and range). Scenes whose
render.shadows picks the soft-shadow pipeline give their G-buffer's first hits: agreement
only, no Mrays/s.

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
import multiprocessing
import os
import platform
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
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


def embree_scene(tris, robust):
    """An Embree scene over triangles f32 [T,3,3], built (embreex commits on the first
    query: one ray); the seconds of the upload, of the build, and the build's CPU seconds."""
    t0 = time.perf_counter()
    scene = rtcore_scene.EmbreeScene(robust=robust)
    mesh_construction.TriangleMesh(scene, tris)
    t1, c1 = time.perf_counter(), time.process_time()
    scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
    return scene, t1 - t0, time.perf_counter() - t1, time.process_time() - c1


def trace(scene, o, d, tfar, occluded):
    """Occluded: blocked per ray; else {primID, tfar, u, v} per ray."""
    far = tfar.copy()  # embreex writes tfar in place
    if occluded:
        return scene.run(o, d, dists=far, query="OCCLUDED") >= 0
    r = scene.run(o, d, dists=far, output=1)
    return {k: r[k] for k in ("primID", "tfar", "u", "v")}


def shares(n, workers, chunk=4096):
    """Worker k's rays: chunks k, k + workers, ... of `chunk` rays (every part of the image
    in each share)."""
    return [np.concatenate([np.arange(c, min(c + chunk, n))
                            for c in range(k * chunk, n, workers * chunk)] or [[]]).astype(np.int64)
            for k in range(workers)]


def worker(conn, barrier, tris, robust):
    """A process of the pool: its own Embree scene; `load` keeps its share of a query, `run`
    traces it after the pool's barrier (wall start, end and CPU seconds back)."""
    scene = embree_scene(tris, robust)[0]
    queries = {}
    conn.send("ready")
    while (msg := conn.recv()) is not None:
        if msg[0] == "load":
            queries[msg[1]] = msg[2]
            conn.send("loaded")
        else:
            q = queries[msg[1]]
            barrier.wait()
            t0, c0 = time.perf_counter(), time.process_time()
            if len(q[0]):  # (a share can be empty: fewer rays than chunks)
                trace(scene, *q)
            conn.send((t0, time.perf_counter(), time.process_time() - c0))


class Embree:
    """Embree over the scene's triangles, its build time, and timed queries: on 1 thread (this
    process), and on `threads` worker processes, each tracing its share of the rays with a
    scene of its own (Python threads tracing chunks share the GIL between their calls)."""

    def __init__(self, tris, robust, threads):
        self.threads = threads
        self.scene, upload_s, build_s, build_cpu_s = embree_scene(tris, robust)
        self.upload_ms, self.build_ms = upload_s * 1e3, build_s * 1e3
        self.build_cores = build_cpu_s / build_s
        self.pool = []
        if threads > 1:
            ctx = multiprocessing.get_context("spawn")
            barrier = ctx.Barrier(threads)
            for _ in range(threads):
                mine, theirs = ctx.Pipe()
                # daemons: an error that ends this script ends them too
                proc = ctx.Process(target=worker, args=(theirs, barrier, tris, robust),
                                   daemon=True)
                proc.start()
                self.pool.append((proc, mine))
            for _, conn in self.pool:
                conn.recv()
        self.loaded = set()

    def close(self):
        for proc, conn in self.pool:
            conn.send(None)
            proc.join()

    def once(self, name, query, threads):
        """One run of a query (o, d, tfar, occluded): its result (1 thread; None on the pool),
        wall and CPU seconds."""
        if threads == 1:
            t0, c0 = time.perf_counter(), time.process_time()
            res = trace(self.scene, *query)
            return res, time.perf_counter() - t0, time.process_time() - c0
        if name not in self.loaded:
            o, d, tfar, occluded = query
            for (_, conn), idx in zip(self.pool, shares(len(o), len(self.pool))):
                conn.send(("load", name, (o[idx], d[idx], tfar[idx], occluded)))
                conn.recv()
            self.loaded.add(name)
        for _, conn in self.pool:
            conn.send(("run", name))
        times = [conn.recv() for _, conn in self.pool]
        wall = max(t[1] for t in times) - min(t[0] for t in times)
        return None, wall, sum(t[2] for t in times)


def rounds(emb, queries, repeats, rerender):
    """Embree's queries and our renders in turns, so that both sides are timed over the same
    seconds (this machine's speed drifts between runs a minute apart, and ours and Embree's
    with it): round k renders once (`rerender(k)`, k > 0; round 0 is the render that wrote the
    AOVs) and then runs every query at 1 thread and at emb.threads. Per query: its first
    result, and per thread count the seconds of every round and (median, best, the cores it
    got: CPU time / wall time over the rounds); and the renders' statistics."""
    first, secs, cpu = {}, {}, {}
    renders = []
    counts = sorted({1, emb.threads})
    for k in range(repeats):
        if k > 0 and rerender:
            renders.append(rerender(k))
        for name, q in queries.items():
            for th in counts:
                res, wall, cpu_s = emb.once(name, q, th)
                if res is not None:
                    first.setdefault(name, res)
                secs.setdefault(name, {}).setdefault(th, []).append(wall)
                cpu[(name, th)] = cpu.get((name, th), 0.0) + cpu_s
    summary = {name: {th: (statistics.median(ts), min(ts), cpu[(name, th)] / sum(ts))
                      for th, ts in per.items()} for name, per in secs.items()}
    return first, secs, summary, renders


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


def primary_query(aov):
    """The primary rays of the AOVs, closest hit, to infinity."""
    o, d = aov["ray_origin"].reshape(-1, 3), aov["ray_direction"].reshape(-1, 3)
    return o, d, np.full(len(o), np.inf, np.float32), False


def primary(res, aov, tris):
    """How Embree's first hits `res` agree with ours."""
    o, d = aov["ray_origin"].reshape(-1, 3), aov["ray_direction"].reshape(-1, 3)
    ids, t = aov["triangle_id"].reshape(-1), aov["hit_t"].reshape(-1)
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
    return {
        "rays": len(o),
        "agree_pct": 100 * same.mean(),
        "agree_ties_pct": 100 * (same | tie).mean(),
        "ties": int(tie.sum()),
        "disagree": len(other),
        "disagree_on_edge": int(on_edge.sum()),
        "max_t_rel_same_id": float(np.max(dt[same & both] / t[same & both], initial=0.0)),
    }


def feeler_query(aov, info, first_light_only=False):
    """intersect2's feelers: per light, from the hit point towards it where N·L > 0; the
    query and which hit pixels each light's feelers start from. `first_light_only`: the
    scene's first light alone, as Wagner 2018's kernel shades (one point light; the others are
    left out), so that its shadow AOV (0 or 1 per pixel) is compared with the same feelers."""
    o, d = aov["ray_origin"].reshape(-1, 3), aov["ray_direction"].reshape(-1, 3)
    t, n = aov["hit_t"].reshape(-1), aov["normal"].reshape(-1, 3)
    hit = aov["triangle_id"].reshape(-1) >= 0
    lights = np.asarray(info["light_positions"], np.float32).reshape(-1, 3)
    if first_light_only:
        lights = lights[:1]
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
    return (ro, rd, far, True), traced


def feelers(blocked_traced, traced, aov):
    """How Embree's occlusion agrees with our shadow shares."""
    hit = aov["triangle_id"].reshape(-1) >= 0
    lit = np.zeros(hit.sum(), np.float32)
    k = 0
    for front in traced:
        unblocked = np.zeros(len(front), bool)
        unblocked[front] = ~blocked_traced[k:k + front.sum()]
        k += front.sum()
        lit += unblocked
    lit /= max(len(traced), 1)
    ours = aov["shadow"].reshape(-1)[hit]
    return {"rays": int(sum(f.sum() for f in traced)),
            "agree_pct": 100 * (np.abs(lit - ours) < 1e-6).mean()}


def paired(embree_s, runs, value):
    """Ours / Embree per round (Embree's seconds at its most threads over ours, the same
    round): median, smallest and largest."""
    r = [e / (v / 1e3) for e, v in zip(embree_s, map(value, runs)) if v]
    if not r:
        return None
    return {"median": statistics.median(r), "min": min(r), "max": max(r), "rounds": r}


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
    queries = {"primary": primary_query(aov)}
    if ray_tracer and info["lights"] > 0:
        wagner = a.tracer == "bvh" and a.bvh_variant == "wagner"
        queries["feelers"], traced = feeler_query(aov, info, first_light_only=wagner)
    # the megakernel times primary rays and feelers together: agreement only
    timed = ray_tracer and a.bvh_variant == "sah"
    # the SAH BVH's frame also as one kernel per pass (the fused pass, the default of
    # --tracer bvh), rendered beside the four kernels in every round
    fused = [w for w in pipeline_args if w != "--four-kernels"]
    fused_args = fused if timed and a.tracer == "bvh" else None
    fused_runs = [rerun(a, scene, fused_args, d, "0f")] if fused_args else []

    def rerender(k):
        if fused_args:
            fused_runs.append(rerun(a, scene, fused_args, d, f"{k}f"))
        return rerun(a, scene, pipeline_args, d, k)
    first, secs, summary, renders = rounds(emb, queries, a.repeats, rerender if timed else None)
    emb.close()
    r = {"scene": str(scene.relative_to(ROOT) if scene.is_relative_to(ROOT) else scene),
         "size": f"{a.size}×{a.size}", "triangles": len(tris), "tracer": stats["tracer"],
         "variant": a.bvh_variant if ray_tracer else None,
         "embree_build_ms": emb.build_ms, "embree_upload_ms": emb.upload_ms,
         "embree_build_cores": emb.build_cores,
         "bvh_build_ms": stats.get("bvh_build_ms", stats.get("grid_build_ms")), "gl_renderer": stats["renderer"],
         "primary": primary(first["primary"], aov, tris) | {"embree_s": summary["primary"]}}
    if "feelers" in queries:
        r["feelers"] = feelers(first["feelers"], traced, aov) | {"embree_s": summary["feelers"]}
    if timed:
        runs = [stats] + renders
        for kind, kernel, kinds in (("primary", "intersect1", ("primary",)),
                                    ("feelers", "intersect2",
                                     ("shadow_first_light", "shadow_other_lights"))):
            if kind not in r:
                continue
            m = r[kind]
            m["ours_ms"] = median_of(runs, lambda s: s["gpu_ms"][kernel])
            m["kind_ms"] = median_of(runs, lambda s: kind_ms(s, *kinds))
            m["paired"] = paired(secs[kind][a.threads], runs, lambda s: s["gpu_ms"][kernel])
        if "feelers" in r:
            r["frame"] = frame(secs, a.threads, runs)
            if fused_runs:
                r["frame_fused"] = frame(secs, a.threads, fused_runs)
    return r


def frame(secs, threads, runs):
    """The whole frame: our GPU time of every kernel of the last frame (`gpu_ms_total`)
    against Embree's time for the same primary rays plus feelers on `threads` processes, per
    round (ours / Embree, the same round: > 1 is slower), and each kernel's share of ours."""
    embree_ms = [(p + f) * 1e3 for p, f in zip(secs["primary"][threads], secs["feelers"][threads])]
    per_round = [s["gpu_ms_total"] / e for s, e in zip(runs, embree_ms)]
    total = statistics.median(s["gpu_ms_total"] for s in runs)
    kernels = {k: statistics.median(s["gpu_ms"].get(k, 0.0) for s in runs)
               for k in runs[0]["gpu_ms"]}
    return {"ours_ms": total, "embree_ms": statistics.median(embree_ms),
            "ratio": {"median": statistics.median(per_round), "min": min(per_round),
                      "max": max(per_round)},
            "kernel_ms": dict(sorted(kernels.items(), key=lambda kv: -kv[1]))}


def rerun(a, scene, pipeline_args, d, k):
    """The statistics of one more render of the scene (no AOVs): round k of `rounds`."""
    f = d / f"stats{k}.json"
    gpgpu_rt(a.bin, "render", scene, *pipeline_args, "--width", a.size, "--height", a.size,
             "--stats", f, "-o", d / f"image{k}.png")
    return json.loads(f.read_text())


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
        # ours in Müller 2015's four kernels; the fused pass, the default, is rendered beside
        four = ["--four-kernels"] if a.bvh_variant == "sah" else []
        return ["--tracer", "bvh", "--bvh-variant", a.bvh_variant, *four]
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
    pr = m.get("paired")
    pair = f"{pr['median']:.3f} ({pr['min']:.3f}–{pr['max']:.3f})" if pr else "—"
    return [fmt(e1), fmt(en), fmt(ours), fmt(ours / en if ours else None, 3), pair, fmt(kind)]


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
    wagner = a.tracer == "bvh" and a.bvh_variant == "wagner"
    lines = [
        f"# Embree as the peer of `{tracer_label(a)}`: the same rays on "
        "the same machine", "",
        *([f"**{a.note}**", ""] if a.note else []),
        f"- command: `{command}`",
        f"- date: {datetime.date.today().isoformat()}; machine: {cpu}, {os.cpu_count()} cores "
        f"(load average {load[0]} before, {load[1]} after); ours on "
        f"`{results[0]['gl_renderer']}` (all cores)",
        f"- Embree: embreex {embreex_version()}, {flags}; rtcIntersect1/rtcOccluded1 per ray "
        f"(embreex binds no packet calls), 1 thread per call: the {th}-process column splits "
        f"the rays over {th} worker processes, each with its own Embree scene, timed from a "
        "common barrier to the last one's end; build = rtcCommitScene (multi-threaded, TBB)",
        *(timing_bullets(a) if not wagner else wagner_bullets(a)), "",
        "## Primary rays (closest hit)", "",
        f"| scene | size | triangles | Embree build ms | our build ms (BVH or grid) | Embree Mrays/s "
        f"(1 thread) | Embree Mrays/s ({th} processes) | ours Mrays/s | ours/Embree | "
        "ours/Embree per round: median (range) | "
        "ours Mrays/s, whole kind | first-hit agreement % (ids / with ties) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        m = r["primary"]
        lines.append("| " + " | ".join([
            f"`{r['scene']}`" + label(r), r["size"],
            str(r["triangles"]), fmt(r["embree_build_ms"], 1), fmt(r["bvh_build_ms"], 1),
            *rate_cells(m, th), f"{m['agree_pct']:.4f} / {m['agree_ties_pct']:.4f}"]) + " |")
    feelers_title = ("Shadow feelers (any hit, towards the scene's first light only)" if wagner
                     else "Shadow feelers (any hit, intersect2)")
    lines += ["", f"## {feelers_title}", "",
              f"| scene | feelers | Embree Mrays/s (1 thread) | Embree Mrays/s ({th} processes) "
              "| ours Mrays/s | ours/Embree | ours/Embree per round: median (range) "
              "| ours Mrays/s, whole kind | shadow agreement % (hit pixels) |",
              "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        if "feelers" in r:
            m = r["feelers"]
            lines.append("| " + " | ".join([f"`{r['scene']}`", str(m["rays"]),
                                            *rate_cells(m, th), f"{m['agree_pct']:.4f}"]) + " |")
    lines += frame_lines(results, th)
    lines += ["", "## Details", "",
              "| scene | Embree upload ms (embreex copy) | cores Embree got: build, "
              f"{th}-process rays (CPU / wall time) | Embree best Mrays/s ({th} processes) | ties "
              "| other disagreements (on a shared edge) | max relative t difference, same id |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        m = r["primary"]
        lines.append(f"| `{r['scene']}` | {r['embree_upload_ms']:.1f} | "
                     f"{r['embree_build_cores']:.2f}, {m['embree_s'][th][2]:.2f} | "
                     f"{mrays(m['rays'], m['embree_s'][th][1]):.2f} | {m['ties']} | "
                     f"{m['disagree']} ({m['disagree_on_edge']}) | {m['max_t_rel_same_id']:.1e} |")
    ours_test = ("Listing 4.2 (Wagner's Möller–Trumbore, with its ε)" if wagner else
                 "Algorithm 1 (Möller–Trumbore without an epsilon, the thesis' test)")
    lines += ["", "On a shared edge: one tracer's first hit lies on an edge of its triangle "
              "(within 1e-3, barycentric), and the other's ray slipped between the two triangles "
              "of that edge by a rounding error and went on to a farther one. Neither test is "
              f"watertight: {ours_test} and Embree without its robust mode.", ""]
    return "\n".join(lines)


def frame_lines(results, threads):
    """The whole-frame table: ours against Embree's primary rays plus feelers."""
    rows = [r for r in results if "frame" in r]
    if not rows:
        return []
    lines = ["", "## The whole frame", "",
             f"Ours: every kernel of the last frame (`gpu_ms_total`: the image clears, "
             f"transform, eye rays, the searches, hit evaluation, counts, shading); Embree: "
             f"the same primary rays plus "
             f"feelers on {threads} processes, nothing else (no shading). Time ratio ours / "
             "Embree per round (> 1: ours slower); the shares are each kernel's part of ours.", "",
             "| scene | ours ms | Embree ms (primary + feelers) | ours / Embree: median (range) "
             "| kernels: ms (share) |", "|---|---:|---:|---:|---|"]
    for r in rows:
        for key, how in (("frame", ""), ("frame_fused", " (fused pass)")):
            if key not in r:
                continue
            f = r[key]
            shares = ", ".join(f"{k} {ms:.1f} ({100 * ms / f['ours_ms']:.0f} %)"
                               for k, ms in f["kernel_ms"].items() if ms > 0)
            q = f["ratio"]
            lines.append(f"| `{r['scene']}`{how} | {f['ours_ms']:.1f} | {f['embree_ms']:.1f} | "
                         f"{q['median']:.2f} ({q['min']:.2f}–{q['max']:.2f}) | {shares} |")
    if any("frame_fused" in r for r in rows):
        lines += ["", "fused pass (the default of `--tracer bvh`; the other rows: `--four-kernels`): "
                  "the same frame with each pass in one kernel "
                  "(`glsl/bvh/fused_pass.comp`: closest hit, Listings 13–14, the feelers and "
                  "Listing 16), rendered beside the four kernels in every round; its "
                  "`intersect1` is the blocks' entry pass alone, and the Mrays/s above are the "
                  "four kernels'."]
    return lines


def timing_bullets(a):
    """How Müller's pipeline (`--tracer bvh --bvh-variant sah`, or a grid) is timed."""
    return [
        f"- Mrays/s: rays / seconds, medians of {a.repeats} Embree runs; ours medians of "
        f"{a.repeats} renders, each timed in the last of its {a.frames} frames (W·H / "
        "gpu_ms.intersect1; feelers / gpu_ms.intersect2); ours/Embree: the ratio of the "
        f"medians. In {a.repeats} rounds each of our renders is followed by Embree's runs of the "
        "same rays (1 thread, then all), so both sides are timed over the same seconds; per "
        "round: ours over Embree's of that round. "
        "Agreement: same triangle id / with ties (ids differ, t within 1e-5 relative)",
        "- ours, whole kind: the rays over the GPU time of their ray kind (`ray_kinds`): for "
        "`--tracer bvh` intersect1 with the hit evaluation (`evaluate_hit`, Listings 13–14) and "
        "the addition of its per-pixel counts (`pixel_counts`), which the BVH runs as kernels "
        "of their own; intersect2 with its counts",
    ]


def wagner_bullets(a):
    """Wagner's megakernel: one dispatch traces a pixel's primary ray and its one feeler, so
    there is no time of ours per kind of ray to set beside Embree's."""
    return [
        f"- Mrays/s: Embree's only, rays / seconds, medians of {a.repeats} runs. Ours: none — "
        "Wagner 2018's kernel (`glsl/wagner2018/raytrace.comp`) traces a pixel's primary ray "
        "and its shadow feeler in one dispatch, so there is no time of ours per kind of ray "
        "(the build column is the CPU build of Listings 4.3–4.4)",
        "- feelers: from each primary hit towards the scene's **first** light only, where "
        "N·L > 0, from the shadow offset to the light — Wagner's kernel shades with one point "
        "light (the others are left out, as the thesis' one light), and its shadow AOV is 0 or 1 "
        "per pixel; agreement: that AOV against Embree's occlusion of the same feelers",
        "- agreement of first hits: same triangle id / with ties (ids differ, t within 1e-5 "
        "relative)",
    ]


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
