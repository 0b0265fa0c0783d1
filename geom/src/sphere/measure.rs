//! How an image triangle is measured on the surface it lands on.
//!
//! Each vertex's sphere point has an *image* in space ([`SphereImage`]): the point itself for a
//! sphere embedding, the point carried onto a target surface for a map between surfaces. An
//! image triangle is measured by its chord in its own plane ([`Measure::Upright`], the
//! evaluator's energy), refused when it is turned over ([`upright`]: its normal opposes the
//! surface under its corners), or by its projection on its corners' smooth normals with
//! Garanzha et al.'s `χ(D, ε)` in place of its determinant ([`Measure::Untangle`]), finite on
//! turned-over images.

use crate::mesh::{P3, V3};
use crate::optim::RestTriangle;
use crate::optim::sym_dirichlet::{Derivatives, IDENTITY, Mat2};

/// Where a vertex's sphere point lands in space, its derivatives along the tangent frame, and
/// which way is out there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Image {
    pub x: P3,
    pub d: [V3; 2],
    /// The unit normal of the surface face the point lands in.
    pub up: V3,
    /// Whether the point sits on a vertex of the surface (as an anchor does): which face is
    /// under a triangle there depends on the triangle ([`SphereImage::up_at`]).
    pub at_vertex: bool,
    /// A normal that varies continuously with the point (vertex normals interpolated across
    /// the face), for the untangling energy, which must not jump where `up` changes face.
    pub smooth: V3,
}

/// Where a vertex's sphere point lands in space, how it moves, and which way is out there.
pub trait SphereImage: Sync {
    /// The image of vertex `v` placed at `p`, with derivatives along the tangent frame `frame`
    /// at `p`; `None` where it has none.
    fn image(&self, v: u32, p: &P3, frame: &[V3; 2]) -> Option<Image>;
    /// The unit normal of the surface face under the sphere point `p`, found from where
    /// vertex `near` was last.
    fn up_at(&self, near: u32, p: &P3) -> V3;
}

/// The sphere itself: the image of a point is the point (a sphere embedding's energy).
pub struct OnSphere;

impl SphereImage for OnSphere {
    fn image(&self, _v: u32, p: &P3, frame: &[V3; 2]) -> Option<Image> {
        Some(Image { x: *p, d: *frame, up: p.coords, at_vertex: false, smooth: p.coords })
    }
    fn up_at(&self, _near: u32, p: &P3) -> V3 {
        p.coords
    }
}

/// Whether triangle `tri`'s image is upright: its normal agrees with the sum of the surface
/// normals under its corners. Then it agrees with at least one of them, so it is not a flip
/// as the evaluator counts one (a face whose normal opposes the surface under every corner
/// and under its centroid). A corner on a surface vertex takes the face its triangle leaves
/// the vertex through: the face under a point of the spherical triangle just inside that
/// corner (a vertex's own normal, or the face nearest by centroid, called 13 and 26 faces of
/// the cow's identity map turned over at its sharp vertices). (The normal under the centroid
/// on the sphere alone let chords across a crease pass that oppose every corner: plane ->
/// bird 5 and 2 evaluator flips with none seen.)
pub(super) fn upright<I: SphereImage>(image: &I, s: &[P3], tri: [u32; 3], images: [&Image; 3]) -> bool {
    let n = (images[1].x - images[0].x).cross(&(images[2].x - images[0].x));
    n.dot(&(0..3).map(|k| corner_up(image, s, tri, images, k)).sum()) > 0.0
}

/// The surface normal under corner `k` of triangle `tri` ([`upright`]).
fn corner_up<I: SphereImage>(image: &I, s: &[P3], tri: [u32; 3], images: [&Image; 3], k: usize) -> V3 {
    if !images[k].at_vertex {
        return images[k].up;
    }
    let [a, b, c] = [k, (k + 1) % 3, (k + 2) % 3].map(|i| s[tri[i] as usize].coords);
    image.up_at(tri[k], &P3::from((a * (1.0 - 2.0 * CORNER_INSET) + (b + c) * CORNER_INSET).normalize()))
}

/// How far inside a corner, as a fraction of the way to the other corners, the face under a
/// corner on a surface vertex is looked up.
const CORNER_INSET: f64 = 1e-3;

