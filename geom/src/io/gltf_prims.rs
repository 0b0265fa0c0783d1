//! Primitives of a glTF scene merged into one [`SplitMesh`]: positions and normals through each
//! node's world matrix (normals by its inverse transpose; winding reversed where the matrix
//! mirrors), attributes kept only when every primitive has them.

use crate::error::{Result, parse_err};
use crate::mesh::{SplitMesh, Warning};
use nalgebra::{Matrix3, Matrix4, Point3, Vector3};

/// One triangle primitive's data as read (components flattened, with their count per element).
pub(crate) struct Primitive {
    pub world: [[f64; 4]; 4],
    pub positions: Vec<f64>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<(Vec<f64>, usize)>,
    pub texcoords: Vec<(Vec<f64>, usize)>,
    pub color: Option<(Vec<f64>, usize)>,
    pub joints: Option<(Vec<f64>, usize)>,
    pub weights: Option<(Vec<f64>, usize)>,
}

/// Attributes present in every primitive so far (`None` once one lacks it).
#[derive(Default)]
pub(crate) struct Accumulator {
    out: SplitMesh,
    prims: usize,
    dropped: Vec<String>,
}

fn chunks<const N: usize, T: Copy + Default>(v: &[f64], n: usize, f: impl Fn(f64) -> T, fill: T) -> Vec<[T; N]> {
    v.chunks_exact(n)
        .map(|c| {
            let mut a = [fill; N];
            for (k, x) in a.iter_mut().enumerate() {
                if k < n {
                    *x = f(c[k]);
                }
            }
            a
        })
        .collect()
}

impl Accumulator {
    pub fn warn(&mut self, w: Warning) {
        self.out.warnings.push(w);
    }
    pub fn n_vertices(&self) -> usize {
        self.out.positions.len()
    }
    pub fn n_triangles(&self) -> usize {
        self.out.triangles.len()
    }

    fn keep<T>(slot: &mut Option<Vec<T>>, first: bool, new: Option<Vec<T>>, name: &str, dropped: &mut Vec<String>) {
        if first {
            *slot = new;
            return;
        }
        match (slot.as_mut(), new) {
            (Some(s), Some(n)) => s.extend(n),
            (None, None) => {}
            _ => {
                *slot = None;
                dropped.push(name.to_string());
            }
        }
    }

    /// Adds a primitive.
    ///
    /// # Errors
    /// `Parse` for a position accessor that is not 3D or a singular world matrix.
    pub fn push(&mut self, p: Primitive) -> Result<()> {
        let m = Matrix4::from_column_slice(&p.world.concat());
        let lin: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into();
        let normal_m = lin
            .try_inverse()
            .map(|i| i.transpose())
            .ok_or_else(|| parse_err("glTF", "nodes", "a node's world matrix is singular (zero scale)"))?;
        let mirror = lin.determinant() < 0.0;
        let base = self.out.positions.len() as u32;
        if !p.positions.len().is_multiple_of(3) {
            return Err(parse_err("glTF", "POSITION", "positions must be VEC3"));
        }
        self.out.positions.extend(p.positions.chunks_exact(3).map(|c| {
            let q = m.transform_point(&Point3::new(c[0], c[1], c[2]));
            [q.x, q.y, q.z]
        }));
        self.out.triangles.extend(p.triangles.iter().map(|t| {
            let t = t.map(|i| i + base);
            if mirror { [t[0], t[2], t[1]] } else { t }
        }));
        let first = self.prims == 0;
        self.prims += 1;
        let normals = p.normals.map(|(v, n)| {
            chunks::<3, f64>(&v, n, |x| x, 0.0)
                .into_iter()
                .map(|c| {
                    let q = (normal_m * Vector3::from(c)).normalize();
                    [q.x as f32, q.y as f32, q.z as f32]
                })
                .collect()
        });
        let a = &mut self.out.attributes;
        Self::keep(&mut a.normals, first, normals, "NORMAL", &mut self.dropped);
        let color = p.color.map(|(v, n)| chunks::<4, f32>(&v, n, |x| x as f32, 1.0));
        Self::keep(&mut a.color, first, color, "COLOR_0", &mut self.dropped);
        let joints = p.joints.map(|(v, n)| chunks::<4, u16>(&v, n, |x| x as u16, 0));
        Self::keep(&mut a.joints, first, joints, "JOINTS_0", &mut self.dropped);
        let weights = p.weights.map(|(v, n)| chunks::<4, f32>(&v, n, |x| x as f32, 0.0));
        Self::keep(&mut a.weights, first, weights, "WEIGHTS_0", &mut self.dropped);
        let tc: Vec<Vec<[f32; 2]>> =
            p.texcoords.iter().map(|(v, n)| chunks::<2, f32>(v, *n, |x| x as f32, 0.0)).collect();
        if first {
            a.texcoords = tc;
        } else {
            let k = a.texcoords.len().min(tc.len());
            if k < a.texcoords.len().max(tc.len()) {
                self.dropped.push(format!("TEXCOORD_{k}.."));
            }
            a.texcoords.truncate(k);
            for (s, t) in a.texcoords.iter_mut().zip(tc) {
                s.extend(t);
            }
        }
        Ok(())
    }

    pub fn finish(mut self) -> SplitMesh {
        if !self.dropped.is_empty() {
            self.dropped.sort();
            self.dropped.dedup();
            let msg = format!("attributes not on every primitive were dropped: {}", self.dropped.join(", "));
            self.out.warnings.push(Warning::new("attributes_dropped", msg));
        }
        self.out
    }
}
