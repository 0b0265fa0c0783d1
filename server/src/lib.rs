//! The job server: axum REST and tonic gRPC served on one port, two thin faces over one
//! [`service::JobService`]; plus the janitor that requeues expired leases. The binary also runs
//! in-process workers (`surfmap_worker`).

pub mod auth;
pub mod error;
pub mod grpc;
pub mod grpc_decode;
pub mod openapi;
pub mod rest;
pub mod serve;
pub mod service;
pub mod stopping;
pub mod ui;
pub mod views;

use std::time::Duration;
use surfmap_proto::v1::surfmap_server::SurfmapServer;

/// What every handler shares.
#[derive(Debug, Clone)]
pub struct AppState {
    pub service: service::JobService,
    pub auth: auth::Auth,
}

/// REST and gRPC (with health and reflection) on one router.
pub fn app(state: AppState) -> axum::Router {
    surfmap_worker::telemetry::prometheus();
    let limit = state.service.limits.max_body_bytes;
    let grpc = SurfmapServer::new(grpc::GrpcApi { state: state.clone() })
        .max_decoding_message_size(limit)
        .max_encoding_message_size(limit);
    let (reporter, health) = tonic_health::server::health_reporter();
    tokio::spawn(async move { reporter.set_serving::<SurfmapServer<grpc::GrpcApi>>().await });
    let mut routes = tonic::service::Routes::new(grpc).add_service(health);
    // Reflection in both versions clients speak (grpcurl and most tools: v1; older ones:
    // v1alpha), describing this API and `grpc.health.v1`.
    let reflection = || {
        tonic_reflection::server::Builder::configure()
            .register_encoded_file_descriptor_set(surfmap_proto::FILE_DESCRIPTOR_SET)
            .register_encoded_file_descriptor_set(tonic_health::pb::FILE_DESCRIPTOR_SET)
    };
    match (reflection().build_v1(), reflection().build_v1alpha()) {
        (Ok(v1), Ok(v1alpha)) => routes = routes.add_service(v1).add_service(v1alpha),
        (Err(e), _) | (_, Err(e)) => tracing::warn!("gRPC reflection unavailable: {e}"),
    }
    // tonic's router brings a fallback (gRPC `unimplemented`); replace it with the JSON 404
    // so the merged router has exactly one.
    let grpc = routes
        .into_axum_router()
        .layer(axum::middleware::map_response(grpc_decode::decode_failure_is_invalid_argument));
    rest::router(state.clone()).merge(ui::router(state)).merge(grpc.fallback(rest::not_found))
}

/// Requeues expired leases every `period` until `shutdown`.
pub async fn janitor(store: surfmap_store::Store, period: Duration, mut shutdown: surfmap_worker::Shutdown) {
    loop {
        match store.requeue_expired().await {
            Ok(s) if s != Default::default() => tracing::info!(?s, "janitor: expired leases swept"),
            Ok(_) => {}
            Err(e) => tracing::warn!("janitor: {e}"),
        }
        tokio::select! {
            _ = tokio::time::sleep(period) => {}
            _ = shutdown.changed() => return,
        }
    }
}
