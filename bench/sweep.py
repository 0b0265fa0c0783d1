"""Robustness sweep on unseen cases: every closed mesh of ../shared/meshes (its README's table),
made into a case by ../shared/tools/mkcase.py (another triangulation by edge flips, a smooth
twist and bend, shuffled vertex order, farthest-point anchors, the true correspondence), mapped
by each method that applies, judged by the shared evaluator. Cases are drawn from a seed that is
printed, so any run can be repeated.

Usage: python3 bench/sweep.py SURFMAP_BINARY [--seed N] [--cases N] [--max-vertices V] [--max-genus G]
                              [--method M] [--only I ...] [--check] [--require-ok]
  --cases        how many cases to draw (default 150)
  --max-vertices only meshes up to this size (default: all)
  --max-genus    only meshes up to this genus (default: all)
  --method       every case with this method (auto, spherical, ...) in place of the drawn one; the
                 draw is the same, so a case index names the same mesh and anchors either way
  --only         run only these case indices of the draw (the others are drawn, not run)
  --check        exit 1 on a defect: a success with flipped faces, anchors off their partners,
                 a map off the surface, or an internal error or crash (CI runs a slice this way)
  --require-ok   exit 1 unless every case run is ok (CI pins cases a fix made pass this way)
Prints one row per case (case, mesh, genus, method, anchors, outcome, flips, gt, time) and a
summary by outcome; "must" marks the classes that must not miss (genus 0 with >= 12 anchors,
genus >= 1 with >= 24). Needs numpy + scipy.
"""
import argparse
import collections
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.environ.get("SURFMAP_SHARED", os.path.join(HERE, "..", "..", "shared"))
M = os.path.join(SHARED, "meshes")
MKCASE = os.path.join(SHARED, "tools", "mkcase.py")
sys.path.insert(0, os.path.join(SHARED, "eval"))
import meshmetrics as mm  # noqa: E402

GT_BOUND = 0.05


def closed_meshes():
    """(file, vertices, genus) of every closed mesh in the shared README's table."""
    out = []
    for line in open(os.path.join(M, "README.md")):
        cells = [c.strip() for c in line.split("|")]
        if len(cells) > 8 and cells[7] == "yes" and cells[1].endswith((".off", ".obj", ".ply")):
            if os.path.exists(os.path.join(M, cells[1])) and cells[2].isdigit():
                out.append((cells[1], int(cells[2]), int(cells[5])))
    return out


def draw(rng, meshes, forced=None):
    path, nv, genus = meshes[rng.integers(len(meshes))]
    methods = ["voronoi", "greedy"] + (["homology"] if genus >= 1 else [])
    method = methods[rng.integers(len(methods))]
    anchors = 1 if method == "homology" else int(rng.integers(6, 46))
    return {"mesh": path, "vertices": nv, "genus": genus, "method": forced or method, "anchors": anchors,
            "mkcase_seed": int(rng.integers(1, 1 << 30)), "strength": round(float(rng.uniform(0.5, 1.0)), 3)}


def must_not_miss(c):
    return (c["genus"] == 0 and c["anchors"] >= 12) or (c["genus"] >= 1 and c["anchors"] >= 24)


def run_case(binary, c, tmp):
    d = os.path.join(tmp, "case")
    subprocess.run([sys.executable, MKCASE, os.path.join(M, c["mesh"]), d, "--seed", str(c["mkcase_seed"]),
                    "--anchors", str(c["anchors"]), "--strength", str(c["strength"])],
                   check=True, capture_output=True, text=True)
    anchors = json.load(open(os.path.join(d, "anchors.json")))["anchors"]
    spec = os.path.join(d, "spec.json")
    json.dump({"method": c["method"], "anchors": anchors}, open(spec, "w"))
    out = os.path.join(d, "out")
    t0 = time.perf_counter()
    p = subprocess.run([binary, "map", os.path.join(d, "source.obj"), os.path.join(d, "target.obj"),
                        "--spec", spec, "--out", out], capture_output=True, text=True)
    r = {"time": time.perf_counter() - t0}
    if p.returncode != 0:
        m = re.search(r"error \[([a-z_]+)\]", p.stderr)
        r["outcome"] = m.group(1) if m else f"crash (exit {p.returncode})"
        r["message"] = p.stderr.strip().splitlines()[-1][:200] if p.stderr.strip() else ""
        return r
    S, T = mm.load_mesh(os.path.join(d, "source.obj")), mm.load_mesh(os.path.join(d, "target.obj"))
    MP = mm.load_mesh(os.path.join(out, "source_on_target.obj"))
    gt = T[0][np.loadtxt(os.path.join(d, "gt.txt"), dtype=np.int64)]
    e = mm.evaluate_map(S, T, MP, anchors, gt, samples=20000)
    rep = json.load(open(os.path.join(out, "metrics.json")))
    r.update(flips=e["flipped_faces"] + rep["target_to_source"]["flipped_faces"], gt=e["gt_error_mean"],
             anchor=e.get("anchor_error_max", 0.0), off=e["off_surface_max"], area=e["area_ratio"])
    defect = r["flips"] > 0 or r["anchor"] > 1e-9 or r["off"] > 1e-6
    r["outcome"] = "DEFECT" if defect else ("ok" if r["gt"] <= GT_BOUND else f"gt > {GT_BOUND}")
    return r


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binary")
    ap.add_argument("--seed", type=int, default=int(time.time()) % 100000)
    ap.add_argument("--cases", type=int, default=150)
    ap.add_argument("--max-vertices", type=int, default=1 << 40)
    ap.add_argument("--max-genus", type=int, default=1 << 40)
    ap.add_argument("--method")
    ap.add_argument("--only", type=int, nargs="+")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--require-ok", action="store_true")
    a = ap.parse_args()
    if a.only:
        a.cases = max(a.cases, max(a.only) + 1)
    meshes = [m for m in closed_meshes() if m[1] <= a.max_vertices and m[2] <= a.max_genus]
    print(f"seed {a.seed}, {a.cases} cases over {len(meshes)} closed meshes", flush=True)
    rng = np.random.default_rng(a.seed)
    counts, must_miss, defects = collections.Counter(), [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(a.cases):
            c = draw(rng, meshes, a.method)
            if a.only and i not in a.only:
                continue
            r = run_case(a.binary, c, tmp)
            counts[r["outcome"]] += 1
            must = must_not_miss(c)
            if must and r["outcome"] != "ok":
                must_miss.append(i)
            if r["outcome"] == "DEFECT" or r["outcome"] in ("internal",) or r["outcome"].startswith("crash"):
                defects.append(i)
            figures = (f"flips {r['flips']} gt {r['gt']:.4f} area {r['area']:.3f}" if "gt" in r
                       else r.get("message", ""))
            print(f"{i:3d} {c['mesh']:30s} g{c['genus']} {c['method']:8s} {c['anchors']:2d} "
                  f"{'must' if must else '    '} {r['outcome']:18s} {r['time']:6.2f}s  {figures}", flush=True)
    print(json.dumps({"seed": a.seed, "outcomes": counts, "must_not_miss_missed": must_miss, "defects": defects}))
    if a.check and defects:
        sys.exit(1)
    if a.require_ok and set(counts) - {"ok"}:
        sys.exit(1)


if __name__ == "__main__":
    main()
