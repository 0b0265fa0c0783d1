"""The asynchronous client (``AsyncClient``) and ``AsyncJob``: the same calls as coroutines."""

from __future__ import annotations

import asyncio
import os
import pathlib
import time
from typing import Any, AsyncIterator, Dict, List, Optional, Sequence, Tuple, Union

import httpx

from ._client import (DEFAULT_URL, _END, Progress, _headers, _job_event, _raise_for_end, _Reporter, _spec_of,
                      _timeout, _wanted)
from ._endpoints import path as endpoint
from ._errors import Timeout, from_response
from ._mesh import is_mesh_id, mesh_input
from ._models import Artifact, JobData, Mesh, SseParser


class AsyncJob(JobData):
    def __init__(self, client: "AsyncClient", data: Dict[str, Any]):
        super().__init__(data)
        self._client = client

    async def refresh(self) -> "AsyncJob":
        self._set(await self._client._json("get_job", id=self.id))
        return self

    async def wait(self, timeout: Optional[float] = None, progress: Progress = None,
                   raise_on_failure: bool = True) -> "AsyncJob":
        end = await self._client.wait(self.id, timeout=timeout, progress=progress, raise_on_failure=False)
        self._set(end.raw)
        _raise_for_end(self, raise_on_failure)
        return self

    async def cancel(self) -> "AsyncJob":
        self._set(await self._client._json("cancel_job", id=self.id))
        return self

    def events(self) -> AsyncIterator["AsyncJob"]:
        return self._client.events(self.id)

    async def artifact(self, name: str) -> bytes:
        return await self._client.artifact(self.id, name)

    async def download(self, directory: Union[str, os.PathLike], names: Optional[Sequence[str]] = None) -> List[pathlib.Path]:
        if not self.artifacts:
            await self.refresh()
        return await self._client.download(self.id, directory, names=names, artifacts=self.artifacts)


