#!/usr/bin/env python3
"""Method `homology` between different shapes: every basis pair (0..B-1)² and rotation τ, with the
evaluator-rule flips both ways (from metrics.json, which agrees with ../shared/eval) and the induced
map on H1 in the reference bases.

usage: [BASES=3] python3 bench/homology_classes.py [path/to/surfmap]
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
M = os.path.join(os.environ.get("SURFMAP_SHARED", os.path.join(HERE, "..", "..", "shared")), "meshes")
PAIRS = [p for p in [("kitten.nf20k.off", "rocker_arm/rocker-arm.obj", 4), ("eight.off", "cup_input_simple_10000.off", 2)]
         if os.environ.get("PAIR", "") in p[0]]


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(HERE, "..", "target")), "release", "surfmap")
    bases = int(os.environ.get("BASES", "3"))
    print("| pair | basis s,t | rotation | flips s→t/t→s | H1 (reference bases) | time ms |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        spec_path, out = os.path.join(tmp, "spec.json"), os.path.join(tmp, "out")
        for a, b, rotations in PAIRS:
            for bs in range(bases):
                for bt in range(bases):
                    for r in range(rotations):
                        spec = {"method": "homology", "anchors": [[0, 0]],
                                "options": {"basis": [bs, bt], "rotation": r, "metric_samples": 20000}}
                        json.dump(spec, open(spec_path, "w"))
                        p = subprocess.run([binary, "map", os.path.join(M, a), os.path.join(M, b), "--spec", spec_path,
                                            "--out", out], capture_output=True, text=True)
                        if p.returncode:
                            print(f"| {a} ↔ {b} | {bs},{bt} | {r} | — | {p.stderr.strip().splitlines()[-1]} | — |")
                            continue
                        m = json.load(open(os.path.join(out, "metrics.json")))
                        h = m["homology"]
                        print(f"| {a} ↔ {b} | {bs},{bt} | {r} | {m['source_to_target']['flipped_faces']}/"
                              f"{m['target_to_source']['flipped_faces']} | {h.get('h1_reference') or h['h1']} | "
                              f"{m['timings_ms'][-1][1]:.0f} |", flush=True)


if __name__ == "__main__":
    main()
