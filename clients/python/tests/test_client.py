"""The client against the real server: every endpoint, an error of each kind, a job that fails
with a code, a cancelled job, a 100k-vertex upload, sync and async."""

from __future__ import annotations

import asyncio
import hashlib
import json

import numpy as np
import pytest

import surfmap
from surfmap import AsyncClient, Client, Spec
from harness import ANCHORS, icosphere


@pytest.fixture(scope="module")
def done(server, pair, spec, tmp_path_factory):
    """One job run to its end with a progress callback, shared by the tests that read it."""
    seen = []
    with Client(server.url) as c:
        job = c.map(pair[0], pair[1], spec, wait=True, timeout=300, progress=seen.append)
        yield job, seen


def test_map_waits_reports_progress_and_downloads(server, done, tmp_path):
    job, seen = done
    assert job.state == "succeeded", job
    assert job.id and job.error is None
    assert seen[-1].state == "succeeded" and seen[0].id == job.id
    assert all(b.progress >= a.progress or b.stage != a.stage for a, b in zip(seen, seen[1:]) if a.state == b.state)
    m = job.metrics
    assert m["source_to_target"]["flipped_faces"] == 0, m
    assert "timings_ms" in m
    paths = job.download(tmp_path / "out")
    names = {p.name for p in paths}
    assert {"metrics.json", "morph.glb", "source_on_target.obj", "source_to_target.csv"} <= names, names
    for a in job.artifacts:
        assert hashlib.sha256((tmp_path / "out" / a.name).read_bytes()).hexdigest() == a.sha256, a.name
    assert json.loads((tmp_path / "out" / "metrics.json").read_text())["source_to_target"] == pytest.approx(m["source_to_target"], rel=1e-12)
    with Client(server.url) as c:
        assert [a.name for a in c.artifacts(job.id)] == [a.name for a in job.artifacts]
        assert c.artifact(job.id, "morph.glb")[:4] == b"glTF"
        only = c.download(job.id, tmp_path / "one", names=["metrics.json"])
        assert [p.name for p in only] == ["metrics.json"]


def test_uploads_from_path_bytes_and_arrays(server, pair):
    v, f = icosphere(2)
    with Client(server.url) as c:
        a = c.upload(pair[0])
        b = c.upload(pair[0].read_bytes(), format="obj")
        assert a.id == b.id == hashlib.sha256(pair[0].read_bytes()).hexdigest()
        assert a.summary["vertices"] == 642 and a.format == "obj"
        n = c.upload((v, f))
        assert n.summary["vertices"] == len(v) and n.summary["genus"] == 0
        d = c.upload({"vertices": v.astype(np.float32), "faces": f.astype(np.int32)})
        assert d.summary["faces"] == len(f)
        got = c.mesh(a.id)
        assert (got.id, got.format, got.size_bytes) == (a.id, "obj", pair[0].stat().st_size)
        assert got.summary["vertices"] == 642
        glb = c.mesh_glb(a.id)
        assert glb[:4] == b"glTF" and int.from_bytes(glb[8:12], "little") == len(glb)
        with pytest.raises(ValueError):
            c.upload((v[:, :2], f))


def test_a_100k_vertex_upload(server):
    v, f = icosphere(7)
    assert len(v) >= 100_000
    with Client(server.url) as c:
        m = c.upload((v, f))
    assert (m.summary["vertices"], m.summary["faces"], m.summary["genus"]) == (len(v), len(f), 0)


def test_submit_from_a_spec_object_events_list_and_retry(server, pair, done):
    with Client(server.url) as c:
        src, tgt = c.upload(pair[0]), c.upload(pair[1])
        job = c.submit(src, tgt.id, Spec("greedy", ANCHORS), idempotency_key="py-greedy-1")
        assert job.state in ("queued", "running") and job.method == "greedy"
        again = c.submit(src.id, tgt.id, {"method": "greedy", "anchors": ANCHORS}, idempotency_key="py-greedy-1")
        assert again.id == job.id
        states = [j.state for j in c.events(job.id)]
        assert states[-1] == "succeeded", states
        assert job.refresh().state == "succeeded"
        ids = [j.id for j in c.jobs(method="greedy")]
        assert ids[0] == job.id
        ok = [j.id for j in c.jobs(state="succeeded")]
        assert job.id in ok and done[0].id in ok
        page, cursor = c.list_jobs(limit=1)
        assert len(page) == 1 and cursor is not None
        page2, _ = c.list_jobs(limit=1, cursor=cursor)
        assert page2[0].id != page[0].id
        assert [j.id for j in c.jobs(page_size=1)] == [j.id for j in c.jobs()]
        # The spec comes back with its defaults; submitting it again is a retry.
        assert job.spec["method"] == "greedy" and job.spec["anchors"] == ANCHORS and "options" in job.spec
        r = c.retry(job)
        assert r.id != job.id and r.spec == job.spec and r.meshes == job.meshes
        assert r.wait(timeout=300).state == "succeeded"


