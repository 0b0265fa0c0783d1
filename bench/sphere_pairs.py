"""The sphere pair map (issue 50) on the issue's case kinds, both directions, judged by the shared
evaluator, maps written even when they fold (the job would refuse them with `map_folds`):
the peer's pairs, same-shape cow cases from mkcase.py (24 anchors), SMPL man -> woman with 6 and
12 farthest-point anchors, cat -> lion with 12 of the 55 markers.

Usage: python3 bench/sphere_pairs.py EXAMPLE_BINARY [FILTER]
  EXAMPLE_BINARY: target/release/examples/sphere_pair (cargo build --release -p surfmap-geom --example sphere_pair)
"""
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

sys.path.insert(0, HERE)
from different import fps_from as fps  # noqa: E402

M = os.path.join(SHARED, "meshes")
L = os.path.join(M, "landmarks")
R = os.path.join(M, "registered")


def cases(tmp):
    a = [int(x) for x in open(os.path.join(L, "cat_horse", "landmarks0.txt")).read().split()]
    b = [int(x) for x in open(os.path.join(L, "cat_horse", "landmarks1.txt")).read().split()]
    yield "plane->bird", os.path.join(L, "plane_bird", "61.off"), os.path.join(L, "plane_bird", "248.off"), \
        [[4816, 8], [4152, 11546], [1732, 5170]], None, None
    yield "cat->horse", os.path.join(L, "cat_horse", "input0.obj"), os.path.join(L, "cat_horse", "input1.obj"), \
        [[x, y] for x, y in zip(a, b)], None, None
    for seed in (1, 2, 3):
        out = os.path.join(tmp, f"cow{seed}")
        subprocess.run([sys.executable, os.path.join(SHARED, "tools", "mkcase.py"), "--seed", str(seed),
                        "--anchors", "24", os.path.join(M, "cow.off"), out], check=True, capture_output=True)
        anchors = json.load(open(os.path.join(out, "anchors.json")))["anchors"]
        gt = np.loadtxt(os.path.join(out, "gt.txt"), dtype=int)
        yield f"cow seed {seed}", os.path.join(out, "source.obj"), os.path.join(out, "target.obj"), anchors, gt, None
    man, woman = os.path.join(R, "smpl_human/human_man.obj"), os.path.join(R, "smpl_human/human_woman.obj")
    V, _ = mm.load_mesh(man)
    for k in (6, 12):
        yield f"SMPL {k}", man, woman, [[i, i] for i in fps(V, k, 0)], np.arange(len(V)), None
    cat, lion = os.path.join(R, "sumner_cat_lion/cat-reference.obj"), os.path.join(R, "sumner_cat_lion/lion-reference.obj")
    mk = np.loadtxt(os.path.join(R, "sumner_cat_lion/cat_lion_markers.txt"), dtype=int, usecols=(0, 1))
    C, _ = mm.load_mesh(cat)
    pick = fps(C[mk[:, 0]], 12, 0)
    held = mk[[i for i in range(len(mk)) if i not in pick]]
    yield "cat->lion 12", cat, lion, mk[pick].tolist(), None, held


def main():
    binary = sys.argv[1]
    flt = sys.argv[2] if len(sys.argv) > 2 else ""
    with tempfile.TemporaryDirectory() as tmp:
        for name, s, t, anchors, gt, held in cases(tmp):
            if flt not in name:
                continue
            af = os.path.join(tmp, "anchors.json")
            json.dump({"anchors": [[int(x), int(y)] for x, y in anchors]}, open(af, "w"))
            out = os.path.join(tmp, "out")
            t0 = time.time()
            p = subprocess.run([binary, s, t, af, out], capture_output=True, text=True)
            secs = time.time() - t0
            times = {l[:3]: l.split()[1] for l in p.stdout.splitlines() if l[:4] in ("s2t:", "t2s:")}
            S, T = mm.load_mesh(s), mm.load_mesh(t)
            rev = [[b, a] for a, b in anchors]
            for d, (A, B, f, an) in {"s2t": (S, T, "s2t.obj", anchors), "t2s": (T, S, "t2s.obj", rev)}.items():
                path = os.path.join(out, f)
                if not os.path.exists(path):
                    print(f"{name:14s} {d} FAILED {p.stdout.strip()[-200:]}", flush=True)
                    continue
                MP = mm.load_mesh(path)
                g = B[0][gt] if (gt is not None and d == "s2t") else None
                e = mm.evaluate_map(A, B, MP, an, g, samples=20000)
                extra = ""
                sa = np.sqrt(mm.face_areas(*B).sum())
                if "gt_error_mean" in e:
                    extra = f" gt {e['gt_error_mean'] / sa:.4f}·√A"
                if held is not None:
                    hs, ht = (held[:, 0], held[:, 1]) if d == "s2t" else (held[:, 1], held[:, 0])
                    extra = f" held-out {np.median(np.linalg.norm(MP[0][hs] - B[0][ht], axis=1)) / sa:.4f}·√A"
                print(f"{name:14s} {d} flips {e['flipped_faces']:3d} L2 {e['l2_stretch']:.3f} "
                      f"E_ang {e['angle_distortion']:.3f} area {e['area_ratio']:.4f}{extra} "
                      f"{times.get(d, '?')} s (run {secs:.1f} s)", flush=True)
            for f in ("s2t.obj", "t2s.obj"):
                if os.path.exists(os.path.join(out, f)):
                    os.remove(os.path.join(out, f))


if __name__ == "__main__":
    main()
