#!/usr/bin/env python3
"""Method `homology` with feature curves (boundary loops on genus 0), judged by
../shared/eval/meshmetrics.py: same-shape cases (known correspondence) and different shapes.

usage: [FEATURES=k] [META=1] python3 bench/homology_features.py [path/to/surfmap] [filter]

META=1 also builds the meta-mesh (`meta_mesh: true`) and prints, per case, its vertices, faces and
edge crossings and the milliseconds of the meta-mesh stage.

Features are built on each mesh: k centres by farthest-point sampling among interior vertices at
least two rings from the boundary, each a shortest edge path of about 6% of the bounding-box
diagonal along the mesh's main axis, two rings apart from each other. On same-shape cases the
target's features are the same vertices (so the ground truth agrees with them). The boundary
loop is appended as a feature by the service itself. Such features do not correspond between
different shapes; the last case places four at anatomically corresponding spots of two heads
(eyes, nose ridge, mouth; see HEADS). On surfaces with handles the base anchor is the vertex
farthest from every feature (same vertex on the target), and the first homotopy class (basis pair,
rotation) that maps without flips is reported with the class.
"""
import json
import os
import sys
import tempfile

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import table2  # noqa: E402

mm = table2.mm
M = table2.M


def edges_of(F):
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    return E


def boundary_vertices(F):
    E = np.sort(edges_of(F), axis=1)
    u, c = np.unique(E, axis=0, return_counts=True)
    return np.unique(u[c == 1])


def ring(F, S):
    """Vertices in S or adjacent to it."""
    m = np.zeros(F.max() + 1, bool)
    m[list(S)] = True
    hit = m[F].any(1)
    out = m.copy()
    out[F[hit].ravel()] = True
    return out


def features(V, F, k):
    n = len(V)
    E = edges_of(F)
    w = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    blocked = ring(F, ring(F, boundary_vertices(F)).nonzero()[0]) if len(boundary_vertices(F)) else np.zeros(n, bool)
    diag = np.linalg.norm(V.max(0) - V.min(0))
    axis = np.linalg.svd(V - V.mean(0), full_matrices=False)[2][0]
    paths = []
    for _ in range(k):
        free = ~blocked
        cand = free.nonzero()[0]
        if len(cand) == 0:
            break
        if paths:
            used = np.concatenate(paths)
            d = np.min(np.linalg.norm(V[cand, None, :] - V[None, used, :], axis=2), axis=1)
            c = int(cand[d.argmax()])
        else:
            c = int(cand[np.linalg.norm(V[cand] - V[cand].mean(0), axis=1).argmin()])
        keep = free[E[:, 0]] & free[E[:, 1]]
        G = csr_matrix((w[keep], (E[keep, 0], E[keep, 1])), shape=(n, n))
        dist, pred = dijkstra(G, directed=False, indices=c, return_predecessors=True)
        r = 0.06 * diag
        ok = np.isfinite(dist) & (dist > 0.6 * r) & (dist < r)
        if not ok.any():
            ok = np.isfinite(dist) & (dist > 0)
        idx = ok.nonzero()[0]
        e = int(idx[((V[idx] - V[c]) @ axis).argmax()])
        p = [e]
        while p[-1] != c:
            p.append(int(pred[p[-1]]))
        p = np.array(p[::-1])
        paths.append(p)
        blocked |= ring(F, ring(F, p).nonzero()[0])
    return paths


def frontmost(V, xy, r):
    """The vertex nearest the viewer (largest z) within `r` of `xy` in the xy-plane."""
    idx = np.nonzero(np.linalg.norm(V[:, :2] - np.array(xy), axis=1) < r)[0]
    return int(idx[V[idx, 2].argmax()])


def edge_path(V, F, a, b):
    """Shortest edge path from vertex a to vertex b."""
    E = edges_of(F)
    w = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    G = csr_matrix((w, (E[:, 0], E[:, 1])), shape=(len(V), len(V)))
    _, pred = dijkstra(G, directed=False, indices=a, return_predecessors=True)
    p = [b]
    while p[-1] != a:
        p.append(int(pred[p[-1]]))
    return np.array(p[::-1])


# Two heads facing +z with anatomically corresponding features, read off front depth renders:
# left eye, right eye (inner to outer corner), nose ridge (brow to tip), mouth (corner to corner);
# each end is the front-most vertex within r of the given (x, y).
HEADS = {
    "demosthenes-low-res.obj": ([[(0.02, 1.19), (0.12, 1.19)], [(0.26, 1.19), (0.36, 1.19)],
                                 [(0.19, 1.25), (0.19, 1.0)], [(0.10, 0.92), (0.28, 0.92)]], 0.03),
    "camelhead.off": ([[(-0.16, 0.10), (-0.07, 0.10)], [(0.07, 0.10), (0.16, 0.10)],
                       [(0.0, 0.10), (0.0, -0.17)], [(-0.08, -0.2), (0.08, -0.2)]], 0.012),
}


def head_features(name, V, F):
    segs, r = HEADS[name]
    return [edge_path(V, F, frontmost(V, a, r), frontmost(V, b, r)) for a, b in segs]


def run(binary, tmp, s, t, feats, anchors, gt, cls=None):
    spec = {"method": "homology", "anchors": anchors,
            "features": [{"source": [int(x) for x in a], "target": [int(x) for x in b]} for a, b in feats],
            "options": {}}
    if os.environ.get("META"):
        spec["options"]["meta_mesh"] = True
    if cls:
        spec["options"].update(basis=list(cls[0]), rotation=cls[1])
    e = table2.run(binary, tmp, "", s, t, anchors or None, gt, "homology", spec=spec, repeats=1)
    if "error" not in e:
        e["features"] = e["report"]["features"]
    return e


