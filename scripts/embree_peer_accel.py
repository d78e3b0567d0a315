#!/usr/bin/env python3
"""Every accelerator of Müller 2015's pipeline against Intel Embree on the same rays: one run of
tools/embree_peer.py per tracer (bvh, grid-exact, grid-exact+pc, grid-thesis, base; the base
tracer without the bunny), then one markdown file with a summary table (ours/Embree of primary
rays and feelers per scene) and every run's tables.

    python3 scripts/embree_peer_accel.py            # docs/results/embree_peer_accel.md, 128²
    python3 scripts/embree_peer_accel.py --size 512 --out /tmp/peer_accel.md
"""
import argparse
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = ["scenes/cow.toml", "scenes/stadium.toml", "scenes/teapot1.toml", "scenes/bunny.toml"]


def run(d, size):
    for t in TRACERS:
        scenes = [s for s in SCENES if not (t == "base" and "bunny" in s)]
        subprocess.run([sys.executable, str(ROOT / "tools/embree_peer.py"), *scenes, "--tracer", t,
                        "--size", str(size), "--repeats", "3", "--min-agreement", "0",
                        "--out", str(d / f"peer_{t}.md")], cwd=ROOT, check=True)


def combine(d, out_path, size):
    tracers = TRACERS
    out = ["# Every accelerator of Müller 2015's pipeline against Embree on the same rays", "",
           f"One `python3 tools/embree_peer.py SCENES --tracer T --size {size} --repeats 3 --min-agreement 0` "
           "per tracer T, one after the other (`python3 scripts/embree_peer_accel.py`; each section "
           "gives its machine and load): compare the ours/Embree column, measured within one run. "
           "The base tracer skips the bunny (69451 triangles: a minute a frame on llvmpipe). "
           "Summary: ours/Embree (2 threads) per scene, primary rays | feelers, ours over the "
           "GPU time of the whole ray kind (the BVH's hit evaluation and counts included, which "
           "the other tracers do inside intersect1).", ""]
    rows = {}
    scenes = []
    for t in tracers:
        j = json.loads((d / f"peer_{t}.json").read_text())
        res = j["results"] if isinstance(j, dict) and "results" in j else j
        for r in res:
            if r["scene"] not in scenes:
                scenes.append(r["scene"])
            def ratio(m):
                if "ours_ms" not in m: return None
                th = max(int(k) for k in m["embree_s"].keys())
                e = m["rays"] / m["embree_s"][str(th)][0] / 1e6
                # the whole ray kind: the BVH evaluates its hits in a kernel of its own, the
                # other tracers inside intersect1
                o = m["rays"] / ((m.get("kind_ms") or m["ours_ms"]) / 1e3) / 1e6
                return o / e
            p = ratio(r["primary"]); f = ratio(r["feelers"]) if "feelers" in r else None
            rows[(t, r["scene"])] = (p, f, r["primary"]["agree_ties_pct"])
    out.append("| tracer | " + " | ".join(f"`{s}`" for s in scenes) + " |")
    out.append("|---|" + "---:|" * len(scenes))
    fmt = lambda x: "—" if x is None else f"{x:.3f}"
    for t in tracers:
        cells = []
        for s in scenes:
            v = rows.get((t, s))
            cells.append("—" if v is None else f"{fmt(v[0])} \\| {fmt(v[1])}")
        out.append(f"| `--tracer {t}` | " + " | ".join(cells) + " |")
    out.append("")
    for t in tracers:
        md = (d / f"peer_{t}.md").read_text()
        md = re.sub(r"^# ", "## ", md, flags=re.M) if False else md.replace("\n## ", "\n### ").replace("# Embree", "## Embree", 1)
        out.append(md)
    out_path.write_text("\n".join(out) + "\n")

TRACERS = ["bvh", "grid-exact", "grid-exact+pc", "grid-thesis", "base"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--out", type=Path, default=ROOT / "docs/results/embree_peer_accel.md")
    ap.add_argument("--work", type=Path, help="keep each run's files here")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        d = a.work or Path(tmp)
        d.mkdir(parents=True, exist_ok=True)
        run(d, a.size)
        combine(d, a.out, a.size)


if __name__ == "__main__":
    main()
