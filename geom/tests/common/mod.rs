//! Shared helpers for the geometry integration tests.
#![allow(dead_code)]

use geom::Mesh;
use geom::io::{ReadOptions, read_path};
use geom::mesh::P3;
use std::path::{Path, PathBuf};

pub fn shared_mesh(name: &str) -> PathBuf {
    let root = std::env::var_os("SURFMAP_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared"));
    let p = root.join("meshes").join(name);
    assert!(p.exists(), "shared mesh {} not found (set SURFMAP_SHARED)", p.display());
    p
}

pub fn load(name: &str) -> Mesh {
    read_path(&shared_mesh(name), &ReadOptions::default()).expect("read shared mesh").mesh
}

/// Euclidean farthest-point sampling from vertex 0.
pub fn fps(m: &Mesh, k: usize) -> Vec<u32> {
    let p = m.positions();
    let mut d: Vec<f64> = p.iter().map(|x| (x - p[0]).norm()).collect();
    let mut out = vec![0u32];
    while out.len() < k {
        let i = (0..p.len()).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap();
        out.push(i as u32);
        for (j, x) in p.iter().enumerate() {
            d[j] = d[j].min((x - p[i]).norm());
        }
    }
    out
}

/// A copy with vertices in another order; returns it and new index of each old vertex.
pub fn shuffled(m: &Mesh) -> (Mesh, Vec<u32>) {
    let n = m.n_vertices() as u64;
    // A fixed permutation: multiplication by a unit modulo n.
    let mut a = 7919u64;
    while gcd(a, n) != 1 {
        a += 2;
    }
    let perm: Vec<u32> = (0..n).map(|i| ((i * a + 13) % n) as u32).collect();
    let mut pos = vec![P3::origin(); n as usize];
    for (i, &p) in perm.iter().enumerate() {
        pos[p as usize] = m.positions()[i];
    }
    let faces: Vec<[u32; 3]> = m.faces().iter().map(|f| f.map(|v| perm[v.idx()])).collect();
    (Mesh::from_triangles(pos, &faces).unwrap(), perm)
}

/// Another triangulation of the same surface: every face split into four at its edge
/// midpoints. Vertex `i` of `m` is vertex `i` of the copy (the ground truth is the identity on
/// them); the new vertices follow.
pub fn subdivided(m: &Mesh) -> Mesh {
    geom::mesh::refine::Refined::identity(m).subdivide().unwrap().mesh
}

/// A vertex path of `m` on its subdivision `fine` ([`subdivided`]): each edge through its midpoint.
pub fn path_on_subdivided(m: &Mesh, fine: &Mesh, path: &[geom::VertexId]) -> Vec<geom::VertexId> {
    let mut out = vec![path[0]];
    for w in path.windows(2) {
        let mid = nalgebra::center(&m.position(w[0]), &m.position(w[1]));
        let c = fine.vertex_neighbors(w[0]).find(|&c| fine.position(c) == mid).expect("the edge's midpoint");
        out.extend([c, w[1]]);
    }
    out
}

