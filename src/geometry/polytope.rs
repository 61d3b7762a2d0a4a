//! A convex polytope as a boundary representation (vertices and face loops) that is
//! cut by half-spaces without ever rebuilding a hull.
//!
//! Cutting a polytope by taking the convex hull of its kept vertices and edge
//! crossings fails on what the capped bed meets every time a pellet touches the
//! tube: a wall cap of hundreds of planes each shaving a sliver a ten-thousandth of
//! the pellet thick, whose crossings lie within round-off of the faces they cut, so
//! that the hull's visibility tests disagree and its faces come out inconsistently
//! oriented. Here each cut classifies every vertex once (outside, inside, or on the
//! plane within a tolerance), each crossed edge gets one crossing point shared by
//! its two faces, and the new face is the loop the removed part leaves open. The
//! result is closed and consistently oriented by construction, whatever the sizes.

use std::collections::HashMap;

use nalgebra::{Isometry3, Point3, Vector3};

use super::{ConvexPolyhedron, GeometryError};
use crate::Real;

/// Vertices within this fraction of the polytope's size of a cutting plane count as
/// on it: a cut never makes a crossing point closer than this to a vertex.
const ON_PLANE: Real = 1e-13;

/// A closed convex polytope: vertices and convex face loops.
///
/// Invariant: every face loop is counter-clockwise seen from outside, and every
/// directed edge of a loop appears reversed in exactly one other loop (closed,
/// consistently oriented), and every vertex is used by a face.
#[derive(Clone, Debug)]
pub struct Polytope {
    vertices: Vec<Point3<Real>>,
    faces: Vec<Vec<u32>>,
}

impl Polytope {
    /// The template `poly` placed in the world by `pose` (body to world).
    pub fn placed(poly: &ConvexPolyhedron, pose: &Isometry3<Real>) -> Self {
        Polytope {
            vertices: poly.vertices().iter().map(|v| pose * v).collect(),
            faces: (0..poly.face_count())
                .map(|f| poly.face(f).to_vec())
                .collect(),
        }
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Point3<Real>] {
        &self.vertices
    }

    /// The face loops (indices into [`Self::vertices`], counter-clockwise from
    /// outside).
    pub fn faces(&self) -> &[Vec<u32>] {
        &self.faces
    }

    /// Keeps the half-space `normal · x ≤ offset` (`normal` of unit length).
    /// Returns whether anything was cut off; an error, the polytope left as it was,
    /// if nothing would be left.
    pub fn cut(&mut self, normal: &Vector3<Real>, offset: Real) -> Result<bool, GeometryError> {
        let tolerance = ON_PLANE * self.size();
        let side: Vec<Side> = self
            .vertices
            .iter()
            .map(|x| Side::of(normal.dot(&x.coords) - offset, tolerance))
            .collect();
        if !side.iter().any(|s| s.is_out()) {
            return Ok(false);
        }
        if !side.iter().any(|s| matches!(s, Side::In(_))) {
            return Err(GeometryError::CutAway {
                count: self.vertices.len(),
            });
        }
        // Each face clipped; a crossed edge's point made once, from its inside end.
        let mut crossing: HashMap<(u32, u32), u32> = HashMap::new();
        let mut faces = Vec::with_capacity(self.faces.len() + 1);
        for face in &self.faces {
            let mut kept = Vec::with_capacity(face.len() + 1);
            for (k, &v) in face.iter().enumerate() {
                let w = face[(k + 1) % face.len()];
                if !side[v as usize].is_out() {
                    kept.push(v);
                }
                let (inside, outside, di, dout) = match (side[v as usize], side[w as usize]) {
                    (Side::In(di), Side::Out(dout)) => (v, w, di, dout),
                    (Side::Out(dout), Side::In(di)) => (w, v, di, dout),
                    _ => continue,
                };
                let id = *crossing.entry((inside, outside)).or_insert_with(|| {
                    let (a, b) = (
                        self.vertices[inside as usize],
                        self.vertices[outside as usize],
                    );
                    self.vertices.push(a + (b - a) * (di / (di - dout)));
                    (self.vertices.len() - 1) as u32
                });
                kept.push(id);
            }
            // A face left with only points on the plane lies in the new face.
            let on_plane = kept
                .iter()
                .all(|&v| side.get(v as usize).is_none_or(|s| matches!(s, Side::On)));
            if kept.len() >= 3 && !on_plane {
                faces.push(kept);
            }
        }
        let Some(cap) = open_loop(&faces) else {
            let count = self.vertices.len();
            self.vertices.truncate(side.len());
            return Err(GeometryError::CutRoundOff { count });
        };
        faces.push(cap);
        self.faces = faces;
        self.drop_unused_vertices();
        Ok(true)
    }

