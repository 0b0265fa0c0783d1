"""Builds the Table-2-style comparison of `voronoi` and `greedy` on cases made from
../shared/meshes, runs `surfmap map` on each, and judges every result with the shared evaluator.

Usage: python3 bench/table2.py [SURFMAP_BINARY] [CASE_FILTER]
(default binary: $CARGO_TARGET_DIR/release/surfmap or target/release/surfmap). Needs numpy+scipy.
Cases: same-shape pairs with known correspondence (shuffled vertex order, twist, bend, another
triangulation by subdivision, and by QEM simplification to half the vertices) with farthest-point anchors; SMPL man/woman (i <-> i); Sumner
cat/lion (55 markers); genus 1 and 2. Prints a markdown table; times are wall-clock medians of 3.
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
SHARED = os.environ.get("SURFMAP_SHARED", os.path.join(HERE, "..", "..", "shared"))
sys.path.insert(0, os.path.join(SHARED, "eval"))
import meshmetrics as mm  # noqa: E402

M = os.path.join(SHARED, "meshes")


def write_off(p, V, F):
    with open(p, "w") as f:
        f.write(f"OFF\n{len(V)} {len(F)} 0\n")
        f.writelines(f"{x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in F)


def fps(V, k):
    idx = [0]
    d = np.linalg.norm(V - V[0], axis=1)
    for _ in range(k - 1):
        i = int(d.argmax())
        idx.append(i)
        d = np.minimum(d, np.linalg.norm(V - V[i], axis=1))
    return idx


def deform(V, kind):
    c = V.mean(0)
    if kind == "twist":
        lo, hi = V[:, 1].min(), V[:, 1].max()
        t = (V[:, 1] - lo) / (hi - lo) * 0.8
        x, z = V[:, 0] - c[0], V[:, 2] - c[2]
        W = V.copy()
        W[:, 0] = c[0] + x * np.cos(t) - z * np.sin(t)
        W[:, 2] = c[2] + x * np.sin(t) + z * np.cos(t)
        return W
    if kind == "bend":
        d = V.max(0) - V.min(0)
        ax = int(d.argmax())
        o = (ax + 1) % 3
        R = d[ax] * 1.2
        u = (V[:, ax] - c[ax]) / R
        W = V.copy()
        W[:, ax] = c[ax] + R * np.sin(u)
        W[:, o] = V[:, o] + R * (1 - np.cos(u))
        return W
    return V


def subdivide(V, F):
    edges = {}
    NV = [*V]
    for f in F:
        for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            k = (min(a, b), max(a, b))
            if k not in edges:
                edges[k] = len(NV)
                NV.append((V[a] + V[b]) / 2)
    NF = []
    for a, b, c in F:
        ab, bc, ca = edges[(min(a, b), max(a, b))], edges[(min(b, c), max(b, c))], edges[(min(c, a), max(c, a))]
        NF += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return np.array(NV), np.array(NF)


def same_shape(tmp, name, path, kind, k):
    V, F = mm.load_mesh(path)
    V = V.astype(float)
    n = len(V)
    src = os.path.join(tmp, f"{name}_s.off")
    tgt = os.path.join(tmp, f"{name}_t.off")
    if kind == "shuffle":
        perm = np.random.default_rng(0).permutation(n)
        W = np.empty_like(V)
        W[perm] = V
        write_off(tgt, W, perm[F])
        write_off(src, V, F)
    elif kind == "subdivided":
        # Source: the mesh; target: another triangulation (one 1-to-4 split), same vertex ids first.
        NV, NF = subdivide(V, F)
        perm = np.arange(n)
        write_off(src, V, F)
        write_off(tgt, NV, NF)
    else:
        perm = np.arange(n)
        write_off(src, V, F)
        write_off(tgt, deform(V, kind), F)
    gt = os.path.join(tmp, f"{name}_gt.txt")
    np.savetxt(gt, perm, fmt="%d")
    anchors = [[i, int(perm[i])] for i in fps(V, k)]
    return src, tgt, anchors, gt


def simplified(tmp, binary, name, path, k):
    """Source: the mesh simplified to half its vertices by `surfmap convert --simplify` (every
    kept vertex is an original one); target: the mesh. Ground truth: the kept indices."""
    V, _ = mm.load_mesh(path)
    src = os.path.join(tmp, f"{name}_s.off")
    gt = os.path.join(tmp, f"{name}_gt.txt")
    subprocess.run([binary, "convert", path, src, "--simplify", str(len(V) // 2), "--kept", gt],
                   check=True, capture_output=True)
    kept = np.loadtxt(gt, dtype=np.int64)
    VS, _ = mm.load_mesh(src)
    tgt = os.path.join(tmp, f"{name}_t.off")
    VT, FT = mm.load_mesh(path)
    write_off(tgt, VT.astype(float), FT)
    return src, tgt, [[i, int(kept[i])] for i in fps(VS.astype(float), k)], gt


def cases(tmp, binary):
    out = []
    for name, path, kind, k in [
        ("cow shuffled", "cow.off", "shuffle", 24),
        ("cow twisted", "cow.off", "twist", 24),
        ("bunny bent", "bunny.off", "bend", 24),
        ("homer twisted", "homer.obj", "twist", 24),
        ("armadillo bent", "armadillo.obj", "bend", 45),
        ("armadillo/subdivided", "armadillo.obj", "subdivided", 45),
        ("torus twisted (g1)", "torus.obj", "twist", 24),
        ("torus bent (g1)", "torus.obj", "bend", 24),
        ("rocker arm bent (g1)", "rocker_arm/rocker-arm.obj", "bend", 24),
        ("kitten twisted (g1)", "kitten.nf20k.off", "twist", 24),
        ("eight bent (g2)", "eight.off", "bend", 24),
        ("eight_lowres twisted (g2)", "eight_lowres.off", "twist", 24),
    ]:
        tag = name.split()[0].replace("/", "_") + "_" + kind
        s, t, a, gt = same_shape(tmp, tag, os.path.join(M, path), kind, k)
        out.append((name, s, t, a, gt))
    for name, path in [("cow simplified 50% (retriangulation)", "cow.off"),
                       ("homer simplified 50% (retriangulation)", "homer.obj")]:
        tag = name.split()[0] + "_simplified"
        s, t, a, gt = simplified(tmp, binary, tag, os.path.join(M, path), 24)
        out.append((name, s, t, a, gt))
    man = os.path.join(M, "registered/smpl_human/human_man.obj")
    woman = os.path.join(M, "registered/smpl_human/human_woman.obj")
    V, _ = mm.load_mesh(man)
    gt = os.path.join(tmp, "smpl_gt.txt")
    np.savetxt(gt, np.arange(len(V)), fmt="%d")
    out.append(("SMPL man/woman", man, woman, [[i, i] for i in fps(V, 24)], gt))
    mk = np.loadtxt(os.path.join(M, "registered/sumner_cat_lion/cat_lion_markers.txt"), dtype=int, usecols=(0, 1))
    out.append((
        "cat/lion (55 markers)",
        os.path.join(M, "registered/sumner_cat_lion/cat-reference.obj"),
        os.path.join(M, "registered/sumner_cat_lion/lion-reference.obj"),
        mk.tolist(),
        None,
    ))
    return out


def run(binary, tmp, name, s, t, anchors, gt, method, spec=None, repeats=3):
    """Runs `surfmap map` `repeats` times (wall median) and judges the result with the evaluator.
    `spec`: a whole job spec (written to a file and passed with --spec) instead of --method.
    `SURFMAP_OPTIONS` (JSON) in the environment: job options for every run without a spec."""
    extra = os.environ.get("SURFMAP_OPTIONS")
    if spec is None and extra:
        spec = {"method": method, "anchors": anchors, "options": json.loads(extra)}
    if spec is None:
        af = os.path.join(tmp, "anchors.json")
        json.dump({"anchors": anchors}, open(af, "w"))
        how = ["--anchors", af, "--method", method]
    else:
        sf = os.path.join(tmp, "spec.json")
        json.dump(spec, open(sf, "w"))
        how = ["--spec", sf]
    out = os.path.join(tmp, "out")
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        p = subprocess.run([binary, "map", s, t, *how, "--out", out], capture_output=True, text=True)
        times.append(time.perf_counter() - t0)
        if p.returncode != 0:
            return {"error": p.stderr.strip().splitlines()[-1]}
    S, T, MP = mm.load_mesh(s), mm.load_mesh(t), mm.load_mesh(os.path.join(out, "source_on_target.obj"))
    g = T[0][np.loadtxt(gt, dtype=np.int64)] if gt else None
    e = mm.evaluate_map(S, T, MP, anchors, g, samples=100000)
    rep = json.load(open(os.path.join(out, "metrics.json")))
    e["time"] = statistics.median(times)
    e["patches"] = rep["patches"]
    e["own_l2"] = rep["source_to_target"]["l2_stretch"]
    e["rev_flips"] = rep["target_to_source"]["flipped_faces"]
    e["report"] = rep
    return e


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(HERE, "..", "target")), "release", "surfmap")
    filt = sys.argv[2] if len(sys.argv) > 2 else ""
    with tempfile.TemporaryDirectory() as tmp:
        print("| case | #v (s/t) | n_a | method | time s | patches | E_ang | L2 | flips s→t/t→s | area | off-surface | anchor err | gt mean |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for name, s, t, a, gt in cases(tmp, binary):
            if filt not in name:
                continue
            nv = f"{len(mm.load_mesh(s)[0])}/{len(mm.load_mesh(t)[0])}"
            for method in ["voronoi", "greedy"]:
                e = run(binary, tmp, name, s, t, a, gt, method)
                if "error" in e:
                    print(f"| {name} | {nv} | {len(a)} | {method} | — | — | — | — | — | — | — | — | {e['error']} |")
                    continue
                gtm = f"{e['gt_error_mean']:.4f}" if "gt_error_mean" in e else "—"
                fb = e["report"].get("layout", {}).get("fallback")
                shown = f"{method} ({fb} layout)" if fb else method
                print(f"| {name} | {nv} | {len(a)} | {shown} | {e['time']:.2f} | {e['patches']} | "
                      f"{e['angle_distortion']:.3f} | {e['l2_stretch']:.4f} | {e['flipped_faces']}/{e['rev_flips']} | "
                      f"{e['area_ratio']:.4f} | {e['off_surface_max']:.1e} | {e['anchor_error_max']:.1e} | {gtm} |",
                      flush=True)


if __name__ == "__main__":
    main()
