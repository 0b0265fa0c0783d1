//! Method `homology`: the canonical basis of botijo (41k vertices, genus 5) and of fertility
//! (genus 4), and a whole genus-1 job on 10k-vertex meshes (the kitten against a bent copy of
//! itself, base vertex 0), as `surfmap map` runs it.
//! `cargo bench -p surfmap-geom --bench homology`

use criterion::{Criterion, criterion_group, criterion_main};
use geom::homology::{CanonicalBasisOptions, canonical_basis};
use geom::io::{ReadOptions, read_path};
use geom::mesh::{Mesh, VertexId};
use geom::pipeline::homology::run as run_map;
use geom::pipeline::{HomologyOptions, HomologySpec};
use geom::progress::NoProgress;

mod common;
use common::{bent, shared};

fn load(name: &str) -> Mesh {
    read_path(&shared(name), &ReadOptions::default()).expect("shared mesh").mesh
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("homology");
    g.sample_size(10);
    for name in ["botijo.off", "genus3.off", "kitten.nf20k.off"] {
        let m = load(name);
        let o = CanonicalBasisOptions::default();
        if canonical_basis(&m, VertexId(0), &o).is_err() {
            eprintln!("{name}: no canonical basis through vertex 0 (known gap), not timed");
            continue;
        }
        g.bench_function(format!("basis_{name}"), |b| b.iter(|| canonical_basis(&m, VertexId(0), &o).expect("basis")));
    }
    let s = load("kitten.nf20k.off");
    let t = bent(&s);
    let spec = HomologySpec {
        anchors: geom::pipeline::AnchorRow::ids([[0, 0]]),
        features: Vec::new(),
        options: HomologyOptions::default(),
    };
    g.bench_function("kitten_bent_genus1_map", |b| b.iter(|| run_map(&spec, &s, &t, &mut NoProgress).expect("map")));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
