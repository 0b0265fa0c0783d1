"""Robustness sweep for `voronoi`/`greedy`: many shared meshes x deformations with farthest-point
anchors, plus the registered pairs, each judged by the shared evaluator (flips both ways, area,
L2, ground-truth error). Prints one line per case and a summary of the cases that miss a threshold.

Usage: python3 bench/sweep.py BINARY [METHOD] [FILTER]   (needs numpy + scipy)
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import table2 as t2  # noqa: E402

M = t2.M
mm = t2.mm


def cases(tmp):
    g0 = ["cow.off", "horse.off", "cat-low-resolution.obj", "bunny.off", "maxplanck.nf25k.off", "spot.obj",
          "elephant.obj", "dragon.off", "homer.obj", "armadillo.obj"]
    g1 = ["torus.obj", "knot.obj", "kitten.nf20k.off", "cow-low-resolution.obj", "rocker_arm/rocker-arm2500.off"]
    g2 = ["eight.off", "eight_lowres.off", "cup_input_simple_10000.off", "skull_low_resolution.obj"]
    for path in g0 + g1 + g2:
        for kind in ["bend", "twist", "shuffle", "subdivided"]:
            name = f"{os.path.basename(path).split('.')[0]} {kind}"
            tag = name.replace(" ", "_")
            yield name, lambda tag=tag, path=path, kind=kind: t2.same_shape(tmp, tag, os.path.join(M, path), kind, 24)
    man = os.path.join(M, "registered/smpl_human/human_man.obj")
    woman = os.path.join(M, "registered/smpl_human/human_woman.obj")
    cat = os.path.join(M, "registered/sumner_cat_lion")

    def reg(a, b, k, start):
        V, _ = mm.load_mesh(a)
        gt = os.path.join(tmp, "reg_gt.txt")
        np.savetxt(gt, np.arange(len(V)), fmt="%d")
        V = V.astype(float)
        idx = t2.fps(np.roll(V, -start, 0), k)
        idx = [(i + start) % len(V) for i in idx]
        return a, b, [[i, i] for i in idx], gt

    for k in [8, 12, 16, 24, 32, 45]:
        yield f"smpl {k}", lambda k=k: reg(man, woman, k, 0)
    for start in [100, 3000]:
        yield f"smpl 24 start {start}", lambda s=start: reg(man, woman, 24, s)
    for pose in ["cat-01", "cat-02", "cat-05"]:
        yield f"cat ref/{pose}", lambda p=pose: reg(f"{cat}/cat-reference.obj", f"{cat}/{p}.obj", 24, 0)
    yield "lion ref/lion-01", lambda: reg(f"{cat}/lion-reference.obj", f"{cat}/lion-01.obj", 24, 0)
    mk = np.loadtxt(f"{cat}/cat_lion_markers.txt", dtype=int, usecols=(0, 1)).tolist()
    yield "cat-01/lion-01 55", lambda: (f"{cat}/cat-01.obj", f"{cat}/lion-01.obj", mk, None)
    yield "lion/cat 55", lambda: (f"{cat}/lion-reference.obj", f"{cat}/cat-reference.obj", [[b, a] for a, b in mk], None)


def gt_map_l2(tmp, s, t, gt):
    """L2 stretch of the ground-truth map itself (source vertex i at target vertex gt[i]): how far
    from isometric the case's deformation is. A low-distortion map cannot follow a ground truth
    whose own L2 stretch is high, so its ground-truth error there measures the case."""
    VS, FS = mm.load_mesh(s)
    VT, _ = mm.load_mesh(t)
    p = os.path.join(tmp, "gt_map.off")
    t2.write_off(p, VT[np.loadtxt(gt, dtype=np.int64)].astype(float), FS)
    out = subprocess.run([sys.executable, os.path.join(os.path.dirname(M), "eval", "meshmetrics.py"), s, t, p,
                          "--samples", "1000"], capture_output=True, text=True, check=True).stdout
    return json.loads(out)["l2_stretch"]


def main():
    binary = sys.argv[1]
    method = sys.argv[2] if len(sys.argv) > 2 else "voronoi"
    filt = sys.argv[3] if len(sys.argv) > 3 else ""
    bad = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, make in cases(tmp):
            if filt not in name:
                continue
            s, t, a, gt = make()
            e = t2.run(binary, tmp, name, s, t, a, gt, method, repeats=1)
            if "error" in e:
                print(f"{name:32s} ERROR {e['error']}", flush=True)
                bad.append(name)
                continue
            gtm = e.get("gt_error_mean", float("nan"))
            same_shape = gt is not None and any(k in name for k in ["bend", "twist", "shuffle", "subdivided"])
            gt_l2 = gt_map_l2(tmp, s, t, gt) if same_shape else float("nan")
            fb = e["report"].get("layout", {}).get("fallback")
            g = e["report"].get("global")
            if g and not g["used"]:
                fb = f"{fb or ''} per-patch: {g.get('fallback')}"
            name = f"{name} [{fb}]" if fb else name
            line = (f"{name:32s} {e['time']:6.2f}s flips {e['flipped_faces']}/{e['rev_flips']} area {e['area_ratio']:.4f} "
                    f"L2 {e['l2_stretch']:.4f} gt {gtm:.4f} (gt map L2 {gt_l2:.3f}) anchor {e['anchor_error_max']:.1e} off {e['off_surface_max']:.1e}"
                    + (f" E0 {e['report']['smoothing']['energy_before']:.3f} G {e['report'].get('global')}" if os.environ.get("SWEEP_ENERGY") else ""))
            miss = e["flipped_faces"] or e["rev_flips"] or not 0.97 <= e["area_ratio"] <= 1.03 or \
                e["anchor_error_max"] > 1e-9 or e["off_surface_max"] > 1e-6
            # Same-shape cases (24 anchors): the ground-truth error and L2 bounds as well.
            if same_shape:
                miss = miss or gtm > 0.02 or e["l2_stretch"] > 1.15
            if miss:
                bad.append(name)
            print(line + ("   <-- MISS" if miss else ""), flush=True)
    print(json.dumps({"missed": bad}))


if __name__ == "__main__":
    main()
