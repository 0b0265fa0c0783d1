//! tonic answers a request body that is not a protobuf message of its type with INTERNAL and
//! no error code (its codec decodes before any handler runs). This response map turns that
//! answer into what every other bad request gets: INVALID_ARGUMENT with `surfmap-error-code`.

use axum::http::HeaderValue;
use axum::response::Response;

/// The code a client sees for undecodable request bytes.
pub const CODE: &str = "invalid_message";

/// Rewrites tonic's decode failure (a trailers-only answer: the status is in the headers).
pub async fn decode_failure_is_invalid_argument(mut res: Response) -> Response {
    let h = res.headers();
    let internal = h.get("grpc-status").is_some_and(|v| v == "13");
    let message = h.get("grpc-message").and_then(|v| v.to_str().ok()).unwrap_or("").replace("%20", " ");
    if internal && message.starts_with("failed to decode Protobuf message") {
        let h = res.headers_mut();
        h.insert("grpc-status", HeaderValue::from_static("3"));
        h.insert("surfmap-error-code", HeaderValue::from_static(CODE));
        metrics::counter!("surfmap_requests_rejected_total", "code" => CODE).increment(1);
    }
    res
}
