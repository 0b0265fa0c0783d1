//! Polygon triangulation for readers: ear clipping (Meisters 1975) in the plane of the
//! polygon's Newell normal, which handles non-convex planar polygons; a fan for degenerate ones.

use nalgebra::Vector3;

/// Appends triangles for `poly` (vertex indices into `positions`) to `out`, preserving the
/// polygon's orientation. Returns false when the polygon was degenerate and a fan was used.
pub fn triangulate_polygon(positions: &[[f64; 3]], poly: &[u32], out: &mut Vec<[u32; 3]>) -> bool {
    let n = poly.len();
    if n == 3 {
        out.push([poly[0], poly[1], poly[2]]);
        return true;
    }
    let p = |i: usize| {
        let q = positions[poly[i] as usize];
        Vector3::new(q[0], q[1], q[2])
    };
    // Newell normal.
    let mut nrm = Vector3::zeros();
    for i in 0..n {
        let (a, b) = (p(i), p((i + 1) % n));
        nrm += Vector3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    let len = nrm.norm();
    if len.is_nan() || len <= 0.0 {
        fan(poly, out);
        return false;
    }
    let nrm = nrm / len;
    let u = if nrm.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let u = (u - nrm * nrm.dot(&u)).normalize();
    let v = nrm.cross(&u);
    let pts: Vec<[f64; 2]> = (0..n).map(|i| [p(i).dot(&u), p(i).dot(&v)]).collect();
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    let mut idx: Vec<usize> = (0..n).collect();
    let start = out.len();
    let mut guard = 0usize;
    while idx.len() > 3 {
        let m = idx.len();
        let mut clipped = false;
        for i in 0..m {
            let (ia, ib, ic) = (idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]);
            let (a, b, c) = (pts[ia], pts[ib], pts[ic]);
            if cross(a, b, c) <= 0.0 {
                continue;
            }
            let inside = idx.iter().any(|&j| {
                j != ia && j != ib && j != ic && {
                    let q = pts[j];
                    cross(a, b, q) >= 0.0 && cross(b, c, q) >= 0.0 && cross(c, a, q) >= 0.0
                }
            });
            if inside {
                continue;
            }
            out.push([poly[ia], poly[ib], poly[ic]]);
            idx.remove(i);
            clipped = true;
            break;
        }
        guard += 1;
        if !clipped || guard > n {
            out.truncate(start);
            fan(poly, out);
            return false;
        }
    }
    out.push([poly[idx[0]], poly[idx[1]], poly[idx[2]]]);
    true
}

fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>) {
    for i in 1..poly.len() - 1 {
        out.push([poly[0], poly[i], poly[i + 1]]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_gives_two_triangles() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let mut out = Vec::new();
        assert!(triangulate_polygon(&p, &[0, 1, 2, 3], &mut out));
        assert_eq!(out.len(), 2);
    }

    #[test]
    fn non_convex_l_shape_has_no_outside_triangle() {
        // L-shape: fan from vertex 0 would create a triangle outside the polygon.
        let p = [[0., 0., 0.], [2., 0., 0.], [2., 1., 0.], [1., 1., 0.], [1., 2., 0.], [0., 2., 0.]];
        let mut out = Vec::new();
        assert!(triangulate_polygon(&p, &[0, 1, 2, 3, 4, 5], &mut out));
        assert_eq!(out.len(), 4);
        let area: f64 = out
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
            })
            .sum();
        assert!((area - 3.0).abs() < 1e-12, "area {area}");
        for t in &out {
            let [a, b, c] = t.map(|i| p[i as usize]);
            assert!((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0);
        }
    }
}