def test_operations_endpoints(server, auth_server):
    with Client(server.url) as c:
        assert c.health()["status"] == "ok"
        assert c.ready()["store"] == "sqlite"
        assert "openapi" in c.openapi()
        assert "surfmap_" in c.metrics_text()
    with Client(auth_server.url) as c:
        with pytest.raises(surfmap.Unauthorized):
            c.metrics_text()
        assert "surfmap_" in c.metrics_text(token="ops-token")


def test_errors_carry_the_service_code(server, pair, spec, done):
    with Client(server.url) as c:
        src = c.upload(pair[0])
        with pytest.raises(surfmap.BadRequest) as e:
            c.submit(src, src, {"method": "nope", "anchors": ANCHORS})
        assert e.value.code == "unknown_method" and e.value.status == 400
        with pytest.raises(surfmap.BadRequest) as e:
            c.submit(src, src, {"method": "voronoi", "anchors": ANCHORS, "colour": 3})
        assert e.value.code == "invalid_spec"
        with pytest.raises(surfmap.BadRequest) as e:
            c.list_jobs(limit=0)
        assert e.value.code == "invalid_query"
        with pytest.raises(surfmap.BadRequest) as e:
            c.mesh("not-a-mesh-id")
        assert e.value.code == "invalid_mesh_id"
        with pytest.raises(surfmap.NotFound) as e:
            c.job("00000000-0000-0000-0000-000000000000")
        assert e.value.code == "job_not_found"
        with pytest.raises(surfmap.NotFound) as e:
            c.mesh("0" * 64)
        assert e.value.code == "mesh_not_found"
        with pytest.raises(surfmap.NotFound) as e:
            c.submit("0" * 64, src, spec)
        assert e.value.code == "mesh_not_found"
        with pytest.raises(surfmap.NotFound) as e:
            c.artifact(done[0].id, "nothing.txt")
        assert e.value.code == "artifact_not_found"
        with pytest.raises(surfmap.SurfmapError) as e:
            c.download(done[0].id, "unused", names=["nothing.txt"])
        assert e.value.code == "artifact_not_found"
        with pytest.raises(surfmap.Unprocessable) as e:
            c.upload(b"v 0 0 0\nv 1 0 0\nf 1 2 3\n", format="obj")
        assert e.value.status == 422 and e.value.code
        with pytest.raises(surfmap.Unprocessable) as e:
            c.submit(src, src, {"method": "voronoi", "anchors": [[0, 0], [1, 1], [99999, 2]]})
        assert e.value.code == "invalid_anchors"
        c.submit(src, src, spec, idempotency_key="py-conflict")
        with pytest.raises(surfmap.Conflict) as e:
            c.submit(src, src, Spec("greedy", ANCHORS), idempotency_key="py-conflict")
        assert e.value.code == "idempotency_conflict"


def test_tokens_and_tenants(auth_server, pair, spec):
    with Client(auth_server.url) as anon:
        with pytest.raises(surfmap.Unauthorized) as e:
            anon.list_jobs()
        assert (e.value.code, e.value.status) == ("unauthorized", 401)
    with Client(auth_server.url, token="wrong") as bad:
        with pytest.raises(surfmap.Unauthorized):
            bad.upload(pair[0])
    with Client(auth_server.url, token="alpha-token") as a, Client(auth_server.url, token="beta-token") as b:
        job = a.map(pair[0], pair[1], spec, wait=True, timeout=300)
        assert job.state == "succeeded"
        assert [j.id for j in a.jobs()] == [job.id]
        assert list(b.jobs()) == []
        for call in (lambda: b.job(job.id), lambda: b.artifact(job.id, "metrics.json"), lambda: b.cancel(job.id),
                     lambda: b.mesh(job.source), lambda: b.mesh_glb(job.source), lambda: list(b.events(job.id))):
            with pytest.raises(surfmap.NotFound):
                call()


def test_a_body_over_the_limit_is_413(limited_server):
    v, f = icosphere(6)  # about 4 MB of OBJ
    with Client(limited_server.url) as c:
        with pytest.raises(surfmap.PayloadTooLarge) as e:
            c.upload((v, f))
    assert (e.value.status, e.value.code) == (413, "payload_too_large")


