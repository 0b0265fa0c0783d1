#!/usr/bin/env python3
"""Method `homology` on same-shape cases (known correspondence) and different shapes: every
rotation τ of the 4g-gon, judged by ../shared/eval/meshmetrics.py.

usage: [ANCHORS=k] [BASES=n] python3 bench/homology.py [path/to/surfmap] [filter]
(ANCHORS: farthest-point anchors, the first is the base vertex; BASES: enumerate basis indices
0..n on each mesh as well as every rotation.)
"""
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import table2  # noqa: E402  (case builders)

M = table2.M


def run(binary, tmp, s, t, anchors, gt, rotation, basis=(0, 0)):
    spec = {"method": "homology", "anchors": anchors, "options": {"rotation": rotation, "basis": list(basis)}}
    e = table2.run(binary, tmp, "", s, t, anchors, gt, "homology", spec=spec, repeats=1)
    if "error" not in e:
        e["h1"] = e["report"]["homology"]["h1"]
    return e


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(HERE, "..", "target")), "release", "surfmap")
    filt = sys.argv[2] if len(sys.argv) > 2 else ""
    cases = [
        ("torus twisted (g1)", "torus.obj", "twist", 1),
        ("torus shuffled (g1)", "torus.obj", "shuffle", 1),
        ("kitten twisted (g1)", "kitten.nf20k.off", "twist", 1),
        ("rocker arm bent (g1)", "rocker_arm/rocker-arm.obj", "bend", 1),
        ("eight bent (g2)", "eight.off", "bend", 2),
        ("eight_lowres shuffled (g2)", "eight_lowres.off", "shuffle", 2),
        ("genus3 twisted (g3)", "genus3.off", "twist", 3),
        ("3holes bent (g3)", "3holes.off", "bend", 3),
        ("torus subdivided (g1)", "torus.obj", "subdivided", 1),
        ("kitten subdivided (g1)", "kitten.nf20k.off", "subdivided", 1),
        ("eight_lowres subdivided (g2)", "eight_lowres.off", "subdivided", 2),
        ("3holes subdivided (g3)", "3holes.off", "subdivided", 3),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        print("| case | basis s,t / rotation | time s | flips s→t/t→s | area | L2 | E_ang | anchor | gt mean | H1 |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for name, path, kind, g in cases:
            if filt not in name:
                continue
            s, t, anchors, gt = table2.same_shape(tmp, name.split()[0], os.path.join(M, path), kind, int(os.environ.get("ANCHORS", "1")))
            nb = int(os.environ.get("BASES", "1"))
            for bs, bt, rot in [(i, j, r) for i in range(nb) for j in range(nb) for r in range(4 if g == 1 else g)]:
                e = run(binary, tmp, s, t, anchors, gt, rot, (bs, bt))
                if "error" in e:
                    print(f"| {name} | {bs},{bt} / {rot} | — | {e['error']} |")
                    continue
                print(f"| {name} | {bs},{bt} / {rot} | {e['time']:.2f} | {e['flipped_faces']}/{e['rev_flips']} | "
                      f"{e['area_ratio']:.4f} | {e['l2_stretch']:.4f} | {e['angle_distortion']:.3f} | "
                      f"{e['anchor_error_max']:.1e} | {e.get('gt_error_mean', float('nan')):.4f} | {e['h1']} |")
                sys.stdout.flush()


if __name__ == "__main__":
    main()
