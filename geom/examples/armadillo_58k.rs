//! Writes the `map` benchmark's 58k-vs-6k case so the CLI can be timed end to end:
//! `cargo run --release -p surfmap-geom --example armadillo_58k -- DIR` writes `fine.obj` (armadillo
//! subdivided once), `coarse.obj` (a 6k-vertex simplification) and `anchors.json` (45 farthest
//! points of the coarse mesh and their partners, as `benches/map.rs` picks them), then
//! `surfmap map DIR/fine.obj DIR/coarse.obj --anchors DIR/anchors.json --out OUT`.
//! It also writes the benchmark's other case: `armadillo.obj`, `bent.obj` and `bent_anchors.json`
//! (45 farthest points), for `surfmap map DIR/armadillo.obj DIR/bent.obj --anchors DIR/bent_anchors.json`.
use std::path::{Path, PathBuf};

#[path = "../benches/common/mod.rs"]
mod common;

fn main() {
    let Some(dir) = std::env::args().nth(1).map(PathBuf::from) else {
        eprintln!("usage: armadillo_58k DIR");
        std::process::exit(2);
    };
    if let Err(e) = run(&dir) {
        eprintln!("{e}");
        std::process::exit(2);
    }
}

fn run(dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let s = geom::io::read_path(&common::shared("armadillo.obj"), &Default::default())?.mesh;
    let fine = geom::mesh::shapes::subdivide(&s, 1);
    let opts = geom::simplify::DecimateOptions { target_vertices: 6000, ..Default::default() };
    let coarse = geom::simplify::decimate(&s, &opts)?;
    std::fs::create_dir_all(dir)?;
    geom::io::write_path(&fine, &dir.join("fine.obj"))?;
    geom::io::write_path(&coarse.mesh, &dir.join("coarse.obj"))?;
    let anchors: Vec<[u64; 2]> =
        common::fps(&coarse.mesh, 45).into_iter().map(|a| [u64::from(coarse.kept[a as usize].0), a]).collect();
    std::fs::write(dir.join("anchors.json"), format!("{{\"anchors\": {anchors:?}}}"))?;
    geom::io::write_path(&s, &dir.join("armadillo.obj"))?;
    geom::io::write_path(&common::bent(&s), &dir.join("bent.obj"))?;
    let anchors: Vec<[u64; 2]> = common::fps(&s, 45).into_iter().map(|a| [a, a]).collect();
    std::fs::write(dir.join("bent_anchors.json"), format!("{{\"anchors\": {anchors:?}}}"))?;
    Ok(())
}
