use geom::domain::tracer::{TraceRequest, Tracer};
use geom::domain::walks::walks;
use geom::io::{ReadOptions, read_path};
use geom::mesh::VertexId;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let m = read_path(std::path::Path::new(&args[1]), &ReadOptions::default()).unwrap().mesh;
    let a: serde_json::Value = serde_json::from_slice(&std::fs::read(&args[2]).unwrap()).unwrap();
    let anchors: Vec<VertexId> =
        a["anchors"].as_array().unwrap().iter().map(|p| VertexId(p[0].as_u64().unwrap() as u32)).collect();
    let mut t = Tracer::new(&m, &anchors, &Default::default()).unwrap();
    let r = geom::domain::voronoi::source_layout(&mut t, 2, &Default::default(), &mut geom::progress::NoProgress);
    println!("{:?}", r.as_ref().err());
    for w in walks(&t) {
        println!("walk {:?} halves {:?}", w.corners(&t), w.halves);
    }
    for (x, y) in [(14u32, 1u32), (10, 1), (1, 10), (1, 14)] {
        let ok = t.trace(&TraceRequest { a: x, b: y, ..Default::default() }).unwrap().is_some();
        println!("{x}->{y}: {ok}");
    }
    for (i, p) in t.paths().iter().enumerate() {
        if p.a == 1 || p.b == 1 || p.a == 14 || p.b == 14 {
            println!("path {i}: {}-{} len {}", p.a, p.b, p.nodes.len());
        }
    }
}
