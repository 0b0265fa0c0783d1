//! The subcommands: each returns the JSON (or text) to print, or a `geom::Error`.

use geom::io::{self, ReadOptions};
use geom::{Error, InputError, Result};
use serde_json::json;
use std::path::Path;

fn read(path: &Path) -> Result<io::ReadResult> {
    io::read_path(path, &ReadOptions::default())
        .map_err(|e| match e {
            Error::Input(InputError::Invalid(m)) => Error::Input(InputError::Invalid(m)),
            Error::Input(i) => Error::Input(InputError::Invalid(format!("{}: {i}", path.display()))).with_code_of(i),
            other => other,
        })
}

trait WithCode {
    fn with_code_of(self, i: InputError) -> Error;
}
impl WithCode for Error {
    fn with_code_of(self, i: InputError) -> Error {
        // Keep the original variant (and code); the path is added by the caller's message.
        let _ = self;
        Error::Input(i)
    }
}

/// `surfmap inspect MESH`.
pub fn inspect(path: &Path) -> Result<String> {
    let r = read(path)?;
    let s = geom::topology::summary(&r.mesh);
    let mut v = serde_json::to_value(&s).map_err(|e| Error::Internal(e.to_string()))?;
    v["format"] = json!(r.format);
    v["warnings"] = serde_json::to_value(&r.warnings).map_err(|e| Error::Internal(e.to_string()))?;
    let a = r.mesh.attributes();
    v["attributes"] = json!({
        "normals": a.normals.is_some(), "colors": a.colors.is_some(), "uvs": a.uvs.is_some()
    });
    serde_json::to_string_pretty(&v).map_err(|e| Error::Internal(e.to_string()))
}

/// `surfmap convert IN OUT`.
pub fn convert(input: &Path, output: &Path) -> Result<String> {
    let r = read(input)?;
    io::write_path(&r.mesh, output)?;
    let s = geom::topology::summary(&r.mesh);
    Ok(json!({"written": output.display().to_string(), "vertices": s.vertices, "faces": s.faces,
              "warnings": r.warnings.iter().map(|w| &w.message).collect::<Vec<_>>()})
    .to_string())
}

/// `surfmap metrics SOURCE TARGET MAPPED`.
pub fn metrics(
    source: &Path,
    target: &Path,
    mapped: &Path,
    anchors: Option<&Path>,
    gt: Option<&Path>,
    samples: usize,
    seed: u64,
) -> Result<String> {
    let _ = (source, target, mapped, anchors, gt, samples, seed);
    Err(Error::Internal("metrics not built yet".into()))
}
