//! `ApiError`: every failure a client can see, with its HTTP status, a stable snake_case code
//! and a message; rendered as `{code, message}` JSON over REST and as a status over gRPC.

use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::Serialize;
use surfmap_store::StoreError;

/// A client-visible error.
#[derive(Debug, Clone)]
pub struct ApiError {
    pub status: StatusCode,
    pub code: String,
    pub message: String,
    /// Seconds for a `Retry-After` header (429, 503).
    pub retry_after_secs: Option<u64>,
}

/// The JSON body of every error response.
#[derive(Debug, Serialize, serde::Deserialize, utoipa::ToSchema)]
pub struct ErrorBody {
    pub code: String,
    pub message: String,
}

impl ApiError {
    pub fn new(status: StatusCode, code: &str, message: impl Into<String>) -> ApiError {
        ApiError { status, code: code.to_string(), message: message.into(), retry_after_secs: None }
    }
    /// 429: a shared budget is spent for now.
    pub fn busy(code: &str, message: impl Into<String>, retry_after_secs: u64) -> ApiError {
        ApiError { retry_after_secs: Some(retry_after_secs), ..Self::new(StatusCode::TOO_MANY_REQUESTS, code, message) }
    }
    pub fn bad_request(code: &str, message: impl Into<String>) -> ApiError {
        Self::new(StatusCode::BAD_REQUEST, code, message)
    }
    pub fn not_found(code: &str, message: impl Into<String>) -> ApiError {
        Self::new(StatusCode::NOT_FOUND, code, message)
    }
    pub fn too_large(message: impl Into<String>) -> ApiError {
        Self::new(StatusCode::PAYLOAD_TOO_LARGE, "payload_too_large", message)
    }
    pub fn unauthorized() -> ApiError {
        Self::new(StatusCode::UNAUTHORIZED, "unauthorized", "missing or unknown bearer token")
    }
    pub fn internal(what: impl std::fmt::Display) -> ApiError {
        tracing::error!("internal error: {what}");
        Self::new(StatusCode::INTERNAL_SERVER_ERROR, "internal", "internal error (logged on the server)")
    }
}

impl From<geom::Error> for ApiError {
    fn from(e: geom::Error) -> ApiError {
        match &e {
            geom::Error::Input(geom::InputError::Spec(_) | geom::InputError::UnknownMethod(_)) => {
                Self::bad_request(e.code(), e.to_string())
            }
            geom::Error::Input(geom::InputError::TooLarge { .. }) => {
                Self::new(StatusCode::PAYLOAD_TOO_LARGE, e.code(), e.to_string())
            }
            geom::Error::Input(_) | geom::Error::Numerical(_) | geom::Error::MapFolds { .. } => {
                Self::new(StatusCode::UNPROCESSABLE_ENTITY, e.code(), e.to_string())
            }
            geom::Error::Cancelled => Self::new(StatusCode::CONFLICT, "cancelled", "cancelled"),
            geom::Error::Internal(m) => Self::internal(m),
        }
    }
}

impl From<StoreError> for ApiError {
    fn from(e: StoreError) -> ApiError {
        match e {
            StoreError::IdempotencyConflict => Self::new(
                StatusCode::CONFLICT,
                "idempotency_conflict",
                "this Idempotency-Key was used for a different request",
            ),
            other => {
                tracing::error!("store error: {other}");
                Self::new(StatusCode::SERVICE_UNAVAILABLE, "store_unavailable", "the job store is unavailable; retry")
            }
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        metrics::counter!("surfmap_requests_rejected_total", "code" => self.code.clone()).increment(1);
        let retry = self.retry_after_secs;
        let mut r = (self.status, axum::Json(ErrorBody { code: self.code, message: self.message })).into_response();
        if let Some(v) = retry.and_then(|s| axum::http::HeaderValue::from_str(&s.to_string()).ok()) {
            r.headers_mut().insert(axum::http::header::RETRY_AFTER, v);
        }
        r
    }
}

impl From<ApiError> for tonic::Status {
    fn from(e: ApiError) -> tonic::Status {
        use tonic::Code;
        let code = match e.status {
            StatusCode::BAD_REQUEST | StatusCode::UNPROCESSABLE_ENTITY => Code::InvalidArgument,
            StatusCode::NOT_FOUND => Code::NotFound,
            StatusCode::UNAUTHORIZED => Code::Unauthenticated,
            StatusCode::FORBIDDEN => Code::PermissionDenied,
            StatusCode::CONFLICT => Code::AlreadyExists,
            StatusCode::PAYLOAD_TOO_LARGE | StatusCode::TOO_MANY_REQUESTS => Code::ResourceExhausted,
            StatusCode::SERVICE_UNAVAILABLE => Code::Unavailable,
            _ => Code::Internal,
        };
        let mut s = tonic::Status::new(code, e.message);
        if let Ok(v) = e.code.parse() {
            s.metadata_mut().insert("surfmap-error-code", v);
        }
        s
    }
}
