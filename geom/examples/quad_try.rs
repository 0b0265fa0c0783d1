//! Scratch driver for the quad method: `quad_try MESH LEVEL`.
use geom::quad::*;
use geom::{Mesh, VertexId};

fn fps(m: &Mesh, k: usize) -> Vec<VertexId> {
    let p = m.positions();
    let mut d: Vec<f64> = p.iter().map(|x| (x - p[0]).norm()).collect();
    let mut out = vec![VertexId(0)];
    while out.len() < k {
        let i = (0..p.len()).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap_or(0);
        out.push(VertexId::from_idx(i));
        for (j, x) in p.iter().enumerate() {
            d[j] = d[j].min((x - p[i]).norm());
        }
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let m = geom::io::read_path(std::path::Path::new(&args[1]), &Default::default()).unwrap().mesh;
    let level: u32 = args[2].parse().unwrap();
    let pts = fps(&m, 4);
    let t = std::time::Instant::now();
    let part = partition_genus0(&m, [pts[0], pts[1], pts[2], pts[3]], &[], &Default::default()).unwrap();
    println!("partition {:.3}s subdiv {}", t.elapsed().as_secs_f64(), part.subdivisions);
    let opts = QuadParamOptions::default();
    let mut uvs = Vec::new();
    for p in &part.patches {
        let t = std::time::Instant::now();
        let b = base_embedding(p, &opts).unwrap();
        let tb = t.elapsed().as_secs_f64();
        let r = coarse_to_fine(p, b, &[], &opts, &mut geom::progress::NoProgress).unwrap();
        println!(
            "patch V={} base {} mv {:?} opt {:?} | full mv {:?} final {:?} flips {} base {:.3}s total {:.3}s",
            p.mesh.n_vertices(),
            r.base_vertices,
            r.base_stretch_mv,
            r.base_stretch_opt,
            r.stretch_mv,
            r.stretch_final,
            r.flipped,
            tb,
            t.elapsed().as_secs_f64()
        );
        uvs.push(r.uv);
    }
    let grid = remesh::uniform_grid(&QuadLayout::genus0(), level).unwrap();
    let pos = remesh::sample_uniform(&grid, &part.patches, &uvs).unwrap();
    let rm = Mesh::from_triangles(pos, &grid.faces).unwrap();
    let h = geom::metrics::hausdorff(&m, &rm, 100_000, (1, 2)).unwrap();
    let diag = m.bbox_diagonal();
    println!(
        "level {level}: {} faces, psnr {:.2} dB, hausdorff {:.3}%",
        rm.n_faces(),
        20.0 * (diag / h.rms).log10(),
        100.0 * h.hausdorff / diag
    );
    geom::io::write_path(&rm, std::path::Path::new("/tmp/remesh.obj")).unwrap();
}
