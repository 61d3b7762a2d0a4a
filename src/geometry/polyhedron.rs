//! Convex polyhedron particle templates.

use std::collections::HashMap;

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::plane::{PlaneSoa, PointSoa};
use super::{GeometryError, MassProperties, Plane, TriMesh};
use crate::Real;

/// Two triangle normals closer than this (`1 - n1·n2`) belong to one polygon face.
const COPLANAR_TOLERANCE: Real = 5e-12;
/// Convexity tolerance relative to the mesh size: a dent smaller than this is
/// round-off (STL stores single precision, 6e-8 relative, and extrapolating a small
/// triangle's plane across a large face multiplies that error).
const CONVEXITY_TOLERANCE: Real = 1e-6;
/// Above this many vertices, support queries climb the vertex graph instead of
/// scanning every vertex.
const HILL_CLIMB_THRESHOLD: usize = 48;

/// A convex polyhedron in its body frame: the principal frame of inertia, with the
/// origin at the centroid.
///
/// Invariants:
/// - faces are convex polygons, counter-clockwise seen from outside, each with one
///   outward unit normal; coplanar input triangles are merged into one face;
/// - every vertex lies on or behind every face plane (to round-off);
/// - the inertia tensor is diagonal in this frame (`principal_inertia`).
///
/// The fields a kept contact reads of the template itself come first, in one cache
/// line (hence `repr(C)`; see [`Self::contact_memory`]).
#[derive(Clone, Debug)]
#[repr(C)]
pub struct ConvexPolyhedron {
    vertices: Vec<Point3<Real>>,
    planes: Vec<Plane>,
    circumradius: Real,
    /// Vertex indices of all face loops, concatenated.
    face_loops: Vec<u32>,
    /// `face_loops[face_starts[f]..face_starts[f + 1]]` is face `f`.
    face_starts: Vec<u32>,
    /// The same planes in structure-of-arrays form (for the overlap kernel).
    plane_soa: PlaneSoa,
    /// The vertices in structure-of-arrays form (for the overlap kernel).
    vertex_soa: PointSoa,
    /// Per face, bit `v` set for each of its vertices `v < 128` (for the overlap
    /// kernel's bit-mask path, used only on shapes of at most 128 vertices).
    face_vertex_masks: Vec<u128>,
    edges: Vec<[u32; 2]>,
    /// Vertex adjacency in compressed rows (for hill-climbing support queries).
    neighbour_starts: Vec<u32>,
    neighbours: Vec<u32>,
    /// Bounding sphere (centre, radius) of every face, for culling on large meshes.
    face_spheres: Vec<(Point3<Real>, Real)>,
    volume: Real,
    /// Radius of the sphere of equal volume (kept: contact laws read it per pair).
    equivalent_radius: Real,
    principal_inertia: Vector3<Real>,
    /// Maps body coordinates to the coordinates of the mesh it was built from.
    body_to_input: Isometry3<Real>,
}

/// What a kept contact reads of the template itself: its vertices, its planes and its
/// circumradius (the coplanarity tolerance), in the first cache line.
const CONTACT_HEADER: usize =
    std::mem::offset_of!(ConvexPolyhedron, circumradius) + size_of::<Real>();
const _: () = assert!(CONTACT_HEADER <= 64);

impl ConvexPolyhedron {
    /// Builds a template from a closed, convex triangle mesh given in any frame.
    ///
    /// The mesh is checked (closed, manifold, consistently oriented, convex, no
    /// zero-area facets, no coincident vertices); an inside-out mesh is flipped.
    pub fn from_convex_mesh(mesh: &TriMesh) -> Result<Self, GeometryError> {
        mesh.check_closed()?;
        let mut mesh = mesh.clone();
        let mut mass = MassProperties::of_mesh(&mesh.vertices, &mesh.triangles);
        if mass.volume < 0.0 {
            for t in &mut mesh.triangles {
                t.swap(1, 2);
            }
            mass = MassProperties::of_mesh(&mesh.vertices, &mesh.triangles);
        }
        let scale = mesh.length_scale();
        if !(mass.volume > 1e-12 * scale.powi(3)) {
            return Err(GeometryError::Degenerate {
                count: mesh.vertices.len(),
            });
        }
        check_convex(&mesh, scale)?;

        let rotation = principal_rotation(&mass.inertia);
        let body_to_input = Isometry3::from_parts(
            Translation3::from(mass.centroid.coords),
            UnitQuaternion::from_rotation_matrix(&rotation),
        );
        let body_vertices: Vec<Point3<Real>> = mesh
            .vertices
            .iter()
            .map(|v| body_to_input.inverse_transform_point(v))
            .collect();
        let principal = rotation.matrix().transpose() * mass.inertia * rotation.matrix();
        let principal_inertia = principal.diagonal();

        let loops = merge_coplanar_faces(&body_vertices, &mesh.triangles);
        Ok(Self::from_face_loops(
            body_vertices,
            loops,
            mass.volume,
            principal_inertia,
            body_to_input,
        ))
    }

