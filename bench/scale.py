"""Scale (issue 50): the armadillo against a same-shape copy (`mkcase.py`: edge flips, twist and
bend, shuffled order; 45 farthest-point anchors, seed 1) at 14.6k vertices, subdivided once (58k)
and twice (233k), each mapped with the default method. Prints per size the median wall time, peak
RSS, flips both ways and the median of each stage's milliseconds from `metrics.json`.

Usage: python3 bench/scale.py SURFMAP_BINARY [--levels 0 1 2] [--runs 3] [--work DIR]
  --work  where the cases are written (kept between runs; default /tmp/surfmap-scale)
Needs numpy + scipy (mkcase.py). Making the 233k case takes about two minutes, once.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.environ.get("SURFMAP_SHARED", os.path.join(HERE, "..", "..", "shared"))
MKCASE = os.path.join(SHARED, "tools", "mkcase.py")


def make(binary, work, level):
    case = os.path.join(work, f"level{level}")
    if os.path.exists(os.path.join(case, "anchors.json")):
        return case
    os.makedirs(work, exist_ok=True)
    mesh = os.path.join(SHARED, "meshes", "armadillo.obj")
    if level > 0:
        fine = os.path.join(work, f"armadillo{level}.obj")
        subprocess.run([binary, "convert", mesh, fine, "--subdivide", str(level)], check=True, capture_output=True)
        mesh = fine
    subprocess.run([sys.executable, MKCASE, mesh, case, "--seed", "1", "--anchors", "45"], check=True,
                   capture_output=True)
    return case


def run(binary, case, out):
    p = subprocess.run(["/usr/bin/time", "-f", "%e %M", binary, "map", os.path.join(case, "source.obj"),
                        os.path.join(case, "target.obj"), "--anchors", os.path.join(case, "anchors.json"),
                        "--out", out], capture_output=True, text=True)
    wall, rss = re.findall(r"([\d.]+) (\d+)\s*$", p.stderr)[-1]
    if p.returncode != 0:
        return float(wall), int(rss), None
    return float(wall), int(rss), json.load(open(os.path.join(out, "metrics.json")))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--work", default="/tmp/surfmap-scale")
    a = ap.parse_args()
    for level in a.levels:
        case = make(a.binary, a.work, level)
        walls, rsss, stages, flips, n, method = [], [], {}, None, None, None
        for i in range(a.runs):
            wall, rss, m = run(a.binary, case, os.path.join(a.work, f"out{level}"))
            walls.append(wall)
            rsss.append(rss)
            if m is None:
                print(f"level {level}: run {i} failed after {wall:.1f} s", flush=True)
                continue
            n, method = m["source_vertices"], m["method"]
            flips = (m["source_to_target"]["flipped_faces"], m["target_to_source"]["flipped_faces"])
            for k, v in m["timings_ms"]:
                stages.setdefault(k, []).append(v)
        st = " ".join(f"{k} {statistics.median(v) / 1000:.2f}" for k, v in stages.items())
        print(f"{n} vertices ({method}): wall {statistics.median(walls):.2f} s, peak RSS "
              f"{max(rsss) / 1024:.0f} MiB, flips {flips}; stages (s): {st}", flush=True)


if __name__ == "__main__":
    main()
