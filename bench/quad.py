#!/usr/bin/env python3
"""Method `quad` measured like Yu & Chuang's Tables 1-4, on shared meshes, judged with the shared
evaluator's sampled Hausdorff / RMS (../shared/eval/meshmetrics.py).

usage: python3 bench/quad.py [path/to/surfmap] [uniform|adaptive|consistency|stretch|markers] [filter]

- uniform: each model alone, levels 1..8: quads, triangles, PSNR (ours and the evaluator's),
  symmetric Hausdorff in % of the bbox diagonal, time (median of 3).
- adaptive: eps = 0.002, separately (each model alone, SA) and consistently (pairs, CA): faces, PSNR.
- stretch: every closed shared mesh alone (4 partition points on genus 0, 24 anchors otherwise):
  L2 / L-inf stretch of the mean-value start and of the result, flips, PSNR at level 6.
- markers: cat + cat-05 + lion with 4 + 8 of the 55 markers, each farthest-point choice (filter:
  the start markers, e.g. 0-54): outcome, identical faces, evaluator PSNR per model.
- consistency: pairs with ground truth (SMPL man/woman i<->i, Sumner cat poses i<->i, same-shape
  deformations): identical faces, feature (u, v) error, and the ground-truth error of the remesh
  correspondence (remesh vertex k of model 0, carried to model 1 through the known
  correspondence, against remesh vertex k of model 1), divided by sqrt(area).
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import table2  # noqa: E402

mm = table2.mm
M = table2.M
MODELS = ["maxplanck.nf25k.off", "cat-low-resolution.obj", "armadillo.obj", "bunny.off", "elephant.obj"]


def spec_for(paths, k_features=0, **options):
    V0, _ = mm.load_mesh(paths[0])
    ids = table2.fps(V0.astype(float), 4 + k_features)
    return {"method": "quad", "anchors": [[i] * len(paths) for i in ids], "options": options}


def run(binary, tmp, paths, spec, repeats=1):
    sp = os.path.join(tmp, "spec.json")
    with open(sp, "w") as f:
        json.dump(spec, f)
    out = os.path.join(tmp, "out")
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        p = subprocess.run([binary, "remesh", *paths, "--spec", sp, "--out", out], capture_output=True, text=True)
        times.append(time.perf_counter() - t)
        if p.returncode != 0:
            return {"error": p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}"}
    rep = json.loads(p.stdout)
    rep["time"] = statistics.median(times)
    rep["out"] = out
    return rep


def evaluator_psnr(orig, remesh):
    V, F = mm.load_mesh(orig)
    R, FR = mm.load_mesh(remesh)
    h, rms = mm.hausdorff(R.astype(float), FR, V.astype(float), F)
    d = mm.bbox_diag(V.astype(float))
    return 20 * np.log10(d / rms), h / d


def uniform(binary, filt):
    print("| model | level | quads | triangles | PSNR dB (ours / evaluator) | Hausdorff % | time s |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in MODELS:
            if filt not in name:
                continue
            path = os.path.join(M, name)
            for level in range(1, 9):
                r = run(binary, tmp, [path], spec_for([path], level=level, image_level=0), repeats=3 if level == 8 else 1)
                if "error" in r:
                    print(f"| {name} | {level} | {r['error']} |")
                    continue
                m = r["per_model"][0]
                ep, eh = evaluator_psnr(path, os.path.join(r["out"], "remesh_0.obj"))
                print(f"| {name} | {level} | {r['remesh_quads']} | {r['remesh_faces']} | {m['psnr_db']:.2f} / {ep:.2f} | "
                      f"{100 * m['hausdorff']:.2f} | {r['time']:.2f} |")
                sys.stdout.flush()


PAIRS = [
    ("SMPL man + woman", ["registered/smpl_human/human_man.obj", "registered/smpl_human/human_woman.obj"], "identity", 6),
    ("cat reference + cat-01", ["registered/sumner_cat_lion/cat-reference.obj", "registered/sumner_cat_lion/cat-01.obj"], "identity", 6),
    ("cat + lion (markers)", ["registered/sumner_cat_lion/cat-reference.obj", "registered/sumner_cat_lion/lion-reference.obj"], "markers", 0),
]


def pair_spec(paths, kind, k, **options):
    if kind == "markers":
        rows = []
        for line in open(os.path.join(M, "registered/sumner_cat_lion/cat_lion_markers.txt")):
            p = line.split()
            if len(p) >= 2 and p[0].isdigit():
                rows.append([int(p[0]), int(p[1])])
        # Partition points: four markers spread out (farthest-point order among the markers).
        V0, _ = mm.load_mesh(paths[0])
        P = V0[[r[0] for r in rows]].astype(float)
        order = table2.fps(P, len(rows))
        rows = [rows[i] for i in order]
        return {"method": "quad", "anchors": rows, "options": options}
    s = spec_for(paths, k, **options)
    return s


def adaptive(binary, filt):
    print("| model | SA faces | SA PSNR | CA faces | CA PSNR | pair |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in MODELS:
            if filt not in name:
                continue
            p = os.path.join(M, name)
            # Consistent with a bent copy of itself (another shape, same connectivity).
            V, F = mm.load_mesh(p)
            q = os.path.join(tmp, "bent_" + os.path.basename(name) + ".off")
            table2.write_off(q, table2.deform(V.astype(float), "bend"), F)
            ca = run(binary, tmp, [p, q], spec_for([p, q], 6, level=8, adaptive_epsilon=0.002, image_level=0))
            sa = run(binary, tmp, [p], spec_for([p], level=8, adaptive_epsilon=0.002, image_level=0))
            sa_s = sa["error"] if "error" in sa else f"{sa['remesh_faces']} | {sa['per_model'][0]['psnr_db']:.2f}"
            ca_s = ca["error"] if "error" in ca else f"{ca['remesh_faces']} | {ca['per_model'][0]['psnr_db']:.2f}"
            print(f"| {name} | {sa_s} | {ca_s} | with a bent copy |")
            sys.stdout.flush()
        for name, rel, kind, k in PAIRS:
            if filt not in name:
                continue
            paths = [os.path.join(M, r) for r in rel]
            ca = run(binary, tmp, paths, pair_spec(paths, kind, k, level=8, adaptive_epsilon=0.002, image_level=0))
            for i, p in enumerate(paths):
                sa = run(binary, tmp, [p], spec_for([p], level=8, adaptive_epsilon=0.002, image_level=0))
                sa_s = "error" if "error" in sa else f"{sa['remesh_faces']} | {sa['per_model'][0]['psnr_db']:.2f}"
                ca_s = ca["error"] if "error" in ca else f"{ca['remesh_faces']} | {ca['per_model'][i]['psnr_db']:.2f}"
                print(f"| {os.path.basename(p)} | {sa_s} | {ca_s} | {name} |")
                sys.stdout.flush()


def consistency(binary, filt):
    print("| pair | identical faces | features | feature uv err | flipped uv | stretch MV -> final (L2) | gt mean / max (÷√area) | time s |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        cases = [(n, [os.path.join(M, r) for r in rel], kind, k) for n, rel, kind, k in PAIRS if kind == "identity"]
        for kind, base in [("bend", "bunny.off"), ("bend", "elephant.obj"), ("twist", "bunny.off"), ("twist", "elephant.obj"),
                           ("twist", "torus.obj"), ("bend", "kitten.nf20k.off"), ("bend", "rocker_arm/rocker-arm.obj"),
                           ("bend", "eight.off"), ("twist", "genus3.off")]:
            if True:
                V, F = mm.load_mesh(os.path.join(M, base))
                s = os.path.join(tmp, f"{os.path.basename(base)}_{kind}_s.off")
                t = os.path.join(tmp, f"{os.path.basename(base)}_{kind}_t.off")
                table2.write_off(s, V.astype(float), F)
                table2.write_off(t, table2.deform(V.astype(float), kind), F)
                cases.append((f"{base} {kind}", [s, t], "identity", 6 if base in ("bunny.off", "elephant.obj") else 20))
        for name, paths, kind, k in cases:
            if filt not in name:
                continue
            r = run(binary, tmp, paths, pair_spec(paths, kind, k, level=6, image_level=0), repeats=3)
            if "error" in r:
                print(f"| {name} | {r['error']} |")
                continue
            R0, F0 = mm.load_mesh(os.path.join(r["out"], "remesh_0.obj"))
            R1, F1 = mm.load_mesh(os.path.join(r["out"], "remesh_1.obj"))
            same = bool(np.array_equal(F0, F1))
            VA, FA = mm.load_mesh(paths[0])
            VB, FB = mm.load_mesh(paths[1])
            VA, VB = VA.astype(float), VB.astype(float)
            # Remesh vertices of model 0 as (face, barycentric) on model 0, carried to model 1.
            _, face, cp = mm.SurfaceIndex(VA, FA).query(R0.astype(float))
            T = VA[FA[face]]
            v0, v1, v2 = T[:, 1] - T[:, 0], T[:, 2] - T[:, 0], cp - T[:, 0]
            d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
            d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
            den = d00 * d11 - d01 * d01
            b1 = (d11 * d20 - d01 * d21) / den
            b2 = (d00 * d21 - d01 * d20) / den
            b0 = 1 - b1 - b2
            TB = VB[FB[face]]
            gtp = TB[:, 0] * b0[:, None] + TB[:, 1] * b1[:, None] + TB[:, 2] * b2[:, None]
            err = np.linalg.norm(gtp - R1.astype(float), axis=1) / np.sqrt(mm.face_areas(VB, FB).sum())
            flips = sum(p["flipped_uv"] for m in r["per_model"] for p in m["patches"])
            fmt = lambda x, f: "inf" if x is None else format(x, f)  # noqa: E731  (inf: a flat start triangle)
            st = ", ".join(f"{fmt(m['stretch_mv'][0], '.3g')} -> {fmt(m['stretch'][0], '.3f')}" for m in r["per_model"])
            print(f"| {name} | {same} | {r['feature_points']} | {r['feature_uv_error']:.1e} | {flips} | {st} | "
                  f"{err.mean():.4f} / {err.max():.4f} | {r['time']:.2f} |")
            sys.stdout.flush()


GENUS0 = ["cow.off", "horse.off", "cat-low-resolution.obj", "armadillo.obj", "bunny.off", "maxplanck.nf25k.off", "spot.obj",
          "elephant.obj", "dragon.off", "homer.obj", "landmarks/cat_horse/input0.obj", "landmarks/cat_horse/input1.obj",
          "landmarks/plane_bird/61.off", "landmarks/plane_bird/248.off", "registered/smpl_human/human_man.obj",
          "registered/sumner_cat_lion/cat-reference.obj", "registered/sumner_cat_lion/lion-reference.obj"]
HIGHER = ["torus.obj", "knot.obj", "kitten.nf20k.off", "cow-low-resolution.obj", "rocker_arm/rocker-arm.obj",
          "rocker_arm/rocker-arm2500.off", "eight.off", "eight_lowres.off", "cup_input_simple_10000.off",
          "skull_low_resolution.obj", "genus3.off", "3holes.off", "fertility.off", "botijo.off"]


def stretch(binary, filt):
    """Every closed shared mesh alone: normalized stretch of the mean-value start and of the result."""
    print("| mesh | L2 MV start | L2 final | L∞ MV | L∞ final | flipped | flat | PSNR L6 | time s |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in GENUS0 + HIGHER:
            if filt not in name:
                continue
            p = os.path.join(M, name)
            k = 0 if name in GENUS0 else 20
            r = run(binary, tmp, [p], spec_for([p], k, level=6, image_level=0, metric_samples=20000))
            if "error" in r:
                print(f"| {name} | {r['error']} |")
                continue
            m = r["per_model"][0]
            fl = sum(x["flipped_uv"] for x in m["patches"])
            ft = sum(x["flat_uv"] for x in m["patches"])
            ok = "below" if m["stretch"][0] < m["stretch_mv"][0] else "NOT below"
            print(f"| {name} | {m['stretch_mv'][0]:.4g} | {m['stretch'][0]:.4f} ({ok}) | {m['stretch_mv'][1]:.4g} | "
                  f"{m['stretch'][1]:.3f} | {fl} | {ft} | {m['psnr_db']:.2f} | {r['time']:.2f} |")
            sys.stdout.flush()


def markers(binary, filt):
    """Issue 33's set: cat-reference + cat-05 + lion-reference, 12 of the 55 markers in
    farthest-point order on the cat from marker `start` (4 partition points, 8 features), level 6.
    filt: the starts to run ("0", "0-54"; default all)."""
    lo, _, hi = (filt or "0-54").partition("-")
    starts = range(int(lo), int(hi or lo) + 1)
    root = os.path.join(M, "registered/sumner_cat_lion")
    paths = [os.path.join(root, n) for n in ("cat-reference.obj", "cat-05.obj", "lion-reference.obj")]
    mk = np.loadtxt(os.path.join(root, "cat_lion_markers.txt"), dtype=int, usecols=(0, 1))
    V0, _ = mm.load_mesh(paths[0])
    P = V0[mk[:, 0]].astype(float)
    print("| start | outcome | identical faces | PSNR dB per model (evaluator) | time s |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for start in starts:
            order, d = [start], np.linalg.norm(P - P[start], axis=1)
            while len(order) < 12:
                i = int(np.argmax(d))
                order.append(i)
                d = np.minimum(d, np.linalg.norm(P - P[i], axis=1))
            rows = [[int(mk[i, 0]), int(mk[i, 0]), int(mk[i, 1])] for i in order]
            r = run(binary, tmp, paths, {"method": "quad", "anchors": rows, "options": {"level": 6, "image_level": 0}})
            if "error" in r:
                print(f"| {start} | {r['error']} | | | |")
                continue
            F = [mm.load_mesh(os.path.join(r["out"], f"remesh_{i}.obj"))[1] for i in range(3)]
            same = all(np.array_equal(F[0], f) for f in F[1:])
            ps = [evaluator_psnr(p, os.path.join(r["out"], f"remesh_{i}.obj"))[0] for i, p in enumerate(paths)]
            print(f"| {start} | ok | {same} | {' / '.join(f'{x:.2f}' for x in ps)} | {r['time']:.1f} |")
            sys.stdout.flush()


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(HERE, "..", "target")), "release", "surfmap")
    what = sys.argv[2] if len(sys.argv) > 2 else "uniform"
    filt = sys.argv[3] if len(sys.argv) > 3 else ""
    modes = {"uniform": uniform, "adaptive": adaptive, "consistency": consistency, "stretch": stretch, "markers": markers}
    modes[what](binary, filt)


if __name__ == "__main__":
    main()