    /// Builds a template from the convex hull of `points`.
    pub fn from_hull(points: &[Point3<Real>]) -> Result<Self, GeometryError> {
        Self::from_convex_mesh(&super::convex_hull(points)?)
    }

    /// Assembles the template from body-frame vertices and face loops, dropping
    /// vertices no face uses (such as the centre of a fan-triangulated cap).
    fn from_face_loops(
        vertices: Vec<Point3<Real>>,
        loops: Vec<Vec<usize>>,
        volume: Real,
        principal_inertia: Vector3<Real>,
        body_to_input: Isometry3<Real>,
    ) -> Self {
        let mut remap = vec![u32::MAX; vertices.len()];
        let mut kept = Vec::new();
        let mut face_loops = Vec::new();
        let mut face_starts = vec![0u32];
        for face in &loops {
            for &v in face {
                if remap[v] == u32::MAX {
                    remap[v] = kept.len() as u32;
                    kept.push(vertices[v]);
                }
                face_loops.push(remap[v]);
            }
            face_starts.push(face_loops.len() as u32);
        }
        let vertices = kept;

        let mut planes = Vec::with_capacity(loops.len());
        let mut face_spheres = Vec::with_capacity(loops.len());
        let mut edge_set = std::collections::BTreeSet::new();
        for f in 0..loops.len() {
            let ids = &face_loops[face_starts[f] as usize..face_starts[f + 1] as usize];
            let pts: Vec<Point3<Real>> = ids.iter().map(|&i| vertices[i as usize]).collect();
            planes.push(Plane::fit_polygon(&pts));
            let centre = Point3::from(
                pts.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / pts.len() as Real,
            );
            let radius = pts.iter().map(|p| (p - centre).norm()).fold(0.0, Real::max);
            face_spheres.push((centre, radius));
            for k in 0..ids.len() {
                let (a, b) = (ids[k], ids[(k + 1) % ids.len()]);
                edge_set.insert([a.min(b), a.max(b)]);
            }
        }
        let edges: Vec<[u32; 2]> = edge_set.into_iter().collect();

        let mut adjacency = vec![Vec::new(); vertices.len()];
        for &[a, b] in &edges {
            adjacency[a as usize].push(b);
            adjacency[b as usize].push(a);
        }
        let mut neighbour_starts = vec![0u32];
        let mut neighbours = Vec::new();
        for list in adjacency {
            neighbours.extend(list);
            neighbour_starts.push(neighbours.len() as u32);
        }
        let circumradius = vertices
            .iter()
            .map(|v| v.coords.norm())
            .fold(0.0, Real::max);
        let mut plane_soa = PlaneSoa::default();
        plane_soa.fill(&planes);
        let mut vertex_soa = PointSoa::default();
        vertex_soa.fill(&vertices);
        let face_vertex_masks = (0..loops.len())
            .map(|f| {
                face_loops[face_starts[f] as usize..face_starts[f + 1] as usize]
                    .iter()
                    .filter(|&&v| v < 128)
                    .fold(0u128, |m, &v| m | 1 << v)
            })
            .collect();
        ConvexPolyhedron {
            vertices,
            face_loops,
            face_starts,
            planes,
            plane_soa,
            vertex_soa,
            face_vertex_masks,
            edges,
            neighbour_starts,
            neighbours,
            face_spheres,
            volume,
            equivalent_radius: (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt(),
            principal_inertia,
            circumradius,
            body_to_input,
        }
    }

    /// Vertices in the body frame.
    pub fn vertices(&self) -> &[Point3<Real>] {
        &self.vertices
    }

    /// Number of (merged, polygonal) faces.
    pub fn face_count(&self) -> usize {
        self.planes.len()
    }

    /// Vertex indices of face `f`, counter-clockwise seen from outside.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_loops[self.face_starts[f] as usize..self.face_starts[f + 1] as usize]
    }

    /// Outward supporting planes of the faces, in the body frame.
    pub fn planes(&self) -> &[Plane] {
        &self.planes
    }

    /// Face planes in structure-of-arrays form, padded to a multiple of four.
    pub(crate) fn plane_soa(&self) -> &PlaneSoa {
        &self.plane_soa
    }

    /// Vertices in structure-of-arrays form, padded to a multiple of four.
    pub(crate) fn vertex_soa(&self) -> &PointSoa {
        &self.vertex_soa
    }