def run_classes(binary, tmp, s, t, feats, anchors, gt, genus):
    """Homotopy classes (basis pair in {0,1}², then rotation τ) until one has 0 flips both ways;
    a deformation can change which loops are shortest, so the true class need not be the first.
    Returns the run and the class tried last."""
    for bs in range(2):
        for bt in range(2):
            for r in range(4 if genus == 1 else genus):
                e = run(binary, tmp, s, t, feats, anchors, gt, ((bs, bt), r))
                if "error" in e or (e["flipped_faces"] == 0 and e["rev_flips"] == 0):
                    return e, f"{bs},{bt} τ{r}"
    return e, f"{bs},{bt} τ{r}"


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(HERE, "..", "target")), "release", "surfmap")
    filt = sys.argv[2] if len(sys.argv) > 2 else ""
    k = int(os.environ.get("FEATURES", "4"))
    same = [("face bent", "face.off", "bend"), ("face twisted", "face.off", "twist"),
            ("hand bent", "hand_lowres.obj", "bend"), ("camelhead twisted", "camelhead.off", "twist"),
            ("bunny twisted (closed)", "bunny.off", "twist"), ("face shuffled", "face.off", "shuffle"),
            ("kitten twisted (genus 1)", "kitten.nf20k.off", "twist"), ("torus shuffled (genus 1)", "torus.obj", "shuffle"),
            ("eight bent (genus 2)", "eight.off", "bend"), ("genus3 twisted (genus 3)", "genus3.off", "twist"),
            ("3holes shuffled (genus 3)", "3holes.off", "shuffle"),
            ("eight_lowres shuffled (genus 2)", "eight_lowres.off", "shuffle"),
            ("rocker arm bent (genus 1)", "rocker_arm/rocker-arm.obj", "bend"),
            ("skull twisted (genus 2)", "skull_low_resolution.obj", "twist"),
            ("fertility bent (genus 4)", "fertility.off", "bend")]
    diff = [("face ↔ hand", "face.off", "hand_lowres.obj"), ("face ↔ demosthenes", "face.off", "demosthenes-low-res.obj"),
            ("demosthenes ↔ camelhead", "demosthenes-low-res.obj", "camelhead.off"),
            ("cow ↔ horse (closed)", "cow.off", "horse.off"),
            ("demosthenes ↔ camelhead, anatomical", "demosthenes-low-res.obj", "camelhead.off")]
    print("| case | #v (s/t) | features | time s | E_ang | L2 | flips s→t/t→s | area | off-surface | feature err | gt mean | word |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        rows = []
        for name, path, kind in same:
            if filt not in name:
                continue
            s, t, _, gt = table2.same_shape(tmp, name.split()[0] + "_" + kind, os.path.join(M, path), kind, 1)
            V, F = mm.load_mesh(s)
            perm = np.loadtxt(gt, dtype=np.int64)
            fs = features(V.astype(float), F, k)
            anchors = []
            if "genus" in name:
                used = np.concatenate(fs)
                far = int(np.min(np.linalg.norm(V[:, None, :] - V[None, used, :], axis=2), axis=1).argmax())
                anchors = [[far, int(perm[far])]]
            rows.append((name, s, t, [(f, perm[f]) for f in fs], gt, anchors))
        for name, a, b in diff:
            if filt not in name:
                continue
            s, t = os.path.join(M, a), os.path.join(M, b)
            VS, FS = mm.load_mesh(s)
            VT, FT = mm.load_mesh(t)
            if name.endswith("anatomical"):
                fs, ft = head_features(a, VS.astype(float), FS), head_features(b, VT.astype(float), FT)
            else:
                fs, ft = features(VS.astype(float), FS, k), features(VT.astype(float), FT, k)
            rows.append((name, s, t, list(zip(fs, ft)), None, []))
        for name, s, t, feats, gt, anchors in rows:
            nv = f"{len(mm.load_mesh(s)[0])}/{len(mm.load_mesh(t)[0])}"
            if "genus" in name:
                g = int(name.split("genus ")[1].rstrip(")"))
                e, cls = run_classes(binary, tmp, s, t, feats, anchors, gt, g)
                name = f"{name}, class {cls}"
            else:
                e = run(binary, tmp, s, t, feats, anchors, gt)
            if "error" in e:
                print(f"| {name} | {nv} | {len(feats)} | — | — | — | — | — | — | — | — | {e['error']} |")
                continue
            gtm = f"{e['gt_error_mean']:.4f}" if e.get("gt_error_mean") is not None else "—"
            fe = e["features"]["feature_error"]
            print(f"| {name} | {nv} | {len(feats)} | {e['time']:.2f} | {e['angle_distortion']:.3f} | {e['l2_stretch']:.4f} | "
                  f"{e['flipped_faces']}/{e['rev_flips']} | {e['area_ratio']:.4f} | {e['off_surface_max']:.1e} | "
                  f"{max(fe):.1e} | {gtm} | {e['features']['word']} |", flush=True)
            meta = e["features"].get("meta_mesh")
            if meta:
                ms = dict(e["report"]["timings_ms"]).get("meta_mesh", float("nan"))
                print(f"|   meta-mesh | {meta['vertices']} vertices, {meta['faces']} faces, {meta['crossings']} crossings, "
                      f"{ms:.0f} ms {meta.get('error') or ''} |", flush=True)
            if os.environ.get("DUMP"):
                json.dump(e["report"], sys.stderr, indent=1)


if __name__ == "__main__":
    main()
