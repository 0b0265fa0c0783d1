"""Shared by the client's and the dashboard's tests: the real ``surfmap-server`` on an
ephemeral port (SQLite, in-process workers), and small meshes made here (icospheres written as
OBJ) so that jobs take seconds."""

from __future__ import annotations

import os
import pathlib
import subprocess
import threading

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[3]


class NoBinary(RuntimeError):
    pass


def server_binary() -> pathlib.Path:
    env = os.environ.get("SURFMAP_SERVER_BIN")
    candidates = [pathlib.Path(env)] if env else []
    target = os.environ.get("CARGO_TARGET_DIR")
    if target:
        candidates.append(pathlib.Path(target) / "debug" / "surfmap-server")
    candidates.append(ROOT / "target" / "debug" / "surfmap-server")
    for c in candidates:
        if c.is_file():
            return c
    raise NoBinary(f"no surfmap-server binary (set SURFMAP_SERVER_BIN; looked at {candidates})")


class Server:
    """A running server; ``url`` is its base URL, ``log`` its stderr."""

    def __init__(self, tmp: pathlib.Path, *extra: str):
        tmp.mkdir(parents=True, exist_ok=True)
        self.log = tmp / "server.log"
        args = [str(server_binary()), "--listen", "127.0.0.1:0", "--database-url", f"sqlite://{tmp / 'surfmap.db'}",
                "--data-dir", str(tmp / "data"), *extra]
        env = dict(os.environ, RUST_LOG="info,sqlx=warn")
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=open(self.log, "wb"), env=env, text=True)
        first: list = []
        got = threading.Event()

        def drain():
            assert self.proc.stdout is not None
            first.append(self.proc.stdout.readline())
            got.set()
            for _ in self.proc.stdout:
                pass

        threading.Thread(target=drain, daemon=True).start()
        if not got.wait(60) or not first[0].startswith("listening on "):
            self.stop()
            raise RuntimeError(f"server did not start: {first!r}\n{self.log.read_text()}")
        self.url = "http://" + first[0].split("listening on ", 1)[1].strip()

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def icosphere(level: int):
    """Vertices (n, 3) and faces (m, 3) of a unit icosphere; vertices 0-11 are the icosahedron's."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    verts = np.array(v, dtype=np.float64)
    verts /= np.linalg.norm(verts, axis=1)[:, None]
    faces = np.array(f, dtype=np.int64)
    for _ in range(level):
        edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        mid = verts[uniq[:, 0]] + verts[uniq[:, 1]]
        mid /= np.linalg.norm(mid, axis=1)[:, None]
        n = len(verts)
        verts = np.concatenate([verts, mid])
        m = len(faces)
        a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
        ab, bc, ca = n + inv[:m], n + inv[m:2 * m], n + inv[2 * m:]
        faces = np.concatenate([np.stack([a, ab, ca], 1), np.stack([b, bc, ab], 1), np.stack([c, ca, bc], 1),
                                np.stack([ab, bc, ca], 1)])
    return verts, faces


def deformed(verts):
    """A smooth, genus-preserving deformation: stretched, with a bump."""
    out = verts * np.array([1.4, 0.8, 1.1])
    out[:, 2] += 0.25 * np.exp(-4 * ((verts[:, 0] - 0.3) ** 2 + verts[:, 1] ** 2))
    return out


def write_obj(path: pathlib.Path, verts, faces) -> pathlib.Path:
    with open(path, "w") as fh:
        for p in verts:
            fh.write(f"v {p[0]:.9f} {p[1]:.9f} {p[2]:.9f}\n")
        for a, b, c in faces:
            fh.write(f"f {a + 1} {b + 1} {c + 1}\n")
    return path


ANCHORS = [[0, 0], [3, 3], [4, 4], [7, 7], [8, 8], [11, 11]]