    /// Per face, its vertex set as bits (vertices below 128 only).
    pub(crate) fn face_vertex_masks(&self) -> &[u128] {
        &self.face_vertex_masks
    }

    /// Bounding sphere of each face (centre, radius), in the body frame.
    pub fn face_spheres(&self) -> &[(Point3<Real>, Real)] {
        &self.face_spheres
    }

    /// Undirected edges between distinct faces.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// Volume.
    pub fn volume(&self) -> Real {
        self.volume
    }

    /// Surface area: the sum of the faces' areas.
    pub fn surface_area(&self) -> Real {
        (0..self.face_count())
            .map(|f| {
                let face: Vec<Point3<Real>> = self
                    .face(f)
                    .iter()
                    .map(|&k| self.vertices[k as usize])
                    .collect();
                super::vector_area(&face).norm()
            })
            .sum()
    }

    /// Centroid in the body frame: the origin, by construction.
    pub fn centroid(&self) -> Point3<Real> {
        Point3::origin()
    }

    /// Principal moments of inertia per unit density (the diagonal of the inertia
    /// tensor in the body frame).
    pub fn principal_inertia(&self) -> Vector3<Real> {
        self.principal_inertia
    }

    /// Largest distance of a vertex from the centroid.
    pub fn circumradius(&self) -> Real {
        self.circumradius
    }

    /// Radius of the sphere of equal volume.
    pub fn equivalent_radius(&self) -> Real {
        self.equivalent_radius
    }

    /// The pose of the body frame in the frame of the mesh it was built from.
    pub fn body_to_input(&self) -> &Isometry3<Real> {
        &self.body_to_input
    }

    /// Fan triangulation of the faces (for output and wall meshes).
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        for f in 0..self.face_count() {
            let ids = self.face(f);
            for k in 1..ids.len() - 1 {
                out.push([ids[0], ids[k], ids[k + 1]]);
            }
        }
        out
    }

    /// Where in memory lies what the overlap of a kept contact reads of this
    /// template: the fields of the template it reads, its vertices and its planes, as
    /// address ranges (for software prefetch, which reads nothing: nothing may be
    /// read through them).
    pub fn contact_memory(&self) -> [std::ops::Range<usize>; 3] {
        let range = |start: usize, bytes: usize| start..start + bytes;
        [
            range(std::ptr::from_ref(self).addr(), CONTACT_HEADER),
            range(
                self.vertices.as_ptr().addr(),
                size_of_val(&self.vertices[..]),
            ),
            range(self.planes.as_ptr().addr(), size_of_val(&self.planes[..])),
        ]
    }

    /// Index of a vertex farthest along `dir` (body frame). `hint` is a vertex to
    /// start from on large meshes (the previous answer makes repeated queries cheap).
    #[inline]
    pub fn support_index(&self, dir: &Vector3<Real>, hint: usize) -> usize {
        if self.vertices.len() <= HILL_CLIMB_THRESHOLD {
            let mut best = 0;
            let mut best_dot = Real::NEG_INFINITY;
            for (i, v) in self.vertices.iter().enumerate() {
                let d = v.coords.dot(dir);
                if d > best_dot {
                    best_dot = d;
                    best = i;
                }
            }
            return best;
        }
        // A linear function on a convex polytope has no local maxima on the vertex
        // graph other than the global one.
        let mut current = hint.min(self.vertices.len() - 1);
        let mut current_dot = self.vertices[current].coords.dot(dir);
        loop {
            let mut moved = false;
            let range = self.neighbour_starts[current] as usize
                ..self.neighbour_starts[current + 1] as usize;
            for &n in &self.neighbours[range] {
                let d = self.vertices[n as usize].coords.dot(dir);
                if d > current_dot {
                    current_dot = d;
                    current = n as usize;
                    moved = true;
                }
            }
            if !moved {
                return current;
            }
        }
    }

    /// Scales the template by `factor` about its centroid.
    pub fn scaled(&self, factor: Real) -> Self {
        let mut out = self.clone();
        for v in &mut out.vertices {
            *v *= factor;
        }
        for p in &mut out.planes {
            p.offset *= factor;
        }
        out.plane_soa.fill(&out.planes);
        out.vertex_soa.fill(&out.vertices);
        for s in &mut out.face_spheres {
            s.0 *= factor;
            s.1 *= factor;
        }
        out.volume *= factor.powi(3);
        out.principal_inertia *= factor.powi(5);
        out.circumradius *= factor;
        out.equivalent_radius *= factor;
        out.body_to_input.translation.vector *= factor;
        out
    }
}

