//! Convex hull of a point cloud (incremental, with exact horizon bookkeeping).
//!
//! Used for random convex particles and for meshes whose user asks for the hull of a
//! non-convex particle explicitly. Points within a tiny tolerance of a hull face are
//! treated as lying on it and do not become vertices.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};

use super::{GeometryError, TriMesh};
use crate::Real;

struct HullFace {
    v: [usize; 3],
    normal: Vector3<Real>,
    offset: Real,
    alive: bool,
}

impl HullFace {
    fn new(points: &[Point3<Real>], v: [usize; 3]) -> Self {
        let n = (points[v[1]] - points[v[0]]).cross(&(points[v[2]] - points[v[0]]));
        let normal = n / n.norm();
        HullFace {
            v,
            normal,
            offset: normal.dot(&points[v[0]].coords),
            alive: true,
        }
    }

    fn height(&self, p: &Point3<Real>) -> Real {
        self.normal.dot(&p.coords) - self.offset
    }
}

/// Computes the convex hull of `points` as an outward-oriented closed triangle mesh
/// holding only the hull's vertices.
pub fn convex_hull(points: &[Point3<Real>]) -> Result<TriMesh, GeometryError> {
    let input = TriMesh::new(points.to_vec(), Vec::new())?;
    let scale = input.length_scale();
    let degenerate = GeometryError::Degenerate {
        count: points.len(),
    };
    if points.len() < 4 || scale <= 0.0 {
        return Err(degenerate);
    }
    let eps = 1e-11 * scale;

    // Initial tetrahedron from extreme points.
    let i0 = (0..points.len())
        .min_by(|&a, &b| points[a].x.total_cmp(&points[b].x))
        .unwrap_or(0);
    let far = |f: &dyn Fn(&Point3<Real>) -> Real| {
        (0..points.len())
            .max_by(|&a, &b| f(&points[a]).total_cmp(&f(&points[b])))
            .unwrap_or(0)
    };
    let i1 = far(&|p| (p - points[i0]).norm());
    let axis = points[i1] - points[i0];
    if axis.norm() <= eps {
        return Err(degenerate);
    }
    let line_distance = |p: &Point3<Real>| (p - points[i0]).cross(&axis).norm() / axis.norm();
    let i2 = far(&line_distance);
    if line_distance(&points[i2]) <= eps {
        return Err(degenerate);
    }
    let plane_normal = axis.cross(&(points[i2] - points[i0])).normalize();
    let plane_distance = |p: &Point3<Real>| plane_normal.dot(&(p - points[i0])).abs();
    let i3 = far(&plane_distance);
    if plane_distance(&points[i3]) <= eps {
        return Err(degenerate);
    }

    let mut faces: Vec<HullFace> = Vec::new();
    let mut edge_face: HashMap<(usize, usize), usize> = HashMap::new();
    let interior = Point3::from(
        (points[i0].coords + points[i1].coords + points[i2].coords + points[i3].coords) / 4.0,
    );
    let add_face = |faces: &mut Vec<HullFace>,
                    edge_face: &mut HashMap<(usize, usize), usize>,
                    mut v: [usize; 3]| {
        let mut face = HullFace::new(points, v);
        if face.height(&interior) > 0.0 {
            v.swap(1, 2);
            face = HullFace::new(points, v);
        }
        let id = faces.len();
        for k in 0..3 {
            edge_face.insert((v[k], v[(k + 1) % 3]), id);
        }
        faces.push(face);
    };
    for tri in [[i0, i1, i2], [i0, i1, i3], [i0, i2, i3], [i1, i2, i3]] {
        add_face(&mut faces, &mut edge_face, tri);
    }

    let mut visible = Vec::new();
    for (p_index, p) in points.iter().enumerate() {
        if [i0, i1, i2, i3].contains(&p_index) {
            continue;
        }
        visible.clear();
        visible.extend((0..faces.len()).filter(|&f| faces[f].alive && faces[f].height(p) > eps));
        if visible.is_empty() {
            continue;
        }
        let mut horizon = Vec::new();
        for &f in &visible {
            let v = faces[f].v;
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                let Some(&neighbour) = edge_face.get(&(b, a)) else {
                    return Err(GeometryError::HullRoundOff {
                        count: points.len(),
                        point: p_index,
                    });
                };
                if !visible.contains(&neighbour) {
                    horizon.push((a, b));
                }
            }
        }
        for &f in &visible {
            faces[f].alive = false;
            let v = faces[f].v;
            for k in 0..3 {
                edge_face.remove(&(v[k], v[(k + 1) % 3]));
            }
        }
        for (a, b) in horizon {
            // Same winding as the removed visible face: stays outward.
            let face = HullFace::new(points, [a, b, p_index]);
            let id = faces.len();
            for (x, y) in [(a, b), (b, p_index), (p_index, a)] {
                edge_face.insert((x, y), id);
            }
            faces.push(face);
        }
    }

    // Compact to the vertices in use.
    let mut remap = vec![usize::MAX; points.len()];
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for face in faces.iter().filter(|f| f.alive) {
        let t = face.v.map(|v| {
            if remap[v] == usize::MAX {
                remap[v] = vertices.len();
                vertices.push(points[v]);
            }
            remap[v]
        });
        triangles.push(t);
    }
    TriMesh::new(vertices, triangles)
}
