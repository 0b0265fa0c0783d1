"""The synchronous client and its ``Job``."""

from __future__ import annotations

import json
import os
import pathlib
import time
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import httpx

from ._endpoints import path as endpoint
from ._errors import JobCancelled, JobFailed, SurfmapError, Timeout, from_response
from ._mesh import is_mesh_id, mesh_input
from ._models import Artifact, JobData, Mesh, SseParser, spec_dict

DEFAULT_URL = "http://127.0.0.1:8080"
Progress = Union[None, bool, str, Callable[["JobData"], Any]]


def _headers(token: Optional[str]) -> Dict[str, str]:
    h = {"User-Agent": "surfmap-python/0.1"}
    if token:
        h["Authorization"] = f"Bearer {token}"
    return h


def _timeout(seconds: float) -> httpx.Timeout:
    return httpx.Timeout(seconds, connect=min(10.0, seconds))


class _Reporter:
    """Calls a progress callback, or drives a tqdm bar (``progress=True`` or ``"tqdm"``)."""

    def __init__(self, progress: Progress):
        self.fn: Optional[Callable[[JobData], Any]] = None
        self.bar = None
        if callable(progress):
            self.fn = progress
        elif progress:
            try:
                from tqdm.auto import tqdm
            except ImportError:
                if progress == "tqdm":
                    raise
                return
            self.bar = tqdm(total=100, unit="%", bar_format="{desc} {percentage:3.0f}%|{bar}| {elapsed}")

    def __call__(self, job: JobData) -> None:
        if self.fn is not None:
            self.fn(job)
        if self.bar is not None:
            self.bar.set_description_str(f"{job.state} {job.stage}".strip())
            self.bar.n = round(100 * (1.0 if job.state == "succeeded" else job.progress))
            self.bar.refresh()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _raise_for_end(job: JobData, raise_on_failure: bool) -> None:
    if not raise_on_failure:
        return
    if job.state == "failed":
        code, msg = (job.error.code, job.error.message) if job.error else ("failed", "the job failed")
        raise JobFailed(code, msg, job=job)
    if job.state == "cancelled":
        raise JobCancelled("cancelled", f"job {job.id} was cancelled", job=job)


_END = object()


def _job_event(sse: SseParser, line: str) -> Any:
    """The job data an event-stream line completes, ``_END`` on the server's shutdown event,
    else None."""
    ev = sse.feed(line)
    if ev is None:
        return None
    name, data = ev
    if name == "job":
        return json.loads(data)
    return _END if name == "shutdown" else None


def _wanted(job_id: str, listed: Sequence[Artifact], names: Optional[Sequence[str]]) -> List[str]:
    """The artifact names to download (all, or ``names``), refused when one is not listed."""
    wanted = [a.name for a in listed] if names is None else list(names)
    known = {a.name for a in listed}
    missing = [n for n in wanted if n not in known]
    if missing:
        raise SurfmapError("artifact_not_found", f"job {job_id} has no artifact {missing[0]!r}")
    return wanted


def _spec_of(spec: Any) -> Dict[str, Any]:
    if isinstance(spec, (str, os.PathLike)) and os.path.exists(spec):
        with open(spec, encoding="utf-8") as fh:
            return json.load(fh)
    return spec_dict(spec)


class Job(JobData):
    """A job as last seen, with the client that fetched it: ``refresh``, ``wait``, ``cancel``,
    ``events``, ``artifact``, ``download``."""

    def __init__(self, client: "Client", data: Dict[str, Any]):
        super().__init__(data)
        self._client = client

    def refresh(self) -> "Job":
        self._set(self._client._json("get_job", id=self.id))
        return self

    def wait(self, timeout: Optional[float] = None, progress: Progress = None, raise_on_failure: bool = True) -> "Job":
        """Follows the job's events until it ends; raises ``JobFailed`` / ``JobCancelled``
        (unless ``raise_on_failure=False``) or ``Timeout``."""
        end = self._client.wait(self.id, timeout=timeout, progress=progress, raise_on_failure=False)
        self._set(end.raw)
        _raise_for_end(self, raise_on_failure)
        return self

    def cancel(self) -> "Job":
        self._set(self._client._json("cancel_job", id=self.id))
        return self

    def events(self) -> Iterator["Job"]:
        return self._client.events(self.id)

    @property
    def metrics(self) -> Optional[Dict[str, Any]]:
        if self.result is None and any(a.name == "metrics.json" for a in self.artifacts):
            self.result = json.loads(self.artifact("metrics.json"))
        return self.result

    def artifact(self, name: str) -> bytes:
        return self._client.artifact(self.id, name)

    def download(self, directory: Union[str, os.PathLike], names: Optional[Sequence[str]] = None) -> List[pathlib.Path]:
        """Writes the job's artifacts (all, or `names`) into `directory`; returns the paths."""
        if not self.artifacts:
            self.refresh()
        return self._client.download(self.id, directory, names=names, artifacts=self.artifacts)