/// `k` feature curves: centres spread by farthest-point sampling over vertices `gap` rings away
/// from the boundary and from earlier curves, each a shortest edge path of about `length` times
/// the diagonal from its centre, ending towards +x.
pub fn feature_curves(m: &Mesh, k: usize, length: f64, gap: usize) -> Vec<Vec<geom::VertexId>> {
    use geom::VertexId;
    use geom::geodesic::{VertexDijkstraOptions, vertex_dijkstra};
    let n = m.n_vertices();
    let grow = |b: &mut Vec<bool>| {
        for _ in 0..gap {
            let cur = b.clone();
            for v in (0..n).filter(|&v| cur[v]) {
                for w in m.vertex_neighbors(VertexId::from_idx(v)) {
                    b[w.idx()] = true;
                }
            }
        }
    };
    let mut blocked: Vec<bool> = (0..n).map(|v| m.is_boundary_vertex(VertexId::from_idx(v))).collect();
    grow(&mut blocked);
    let r = length * m.bbox_diagonal();
    let mut centres: Vec<VertexId> = Vec::new();
    let mut out = Vec::new();
    for _ in 0..k {
        let d = |v: VertexId| centres.iter().map(|&c| (m.position(v) - m.position(c)).norm()).fold(1e300, f64::min);
        let c = (0..n).map(VertexId::from_idx).filter(|v| !blocked[v.idx()]).max_by(|&a, &b| d(a).total_cmp(&d(b)));
        let c = c.expect("room for a curve");
        let o = VertexDijkstraOptions { blocked: Some(&blocked), max_distance: Some(r), ..Default::default() };
        let dist = vertex_dijkstra(m, &[(c, 0.0)], &o).unwrap();
        let end = (0..n)
            .map(VertexId::from_idx)
            .filter(|v| dist.dist[v.idx()] > 0.6 * r && dist.dist[v.idx()] <= r)
            .max_by(|a, b| m.position(*a).x.total_cmp(&m.position(*b).x))
            .expect("an end");
        let p = dist.path_to(end).unwrap();
        let mut ring = vec![false; n];
        for v in &p {
            ring[v.idx()] = true;
        }
        grow(&mut ring);
        for (b, x) in blocked.iter_mut().zip(&ring) {
            *b |= x;
        }
        centres.push(c);
        out.push(p);
    }
    out
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// A copy twisted about its vertical axis (up to 0.8 rad), same vertex order.
pub fn twisted(m: &Mesh) -> Mesh {
    let (lo, hi) = m.bbox();
    twisted_about(m, P3::from((lo.coords + hi.coords) / 2.0))
}

/// [`twisted`] about the vertical line through the vertex centroid, as `bench/table2.py`
/// deforms (`deform(V, "twist")`).
pub fn twisted_as_in_the_bench(m: &Mesh) -> Mesh {
    let sum = m.positions().iter().fold(nalgebra::Vector3::zeros(), |a, p| a + p.coords);
    twisted_about(m, P3::from(sum / m.n_vertices() as f64))
}

fn twisted_about(m: &Mesh, c: P3) -> Mesh {
    let (lo, hi) = m.bbox();
    let pos = m
        .positions()
        .iter()
        .map(|p| {
            let t = (p.y - lo.y) / (hi.y - lo.y) * 0.8;
            let (x, z) = (p.x - c.x, p.z - c.z);
            P3::new(c.x + x * t.cos() - z * t.sin(), p.y, c.z + x * t.sin() + z * t.cos())
        })
        .collect();
    m.with_positions(pos).unwrap()
}

/// A copy bent along its longest axis (the evaluator-bench "bend"), same vertex order.
pub fn bent(m: &Mesh) -> Mesh {
    let (lo, hi) = m.bbox();
    let d = hi - lo;
    let ax = (0..3).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap_or(0);
    let o = (ax + 1) % 3;
    let c = (lo.coords + hi.coords) / 2.0;
    let r = d[ax] * 1.2;
    let pos = m
        .positions()
        .iter()
        .map(|p| {
            let u = (p[ax] - c[ax]) / r;
            let mut q = *p;
            q[ax] = c[ax] + r * u.sin();
            q[o] = p[o] + r * (1.0 - u.cos());
            q
        })
        .collect();
    m.with_positions(pos).unwrap()
}

/// The job's `source_on_target.obj`, checked: the source's faces, every vertex on the target
/// (within 1e-9 of its diagonal).
pub fn source_on_target(arts: &[geom::pipeline::Artifact], s: &Mesh, t: &Mesh) -> Mesh {
    let obj = arts.iter().find(|a| a.name == "source_on_target.obj").expect("source_on_target.obj");
    let mapped = geom::io::read(&obj.bytes, &ReadOptions::default()).unwrap().mesh;
    assert_eq!(mapped.faces(), s.faces(), "equal connectivity");
    let loc = geom::topology::Locator::new(t).unwrap();
    let off = mapped.positions().iter().map(|p| loc.project(p).distance).fold(0.0, f64::max);
    assert!(off <= 1e-9 * t.bbox_diagonal(), "off surface {off}");
    mapped
}

/// Asserts that the job wrote every artifact in `names`.
pub fn assert_artifacts(arts: &[geom::pipeline::Artifact], names: &[&str]) {
    for n in names {
        assert!(arts.iter().any(|a| a.name == *n), "missing {n}");
    }
}

/// The job's meta-mesh pair, checked: one face list, at least as many vertices as either input
/// (every input vertex is a meta-vertex), the inputs' Euler characteristic, and every vertex on
/// its own surface (within 1e-9 of its diagonal, exact projection).
pub fn meta_pair(arts: &[geom::pipeline::Artifact], s: &Mesh, t: &Mesh, what: &str, pruned: bool) -> (Mesh, Mesh) {
    let get = |n: &str| {
        let a = arts.iter().find(|a| a.name == n).unwrap_or_else(|| panic!("{what}: missing {n}"));
        geom::io::read(&a.bytes, &ReadOptions::default()).unwrap().mesh
    };
    let (ms, mt) = (get("meta_source.obj"), get("meta_target.obj"));
    assert_eq!(ms.faces(), mt.faces(), "{what}: shared faces");
    if !pruned {
        assert!(ms.n_vertices() >= s.n_vertices().max(t.n_vertices()), "{what}: {} meta vertices", ms.n_vertices());
    }
    assert_eq!(geom::topology::euler_characteristic(&ms), geom::topology::euler_characteristic(s), "{what}: χ");
    for (m, surf) in [(&ms, s), (&mt, t)] {
        let loc = geom::topology::Locator::new(surf).unwrap();
        let off = m.positions().iter().map(|p| loc.project(p).distance).fold(0.0, f64::max);
        assert!(off <= 1e-9 * surf.bbox_diagonal(), "{what}: off surface {off}");
    }
    (ms, mt)
}

/// A GLB of an OBJ file in its own (seam-split) layout with its attributes.
pub fn glb_of_obj(obj: &[u8]) -> Vec<u8> {
    let r = geom::io::read(obj, &ReadOptions::default()).expect("read obj");
    geom::io::write_layout_glb(&r.mesh, r.layout.as_ref(), &[])
}
