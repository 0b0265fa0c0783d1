//! Method `quad` (Yu & Chuang Table 1): consistent parameterization of a pair (SMPL man and
//! woman, 6890 vertices each, 4 partition points and 6 features) and a single bunny job at level 6 as `surfmap remesh` runs it.
//! `cargo bench -p surfmap-geom --bench quad`

use criterion::{Criterion, criterion_group, criterion_main};
use geom::io::{ReadOptions, read_path};
use geom::mesh::{Mesh, VertexId};
use geom::pipeline::JobSpec;
use geom::pipeline::quad::run as run_remesh;
use geom::progress::NoProgress;
use geom::quad::consistent::{ConsistentOptions, consistent_parameterization};

mod common;
use common::{fps, shared};

fn load(name: &str) -> Mesh {
    read_path(&shared(name), &ReadOptions::default()).expect("shared mesh").mesh
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("quad");
    g.sample_size(10);
    let man = load("registered/smpl_human/human_man.obj");
    let woman = load("registered/smpl_human/human_woman.obj");
    let ids = fps(&man, 10);
    let rows: Vec<Vec<VertexId>> = ids.iter().map(|&i| vec![VertexId(i as u32); 2]).collect();
    let o = ConsistentOptions::default();
    g.bench_function("smpl_pair_parameterize", |b| {
        b.iter(|| consistent_parameterization(&[&man, &woman], &rows, &o, &mut NoProgress).expect("param"))
    });
    let bunny = load("bunny.off");
    let ids = fps(&bunny, 4);
    let JobSpec::Quad(spec) = JobSpec::from_json(
        serde_json::json!({"method": "quad", "anchors": ids.iter().map(|&i| [i]).collect::<Vec<_>>(), "options": {"level": 6}})
            .to_string()
            .as_bytes(),
    )
    .expect("spec") else {
        unreachable!("a quad spec")
    };
    g.bench_function("bunny_job_level6", |b| {
        b.iter(|| run_remesh(&spec, std::slice::from_ref(&bunny), &mut NoProgress).expect("job"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
