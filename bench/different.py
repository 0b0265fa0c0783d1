"""Issue 35's different-shape cases beyond the peer's pairs: SMPL man -> woman with 6 and 12
farthest-point anchors (ground truth i <-> i) and Sumner cat -> lion with 12 of the 55 markers
(three farthest-point choices, the other 43 held out), judged by the shared evaluator.

Usage: [METHOD=auto] python3 bench/different.py SURFMAP_BINARY [FILTER]   (needs numpy + scipy)
  METHOD: the job's method (default voronoi)
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import table2 as t2  # noqa: E402

mm = t2.mm
R = os.path.join(t2.M, "registered")


def fps_from(V, k, start):
    """Farthest-point sampling of `k` rows of `V` starting at row `start`."""
    chosen = [start]
    d = np.linalg.norm(V - V[start], axis=1)
    for _ in range(k - 1):
        chosen.append(int(d.argmax()))
        d = np.minimum(d, np.linalg.norm(V - V[chosen[-1]], axis=1))
    return chosen


def cases():
    man, woman = os.path.join(R, "smpl_human/human_man.obj"), os.path.join(R, "smpl_human/human_woman.obj")
    V, _ = mm.load_mesh(man)
    for k in (6, 12):
        yield f"SMPL man->woman {k}", man, woman, [[i, i] for i in t2.fps(V, k)], "identity", None
    cat, lion = os.path.join(R, "sumner_cat_lion/cat-reference.obj"), os.path.join(R, "sumner_cat_lion/lion-reference.obj")
    mk = np.loadtxt(os.path.join(R, "sumner_cat_lion/cat_lion_markers.txt"), dtype=int, usecols=(0, 1))
    C, _ = mm.load_mesh(cat)
    for start in (0, 17, 38):
        pick = fps_from(C[mk[:, 0]], 12, start)
        held = [i for i in range(len(mk)) if i not in pick]
        yield f"cat->lion 12 (start {start})", cat, lion, mk[pick].tolist(), None, mk[held]


def main():
    binary = sys.argv[1]
    flt = sys.argv[2] if len(sys.argv) > 2 else ""
    with tempfile.TemporaryDirectory() as tmp:
        for name, s, t, anchors, gt, held in cases():
            if flt not in name:
                continue
            sf = os.path.join(tmp, "spec.json")
            json.dump({"method": os.environ.get("METHOD", "voronoi"), "anchors": anchors}, open(sf, "w"))
            out = os.path.join(tmp, "out")
            t0 = time.time()
            p = subprocess.run([binary, "map", s, t, "--spec", sf, "--out", out], capture_output=True, text=True)
            secs = time.time() - t0
            if p.returncode != 0:
                print(f"{name:28s} FAILED {secs:5.1f} s {p.stderr.strip().splitlines()[-1][:250]}", flush=True)
                continue
            S, T = mm.load_mesh(s), mm.load_mesh(t)
            rev = [[b, a] for a, b in anchors]
            for d, (A, B, f, an) in {"s->t": (S, T, "source_on_target.obj", anchors),
                                     "t->s": (T, S, "target_on_source.obj", rev)}.items():
                MP = mm.load_mesh(os.path.join(out, f))
                g = B[0][np.arange(len(A[0]))] if gt == "identity" else None
                e = mm.evaluate_map(A, B, MP, an, g, samples=100000)
                extra = ""
                if "gt_error_mean" in e:
                    extra = f" gt {e['gt_error_mean']:.4f}"
                if held is not None:
                    sa = np.sqrt(mm.face_areas(*B).sum())
                    hs, ht = (held[:, 0], held[:, 1]) if d == "s->t" else (held[:, 1], held[:, 0])
                    extra = f" held-out {np.linalg.norm(MP[0][hs] - B[0][ht], axis=1).mean() / sa:.4f}"
                print(f"{name:28s} {d} flips {e['flipped_faces']:3d} L2 {e['l2_stretch']:.3f} "
                      f"E_ang {e['angle_distortion']:.3f} area {e['area_ratio']:.4f}{extra} {secs:5.1f} s", flush=True)


if __name__ == "__main__":
    main()
