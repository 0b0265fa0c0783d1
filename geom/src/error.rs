//! The crate's one error type. Four kinds, as the service maps them: bad input (never retried),
//! numerical failure (never retried), cancellation, and internal bugs.

use thiserror::Error;

/// Result alias used across the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Every failure the geometry core can report.
#[derive(Debug, Error)]
pub enum Error {
    /// The caller's data is unusable; the message names the element at fault.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A solve or construction failed numerically (singular system, folded embedding).
    #[error("numerical failure: {0}")]
    Numerical(String),
    /// The finished map has flipped faces in one direction or both: it is not returned as a
    /// success. The message gives the counts, where they are and the remedies.
    #[error("the map folds ({flipped} flipped faces): {detail}")]
    MapFolds { flipped: usize, detail: String },
    /// The caller asked to stop.
    #[error("cancelled")]
    Cancelled,
    /// A bug: an invariant of this crate does not hold.
    #[error("internal error: {0}")]
    Internal(String),
}

impl Error {
    /// A short, stable machine-readable code for the error kind (used by the CLI and the server).
    pub fn code(&self) -> &'static str {
        match self {
            Error::Input(e) => e.code(),
            Error::Numerical(_) => "numerical",
            Error::MapFolds { .. } => "map_folds",
            Error::Cancelled => "cancelled",
            Error::Internal(_) => "internal",
        }
    }

    /// True for errors caused by the caller's data.
    pub fn is_input(&self) -> bool {
        matches!(self, Error::Input(_))
    }
}

/// Bad input, by element: each variant says what is wrong and where.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum InputError {
    #[error("empty input: {0}")]
    Empty(String),
    #[error("unknown mesh format: {0}")]
    UnknownFormat(String),
    #[error("parse error in {format} at {location}: {message}")]
    Parse { format: &'static str, location: String, message: String },
    #[error("{format} header promises {promised} but the data holds at most {available}")]
    LyingCount { format: &'static str, promised: String, available: String },
    #[error("mesh too large: {what} = {count} exceeds the limit {limit}")]
    TooLarge { what: &'static str, count: u64, limit: u64 },
    #[error("face {face} references vertex {index}, but there are {vertex_count} vertices")]
    IndexOutOfRange { face: usize, index: i64, vertex_count: usize },
    #[error("vertex {vertex} has a non-finite coordinate ({value})")]
    NonFiniteCoordinate { vertex: usize, value: f64 },
    #[error("face {face} has fewer than 3 vertices ({count})")]
    FaceTooSmall { face: usize, count: usize },
    #[error("face {face} repeats vertex {vertex}")]
    DegenerateFace { face: usize, vertex: usize },
    #[error("face {face} duplicates face {other}")]
    DuplicateFace { face: usize, other: usize },
    #[error("non-manifold edge ({a}, {b}): shared by {count} faces")]
    NonManifoldEdge { a: usize, b: usize, count: usize },
    #[error("non-manifold vertex {vertex}: its faces form {fans} separate fans")]
    NonManifoldVertex { vertex: usize, fans: usize },
    #[error("mesh is not orientable (conflict at edge ({a}, {b}))")]
    NonOrientable { a: usize, b: usize },
    #[error("mesh has no faces")]
    NoFaces,
    #[error("invalid argument: {0}")]
    Invalid(String),
    #[error("topology mismatch: {0}")]
    TopologyMismatch(String),
    #[error("not a disk: {0}")]
    NotADisk(String),
    #[error("index {index} out of range for {what} (count {count})")]
    OutOfRange { what: &'static str, index: usize, count: usize },
    #[error("invalid anchors: {0}")]
    Anchors(String),
    #[error("invalid feature curves: {0}")]
    Features(String),
    #[error("invalid job spec: {0}")]
    Spec(String),
    /// The spec names no method this service runs (the message lists them).
    #[error("{0}")]
    UnknownMethod(String),
    #[error("no consistent patch layout: {0}")]
    LayoutConflict(String),
    /// An option's value lies outside its documented range (the message names both).
    #[error("option out of range: {0}")]
    OptionRange(String),
    /// The job's estimated peak memory exceeds the budget a service runs jobs with.
    #[error(
        "the job needs an estimated {estimate_mib} MiB, above the budget of {budget_mib} MiB per job: use smaller meshes or options"
    )]
    OverBudget { estimate_mib: u64, budget_mib: u64 },
    /// A file requires an extension this service does not implement (named).
    #[error("the file requires the extension {0}, which surfmap does not read (export without it)")]
    UnsupportedExtension(String),
    /// Coordinates so large that lengths, areas or their products overflow (the message names
    /// the vertex or the quantity).
    #[error("mesh numbers not finite: {0}")]
    NotFinite(String),
    /// Every vertex at one point, or every face flat onto a line: the mesh has no surface.
    #[error("mesh has no extent: {0}")]
    NoExtent(String),
    /// A closed mesh with a face of zero area (collinear corners): no map can place it.
    #[error(
        "face {face} of the closed mesh has zero area (area {area:e}, largest face {largest:e}): its corners are collinear; repair or remove it"
    )]
    ZeroAreaFace { face: usize, area: f64, largest: f64 },
}

impl InputError {
    /// Stable snake_case code of the variant.
    pub fn code(&self) -> &'static str {
        match self {
            InputError::Empty(_) => "empty_input",
            InputError::UnknownFormat(_) => "unknown_format",
            InputError::Parse { .. } => "parse_error",
            InputError::LyingCount { .. } => "lying_count",
            InputError::TooLarge { .. } => "too_large",
            InputError::IndexOutOfRange { .. } => "index_out_of_range",
            InputError::NonFiniteCoordinate { .. } => "non_finite_coordinate",
            InputError::FaceTooSmall { .. } => "face_too_small",
            InputError::DegenerateFace { .. } => "degenerate_face",
            InputError::DuplicateFace { .. } => "duplicate_face",
            InputError::NonManifoldEdge { .. } => "non_manifold_edge",
            InputError::NonManifoldVertex { .. } => "non_manifold_vertex",
            InputError::NonOrientable { .. } => "non_orientable",
            InputError::NoFaces => "no_faces",
            InputError::Invalid(_) => "invalid_argument",
            InputError::TopologyMismatch(_) => "topology_mismatch",
            InputError::NotADisk(_) => "not_a_disk",
            InputError::OutOfRange { .. } => "out_of_range",
            InputError::Anchors(_) => "invalid_anchors",
            InputError::Features(_) => "invalid_features",
            InputError::Spec(_) => "invalid_spec",
            InputError::UnknownMethod(_) => "unknown_method",
            InputError::LayoutConflict(_) => "layout_conflict",
            InputError::OptionRange(_) => "option_out_of_range",
            InputError::OverBudget { .. } => "over_budget",
            InputError::UnsupportedExtension(_) => "unsupported_extension",
            InputError::NotFinite(_) => "mesh_not_finite",
            InputError::NoExtent(_) => "mesh_no_extent",
            InputError::ZeroAreaFace { .. } => "zero_area_face",
        }
    }
}

/// Shorthand for a parse error.
pub(crate) fn parse_err(format: &'static str, location: impl Into<String>, message: impl Into<String>) -> Error {
    Error::Input(InputError::Parse { format, location: location.into(), message: message.into() })
}
