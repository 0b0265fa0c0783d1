"""The client follows the server's OpenAPI document: every route it calls is there with that
method, and every field its models read is a property of the schema it reads it from."""

from __future__ import annotations

import httpx

import surfmap


def resolve(doc, schema):
    while "$ref" in schema:
        name = schema["$ref"].rsplit("/", 1)[-1]
        schema = doc["components"]["schemas"][name]
    return schema


def test_every_route_the_client_calls_is_documented(server):
    doc = httpx.get(f"{server.url}/openapi.json").json()
    for name, (method, path) in surfmap.ENDPOINTS.items():
        assert path in doc["paths"], f"{name}: {path} is not in the OpenAPI document"
        assert method in doc["paths"][path], f"{name}: {method.upper()} {path} is not in the OpenAPI document"
    # And the other way: the client covers every route of the document.
    covered = {(m, p) for m, p in surfmap.ENDPOINTS.values()}
    for path, item in doc["paths"].items():
        for method in item:
            if method in ("get", "post", "put", "patch", "delete"):
                assert (method, path) in covered, f"{method.upper()} {path} has no client call"


def test_every_field_the_models_read_is_in_its_schema(server):
    doc = httpx.get(f"{server.url}/openapi.json").json()
    schemas = doc["components"]["schemas"]
    for schema, fields in surfmap.FIELDS_READ.items():
        props = resolve(doc, schemas[schema]).get("properties", {})
        for f in fields:
            assert f in props, f"{schema}.{f} is read by the client but not in the document"
    # The models read what the server requires of a job view.
    required = set(schemas["JobView"].get("required", []))
    assert required <= set(surfmap.FIELDS_READ["JobView"]), required - set(surfmap.FIELDS_READ["JobView"])
    # The list filters the client passes are the documented query parameters.
    params = {p["name"] for p in doc["paths"]["/v1/jobs"]["get"]["parameters"]}
    assert {"state", "method", "limit", "cursor"} <= params
    upload = {p["name"] for p in doc["paths"]["/v1/meshes"]["post"].get("parameters", [])}
    assert "format" in upload
