//! Checked triangle meshes: the common input of particle templates and walls.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};

use super::GeometryError;
use crate::Real;

/// A triangle mesh whose vertices are finite and whose facets index valid vertices.
///
/// Nothing else is promised: closedness, orientation and convexity are checked by
/// [`TriMesh::check_closed`] and by the polyhedron builder.
#[derive(Clone, Debug, Default)]
pub struct TriMesh {
    /// Vertex positions.
    pub vertices: Vec<Point3<Real>>,
    /// Facets as vertex index triples, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
}

impl TriMesh {
    /// Builds a mesh after checking coordinates and indices.
    pub fn new(
        vertices: Vec<Point3<Real>>,
        triangles: Vec<[usize; 3]>,
    ) -> Result<Self, GeometryError> {
        for (i, v) in vertices.iter().enumerate() {
            if !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()) {
                return Err(GeometryError::NonFiniteVertex {
                    vertex: i,
                    x: v.x,
                    y: v.y,
                    z: v.z,
                });
            }
        }
        for (f, t) in triangles.iter().enumerate() {
            for &v in t {
                if v >= vertices.len() {
                    return Err(GeometryError::BadVertexIndex {
                        facet: f,
                        vertex: v,
                        count: vertices.len(),
                    });
                }
            }
        }
        Ok(TriMesh {
            vertices,
            triangles,
        })
    }

    /// Radius of the smallest origin-free bounding ball about the vertex mean; a length
    /// scale for tolerances.
    pub fn length_scale(&self) -> Real {
        let n = self.vertices.len().max(1) as Real;
        let mean = self
            .vertices
            .iter()
            .fold(Vector3::zeros(), |a, v| a + v.coords)
            / n;
        self.vertices
            .iter()
            .map(|v| (v.coords - mean).norm())
            .fold(0.0, Real::max)
    }

    /// Vector area (normal times area) of facet `f`.
    pub fn facet_area_vector(&self, f: usize) -> Vector3<Real> {
        let [a, b, c] = self.triangles[f];
        let (a, b, c) = (self.vertices[a], self.vertices[b], self.vertices[c]);
        (b - a).cross(&(c - a)) * 0.5
    }

    /// Checks that the mesh is a closed, consistently oriented 2-manifold without
    /// zero-area facets or nearly coincident vertices.
    pub fn check_closed(&self) -> Result<(), GeometryError> {
        let scale = self.length_scale();
        self.check_no_near_duplicates(scale)?;
        for f in 0..self.triangles.len() {
            let [a, b, c] = self.triangles[f];
            if self.facet_area_vector(f).norm() <= 1e-15 * scale * scale
                || a == b
                || b == c
                || a == c
            {
                return Err(GeometryError::ZeroAreaFacet { facet: f, a, b, c });
            }
        }
        // Every directed edge must appear once, and its reverse once.
        let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
        let mut undirected: HashMap<(usize, usize), usize> = HashMap::new();
        for (f, t) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if let Some(&other) = directed.get(&(a, b)) {
                    return Err(GeometryError::InconsistentOrientation {
                        f1: other,
                        f2: f,
                        a,
                        b,
                    });
                }
                directed.insert((a, b), f);
                *undirected.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut edges: Vec<_> = undirected.into_iter().collect();
        edges.sort_unstable();
        for ((a, b), count) in edges {
            if count > 2 {
                return Err(GeometryError::NonManifoldEdge { a, b, count });
            }
            if count == 1 {
                let facet = directed
                    .get(&(a, b))
                    .or_else(|| directed.get(&(b, a)))
                    .copied()
                    .unwrap_or(0);
                return Err(GeometryError::OpenEdge { a, b, facet });
            }
        }
        Ok(())
    }

    /// Rejects distinct vertices closer than a tiny fraction of the mesh size.
    fn check_no_near_duplicates(&self, scale: Real) -> Result<(), GeometryError> {
        let tol = 1e-9 * scale;
        let mut order: Vec<usize> = (0..self.vertices.len()).collect();
        order.sort_by(|&i, &j| self.vertices[i].x.total_cmp(&self.vertices[j].x));
        for (k, &i) in order.iter().enumerate() {
            for &j in &order[k + 1..] {
                if self.vertices[j].x - self.vertices[i].x > tol {
                    break;
                }
                let distance = (self.vertices[j] - self.vertices[i]).norm();
                if distance <= tol {
                    return Err(GeometryError::DuplicateVertex {
                        a: i.min(j),
                        b: i.max(j),
                        distance,
                    });
                }
            }
        }
        Ok(())
    }
}
