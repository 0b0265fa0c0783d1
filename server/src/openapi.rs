//! The OpenAPI document, derived from the handlers' annotations (utoipa).

use crate::error::ErrorBody;
use crate::rest::{artifacts, jobs, meshes, ops};
use crate::views::{
    ArtifactList, ArtifactView, JobLinks, JobPage, JobView, MeshView, MeshesJobRequest, PairJobRequest, SpecOutline,
    SubmitJobRequest,
};

#[derive(utoipa::OpenApi)]
#[openapi(
    info(
        title = "surfmap",
        description = "Compatible meshes, cross-parameterizations and distortion metrics for pairs of triangle meshes."
    ),
    paths(
        meshes::upload_mesh,
        jobs::submit_job,
        jobs::list_jobs,
        jobs::get_job,
        jobs::cancel_job,
        jobs::job_events,
        artifacts::list_artifacts,
        artifacts::get_artifact,
        ops::healthz,
        ops::readyz,
        ops::metrics,
        ops::openapi
    ),
    components(schemas(
        ErrorBody,
        MeshView,
        JobView,
        JobLinks,
        JobPage,
        ArtifactView,
        ArtifactList,
        SubmitJobRequest,
        PairJobRequest,
        MeshesJobRequest,
        SpecOutline
    ))
)]
pub struct ApiDoc;