/// The smooth normal under the image triangle: the sum of its corners' smooth normals. (The
/// smooth normal under its centroid on the sphere gave lower distortion where it worked but
/// left more images turned over: cat -> lion 2 and 1 evaluator flips against 0 and 0, SMPL
/// with 12 anchors 23 and 17 against 35 and 14, plane -> bird 4 and 2 against 0 and 0.)
pub(super) fn smooth_up(images: [&Image; 3]) -> V3 {
    images[0].smooth + images[1].smooth + images[2].smooth
}

/// How an image triangle is measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measure {
    /// The chord in its own plane (what the evaluator measures); a turned-over image has
    /// infinite energy, so a start without one never gets one.
    Upright,
    /// The chord projected on the plane normal to its corners' smooth normals, its signed
    /// Jacobian determinant `D` replaced by `χ(D, ε) = (D + √(ε² + D²)) / 2` (Garanzha et al.
    /// 2021): finite on turned-over images, which it turns back ([`SphereNewton::untangle`]).
    Untangle(f64),
}

/// The chord `x` projected on the plane normal to `up`, in that plane's coordinates (`x0` at
/// the origin, `x1` on the first axis), and the plane's axes; the layout's orientation is the
/// image's against `up`. `None` when degenerate.
pub fn projected_layout(x: [P3; 3], up: &V3) -> Option<([[f64; 2]; 3], [V3; 2])> {
    let n = up.try_normalize(0.0)?;
    let (e1, e2) = (x[1] - x[0], x[2] - x[0]);
    let flat = |e: &V3| e - n * n.dot(e);
    let u = flat(&e1).try_normalize(0.0).or_else(|| flat(&e2).try_normalize(0.0))?;
    let w = n.cross(&u);
    let l = [[0.0, 0.0], [e1.dot(&u), e1.dot(&w)], [e2.dot(&u), e2.dot(&w)]];
    l.iter().flatten().all(|c| c.is_finite()).then_some((l, [u, w]))
}

impl Measure {
    /// The triangle's layout and axes as this measure sees it; `None` when refused.
    /// `upright` says whether the image is upright ([`upright`]).
    /// `frozen`, when given, is the normal an [`Measure::Untangle`] projection is taken on (a
    /// line search holds the normals of its start, so the energy it searches is the one the
    /// Newton step was computed for).
    pub(super) fn layout(
        self,
        images: [&Image; 3],
        upright: impl Fn() -> bool,
        frozen: Option<&V3>,
    ) -> Option<([[f64; 2]; 3], [V3; 2])> {
        match self {
            Measure::Upright => upright().then(|| chord_layout(images.map(|i| i.x))).flatten(),
            Measure::Untangle(_) => projected_layout(images.map(|i| i.x), frozen.unwrap_or(&smooth_up(images))),
        }
    }

    pub(super) fn energy(self, rest: &RestTriangle, x: [[f64; 2]; 3]) -> Option<f64> {
        match self {
            Measure::Upright => rest.energy_in(x, &IDENTITY),
            Measure::Untangle(eps) => rest.energy_eps(x, &IDENTITY, eps),
        }
    }

    pub(super) fn derivatives(self, rest: &RestTriangle, x: [[f64; 2]; 3], m: &[Mat2; 3]) -> Option<Derivatives> {
        match self {
            Measure::Upright => rest.derivatives_in(x, &IDENTITY, m),
            Measure::Untangle(eps) => rest.derivatives_eps(x, &IDENTITY, m, eps),
        }
    }
}

/// The chord triangle `x` in its own plane (`x0` at the origin, `x1` on the first axis), and
/// the frame's two axes; `None` when degenerate.
pub fn chord_layout(x: [P3; 3]) -> Option<([[f64; 2]; 3], [V3; 2])> {
    let (e1, e2) = (x[1] - x[0], x[2] - x[0]);
    let l1 = e1.norm();
    let n = e1.cross(&e2);
    let nn = n.norm();
    if l1 <= 0.0 || nn <= 0.0 || !nn.is_finite() {
        return None;
    }
    let u = e1 / l1;
    let w = (n / nn).cross(&u);
    Some(([[0.0, 0.0], [l1, 0.0], [e2.dot(&u), e2.dot(&w)]], [u, w]))
}
