"""Typed errors: every REST error is JSON ``{code, message}``; ``.code`` is the service's code."""

from __future__ import annotations

from typing import Any, Optional


class SurfmapError(Exception):
    """An error the service answered (or a job's error), with its stable snake_case ``code``."""

    def __init__(self, code: str, message: str, status: Optional[int] = None, job: Any = None):
        super().__init__(f"{code}: {message}" if status is None else f"{status} {code}: {message}")
        self.code = code
        self.message = message
        self.status = status
        self.job = job


class BadRequest(SurfmapError):
    """400: a bad spec, query, id or body."""


class Unauthorized(SurfmapError):
    """401: a missing or unknown bearer token."""


class NotFound(SurfmapError):
    """404: an unknown job, mesh, artifact or route (or another tenant's)."""


class Conflict(SurfmapError):
    """409: an idempotency key reused for another request."""


class PayloadTooLarge(SurfmapError):
    """413: a body or mesh over the server's limits."""


class Unprocessable(SurfmapError):
    """422: an invalid mesh, anchors, an option out of range, over the memory budget."""


class TooManyRequests(SurfmapError):
    """429: a shared budget is spent; ``retry_after`` seconds."""

    retry_after: Optional[float] = None


class ServerError(SurfmapError):
    """5xx: the store is unavailable, or an internal error."""


class JobFailed(SurfmapError):
    """A job that ended ``failed``; ``.code`` is the job's error code, ``.job`` the job."""


class JobCancelled(SurfmapError):
    """A job that ended ``cancelled`` while it was waited for."""


class Timeout(SurfmapError):
    """A wait that ran out of time; ``.job`` is the job as last seen."""


_BY_STATUS = {400: BadRequest, 401: Unauthorized, 404: NotFound, 405: BadRequest, 409: Conflict,
              413: PayloadTooLarge, 422: Unprocessable, 429: TooManyRequests}


def from_response(status: int, body: bytes, headers: Any = None) -> SurfmapError:
    """The error of a non-2xx answer."""
    import json

    try:
        data = json.loads(body)
        code, message = str(data["code"]), str(data.get("message", ""))
    except (ValueError, KeyError, TypeError):
        code, message = f"http_{status}", body[:200].decode("utf-8", "replace")
    cls = _BY_STATUS.get(status, ServerError if status >= 500 else SurfmapError)
    err = cls(code, message, status)
    if isinstance(err, TooManyRequests) and headers is not None:
        try:
            err.retry_after = float(headers.get("retry-after"))
        except (TypeError, ValueError):
            pass
    return err
