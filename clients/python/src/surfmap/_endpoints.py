"""Every route the client calls, as (method, path template) in the OpenAPI document's
spelling; the tests check each against ``/openapi.json`` so the two cannot drift."""

ENDPOINTS = {
    "upload_mesh": ("post", "/v1/meshes"),
    "get_mesh": ("get", "/v1/meshes/{id}"),
    "get_mesh_glb": ("get", "/v1/meshes/{id}/glb"),
    "submit_job": ("post", "/v1/jobs"),
    "list_jobs": ("get", "/v1/jobs"),
    "get_job": ("get", "/v1/jobs/{id}"),
    "cancel_job": ("post", "/v1/jobs/{id}/cancel"),
    "job_events": ("get", "/v1/jobs/{id}/events"),
    "list_artifacts": ("get", "/v1/jobs/{id}/artifacts"),
    "get_artifact": ("get", "/v1/jobs/{id}/artifacts/{name}"),
    "healthz": ("get", "/healthz"),
    "readyz": ("get", "/readyz"),
    "metrics": ("get", "/metrics"),
    "openapi": ("get", "/openapi.json"),
}


def path(endpoint: str, /, **params: str) -> tuple:
    """(METHOD, path) of an endpoint with its parameters filled in (URL-quoted)."""
    from urllib.parse import quote

    method, template = ENDPOINTS[endpoint]
    return method.upper(), template.format(**{k: quote(str(v), safe="") for k, v in params.items()})
