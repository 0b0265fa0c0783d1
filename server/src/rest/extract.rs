//! What the REST handlers share: the owner extractor, `Query` and `Path` with JSON rejections,
//! limited body reading and the upload reservation, multipart checks and errors.

use crate::AppState;
use crate::error::ApiError;
use axum::body::{Body, Bytes};
use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{HeaderMap, header};

/// The client's owner id (see `auth`).
pub struct Owner(pub String);

impl FromRequestParts<AppState> for Owner {
    type Rejection = ApiError;
    async fn from_request_parts(parts: &mut Parts, st: &AppState) -> Result<Self, ApiError> {
        let h = parts.headers.get(header::AUTHORIZATION).and_then(|v| v.to_str().ok());
        st.auth.owner(h).map(Owner)
    }
}

/// `Query` with a JSON rejection.
pub struct Q<T>(pub T);

impl<T: serde::de::DeserializeOwned + Send, S: Send + Sync> FromRequestParts<S> for Q<T> {
    type Rejection = ApiError;
    async fn from_request_parts(parts: &mut Parts, st: &S) -> Result<Self, ApiError> {
        axum::extract::Query::<T>::from_request_parts(parts, st)
            .await
            .map(|q| Q(q.0))
            .map_err(|e| ApiError::bad_request("invalid_query", e.body_text()))
    }
}

/// `Path` with a JSON rejection.
pub struct P<T>(pub T);

impl<T: serde::de::DeserializeOwned + Send, S: Send + Sync> FromRequestParts<S> for P<T> {
    type Rejection = ApiError;
    async fn from_request_parts(parts: &mut Parts, st: &S) -> Result<Self, ApiError> {
        axum::extract::Path::<T>::from_request_parts(parts, st)
            .await
            .map(|p| P(p.0))
            .map_err(|e| ApiError::bad_request("invalid_path", e.body_text()))
    }
}

/// Refuses a declared length over `limit` at once, then reads at most `limit` bytes.
///
/// # Errors
/// 413 `payload_too_large`.
pub async fn read_limited(headers: &HeaderMap, body: Body, limit: usize) -> Result<Bytes, ApiError> {
    let declared = declared_length(headers);
    if declared.is_some_and(|n| n > limit) {
        return Err(ApiError::too_large(format!(
            "request body of {} bytes exceeds the limit of {limit}",
            declared.unwrap_or(0)
        )));
    }
    axum::body::to_bytes(body, limit)
        .await
        .map_err(|e| ApiError::too_large(format!("request body exceeds the limit of {limit} bytes ({e})")))
}

/// The body length a request declares (`Content-Length`), if any.
pub fn declared_length(headers: &HeaderMap) -> Option<usize> {
    headers.get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()).and_then(|v| v.parse().ok())
}

/// Reserves the upload memory a request's body may take (its declared length, or the body
/// limit when it declares none) before the body is read.
///
/// # Errors
/// 429 `uploads_busy` when concurrent uploads hold the budget.
pub fn reserve_upload(
    st: &crate::AppState,
    headers: &HeaderMap,
) -> Result<tokio::sync::OwnedSemaphorePermit, ApiError> {
    let limit = st.service.limits.max_body_bytes;
    st.service.limits.uploads.reserve(declared_length(headers).unwrap_or(limit).min(limit))
}

/// True for a `multipart/form-data` request.
pub fn is_multipart(headers: &HeaderMap) -> bool {
    headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.starts_with("multipart/form-data"))
}

/// Multipart errors as JSON (413 when over the body limit).
pub fn multipart_error(e: axum::extract::multipart::MultipartError) -> ApiError {
    let status = e.status();
    if status == axum::http::StatusCode::PAYLOAD_TOO_LARGE {
        ApiError::too_large(e.body_text())
    } else {
        ApiError::bad_request("invalid_multipart", e.body_text())
    }
}