def test_a_job_that_fails_raises_its_code(limited_server, long_pair, long_spec):
    with Client(limited_server.url) as c:
        with pytest.raises(surfmap.JobFailed) as e:
            c.map(long_pair[0], long_pair[1], long_spec, wait=True, timeout=300)
        assert e.value.code == "time_limit"
        job = e.value.job
        assert job.state == "failed" and job.error.code == "time_limit" and job.artifacts == []
        assert c.job(job.id).error.code == "time_limit"
        # Without raising: the job as it ended.
        again = c.retry(job).wait(timeout=300, raise_on_failure=False)
        assert (again.state, again.error.code) == ("failed", "time_limit")


def test_cancel_a_running_job(server, long_pair, long_spec):
    with Client(server.url) as c:
        job = c.map(long_pair[0], long_pair[1], long_spec)
        for j in c.events(job.id):
            if j.state == "running":
                break
        assert job.cancel().cancel_requested or job.state == "cancelled"
        with pytest.raises(surfmap.JobCancelled) as e:
            job.wait(timeout=120)
        assert e.value.code == "cancelled" and job.state == "cancelled"
        assert c.job(job.id).state == "cancelled"
        # A queued job is cancelled at once.
        queued = c.submit(long_pair[0], long_pair[1], long_spec)
        blocker_state = c.cancel(queued.id).state
        assert blocker_state in ("cancelled", "running")
        assert c.wait(queued.id, timeout=120, raise_on_failure=False).state == "cancelled"


def test_a_wait_that_times_out(server, long_pair, long_spec):
    with Client(server.url) as c:
        job = c.submit(long_pair[0], long_pair[1], long_spec)
        with pytest.raises(surfmap.Timeout) as e:
            job.wait(timeout=1.5)
        assert e.value.job.id == job.id and e.value.job.state in ("queued", "running")
        job.cancel()
        assert job.wait(timeout=120, raise_on_failure=False).state == "cancelled"


def test_async_client(server, auth_server, pair, spec, tmp_path):
    async def run():
        async with AsyncClient(server.url) as c:
            seen = []
            job = await c.map(pair[0], pair[1], spec, wait=True, timeout=300, progress=seen.append)
            assert job.state == "succeeded" and seen[-1].state == "succeeded"
            assert job.metrics["source_to_target"]["flipped_faces"] == 0
            paths = await job.download(tmp_path / "async")
            assert {"morph.glb", "metrics.json"} <= {p.name for p in paths}
            states = [j.state async for j in c.events(job.id)]
            assert states == ["succeeded"]
            assert job.id in [j.id async for j in c.jobs(state="succeeded")]
            assert (await c.mesh(job.source)).id == job.source
            assert (await c.mesh_glb(job.target))[:4] == b"glTF"
            assert (await c.health())["status"] == "ok" and (await c.ready())["store"] == "sqlite"
            with pytest.raises(surfmap.NotFound) as e:
                await c.job("00000000-0000-0000-0000-000000000000")
            assert e.value.code == "job_not_found"
            r = await c.retry(job)
            assert (await r.wait(timeout=300)).state == "succeeded"
        async with AsyncClient(auth_server.url) as anon:
            with pytest.raises(surfmap.Unauthorized):
                await anon.list_jobs()

    asyncio.run(run())


def test_wait_drives_a_tqdm_bar(server, done, monkeypatch):
    import sys
    import types

    bars = []

    class FakeBar:
        def __init__(self, total, **kw):
            self.total, self.n, self.desc, self.closed = total, 0, "", False
            bars.append(self)

        def set_description_str(self, d):
            self.desc = d

        def refresh(self):
            pass

        def close(self):
            self.closed = True

    mod = types.ModuleType("tqdm.auto")
    mod.tqdm = FakeBar
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    monkeypatch.setitem(sys.modules, "tqdm.auto", mod)
    with Client(server.url) as c:
        job = c.wait(done[0].id, progress=True)
    assert job.state == "succeeded"
    assert len(bars) == 1 and (bars[0].n, bars[0].total, bars[0].closed) == (100, 100, True)
    assert bars[0].desc.startswith("succeeded")
    # Without tqdm, progress=True draws nothing; progress="tqdm" asks for it.
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    with Client(server.url) as c:
        assert c.wait(done[0].id, progress=True).state == "succeeded"
        with pytest.raises(ImportError):
            c.wait(done[0].id, progress="tqdm")
