//! The subcommands: each returns the JSON (or text) to print, or a `geom::Error`.

use geom::io::{self, ReadOptions};
use geom::{Error, InputError, Result, VertexId};
use serde_json::json;
use std::path::Path;

fn read(path: &Path) -> Result<io::ReadResult> {
    io::read_path(path, &ReadOptions::default()).map_err(|e| match e {
        // Name the file in parse errors; keep the variant (and so the code).
        Error::Input(InputError::Parse { format, location, message }) => {
            Error::Input(InputError::Parse { format, location: format!("{}: {location}", path.display()), message })
        }
        other => other,
    })
}

/// A mesh a job can run on: read, then the checks the server's upload makes (finite numbers,
/// an extent, no zero-area face in a closed mesh), naming the file.
fn read_checked(path: &Path) -> Result<(io::ReadResult, geom::topology::Summary)> {
    let r = read(path)?;
    match geom::topology::checked_summary(&r.mesh, None) {
        Ok(s) => Ok((r, s)),
        Err(Error::Input(InputError::NotFinite(m))) => {
            Err(InputError::NotFinite(format!("{}: {m}", path.display())).into())
        }
        Err(Error::Input(InputError::NoExtent(m))) => {
            Err(InputError::NoExtent(format!("{}: {m}", path.display())).into())
        }
        Err(e) => Err(e),
    }
}

/// `surfmap inspect MESH`.
pub fn inspect(path: &Path) -> Result<String> {
    let (r, s) = read_checked(path)?;
    let mut v = serde_json::to_value(&s).map_err(|e| Error::Internal(e.to_string()))?;
    v["format"] = json!(r.format);
    if s.components > 1 {
        v["parts"] =
            serde_json::to_value(geom::topology::parts(&r.mesh)).map_err(|e| Error::Internal(e.to_string()))?;
    }
    v["warnings"] = serde_json::to_value(&r.warnings).map_err(|e| Error::Internal(e.to_string()))?;
    let a = r.mesh.attributes();
    v["attributes"] = match &r.layout {
        Some(l) => json!({
            "names": l.attributes.names(), "input_vertices": l.n_vertices(), "seam_copies": l.n_split()
        }),
        None => json!({"normals": a.normals.is_some(), "colors": a.colors.is_some(), "uvs": a.uvs.is_some()}),
    };
    serde_json::to_string_pretty(&v).map_err(|e| Error::Internal(e.to_string()))
}

/// `surfmap convert IN OUT [--subdivide K] [--simplify N [--kept FILE]]`.
pub fn convert(
    input: &Path,
    output: &Path,
    subdivide: usize,
    simplify: Option<usize>,
    kept: Option<&Path>,
) -> Result<String> {
    let r = read(input)?;
    let mut mesh = if subdivide > 0 { geom::mesh::shapes::try_subdivide(&r.mesh, subdivide)? } else { r.mesh.clone() };
    if let Some(n) = simplify {
        let opts = geom::simplify::DecimateOptions { target_vertices: n, ..Default::default() };
        let d = geom::simplify::decimate(&mesh, &opts)?;
        if let Some(path) = kept {
            let text: String = d.kept.iter().map(|v| format!("{}\n", v.0)).collect();
            std::fs::write(path, text)
                .map_err(|e| InputError::Invalid(format!("cannot write {}: {e}", path.display())))?;
        }
        mesh = d.mesh;
    }
    // A glTF output of an unchanged mesh keeps the input's own layout (seams, attributes).
    let keep_layout = subdivide == 0 && simplify.is_none();
    match (&r.layout, io::Format::from_extension(output)) {
        (Some(l), Some(io::Format::Gltf)) if keep_layout => {
            io::write_bytes(output, &io::write_layout_glb(&mesh, Some(l), &[]))?;
        }
        _ => io::write_path(&mesh, output)?,
    }
    let s = geom::topology::summary(&mesh);
    Ok(json!({"written": output.display().to_string(), "vertices": s.vertices, "faces": s.faces,
              "warnings": r.warnings.iter().map(|w| &w.message).collect::<Vec<_>>()})
    .to_string())
}

/// Reads `{"anchors": [[s, t], ...]}`.
fn read_anchors(path: &Path) -> Result<Vec<(VertexId, VertexId)>> {
    #[derive(serde::Deserialize)]
    struct AnchorFile {
        anchors: Vec<(u32, u32)>,
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::Invalid(format!("cannot read {}: {e}", path.display())))?;
    let f: AnchorFile = serde_json::from_str(&text).map_err(|e| {
        InputError::Invalid(format!("{}: expected {{\"anchors\": [[s, t], ...]}}: {e}", path.display()))
    })?;
    Ok(f.anchors.into_iter().map(|(s, t)| (VertexId(s), VertexId(t))).collect())
}

