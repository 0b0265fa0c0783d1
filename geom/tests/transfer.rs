//! Attribute transfer through an exact map: spot onto itself (one layout without seams on the
//! target) gets its own UVs back at every corner, and its UV seams become the target's seams.

mod common;
use geom::io::ReadOptions;
use geom::map::transfer::{SourceField, TransferOptions, transfer};
use geom::topology::Locator;

#[test]
fn an_exact_map_carries_uvs_exactly_and_splits_the_seams() {
    let obj = std::fs::read(common::shared_mesh("spot.obj")).unwrap();
    let r = geom::io::read(&obj, &ReadOptions::default()).unwrap();
    let lay = r.layout.as_ref().unwrap();
    let field = SourceField { mesh: &r.mesh, layout: Some(lay), locator: Locator::new(&r.mesh).unwrap() };
    let images = r.mesh.positions().to_vec();
    let o = TransferOptions { texcoords: vec![0], ..Default::default() };
    let t = transfer(&field, &r.mesh, None, &images, &o).unwrap();
    // One output vertex per distinct (vertex, UV): the source's own split count.
    assert_eq!(t.split_vertices, lay.n_split());
    assert_eq!(t.positions.len(), lay.n_vertices());
    // Every corner carries the UV the source has at that corner.
    let uv = &t.attributes.texcoords[0];
    for (f, tri) in t.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (uv[tri[k] as usize], lay.attributes.texcoords[0][lay.triangles[f][k] as usize]);
            assert!((a[0] - b[0]).abs() < 1e-5 && (a[1] - b[1]).abs() < 1e-5, "face {f} corner {k}: {a:?} vs {b:?}");
        }
    }
}
