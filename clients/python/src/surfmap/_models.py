"""The service's JSON shapes as the client reads them. Field lists follow the OpenAPI document's
schemas (``MeshView``, ``JobView``, ``ArtifactView``, ``JobPage``, ``ErrorBody``); the client's
tests check every field read here against ``/openapi.json``."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional

TERMINAL = frozenset({"succeeded", "failed", "cancelled"})

# OpenAPI schema -> the properties this client reads (checked against the server's document).
FIELDS_READ: Dict[str, List[str]] = {
    "MeshView": ["id", "format", "size_bytes", "summary", "warnings"],
    "ArtifactView": ["name", "content_type", "size", "sha256", "url"],
    "JobView": ["id", "state", "stage", "progress", "attempts", "max_attempts", "method", "spec", "meshes",
                "source", "target", "cancel_requested", "worker", "created_at_ms", "updated_at_ms",
                "started_at_ms", "finished_at_ms", "error", "result", "artifacts", "links"],
    "JobLinks": ["self", "events", "artifacts", "cancel"],
    "JobPage": ["jobs", "next_cursor"],
    "ArtifactList": ["artifacts"],
    "ErrorBody": ["code", "message"],
}


@dataclass
class Spec:
    """A job spec (the README's): ``method``, ``anchors``, optional ``features`` and ``options``."""

    method: str
    anchors: List[Any] = field(default_factory=list)
    options: Optional[Dict[str, Any]] = None
    features: Optional[List[Any]] = None

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {"method": self.method, "anchors": list(self.anchors)}
        if self.features is not None:
            d["features"] = self.features
        if self.options is not None:
            d["options"] = self.options
        return d


def spec_dict(spec: Any) -> Dict[str, Any]:
    if isinstance(spec, Spec):
        return spec.to_dict()
    if isinstance(spec, dict):
        return spec
    raise TypeError(f"a spec is a dict or a surfmap.Spec, not {type(spec).__name__}")


@dataclass
class Mesh:
    id: str
    format: str
    size_bytes: int
    summary: Dict[str, Any]
    warnings: List[str]

    @classmethod
    def from_json(cls, d: Dict[str, Any]) -> "Mesh":
        return cls(d["id"], d["format"], d["size_bytes"], d.get("summary") or {}, list(d.get("warnings") or []))


@dataclass
class Artifact:
    name: str
    content_type: str
    size: int
    sha256: str
    url: str

    @classmethod
    def from_json(cls, d: Dict[str, Any]) -> "Artifact":
        return cls(d["name"], d["content_type"], d["size"], d["sha256"], d["url"])


@dataclass
class JobError:
    code: str
    message: str


class JobData:
    """The fields of a ``JobView``, as attributes; ``raw`` is the JSON."""

    def __init__(self, d: Dict[str, Any]):
        self._set(d)

    def _set(self, d: Dict[str, Any]) -> None:
        self.raw = d
        self.id: str = d["id"]
        self.state: str = d["state"]
        self.stage: str = d.get("stage") or ""
        self.progress: float = float(d.get("progress") or 0.0)
        self.attempts: int = d.get("attempts", 0)
        self.max_attempts: int = d.get("max_attempts", 0)
        self.method: str = d.get("method", "")
        self.spec: Dict[str, Any] = d.get("spec") or {}
        self.meshes: List[str] = list(d.get("meshes") or [])
        self.source: str = d.get("source", "")
        self.target: str = d.get("target", "")
        self.cancel_requested: bool = bool(d.get("cancel_requested"))
        self.worker: Optional[str] = d.get("worker")
        self.created_at_ms: int = d.get("created_at_ms", 0)
        self.updated_at_ms: int = d.get("updated_at_ms", 0)
        self.started_at_ms: Optional[int] = d.get("started_at_ms")
        self.finished_at_ms: Optional[int] = d.get("finished_at_ms")
        e = d.get("error")
        self.error: Optional[JobError] = JobError(e["code"], e.get("message", "")) if e else None
        self.result: Optional[Dict[str, Any]] = d.get("result")
        self.artifacts: List[Artifact] = [Artifact.from_json(a) for a in d.get("artifacts") or []]
        self.links: Dict[str, str] = dict(d.get("links") or {})

    @property
    def done(self) -> bool:
        return self.state in TERMINAL

    @property
    def metrics(self) -> Optional[Dict[str, Any]]:
        """The metrics report of a succeeded job (``metrics.json``)."""
        return self.result

    def __repr__(self) -> str:
        extra = f", error={self.error.code!r}" if self.error else ""
        return f"Job(id={self.id!r}, state={self.state!r}, stage={self.stage!r}, progress={self.progress:.2f}{extra})"


class SseParser:
    """Server-sent events, a line at a time: ``feed(line)`` returns ``(event, data)`` at the
    blank line that ends an event, else None."""

    def __init__(self) -> None:
        self.name, self.data = "message", []

    def feed(self, line: str):
        line = line.rstrip("\r\n")
        if not line:
            out = (self.name, "\n".join(self.data)) if self.data else None
            self.name, self.data = "message", []
            return out
        if line.startswith(":"):
            return None
        if line.startswith("event:"):
            self.name = line[6:].strip()
        elif line.startswith("data:"):
            v = line[5:]
            self.data.append(v[1:] if v.startswith(" ") else v)
        return None
