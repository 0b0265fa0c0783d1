"""The peer's landmark pairs (issue 35): plane -> bird (3 landmarks) and cat -> horse (17), each
posted both ways, judged by the shared evaluator in both directions.

Usage: python3 bench/peer.py SURFMAP_BINARY [FILTER] [--spec-extra JSON]   (needs numpy + scipy)
Prints one line per job direction: flips, L2, E_ang, area ratio, anchor error, wall time.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "..", "..", "shared")
L = os.path.join(SHARED, "meshes", "landmarks")
EVAL = os.path.join(SHARED, "eval", "meshmetrics.py")


def cat_horse():
    a = [int(x) for x in open(os.path.join(L, "cat_horse", "landmarks0.txt")).read().split()]
    b = [int(x) for x in open(os.path.join(L, "cat_horse", "landmarks1.txt")).read().split()]
    return (os.path.join(L, "cat_horse", "input0.obj"), os.path.join(L, "cat_horse", "input1.obj"),
            [[x, y] for x, y in zip(a, b)])


def plane_bird():
    return (os.path.join(L, "plane_bird", "61.off"), os.path.join(L, "plane_bird", "248.off"),
            [[4816, 8], [4152, 11546], [1732, 5170]])


PAIRS = {"plane->bird": plane_bird, "cat->horse": cat_horse}


def evaluate(src, tgt, mapped, anchors, tmp):
    af = os.path.join(tmp, "anchors.json")
    json.dump({"anchors": anchors}, open(af, "w"))
    out = subprocess.run([sys.executable, EVAL, src, tgt, mapped, "--anchors", af],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def run(binary, name, src, tgt, anchors, extra):
    with tempfile.TemporaryDirectory() as tmp:
        spec = {"method": "voronoi", "anchors": anchors}
        spec.update(extra)
        sf = os.path.join(tmp, "spec.json")
        json.dump(spec, open(sf, "w"))
        out = os.path.join(tmp, "out")
        t0 = time.time()
        p = subprocess.run([binary, "map", src, tgt, "--spec", sf, "--out", out], capture_output=True, text=True)
        secs = time.time() - t0
        if p.returncode != 0:
            print(f"{name:24s} FAILED {secs:6.1f} s  {p.stderr.strip().splitlines()[-1][:300]}", flush=True)
            return
        rev = [[b, a] for a, b in anchors]
        for d, (a, b, m, an) in {"s->t": (src, tgt, "source_on_target.obj", anchors),
                                 "t->s": (tgt, src, "target_on_source.obj", rev)}.items():
            e = evaluate(a, b, os.path.join(out, m), an, tmp)
            print(f"{name:24s} {d} flips {e['flipped_faces']:4d} L2 {e['l2_stretch']:.3f} "
                  f"E_ang {e['angle_distortion']:.3f} area {e['area_ratio']:.4f} "
                  f"anchor {e.get('anchor_error_max', 0):.1e} {secs:6.1f} s", flush=True)


def main():
    args = sys.argv[1:]
    extra = {}
    if "--spec-extra" in args:
        i = args.index("--spec-extra")
        extra = json.loads(args[i + 1])
        del args[i:i + 2]
    binary = args[0]
    flt = args[1] if len(args) > 1 else ""
    for name, make in PAIRS.items():
        src, tgt, anchors = make()
        for label, (a, b, an) in {name: (src, tgt, anchors),
                                  name + " (swapped)": (tgt, src, [[y, x] for x, y in anchors])}.items():
            if flt in label:
                run(binary, label, a, b, an, extra)


if __name__ == "__main__":
    main()
