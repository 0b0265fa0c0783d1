#!/usr/bin/env python3
"""Open meshes in `voronoi` / `greedy` (issue 34, item 5): each shared mesh with boundary loops
onto an mkcase copy (retriangulated, bent and twisted, shuffled), farthest-point anchors.

    bench/open.py BINARY [--seeds 1 2 3] [--anchors 24] [--method voronoi]

Prints per case: flips both ways (the evaluator's), anchors, ground-truth error (mean, in units
of sqrt(area)), area ratio, the boundary check (the largest distance of a source boundary
vertex's image from the target's boundary polyline, relative to the bounding-box diagonal,
both ways) and the time of the whole `surfmap map` process.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "..", "..", "shared")
sys.path.insert(0, os.path.join(SHARED, "eval"))
import meshmetrics as mm  # noqa: E402

MKCASE = os.path.join(SHARED, "tools", "mkcase.py")
MESHES = {"hand_lowres.obj": 24, "face.off": 24, "eight.hole.off": 24}


def boundary_edges(F):
    """Directed boundary edges (a, b) of faces F: edges with no twin."""
    half = {}
    for f in F:
        for k in range(3):
            half[(int(f[k]), int(f[(k + 1) % 3]))] = True
    return [(a, b) for (a, b) in half if (b, a) not in half]


def dist_to_segments(P, V, edges):
    """Distance of each point of P to the nearest segment V[a]-V[b]."""
    A = V[[a for a, _ in edges]]
    B = V[[b for _, b in edges]]
    D = B - A
    L2 = np.maximum((D * D).sum(1), 1e-300)
    out = np.empty(len(P))
    for i, p in enumerate(P):
        t = np.clip(((p - A) * D).sum(1) / L2, 0.0, 1.0)
        q = A + t[:, None] * D
        out[i] = np.sqrt(((q - p) ** 2).sum(1)).min()
    return out


def boundary_off(src, tgt, mapped):
    """Largest distance of a source boundary vertex's image from the target boundary."""
    (VS, FS), (VT, FT) = src, tgt
    be_s = boundary_edges(FS)
    bv = sorted({a for a, _ in be_s})
    d = dist_to_segments(mapped[bv], VT, boundary_edges(FT))
    diag = np.linalg.norm(VT.max(0) - VT.min(0))
    return float(d.max() / diag)


def run(binary, mesh, seed, n_anchors, method, tmp):
    d = os.path.join(tmp, f"{mesh}-{seed}")
    subprocess.run([sys.executable, MKCASE, os.path.join(SHARED, "meshes", mesh), d, "--seed", str(seed),
                    "--anchors", str(n_anchors)], check=True, capture_output=True)
    anchors = json.load(open(os.path.join(d, "anchors.json")))["anchors"]
    spec = os.path.join(d, "spec.json")
    json.dump({"method": method, "anchors": anchors}, open(spec, "w"))
    out = os.path.join(d, "out")
    t0 = time.perf_counter()
    p = subprocess.run([binary, "map", os.path.join(d, "source.obj"), os.path.join(d, "target.obj"), "--spec", spec,
                        "--out", out], capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if p.returncode != 0:
        return {"mesh": mesh, "seed": seed, "outcome": p.stderr.strip().splitlines()[-1][:160], "time": dt}
    S, T = mm.load_mesh(os.path.join(d, "source.obj")), mm.load_mesh(os.path.join(d, "target.obj"))
    MP = mm.load_mesh(os.path.join(out, "source_on_target.obj"))
    MQ = mm.load_mesh(os.path.join(out, "target_on_source.obj"))
    gt = T[0][np.loadtxt(os.path.join(d, "gt.txt"), dtype=np.int64)]
    e = mm.evaluate_map(S, T, MP, anchors, gt, samples=20000)
    e2 = mm.evaluate_map(T, S, MQ, [[b, a] for a, b in anchors], None, samples=20000)
    rep = json.load(open(os.path.join(out, "metrics.json")))
    return {
        "mesh": mesh, "seed": seed, "outcome": "ok", "time": dt,
        "flips": [e["flipped_faces"], e2["flipped_faces"]],
        "anchor": max(e.get("anchor_error_max", 0.0), e2.get("anchor_error_max", 0.0)),
        "gt": e["gt_error_mean"], "area": e["area_ratio"], "l2": e["l2_stretch"],
        "boundary": [boundary_off(S, T, MP[0]), boundary_off(T, S, MQ[0])],
        "loops": rep.get("boundaries", []),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binary")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--anchors", type=int, default=0, help="0: the table's count per mesh")
    ap.add_argument("--method", default="voronoi")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for mesh, n in MESHES.items():
            for seed in a.seeds:
                r = run(a.binary, mesh, seed, a.anchors or n, a.method, tmp)
                if r["outcome"] != "ok":
                    print(f"{mesh:16} seed {seed}: {r['outcome']} ({r['time']:.2f} s)")
                    continue
                print(f"{mesh:16} seed {seed}: flips {r['flips']} anchor {r['anchor']:.1e} gt {r['gt']:.4f} "
                      f"area {r['area']:.3f} L2 {r['l2']:.3f} boundary off {r['boundary'][0]:.1e}/"
                      f"{r['boundary'][1]:.1e} loops {[(x['paired_by'], x['added'], x['off_loop']) for x in r['loops']]} "
                      f"{r['time']:.2f} s")


if __name__ == "__main__":
    main()
