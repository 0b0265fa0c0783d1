"""Fixtures: servers (open, with tokens, with a 2 s time limit) and meshes."""

from __future__ import annotations

import pytest

from harness import ANCHORS, Server, deformed, icosphere, write_obj


@pytest.fixture(scope="session")
def server(tmp_path_factory):
    s = Server(tmp_path_factory.mktemp("open"), "--workers", "1")
    yield s
    s.stop()


@pytest.fixture(scope="session")
def auth_server(tmp_path_factory):
    s = Server(tmp_path_factory.mktemp("auth"), "--workers", "1", "--api-token", "alpha-token",
               "--api-token", "beta-token", "--metrics-token", "ops-token")
    yield s
    s.stop()


@pytest.fixture(scope="session")
def limited_server(tmp_path_factory):
    """Jobs that run over 2 s fail with `time_limit`; bodies over 1 MiB are refused."""
    s = Server(tmp_path_factory.mktemp("limited"), "--workers", "1", "--time-limit-secs", "2", "--max-attempts", "1",
               "--max-body-mb", "1")
    yield s
    s.stop()


@pytest.fixture(scope="session")
def pair(tmp_path_factory):
    """Paths of a small source (icosphere, 642 vertices) and target (its deformed copy)."""
    d = tmp_path_factory.mktemp("meshes")
    v, f = icosphere(3)
    return write_obj(d / "a.obj", v, f), write_obj(d / "b.obj", deformed(v), f)


@pytest.fixture(scope="session")
def spec():
    return {"method": "voronoi", "anchors": ANCHORS}


@pytest.fixture(scope="session")
def long_spec():
    """A job that runs for minutes unless stopped: smoothing that never converges early."""
    return {"method": "voronoi", "anchors": ANCHORS,
            "options": {"smoothing": {"iterations": 10000, "tolerance": 0.0}}}


@pytest.fixture(scope="session")
def long_pair():
    v, f = icosphere(5)
    return (v, f), (deformed(v), f)
