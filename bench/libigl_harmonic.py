"""Time libigl's harmonic disk parameterization on the same meshes as the Rust bench.

Usage: python3 bench/libigl_harmonic.py CAMELHEAD.off HAND_X4.off
Prints the median of 10 runs of: boundary loop, circle map by arc length, cotangent harmonic
solve (igl.harmonic with k=1), as the Rust benchmark times the same three steps.
"""
import statistics
import sys
import time

import igl
import numpy as np


def once(v, f):
    t = time.perf_counter()
    b = igl.boundary_loop(f)
    bc = igl.map_vertices_to_circle(v, b)
    uv = igl.harmonic(v, f, b, bc, 1)
    return time.perf_counter() - t, uv


for path in sys.argv[1:]:
    v, f = igl.read_triangle_mesh(path)
    v = np.asarray(v, dtype=np.float64)
    f = np.asarray(f, dtype=np.int64)
    once(v, f)
    times = [once(v, f)[0] for _ in range(10)]
    print(f"{path}: vertices {len(v)} median {statistics.median(times) * 1000:.1f} ms")