/// Rejects meshes with a vertex in front of some facet plane.
fn check_convex(mesh: &TriMesh, scale: Real) -> Result<(), GeometryError> {
    let tol = CONVEXITY_TOLERANCE * scale;
    for (f, t) in mesh.triangles.iter().enumerate() {
        let n = mesh.facet_area_vector(f).normalize();
        let origin = mesh.vertices[t[0]];
        for (v, p) in mesh.vertices.iter().enumerate() {
            let distance = n.dot(&(p - origin));
            if distance > tol {
                return Err(GeometryError::NotConvex {
                    vertex: v,
                    facet: f,
                    distance,
                });
            }
        }
    }
    Ok(())
}

/// Rotation whose columns are the principal axes, matched to the input axes they are
/// closest to (so that an axis-aligned cuboid stays axis-aligned), right-handed.
fn principal_rotation(inertia: &Matrix3<Real>) -> Rotation3<Real> {
    let off = inertia[(0, 1)].abs() + inertia[(0, 2)].abs() + inertia[(1, 2)].abs();
    if off <= 1e-12 * inertia.trace().abs() {
        return Rotation3::identity();
    }
    let eigen = inertia.symmetric_eigen();
    let mut columns: Vec<Vector3<Real>> = (0..3)
        .map(|k| eigen.eigenvectors.column(k).into())
        .collect();
    let mut axes = [Vector3::zeros(); 3];
    for axis in 0..3 {
        let (k, _) = columns
            .iter()
            .enumerate()
            .max_by(|a, b| a.1[axis].abs().total_cmp(&b.1[axis].abs()))
            .unwrap_or((0, &columns[0]));
        let mut v = columns.remove(k);
        if v[axis] < 0.0 {
            v = -v;
        }
        axes[axis] = v;
    }
    if axes[0].cross(&axes[1]).dot(&axes[2]) < 0.0 {
        axes[2] = -axes[2];
    }
    let m = Matrix3::from_columns(&axes);
    // Re-orthonormalise against round-off in the eigen solver.
    Rotation3::from_matrix_eps(&m, 1e-15, 32, Rotation3::identity())
}

/// Groups edge-connected coplanar triangles and returns each group's boundary loop,
/// with collinear boundary vertices removed.
fn merge_coplanar_faces(vertices: &[Point3<Real>], triangles: &[[usize; 3]]) -> Vec<Vec<usize>> {
    let normals: Vec<Vector3<Real>> = triangles
        .iter()
        .map(|t| {
            (vertices[t[1]] - vertices[t[0]])
                .cross(&(vertices[t[2]] - vertices[t[0]]))
                .normalize()
        })
        .collect();
    let mut edge_owner: HashMap<(usize, usize), usize> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            edge_owner.insert((t[k], t[(k + 1) % 3]), f);
        }
    }
    // Flood-fill groups across edges whose two triangles are coplanar.
    let mut group = vec![usize::MAX; triangles.len()];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for seed in 0..triangles.len() {
        if group[seed] != usize::MAX {
            continue;
        }
        let id = groups.len();
        let mut members = vec![seed];
        group[seed] = id;
        let mut stack = vec![seed];
        while let Some(f) = stack.pop() {
            let t = triangles[f];
            for k in 0..3 {
                if let Some(&g) = edge_owner.get(&(t[(k + 1) % 3], t[k]))
                    && group[g] == usize::MAX
                    && 1.0 - normals[seed].dot(&normals[g]) < COPLANAR_TOLERANCE
                {
                    group[g] = id;
                    members.push(g);
                    stack.push(g);
                }
            }
        }
        groups.push(members);
    }

    let mut loops = Vec::with_capacity(groups.len());
    for (id, members) in groups.iter().enumerate() {
        // Boundary edges: directed edges whose twin lies in another group.
        let mut next: HashMap<usize, usize> = HashMap::new();
        for &f in members {
            let t = triangles[f];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if edge_owner.get(&(b, a)).map(|&g| group[g]) != Some(id) {
                    next.insert(a, b);
                }
            }
        }
        let start = *next.keys().min().unwrap_or(&0);
        let mut ring = vec![start];
        let mut v = next[&start];
        while v != start && ring.len() <= next.len() {
            ring.push(v);
            v = next[&v];
        }
        // Drop collinear vertices (they lie on an edge shared with another face).
        let n = normals[members[0]];
        let mut cleaned: Vec<usize> = Vec::with_capacity(ring.len());
        for k in 0..ring.len() {
            let prev = vertices[ring[(k + ring.len() - 1) % ring.len()]];
            let here = vertices[ring[k]];
            let after = vertices[ring[(k + 1) % ring.len()]];
            let e1 = here - prev;
            let e2 = after - here;
            if e1.cross(&e2).dot(&n) > 1e-12 * e1.norm() * e2.norm() {
                cleaned.push(ring[k]);
            }
        }
        loops.push(cleaned);
    }
    loops
}
