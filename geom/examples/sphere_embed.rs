//! Embeds meshes on the sphere and prints the figures: `cargo run --release -p surfmap-geom
//! --example sphere_embed -- MESH...` (`--subdivide K` first subdivides each mesh K times).

use geom::io::{ReadOptions, read_path};
use geom::progress::NoProgress;
use geom::sphere::{SphereEmbedOptions, embed_sphere};
use std::time::Instant;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut subdivide = 0;
    if let Some(i) = args.iter().position(|a| a == "--subdivide") {
        subdivide = args[i + 1].parse().expect("--subdivide K");
        args.drain(i..i + 2);
    }
    for path in args {
        let read = read_path(std::path::Path::new(&path), &ReadOptions::default()).expect("read");
        let mesh = geom::mesh::shapes::subdivide(&read.mesh, subdivide);
        let t0 = Instant::now();
        match embed_sphere(&mesh, &SphereEmbedOptions::default(), &NoProgress) {
            Ok(e) => println!(
                "{path}: {} vertices, {:.2} s, distortion {:.4}, iterations {}, backtracks {}, converged {}",
                mesh.n_vertices(),
                t0.elapsed().as_secs_f64(),
                e.report.distortion,
                e.report.newton.iterations,
                e.report.newton.backtracks,
                e.report.newton.converged
            ),
            Err(err) => {
                println!("{path}: {} vertices, {:.2} s, error {err}", mesh.n_vertices(), t0.elapsed().as_secs_f64())
            }
        }
    }
}
