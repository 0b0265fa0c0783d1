//! The files a mapping job produces, as bytes: re-embedded meshes, maps as CSV, the layout as
//! JSON and the refined meshes as PLY with a patch id and a colour per face.

use super::Artifact;
use crate::domain::Patch;
use crate::domain::refine::Refined;
use crate::domain::tracer::Tracer;
use crate::error::{Error, Result};
use crate::io::{self, Format};
use crate::map::SurfaceMap;
use crate::mesh::Mesh;
use serde_json::json;

fn polyline(t: &Tracer, p: usize) -> Vec<[f64; 3]> {
    let m = t.mesh();
    t.paths()[p].points.iter().map(|q| q.position(m)).map(|x| [x.x, x.y, x.z]).collect()
}

fn color(i: u32) -> [i32; 3] {
    // Golden-ratio hue walk, full saturation.
    let h = (i as f64 * 0.618_033_988_75).fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    [(r * 255.0) as i32, (g * 255.0) as i32, (b * 255.0) as i32]
}

fn layout_ply(r: &Refined) -> Vec<u8> {
    let patch: Vec<i32> = r.patch.iter().map(|&p| p as i32).collect();
    let cols: Vec<[i32; 3]> = r.patch.iter().map(|&p| color(p)).collect();
    let (red, green, blue): (Vec<i32>, Vec<i32>, Vec<i32>) =
        (cols.iter().map(|c| c[0]).collect(), cols.iter().map(|c| c[1]).collect(), cols.iter().map(|c| c[2]).collect());
    let mut out = Vec::new();
    io::write_ply_with_face_ints(
        &r.mesh,
        &[("patch", &patch), ("red", &red), ("green", &green), ("blue", &blue)],
        &mut out,
    );
    out
}

/// Every artifact of a `voronoi` / `greedy` job except `metrics.json`.
///
/// # Errors
/// `Error::Internal` if serialisation fails.
#[allow(clippy::too_many_arguments)]
pub fn map_artifacts(
    st: &Tracer,
    tt: &Tracer,
    patches: &[Patch],
    rs: &Refined,
    rt: &Refined,
    maps: (&SurfaceMap, &SurfaceMap),
    on_target: &Mesh,
    on_source: &Mesh,
) -> Result<Vec<Artifact>> {
    let anchors: Vec<[u32; 2]> = st.anchors().iter().zip(tt.anchors()).map(|(a, b)| [a.0, b.0]).collect();
    let paths: Vec<_> = (0..st.paths().len())
        .map(|p| {
            json!({
                "anchors": [st.paths()[p].a, st.paths()[p].b],
                "source": polyline(st, p),
                "target": polyline(tt, p),
                "source_length": st.paths()[p].length,
                "target_length": tt.paths()[p].length,
            })
        })
        .collect();
    let pj: Vec<_> = patches.iter().map(|p| json!({"corners": p.corners, "paths": p.sides.map(|h| h / 2)})).collect();
    let layout = json!({ "anchors": anchors, "paths": paths, "patches": pj });
    let layout = serde_json::to_vec_pretty(&layout).map_err(|e| Error::Internal(e.to_string()))?;
    // The large encodings are independent: build them on the thread pool.
    let (mut arts, (ply_s, ply_t)) = rayon::join(
        || maps_and_meshes(maps.0, maps.1, on_target, on_source),
        || rayon::join(|| layout_ply(rs), || layout_ply(rt)),
    );
    arts.extend([
        Artifact { name: "layout.json".into(), content_type: "application/json", bytes: layout },
        Artifact { name: "layout_source.ply".into(), content_type: "application/vnd.ply", bytes: ply_s },
        Artifact { name: "layout_target.ply".into(), content_type: "application/vnd.ply", bytes: ply_t },
    ]);
    Ok(arts)
}

/// The artifacts every method writes: both re-embedded meshes and both maps as CSV.
pub fn maps_and_meshes(s2t: &SurfaceMap, t2s: &SurfaceMap, on_target: &Mesh, on_source: &Mesh) -> Vec<Artifact> {
    let ((obj_t, obj_s), (csv_st, csv_ts)) = rayon::join(
        || rayon::join(|| io::write(on_target, Format::Obj), || io::write(on_source, Format::Obj)),
        || rayon::join(|| s2t.to_csv(), || t2s.to_csv()),
    );
    vec![
        Artifact { name: "source_on_target.obj".into(), content_type: "model/obj", bytes: obj_t },
        Artifact { name: "target_on_source.obj".into(), content_type: "model/obj", bytes: obj_s },
        Artifact { name: "source_to_target.csv".into(), content_type: "text/csv", bytes: csv_st.into_bytes() },
        Artifact { name: "target_to_source.csv".into(), content_type: "text/csv", bytes: csv_ts.into_bytes() },
    ]
}
