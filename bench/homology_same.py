#!/usr/bin/env python3
"""Method `homology` on same-shape cases (issue 33's homology done-when): mkcase with one anchor,
the default job (no basis, rotation or matching), evaluator flips both ways and ground-truth error.

usage: [OPTIONS='{"smoothing": …}'] python3 bench/homology_same.py BINARY [MESH SEED]...
(default: the issue's 11 meshes × seeds 1–3; OPTIONS are merged into the job's options)
"""
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.environ.get("SURFMAP_SHARED", os.path.join(HERE, "..", "..", "shared"))
sys.path.insert(0, os.path.join(SHARED, "eval"))
import numpy as np  # noqa: E402
from meshmetrics import evaluate_map, load_mesh  # noqa: E402

MESHES = ["kitten.nf20k.off", "torus.obj", "knot.obj", "cow-low-resolution.obj", "rocker_arm/rocker-arm.obj",
          "eight.off", "eight_lowres.off", "cup_input_simple_10000.off", "skull_low_resolution.obj",
          "3holes.off", "genus3.off"]


def run(binary, mesh, seed, keep=None):
    tmp = keep or tempfile.mkdtemp()
    os.makedirs(tmp, exist_ok=True)
    case = os.path.join(tmp, "case")
    subprocess.run([sys.executable, os.path.join(SHARED, "tools", "mkcase.py"), os.path.join(SHARED, "meshes", mesh),
                    case, "--seed", str(seed), "--anchors", "1", "--strength", "0.8"], check=True,
                   capture_output=True)
    anchors = json.load(open(os.path.join(case, "anchors.json")))["anchors"]
    spec = os.path.join(tmp, "spec.json")
    options = json.loads(os.environ.get("OPTIONS", "{}"))
    json.dump({"method": "homology", "anchors": anchors, "options": options}, open(spec, "w"))
    out = os.path.join(tmp, "out")
    t0 = time.time()
    p = subprocess.run([binary, "map", os.path.join(case, "source.obj"), os.path.join(case, "target.obj"),
                        "--spec", spec, "--out", out], capture_output=True, text=True)
    dt = time.time() - t0
    if p.returncode:
        lines = p.stderr.strip().splitlines()
        return f"| {mesh} | {seed} | {lines[-1][:120] if lines else p.returncode} | | | {dt:.1f} |"
    src, tgt = load_mesh(os.path.join(case, "source.obj")), load_mesh(os.path.join(case, "target.obj"))
    mapped = load_mesh(os.path.join(out, "source_on_target.obj"))
    gt = tgt[0][np.loadtxt(os.path.join(case, "gt.txt"), dtype=np.int64)]
    e = evaluate_map(src, tgt, mapped, anchors, gt, samples=20000)
    back = json.load(open(os.path.join(out, "metrics.json")))["target_to_source"]["flipped_faces"]
    ok = "ok" if e["flipped_faces"] == 0 and back == 0 and e["gt_error_mean"] <= 0.05 else "MISS"
    return (f"| {mesh} | {seed} | {ok} | {e['flipped_faces']}/{back} | {e['gt_error_mean']:.4f} "
            f"(L2 {e['l2_stretch']:.3f}) | {dt:.1f} |")


def main():
    binary = sys.argv[1]
    rest = sys.argv[2:]
    cases = [(rest[i], int(rest[i + 1])) for i in range(0, len(rest), 2)] or \
        [(m, s) for m in MESHES for s in (1, 2, 3)]
    print("| mesh | seed | outcome | flips s→t/t→s | gt mean | time s |")
    print("|---|---|---|---|---|---|")
    for mesh, seed in cases:
        keep = os.environ.get("KEEP")
        print(run(binary, mesh, seed, keep and os.path.join(keep, f"{os.path.basename(mesh)}_{seed}")), flush=True)


if __name__ == "__main__":
    main()