/// Reads one 0-based target vertex per line.
fn read_gt(path: &Path) -> Result<Vec<VertexId>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::Invalid(format!("cannot read {}: {e}", path.display())))?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let t = l.split_whitespace().next().unwrap_or("");
            t.parse::<u32>().map(VertexId).map_err(|_| {
                InputError::Invalid(format!("{} line {}: expected a vertex index, found {t:?}", path.display(), i + 1))
                    .into()
            })
        })
        .collect()
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
    // The pair passes the checks a map's inputs pass (finite numbers in the report); the
    // mapped mesh is measured as it is (a collapsed face is a result to report).
    let s = read_checked(source)?.0.mesh;
    let t = read_checked(target)?.0.mesh;
    let m = read(mapped)?.mesh;
    let anchors = anchors.map(read_anchors).transpose()?;
    let gt = gt.map(read_gt).transpose()?;
    let opts = geom::metrics::MetricsOptions {
        samples,
        seeds: (seed.wrapping_mul(2).wrapping_add(1), seed.wrapping_mul(2).wrapping_add(2)),
    };
    let r = geom::metrics::evaluate_map(&s, &t, &m, anchors.as_deref(), gt.as_deref(), &opts)?;
    serde_json::to_string_pretty(&r).map_err(|e| Error::Internal(e.to_string()))
}

/// Progress on stderr: a redrawn bar (stage, percent, elapsed) on a terminal, nothing otherwise.
struct StderrProgress {
    tty: bool,
    last: String,
    start: std::time::Instant,
}

impl StderrProgress {
    fn new() -> StderrProgress {
        use std::io::IsTerminal;
        StderrProgress { tty: std::io::stderr().is_terminal(), last: String::new(), start: std::time::Instant::now() }
    }
}

impl geom::progress::Progress for StderrProgress {
    fn report(&mut self, stage: geom::progress::Stage, fraction: f64) {
        if !self.tty {
            return;
        }
        let f = fraction.clamp(0.0, 1.0);
        let filled = (f * 30.0).round() as usize;
        let secs = self.start.elapsed().as_secs();
        let line = format!(
            "\r{stage:<16} [{}{}] {:>3.0}%  {:02}:{:02}",
            "#".repeat(filled),
            " ".repeat(30 - filled),
            f * 100.0,
            secs / 60,
            secs % 60
        );
        if line != self.last {
            use std::io::Write;
            let mut e = std::io::stderr();
            let _ = e.write_all(line.as_bytes());
            let _ = e.flush();
            self.last = line;
        }
    }
}

pub fn map(
    source: &Path,
    target: &Path,
    anchors: Option<&Path>,
    spec: Option<&Path>,
    method: &str,
    out: &Path,
) -> Result<String> {
    use geom::pipeline::{JobSpec, Method};
    let read_bytes =
        |p: &Path| std::fs::read(p).map_err(|e| geom::InputError::Invalid(format!("cannot read {}: {e}", p.display())));
    let spec = match (spec, anchors) {
        (Some(s), _) => JobSpec::from_json(&read_bytes(s)?)?,
        (None, Some(a)) => {
            let m = match method {
                "greedy" => Method::Greedy,
                "homology" => Method::Homology,
                "spherical" => Method::Spherical,
                "voronoi" => Method::Voronoi,
                _ => Method::Auto,
            };
            JobSpec::from_anchors_json(&read_bytes(a)?, m)?
        }
        (None, None) => return Err(geom::InputError::Spec("give --anchors or --spec".into()).into()),
    };
    let (s, t) = (read_checked(source)?.0, read_checked(target)?.0);
    let mut progress = StderrProgress::new();
    let (report, artifacts) =
        geom::pipeline::run_with_layouts(&spec, &[s.mesh, t.mesh], &[s.layout, t.layout], &mut progress)?;
    finish(&progress, out, &artifacts, &report)
}

pub fn remesh(meshes: &[std::path::PathBuf], spec: &Path, out: &Path) -> Result<String> {
    let bytes =
        std::fs::read(spec).map_err(|e| geom::InputError::Invalid(format!("cannot read {}: {e}", spec.display())))?;
    let spec = geom::pipeline::JobSpec::from_json(&bytes)?;
    let (models, layouts): (Vec<_>, Vec<_>) = meshes
        .iter()
        .map(|m| read_checked(m).map(|(r, _)| (r.mesh, r.layout)))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    let mut progress = StderrProgress::new();
    let (report, artifacts) = geom::pipeline::run_with_layouts(&spec, &models, &layouts, &mut progress)?;
    finish(&progress, out, &artifacts, &report)
}

/// Ends the progress line, writes the artifacts into `out` and returns the report as JSON.
fn finish(
    progress: &StderrProgress,
    out: &Path,
    artifacts: &[geom::pipeline::Artifact],
    report: &impl serde::Serialize,
) -> Result<String> {
    if progress.tty {
        eprintln!();
    }
    std::fs::create_dir_all(out)
        .map_err(|e| geom::InputError::Invalid(format!("cannot create {}: {e}", out.display())))?;
    for a in artifacts {
        io::write_bytes(&out.join(&a.name), &a.bytes)?;
    }
    serde_json::to_string_pretty(report).map_err(|e| geom::Error::Internal(e.to_string()))
}
