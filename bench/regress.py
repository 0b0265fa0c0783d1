"""Fingerprints of every job kind, for checking that a refactoring changes no result.

Usage: python3 bench/regress.py SURFMAP_BINARY OUT.json [CASE_FILTER]
       python3 bench/regress.py --compare BEFORE.json AFTER.json

Runs once per case: the Table-2 cases of `bench/table2.py` with `voronoi` and `greedy`, the README's
SMPL job, `homology` on the genus-1 and genus-2 Table-2 cases (one anchor; with the meta-mesh on
the torus), a feature job on the SMPL pair, and a `quad` remesh. For each it records the sha256 of
every artifact and `metrics.json` without its timings. `--compare` lists every value that
differs (exit 1 when any does) and, by name, report fields present on one side only. Needs numpy+scipy.
"""
import hashlib
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import table2  # noqa: E402

TIMED = {"timings_ms", "time_ms", "elapsed_ms"}


def untimed(v):
    if isinstance(v, dict):
        return {k: untimed(x) for k, x in v.items() if k not in TIMED}
    if isinstance(v, list):
        return [untimed(x) for x in v]
    return v


def fingerprint(out):
    arts = {}
    for name in sorted(os.listdir(out)):
        data = open(os.path.join(out, name), "rb").read()
        if name.endswith("metrics.json"):
            arts[name] = untimed(json.loads(data))
        else:
            arts[name] = hashlib.sha256(data).hexdigest()
    return arts


def leaves(x, y, path, diffs, gone, added):
    """Every value that differs between `x` and `y`; keys on one side only are collected by
    name (a report field that was removed or added), not counted as differences."""
    if isinstance(x, dict) and isinstance(y, dict):
        for k in x:
            if k in y:
                leaves(x[k], y[k], f"{path}.{k}", diffs, gone, added)
            else:
                gone.add(f"{path}.{k}".split(".", 2)[-1])
        added.update(f"{path}.{k}".split(".", 2)[-1] for k in y if k not in x)
    elif isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        for i, (p, q) in enumerate(zip(x, y)):
            leaves(p, q, f"{path}[{i}]", diffs, gone, added)
    elif x != y:
        diffs.append(f"{path}: {str(x)[:100]} -> {str(y)[:100]}")


def run(binary, tmp, cmd, meshes, spec):
    sf = os.path.join(tmp, "spec.json")
    json.dump(spec, open(sf, "w"))
    out = tempfile.mkdtemp(dir=tmp)
    p = subprocess.run([binary, cmd, *meshes, "--spec", sf, "--out", out], capture_output=True, text=True)
    if p.returncode != 0:
        return {"error": (p.stderr.strip().splitlines() or ["?"])[-1]}
    return fingerprint(out)


def cases(tmp, binary):
    out = []
    smpl = None
    for name, s, t, a, _gt in table2.cases(tmp, binary):
        if name == "cow shuffled":
            out.extend(pipeline_cases(tmp, s, t, a))
        for method in ["voronoi", "greedy"]:
            out.append((f"{name} / {method}", "map", [s, t], {"method": method, "anchors": a}))
        if "(g" in name:
            options = {"meta_mesh": True} if name.startswith("torus twisted") else {}
            out.append((f"{name} / homology", "map", [s, t], {"method": "homology", "anchors": a[:1], "options": options}))
        if name.startswith("SMPL"):
            smpl = (s, t)
        if name == "bunny bent":
            out.append(("bunny bent / quad", "remesh", [s, t],
                        {"method": "quad", "anchors": a[:6], "options": {"level": 4, "base_vertices": 16}}))
    readme = [[i, i] for i in [0, 6763, 5905, 2445, 1262, 4716, 1633, 1095, 1329, 4463, 4296, 732, 3385, 4599, 5432,
                               2913, 978, 5360, 1921, 1803]]
    out.append(("README SMPL / voronoi", "map", list(smpl), {"method": "voronoi", "anchors": readme}))
    return out


def pipeline_cases(tmp, s, t, a):
    """The pipeline's own paths on one cow pair: `spherical`, `auto` (no method), anchors given as
    surface points with the inverse morph, and a pair of meshes in two parts each."""
    out = [
        ("cow shuffled / spherical", "map", [s, t], {"method": "spherical", "anchors": a}),
        ("cow shuffled / auto", "map", [s, t], {"anchors": a}),
    ]
    (V, F), (W, G) = table2.mm.load_mesh(s), table2.mm.load_mesh(t)
    points = [{"source": [float(x) for x in V[i] + 1e-4], "target": {"face": int(np.flatnonzero((G == j).any(1))[0]),
                                                                      "bary": [1 / 3, 1 / 3, 1 / 3]}}
              for i, j in a]
    out.append(("cow shuffled / voronoi, point anchors, inverse morph", "map", [s, t],
                {"method": "voronoi", "anchors": points, "options": {"inverse_morph": True}}))
    two = []
    for tag, (X, T) in [("s", (V, F)), ("t", (W, G))]:
        path = os.path.join(tmp, f"two_parts_{tag}.off")
        shift = X + np.array([3.0 * np.ptp(X[:, 0]), 0.0, 0.0])
        table2.write_off(path, np.vstack([X, shift]), np.vstack([T, T + len(X)]))
        two.append(path)
    rows = a + [[i + len(V), j + len(W)] for i, j in a]
    out.append(("cow shuffled, two parts / voronoi", "map", two, {"method": "voronoi", "anchors": rows}))
    return out


def main():
    if sys.argv[1] == "--compare":
        a, b = json.load(open(sys.argv[2])), json.load(open(sys.argv[3]))
        bad, gone, added = 0, set(), set()
        for case in sorted(set(a) | set(b)):
            diffs = []
            leaves(a.get(case), b.get(case), "", diffs, gone, added)
            if diffs:
                bad += 1
                print(f"differs: {case}")
                for d in diffs[:8]:
                    print(f"  {d}")
        print(f"keys only before (removed): {sorted(gone)}")
        print(f"keys only after (added): {sorted(added)}")
        print(f"{len(a) - bad} of {len(a)} cases identical in every value both have")
        sys.exit(1 if bad else 0)
    binary, dest = sys.argv[1], sys.argv[2]
    filt = sys.argv[3] if len(sys.argv) > 3 else ""
    res = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, cmd, meshes, spec in cases(tmp, binary):
            if filt in name:
                res[name] = run(binary, tmp, cmd, meshes, spec)
                print(name, "error" in res[name] and res[name]["error"] or "ok", flush=True)
                json.dump(res, open(dest, "w"), indent=1)


if __name__ == "__main__":
    main()