class Client:
    """``Client(url, token=...)``: the service's REST API. Use as a context manager or ``close()``."""

    def __init__(self, url: str = DEFAULT_URL, token: Optional[str] = None, timeout: float = 120.0,
                 http: Optional[httpx.Client] = None):
        self.url = url.rstrip("/")
        self._http = http or httpx.Client(base_url=self.url, headers=_headers(token), timeout=_timeout(timeout))

    def close(self) -> None:
        self._http.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # Plumbing.
    def _call(self, name: str, /, *, params: Any = None, json_body: Any = None, content: Any = None,
              headers: Optional[Dict[str, str]] = None, **path: str) -> httpx.Response:
        method, p = endpoint(name, **path)
        r = self._http.request(method, p, params=params, json=json_body, content=content, headers=headers)
        if r.status_code >= 400:
            raise from_response(r.status_code, r.content, r.headers)
        return r

    def _json(self, name: str, /, **kw: Any) -> Any:
        return self._call(name, **kw).json()

    # Meshes.
    def upload(self, mesh: Any, format: Optional[str] = None) -> Mesh:
        """Uploads a mesh: a path, bytes, or ``(vertices, faces)`` arrays. The id is its sha256."""
        data, hint = mesh_input(mesh, format)
        params = {"format": hint} if hint else None
        h = {"Content-Type": "application/octet-stream"}
        return Mesh.from_json(self._json("upload_mesh", params=params, content=data, headers=h))

    def mesh(self, mesh_id: str) -> Mesh:
        return Mesh.from_json(self._json("get_mesh", id=mesh_id))

    def mesh_glb(self, mesh_id: str) -> bytes:
        """The stored mesh as binary glTF, in the file's own vertices."""
        return self._call("get_mesh_glb", id=mesh_id).content

    def _mesh_id(self, mesh: Any) -> str:
        if isinstance(mesh, Mesh):
            return mesh.id
        if is_mesh_id(mesh) and not os.path.exists(mesh):
            return mesh
        return self.upload(mesh).id

    # Jobs.
    def submit(self, source: Any = None, target: Any = None, spec: Any = None, *, meshes: Optional[Sequence[Any]] = None,
               idempotency_key: Optional[str] = None) -> Job:
        """Queues a job on `source` and `target` (or `meshes`): mesh ids, ``Mesh`` or anything
        ``upload`` takes; `spec` a dict, a ``Spec`` or a JSON file."""
        if spec is None:
            raise TypeError("submit needs a spec")
        body: Dict[str, Any] = {"spec": _spec_of(spec)}
        if meshes is not None:
            if source is not None or target is not None:
                raise TypeError("give source and target, or meshes")
            body["meshes"] = [self._mesh_id(m) for m in meshes]
        else:
            if source is None or target is None:
                raise TypeError("give source and target, or meshes")
            body["source"], body["target"] = self._mesh_id(source), self._mesh_id(target)
        h = {"Idempotency-Key": idempotency_key} if idempotency_key else None
        return Job(self, self._json("submit_job", json_body=body, headers=h))

    def map(self, source: Any, target: Any, spec: Any, *, wait: bool = False, timeout: Optional[float] = None,
            progress: Progress = None, idempotency_key: Optional[str] = None) -> Job:
        """Uploads what needs it, submits, and with ``wait=True`` follows the job to its end
        (raising ``JobFailed`` with the job's code if it fails)."""
        job = self.submit(source, target, spec, idempotency_key=idempotency_key)
        return job.wait(timeout=timeout, progress=progress) if wait else job

    def job(self, job_id: str) -> Job:
        return Job(self, self._json("get_job", id=job_id))

    def list_jobs(self, state: Optional[str] = None, method: Optional[str] = None, limit: Optional[int] = None,
                  cursor: Optional[str] = None) -> Tuple[List[Job], Optional[str]]:
        """One page, newest first, and the cursor of the next (None on the last)."""
        params = {k: v for k, v in {"state": state, "method": method, "limit": limit, "cursor": cursor}.items() if v is not None}
        page = self._json("list_jobs", params=params)
        return [Job(self, j) for j in page["jobs"]], page.get("next_cursor")

    def jobs(self, state: Optional[str] = None, method: Optional[str] = None, page_size: int = 100) -> Iterator[Job]:
        """Every job (of this token), newest first, page after page."""
        cursor = None
        while True:
            page, cursor = self.list_jobs(state, method, page_size, cursor)
            yield from page
            if not cursor:
                return

    def cancel(self, job_id: str) -> Job:
        return Job(self, self._json("cancel_job", id=job_id))

    def retry(self, job: Union[str, JobData]) -> Job:
        """Submits a job again with the same meshes and spec (a new job)."""
        j = self.job(job) if isinstance(job, str) else job
        return self.submit(meshes=j.meshes, spec=j.spec)

    def events(self, job_id: str, read_timeout: float = 60.0) -> Iterator[Job]:
        """The job each time its state, stage or progress changes (the first is the job as it
        is), until it ends or the server stops (the stream then ends: call again)."""
        method, p = endpoint("job_events", id=job_id)
        with self._http.stream(method, p, headers={"Accept": "text/event-stream"},
                               timeout=httpx.Timeout(read_timeout, connect=10.0)) as r:
            if r.status_code >= 400:
                r.read()
                raise from_response(r.status_code, r.content, r.headers)
            sse = SseParser()
            for line in r.iter_lines():
                ev = _job_event(sse, line)
                if ev is _END:
                    return
                if ev is not None:
                    yield Job(self, ev)

    def wait(self, job_id: str, timeout: Optional[float] = None, progress: Progress = None,
             raise_on_failure: bool = True) -> Job:
        """Follows the job over its event stream (reconnecting when it ends early) until it
        ends; ``progress`` is a callback taking each ``Job``, or True for a tqdm bar."""
        deadline = None if timeout is None else time.monotonic() + timeout
        report = _Reporter(progress)
        try:
            job = self.job(job_id)
            report(job)
            while not job.done:
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    raise Timeout("timeout", f"job {job_id} is still {job.state} after {timeout} s", job=job)
                try:
                    for j in self.events(job_id, read_timeout=min(60.0, left) if left else 60.0):
                        job = j
                        report(job)
                        if job.done:
                            break
                        if deadline is not None and time.monotonic() > deadline:
                            break
                except (httpx.ReadTimeout, httpx.RemoteProtocolError, httpx.ReadError):
                    pass  # a quiet or dropped stream: read the job and follow it again
                if not job.done:
                    job = self.job(job_id)
            report(job)
        finally:
            report.close()
        _raise_for_end(job, raise_on_failure)
        return job

    # Artifacts.
    def artifacts(self, job_id: str) -> List[Artifact]:
        return [Artifact.from_json(a) for a in self._json("list_artifacts", id=job_id)["artifacts"]]

    def artifact(self, job_id: str, name: str) -> bytes:
        return self._call("get_artifact", id=job_id, name=name).content

    def download(self, job_id: str, directory: Union[str, os.PathLike], names: Optional[Sequence[str]] = None,
                 artifacts: Optional[Sequence[Artifact]] = None) -> List[pathlib.Path]:
        """Writes a job's artifacts (all, or those in `names`) into `directory`."""
        out = pathlib.Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        listed = list(artifacts) if artifacts is not None else self.artifacts(job_id)
        wanted = _wanted(job_id, listed, names)
        paths = []
        for name in wanted:
            p = out / name
            method, url = endpoint("get_artifact", id=job_id, name=name)
            with self._http.stream(method, url) as r:
                if r.status_code >= 400:
                    r.read()
                    raise from_response(r.status_code, r.content, r.headers)
                with open(p, "wb") as fh:
                    for chunk in r.iter_bytes():
                        fh.write(chunk)
            paths.append(p)
        return paths

    # Operations.
    def health(self) -> Dict[str, Any]:
        return self._json("healthz")

    def ready(self) -> Dict[str, Any]:
        return self._json("readyz")

    def openapi(self) -> Dict[str, Any]:
        return self._json("openapi")

    def metrics_text(self, token: Optional[str] = None) -> str:
        """The Prometheus text of ``/metrics`` (`token`: the server's ``--metrics-token``)."""
        h = {"Authorization": f"Bearer {token}"} if token else None
        return self._call("metrics", headers=h).text
