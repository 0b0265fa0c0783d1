//! Maps two closed genus-0 meshes onto each other through their sphere embeddings, both ways,
//! and writes the mapped meshes for the shared evaluator:
//! `cargo run --release -p surfmap-geom --example sphere_pair -- SRC TGT ANCHORS.json OUTDIR`
//! (`ANCHORS.json` as `{"anchors": [[source, target], ...]}`; writes `OUTDIR/s2t.obj`, the
//! source's connectivity on the target, and `OUTDIR/t2s.obj`).

use geom::io::{ReadOptions, read_path};
use geom::mesh::{Mesh, P3};
use geom::progress::NoProgress;
use geom::sphere::{SphereEmbedOptions, SpherePairOptions, embed_sphere, sphere_pair};
use std::fmt::Write as _;
use std::time::Instant;

fn main() {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [src, tgt, anchors, out] = &args[..] else {
        eprintln!("usage: sphere_pair SRC TGT ANCHORS.json OUTDIR");
        std::process::exit(2);
    };
    let read = |p: &str| read_path(std::path::Path::new(p), &ReadOptions::default()).expect("read").mesh;
    let (a, b) = (read(src), read(tgt));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(anchors).expect("anchors")).expect("json");
    let pairs: Vec<(u32, u32)> = json["anchors"]
        .as_array()
        .expect("anchors array")
        .iter()
        .map(|p| (p[0].as_u64().expect("index") as u32, p[1].as_u64().expect("index") as u32))
        .collect();
    std::fs::create_dir_all(out).expect("outdir");
    let t0 = Instant::now();
    let ea = embed_sphere(&a, &SphereEmbedOptions::default(), &NoProgress).expect("embed source");
    let eb = embed_sphere(&b, &SphereEmbedOptions::default(), &NoProgress).expect("embed target");
    println!("embeddings {:.2} s", t0.elapsed().as_secs_f64());
    let swapped: Vec<(u32, u32)> = pairs.iter().map(|&(s, t)| (t, s)).collect();
    for (name, from, fs, to, ts, anchors) in
        [("s2t", &a, &ea.points, &b, &eb.points, &pairs), ("t2s", &b, &eb.points, &a, &ea.points, &swapped)]
    {
        let t = Instant::now();
        let mut o = SpherePairOptions::default();
        if let Ok(k) = std::env::var("SURFMAP_MAX_MOVE") {
            o.newton.max_move = k.parse().expect("SURFMAP_MAX_MOVE");
        }
        if let Ok(k) = std::env::var("SURFMAP_GLOBAL") {
            o.global_iterations = k.parse().expect("SURFMAP_GLOBAL");
        }
        match sphere_pair(from, fs, to, ts, anchors, &o, &NoProgress) {
            Ok(m) => {
                println!("{name}: {:.2} s {}", t.elapsed().as_secs_f64(), serde_json::to_string(&m.report).unwrap());
                let tris = to.face_indices();
                let pos: Vec<P3> = m
                    .located
                    .iter()
                    .map(|l| {
                        let t = tris[l.face as usize];
                        let p = |k: usize| to.positions()[t[k] as usize].coords * l.bary[k];
                        P3::from(p(0) + p(1) + p(2))
                    })
                    .collect();
                std::fs::write(format!("{out}/{name}.obj"), obj(from, &pos)).expect("write");
            }
            Err(e) => println!("{name}: {:.2} s error {e}", t.elapsed().as_secs_f64()),
        }
    }
}

fn obj(mesh: &Mesh, pos: &[P3]) -> String {
    let mut s = String::new();
    for p in pos {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in mesh.face_indices() {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}
