"""surfmap: a client of the surfmap service (REST).

    from surfmap import Client
    c = Client("http://localhost:8080", token=None)
    job = c.map("a.obj", "b.obj", {"method": "voronoi", "anchors": [[0, 0], [5, 9], [11, 30]]}, wait=True)
    job.download("out/")
"""

from ._async import AsyncClient, AsyncJob
from ._client import Client, Job
from ._endpoints import ENDPOINTS
from ._errors import (
    BadRequest,
    Conflict,
    JobCancelled,
    JobFailed,
    NotFound,
    PayloadTooLarge,
    ServerError,
    SurfmapError,
    Timeout,
    TooManyRequests,
    Unauthorized,
    Unprocessable,
)
from ._models import FIELDS_READ, TERMINAL, Artifact, JobError, Mesh, Spec

__version__ = "0.1.0"
__all__ = [
    "AsyncClient", "AsyncJob", "Client", "Job", "Spec", "Mesh", "Artifact", "JobError", "ENDPOINTS", "FIELDS_READ",
    "TERMINAL", "SurfmapError", "BadRequest", "Unauthorized", "NotFound", "Conflict", "PayloadTooLarge",
    "Unprocessable", "TooManyRequests", "ServerError", "JobFailed", "JobCancelled", "Timeout",
]