    /// Triangles of the faces, counter-clockwise from outside: a fan from a face's
    /// first vertex, or from its centroid (added as a vertex) where three of its
    /// vertices in a row lie on a line, so that no triangle has zero area.
    pub fn triangulate(&self) -> (Vec<Point3<Real>>, Vec<[u32; 3]>) {
        let mut vertices = self.vertices.clone();
        let mut triangles = Vec::new();
        for face in &self.faces {
            let n = face.len();
            let at = |k: usize| self.vertices[face[k % n] as usize];
            let straight = (0..n).any(|k| {
                let (a, b, c) = (at(k), at(k + 1), at(k + 2));
                let (u, v) = (b - a, c - b);
                u.cross(&v).norm() <= 1e-12 * u.norm() * v.norm()
            });
            if straight {
                let centre = face.iter().fold(Vector3::zeros(), |s, &v| {
                    s + self.vertices[v as usize].coords
                }) / n as Real;
                vertices.push(Point3::from(centre));
                let c = (vertices.len() - 1) as u32;
                triangles.extend((0..n).map(|k| [c, face[k], face[(k + 1) % n]]));
            } else {
                triangles.extend((1..n - 1).map(|k| [face[0], face[k], face[k + 1]]));
            }
        }
        (vertices, triangles)
    }

    /// Volume (divergence theorem over the faces, about a vertex to limit
    /// cancellation far from the origin).
    pub fn volume(&self) -> Real {
        let (vertices, triangles) = self.triangulate();
        let origin = vertices[0];
        triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| vertices[v as usize] - origin);
                a.dot(&b.cross(&c))
            })
            .sum::<Real>()
            / 6.0
    }

    /// Largest distance of a vertex from the first one: the length the cut
    /// tolerance scales with.
    fn size(&self) -> Real {
        let first = self.vertices[0];
        self.vertices
            .iter()
            .map(|v| (v - first).norm())
            .fold(0.0, Real::max)
    }

    fn drop_unused_vertices(&mut self) {
        let mut remap = vec![u32::MAX; self.vertices.len()];
        let mut kept = Vec::new();
        for face in &mut self.faces {
            for v in face.iter_mut() {
                if remap[*v as usize] == u32::MAX {
                    remap[*v as usize] = kept.len() as u32;
                    kept.push(self.vertices[*v as usize]);
                }
                *v = remap[*v as usize];
            }
        }
        self.vertices = kept;
    }
}

/// Where a vertex lies against a cutting plane (signed distance, outside positive).
#[derive(Clone, Copy, Debug)]
enum Side {
    In(Real),
    On,
    Out(Real),
}

impl Side {
    fn of(distance: Real, tolerance: Real) -> Self {
        if distance > tolerance {
            Side::Out(distance)
        } else if distance < -tolerance {
            Side::In(distance)
        } else {
            Side::On
        }
    }

    fn is_out(&self) -> bool {
        matches!(self, Side::Out(_))
    }
}

/// The loop closing the faces: the reverse of every directed edge whose twin is
/// missing, chained. `None` unless they form one simple loop of three or more.
fn open_loop(faces: &[Vec<u32>]) -> Option<Vec<u32>> {
    let mut edges = std::collections::HashSet::new();
    for face in faces {
        for (k, &v) in face.iter().enumerate() {
            edges.insert((v, face[(k + 1) % face.len()]));
        }
    }
    // Reversed open edges: from `b` on to `a`.
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in &edges {
        if !edges.contains(&(b, a)) && next.insert(b, a).is_some() {
            return None;
        }
    }
    let &start = next.keys().min()?;
    let mut cap = vec![start];
    let mut at = next[&start];
    while at != start {
        if cap.len() > next.len() {
            return None;
        }
        cap.push(at);
        at = *next.get(&at)?;
    }
    (cap.len() == next.len() && cap.len() >= 3).then_some(cap)
}
