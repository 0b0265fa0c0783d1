//! The `surfmap` command line: `inspect`, `convert` and `metrics` over the geometry core.
//! Exit codes: 0 success, 2 bad input (message on stderr), 1 internal failure.

mod commands;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "surfmap", version, about = "Map one triangle mesh onto another of the same topology")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a JSON summary of a mesh: counts, components, boundary loops, genus, bbox, warnings.
    Inspect {
        /// Mesh file (OBJ, OFF, PLY or STL; detected from content).
        mesh: PathBuf,
    },
    /// Convert a mesh between formats (output format from the extension).
    Convert {
        input: PathBuf,
        output: PathBuf,
        /// Split every triangle into four at edge midpoints, this many times.
        #[arg(long, default_value_t = 0)]
        subdivide: usize,
        /// Then simplify to this many vertices by quadric-error half-edge collapses (every output
        /// vertex is an input vertex).
        #[arg(long)]
        simplify: Option<usize>,
        /// With --simplify: write the input index of every output vertex here, one per line.
        #[arg(long, requires = "simplify")]
        kept: Option<PathBuf>,
    },
    /// Measure a map given as SOURCE re-embedded on TARGET (MAPPED has SOURCE's faces).
    Metrics {
        source: PathBuf,
        target: PathBuf,
        mapped: PathBuf,
        /// JSON file `{"anchors": [[source_vertex, target_vertex], ...]}` (0-based).
        #[arg(long)]
        anchors: Option<PathBuf>,
        /// Text file: one 0-based target vertex per line, one line per source vertex.
        #[arg(long)]
        gt: Option<PathBuf>,
        /// Surface samples per direction for Hausdorff / RMS.
        #[arg(long, default_value_t = 100_000)]
        samples: usize,
        /// Seed of the surface sampling.
        #[arg(long, default_value_t = 0)]
        seed: u64,
    },
    /// Map SOURCE onto TARGET through a common base domain built from corresponding anchors.
    /// Writes source_on_target.obj, target_on_source.obj, source_to_target.csv,
    /// target_to_source.csv, layout.json, layout_source.ply, layout_target.ply and metrics.json.
    Map {
        source: PathBuf,
        target: PathBuf,
        /// JSON `{"anchors": [[source_vertex, target_vertex], ...]}` (0-based); method from --method.
        #[arg(long, conflicts_with = "spec", required_unless_present = "spec")]
        anchors: Option<PathBuf>,
        /// The job spec `{"method": "auto"|"voronoi"|"greedy"|"homology"|"spherical", "anchors": [[s, t], ...], "options": {...}}`
        /// (without `method`: auto, the method that fits the meshes).
        #[arg(long)]
        spec: Option<PathBuf>,
        /// Method when --anchors is given (auto: the one that fits the meshes).
        #[arg(long, default_value = "auto", value_parser = ["auto", "voronoi", "greedy", "homology", "spherical"])]
        method: String,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Consistent quad parameterization of two or more genus-0 meshes and semi-regular remeshes
    /// with identical connectivity (method `quad`). Writes remesh_<i>.obj, param_<i>.obj,
    /// geometry images and normal maps, morph.glb and metrics.json.
    Remesh {
        /// The meshes, in the order of the anchor columns.
        #[arg(required = true, num_args = 1..)]
        meshes: Vec<PathBuf>,
        /// The job spec `{"method": "quad", "anchors": [[v_1, ..., v_N], ...], "options": {...}}`;
        /// the first four anchor rows are the partition points.
        #[arg(long)]
        spec: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    // The pipeline's diagnostics are `tracing` events at debug level: `RUST_LOG=geom=debug`
    // prints them on stderr.
    if std::env::var_os("RUST_LOG").is_some() {
        tracing_subscriber::fmt()
            .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
            .with_writer(std::io::stderr)
            .init();
    }
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { ExitCode::from(2) } else { ExitCode::SUCCESS };
        }
    };
    let result = match cli.command {
        Command::Inspect { mesh } => commands::inspect(&mesh),
        Command::Convert { input, output, subdivide, simplify, kept } => {
            commands::convert(&input, &output, subdivide, simplify, kept.as_deref())
        }
        Command::Metrics { source, target, mapped, anchors, gt, samples, seed } => {
            commands::metrics(&source, &target, &mapped, anchors.as_deref(), gt.as_deref(), samples, seed)
        }
        Command::Map { source, target, anchors, spec, method, out } => {
            commands::map(&source, &target, anchors.as_deref(), spec.as_deref(), &method, &out)
        }
        Command::Remesh { meshes, spec, out } => commands::remesh(&meshes, &spec, &out),
    };
    match result {
        Ok(out) => {
            println!("{out}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("surfmap: error [{}]: {e}", e.code());
            if e.is_input() { ExitCode::from(2) } else { ExitCode::from(1) }
        }
    }
}
