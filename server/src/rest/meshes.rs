//! `POST /v1/meshes`: a raw body or a multipart file part.

use super::extract::{Owner, P, Q, is_multipart, multipart_error, read_limited, reserve_upload};
use crate::AppState;
use crate::error::{ApiError, ErrorBody};
use crate::service::format_hint;
use crate::views::MeshView;
use axum::Json;
use axum::extract::{FromRequest, Multipart, Request, State};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};

/// `?format=` for content that is ambiguous.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct FormatQuery {
    /// obj, off, ply or stl; only used when the content does not tell.
    #[param(pattern = "^(obj|off|ply|stl)$")]
    pub format: Option<String>,
}

/// A mesh file's bytes, as the OpenAPI document describes an upload body.
#[derive(utoipa::ToSchema)]
#[schema(value_type = String, format = Binary)]
pub struct MeshBytes(#[allow(dead_code)] Vec<u8>);

/// The first file part of a multipart body and the format its file name suggests.
pub async fn first_file(mut mp: Multipart) -> Result<(Vec<u8>, Option<&'static str>), ApiError> {
    while let Some(field) = mp.next_field().await.map_err(multipart_error)? {
        let hint = format_hint(field.file_name());
        if matches!(field.name(), Some("file" | "mesh")) || field.file_name().is_some() {
            let bytes = field.bytes().await.map_err(multipart_error)?;
            return Ok((bytes.to_vec(), hint));
        }
    }
    Err(ApiError::bad_request("invalid_multipart", "no file part (name it \"file\")"))
}

/// Uploads one mesh (OBJ, OFF, PLY or STL); returns its content address and summary.
#[utoipa::path(post, path = "/v1/meshes", tag = "meshes", params(FormatQuery),
    request_body(content = MeshBytes, content_type = "application/octet-stream", description = "mesh bytes, or multipart with a `file` part"),
    responses((status = 400, description = "an unknown `format`", body = ErrorBody), (status = 201, description = "stored (or already stored: the id is the content's sha256)", body = MeshView), (status = 413, description = "body or mesh over the limits", body = ErrorBody), (status = 429, description = "concurrent uploads hold the upload memory; see Retry-After", body = ErrorBody), (status = 422, description = "invalid mesh", body = ErrorBody)))]
pub async fn upload_mesh(
    State(st): State<AppState>,
    Owner(owner): Owner,
    Q(q): Q<FormatQuery>,
    req: Request,
) -> Result<(StatusCode, Json<MeshView>), ApiError> {
    let _held = reserve_upload(&st, req.headers())?;
    let (bytes, ext) = if is_multipart(req.headers()) {
        let mp = Multipart::from_request(req, &st)
            .await
            .map_err(|e| ApiError::bad_request("invalid_multipart", e.body_text()))?;
        first_file(mp).await?
    } else {
        let (parts, body) = req.into_parts();
        (read_limited(&parts.headers, body, st.service.limits.max_body_bytes).await?.to_vec(), None)
    };
    if let Some(f) = q.format.as_deref().filter(|f| !["obj", "off", "ply", "stl"].contains(f)) {
        return Err(ApiError::bad_request("unknown_format", format!("format {f:?} is not obj, off, ply or stl")));
    }
    let hint = q.format.as_deref().or(ext);
    let view = st.service.upload_mesh(&owner, bytes, hint).await?;
    Ok((StatusCode::CREATED, Json(view)))
}

/// An uploaded mesh's id, format, size and summary.
#[utoipa::path(get, path = "/v1/meshes/{id}", tag = "meshes", params(("id" = String, Path, pattern = "^[0-9a-f]{64}$")),
    responses((status = 200, description = "the mesh", body = MeshView), (status = 400, description = "not a mesh id", body = ErrorBody),
        (status = 404, description = "unknown mesh", body = ErrorBody)))]
pub async fn get_mesh(
    State(st): State<AppState>,
    Owner(owner): Owner,
    P(id): P<String>,
) -> Result<Json<MeshView>, ApiError> {
    let rec = st.service.mesh(&owner, &id).await?;
    let summary = serde_json::from_str(&rec.summary).unwrap_or(serde_json::Value::Null);
    Ok(Json(MeshView { id: rec.id, format: rec.format, size_bytes: rec.size_bytes, summary, warnings: Vec::new() }))
}

/// The mesh as binary glTF (`model/gltf-binary`) in the file's own vertices, so a spec's
/// vertex ids index it (for viewers such as the dashboard's).
#[utoipa::path(get, path = "/v1/meshes/{id}/glb", tag = "meshes", params(("id" = String, Path, pattern = "^[0-9a-f]{64}$")),
    responses((status = 200, content_type = "model/gltf-binary", description = "the mesh as glTF 2.0 binary"),
        (status = 400, description = "not a mesh id", body = ErrorBody), (status = 404, description = "unknown mesh", body = ErrorBody)))]
pub async fn get_mesh_glb(
    State(st): State<AppState>,
    Owner(owner): Owner,
    P(id): P<String>,
) -> Result<Response, ApiError> {
    let glb = st.service.mesh_glb(&owner, &id).await?;
    Ok(([(header::CONTENT_TYPE, "model/gltf-binary")], glb).into_response())
}