class AsyncClient:
    """``async with AsyncClient(url, token=...) as c:`` the same methods as ``Client``, awaited."""

    def __init__(self, url: str = DEFAULT_URL, token: Optional[str] = None, timeout: float = 120.0,
                 http: Optional[httpx.AsyncClient] = None):
        self.url = url.rstrip("/")
        self._http = http or httpx.AsyncClient(base_url=self.url, headers=_headers(token), timeout=_timeout(timeout))

    async def aclose(self) -> None:
        await self._http.aclose()

    async def __aenter__(self) -> "AsyncClient":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        await self.aclose()

    async def _call(self, name: str, /, *, params: Any = None, json_body: Any = None, content: Any = None,
                    headers: Optional[Dict[str, str]] = None, **path: str) -> httpx.Response:
        method, p = endpoint(name, **path)
        r = await self._http.request(method, p, params=params, json=json_body, content=content, headers=headers)
        if r.status_code >= 400:
            raise from_response(r.status_code, r.content, r.headers)
        return r

    async def _json(self, name: str, /, **kw: Any) -> Any:
        return (await self._call(name, **kw)).json()

    async def upload(self, mesh: Any, format: Optional[str] = None) -> Mesh:
        data, hint = await asyncio.to_thread(mesh_input, mesh, format)
        params = {"format": hint} if hint else None
        h = {"Content-Type": "application/octet-stream"}
        return Mesh.from_json(await self._json("upload_mesh", params=params, content=data, headers=h))

    async def mesh(self, mesh_id: str) -> Mesh:
        return Mesh.from_json(await self._json("get_mesh", id=mesh_id))

    async def mesh_glb(self, mesh_id: str) -> bytes:
        return (await self._call("get_mesh_glb", id=mesh_id)).content

    async def _mesh_id(self, mesh: Any) -> str:
        if isinstance(mesh, Mesh):
            return mesh.id
        if is_mesh_id(mesh) and not os.path.exists(mesh):
            return mesh
        return (await self.upload(mesh)).id

    async def submit(self, source: Any = None, target: Any = None, spec: Any = None, *,
                     meshes: Optional[Sequence[Any]] = None, idempotency_key: Optional[str] = None) -> AsyncJob:
        if spec is None:
            raise TypeError("submit needs a spec")
        body: Dict[str, Any] = {"spec": _spec_of(spec)}
        if meshes is not None:
            if source is not None or target is not None:
                raise TypeError("give source and target, or meshes")
            body["meshes"] = [await self._mesh_id(m) for m in meshes]
        else:
            if source is None or target is None:
                raise TypeError("give source and target, or meshes")
            body["source"], body["target"] = await self._mesh_id(source), await self._mesh_id(target)
        h = {"Idempotency-Key": idempotency_key} if idempotency_key else None
        return AsyncJob(self, await self._json("submit_job", json_body=body, headers=h))

    async def map(self, source: Any, target: Any, spec: Any, *, wait: bool = False, timeout: Optional[float] = None,
                  progress: Progress = None, idempotency_key: Optional[str] = None) -> AsyncJob:
        job = await self.submit(source, target, spec, idempotency_key=idempotency_key)
        return await job.wait(timeout=timeout, progress=progress) if wait else job

    async def job(self, job_id: str) -> AsyncJob:
        return AsyncJob(self, await self._json("get_job", id=job_id))

    async def list_jobs(self, state: Optional[str] = None, method: Optional[str] = None, limit: Optional[int] = None,
                        cursor: Optional[str] = None) -> Tuple[List[AsyncJob], Optional[str]]:
        params = {k: v for k, v in {"state": state, "method": method, "limit": limit, "cursor": cursor}.items() if v is not None}
        page = await self._json("list_jobs", params=params)
        return [AsyncJob(self, j) for j in page["jobs"]], page.get("next_cursor")

    async def jobs(self, state: Optional[str] = None, method: Optional[str] = None,
                   page_size: int = 100) -> AsyncIterator[AsyncJob]:
        cursor = None
        while True:
            page, cursor = await self.list_jobs(state, method, page_size, cursor)
            for j in page:
                yield j
            if not cursor:
                return

    async def cancel(self, job_id: str) -> AsyncJob:
        return AsyncJob(self, await self._json("cancel_job", id=job_id))

    async def retry(self, job: Union[str, JobData]) -> AsyncJob:
        j = await self.job(job) if isinstance(job, str) else job
        return await self.submit(meshes=j.meshes, spec=j.spec)

    async def events(self, job_id: str, read_timeout: float = 60.0) -> AsyncIterator[AsyncJob]:
        method, p = endpoint("job_events", id=job_id)
        async with self._http.stream(method, p, headers={"Accept": "text/event-stream"},
                                     timeout=httpx.Timeout(read_timeout, connect=10.0)) as r:
            if r.status_code >= 400:
                await r.aread()
                raise from_response(r.status_code, r.content, r.headers)
            sse = SseParser()
            async for line in r.aiter_lines():
                ev = _job_event(sse, line)
                if ev is _END:
                    return
                if ev is not None:
                    yield AsyncJob(self, ev)

    async def wait(self, job_id: str, timeout: Optional[float] = None, progress: Progress = None,
                   raise_on_failure: bool = True) -> AsyncJob:
        deadline = None if timeout is None else time.monotonic() + timeout
        report = _Reporter(progress)
        try:
            job = await self.job(job_id)
            report(job)
            while not job.done:
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    raise Timeout("timeout", f"job {job_id} is still {job.state} after {timeout} s", job=job)
                try:
                    stream = self.events(job_id, read_timeout=min(60.0, left) if left else 60.0)
                    async for j in stream:
                        job = j
                        report(job)
                        if job.done or (deadline is not None and time.monotonic() > deadline):
                            break
                    await stream.aclose()
                except (httpx.ReadTimeout, httpx.RemoteProtocolError, httpx.ReadError):
                    pass  # a quiet or dropped stream: read the job and follow it again
                if not job.done:
                    job = await self.job(job_id)
            report(job)
        finally:
            report.close()
        _raise_for_end(job, raise_on_failure)
        return job

    async def artifacts(self, job_id: str) -> List[Artifact]:
        return [Artifact.from_json(a) for a in (await self._json("list_artifacts", id=job_id))["artifacts"]]

    async def artifact(self, job_id: str, name: str) -> bytes:
        return (await self._call("get_artifact", id=job_id, name=name)).content

    async def download(self, job_id: str, directory: Union[str, os.PathLike], names: Optional[Sequence[str]] = None,
                       artifacts: Optional[Sequence[Artifact]] = None) -> List[pathlib.Path]:
        out = pathlib.Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        listed = list(artifacts) if artifacts is not None else await self.artifacts(job_id)
        wanted = _wanted(job_id, listed, names)
        paths = []
        for name in wanted:
            p = out / name
            p.write_bytes(await self.artifact(job_id, name))
            paths.append(p)
        return paths

    async def health(self) -> Dict[str, Any]:
        return await self._json("healthz")

    async def ready(self) -> Dict[str, Any]:
        return await self._json("readyz")

    async def openapi(self) -> Dict[str, Any]:
        return await self._json("openapi")

    async def metrics_text(self, token: Optional[str] = None) -> str:
        h = {"Authorization": f"Bearer {token}"} if token else None
        return (await self._call("metrics", headers=h)).text
