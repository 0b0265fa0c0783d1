//! The kernel of a star: the set of points from which a vertex sees every edge of its link on
//! its left, i.e. where it can sit without folding a triangle. Computed by clipping the link's
//! bounding box with one half-plane per link edge (Sutherland–Hodgman on a convex polygon).

use crate::param::Uv;

/// Centroid of the kernel of the link edges `(a, b)` (each triangle is `(x, a, b)`
/// counter-clockwise), or `None` when the kernel is empty or flat.
pub fn kernel_centroid(link: &[(Uv, Uv)]) -> Option<Uv> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &(a, b) in link {
        for p in [a, b] {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    let mut poly = vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
    let mut next = Vec::with_capacity(poly.len() + 4);
    for &(a, b) in link {
        // Keep points strictly left of a -> b.
        let side = |p: Uv| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
        next.clear();
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp > 0.0 {
                next.push(p);
            }
            if (sp > 0.0) != (sq > 0.0) && sp != sq {
                let t = sp / (sp - sq);
                next.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
        std::mem::swap(&mut poly, &mut next);
        if poly.len() < 3 {
            return None;
        }
    }
    // Area-weighted centroid.
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let c = p[0] * q[1] - q[0] * p[1];
        a += c;
        cx += (p[0] + q[0]) * c;
        cy += (p[1] + q[1]) * c;
    }
    if a <= 0.0 {
        return None;
    }
    Some([cx / (3.0 * a), cy / (3.0 * a)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_of_a_star_shaped_link_lies_where_every_triangle_is_positive() {
        // A non-convex star: an arrowhead whose kernel is a strict part of it.
        let ring: [Uv; 5] = [[1.0, 0.0], [0.2, 0.3], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        let link: Vec<(Uv, Uv)> = (0..5).map(|i| (ring[i], ring[(i + 1) % 5])).collect();
        let c = kernel_centroid(&link).expect("kernel");
        for (a, b) in &link {
            assert!(crate::quad::stretch::area2(c, *a, *b) > 0.0);
        }
        // A link whose kernel is empty (a fold): a reversed edge.
        let bad = vec![([0.0, 0.0], [1.0, 0.0]), ([1.0, 1.0], [0.0, 1.0]), ([0.0, 1.0], [1.0, 1.0])];
        assert!(kernel_centroid(&bad).is_none());
    }
}
