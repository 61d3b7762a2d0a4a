//! The combinatorial structure of an intersection `A ∩ B`, read off the clipping and
//! kept between steps.
//!
//! In general position every vertex of the intersection polyhedron P is one of four
//! kinds: a vertex of A inside B, a vertex of B inside A, an edge of A crossing a face
//! plane of B, or an edge of B crossing a face plane of A. Each face of P is a loop of
//! such vertices on one face plane of A or B. This labelling is the *topology* of P.
//!
//! It changes only when a vertex of one shape crosses a face plane of the other, or an
//! edge of one shape crosses an edge of the other: these are the only events at which
//! the boundaries of two convex polyhedra meet other than transversally. Each such
//! event takes some vertex of P onto a plane it does not lie on; so while every vertex
//! of the topology stays inside every other plane ([`validity`]), the topology is that
//! of the current pose, and P is evaluated from it directly: each vertex of P once, by
//! one cut of an edge, instead of the repeated cuts of clipping every face.
//!
//! The labels are read off a Sutherland–Hodgman clipping that tracks, for every
//! polygon vertex, what it lies on. They are put in a canonical order (vertices sorted
//! by label, each loop starting at its least vertex), so the topology is a function of
//! the combinatorial type alone: a fresh overlap and a kept one evaluate the same
//! topology in the same order, bit for bit.
//!
//! Touching configurations (a vertex of P within the coplanarity tolerance of another
//! plane, flush faces) have no such labelling; the plan is clipped as it is there.

mod edge_slack;
mod validity;

pub(super) use edge_slack::{NearEdge, edge_slack};

use nalgebra::Point3;

use super::masked::{FacePlan, bits};
use super::{OverlapGeometry, OverlapScratch, Pieces, summarise};
use crate::Real;
use crate::geometry::polygon::cut;
use crate::geometry::{ConvexPolyhedron, Plane};

/// Most vertices, faces and loop entries a kept topology holds (a shallow contact of
/// dodecahedra has about ten vertices on five faces).
const MAX_VERTICES: usize = 24;
const MAX_FACES: usize = 12;
const MAX_LOOP: usize = 72;

/// What a vertex of P is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
#[repr(u8)]
enum Kind {
    /// Vertex `inside` of A.
    #[default]
    VertexOfA,
    /// Vertex `inside` of B.
    VertexOfB,
    /// The edge of A from `inside` to `outside` cut by plane `plane` of B.
    EdgeOfA,
    /// The edge of B from `inside` to `outside` cut by plane `plane` of A.
    EdgeOfB,
    /// A point of the clipping that is none of these: where the line of a cut meets
    /// a plane beyond the edge it would have to lie on. Such points are clipped away
    /// later; one left in a final polygon means the configuration has no labelling.
    Unlabelled,
}

/// A vertex of P by what it lies on. For an edge cut, `inside` is the endpoint
/// behind the cutting plane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct VertexLabel {
    kind: Kind,
    inside: u8,
    outside: u8,
    plane: u8,
}

impl VertexLabel {
    /// The label's identity: the same vertex reached from different faces compares
    /// equal.
    fn key(&self) -> (Kind, u8, u8, u8) {
        let (lo, hi) = if self.inside <= self.outside {
            (self.inside, self.outside)
        } else {
            (self.outside, self.inside)
        };
        (self.kind, lo, hi, self.plane)
    }
}

/// A face of P: face `face` of A, or of B with `of_b`, bounded by the loop
/// `loops[start..start + len]` (counter-clockwise about the face's outward normal).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct LoopFace {
    face: u8,
    of_b: bool,
    start: u8,
    len: u8,
}

/// The topology of one intersection (see the module docs).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Topology {
    vertices: [VertexLabel; MAX_VERTICES],
    faces: [LoopFace; MAX_FACES],
    loops: [u8; MAX_LOOP],
    vertex_count: u8,
    face_count: u8,
    loop_len: u8,
}

impl Default for Topology {
    fn default() -> Self {
        Topology {
            vertices: [VertexLabel::default(); MAX_VERTICES],
            faces: [LoopFace::default(); MAX_FACES],
            loops: [0; MAX_LOOP],
            vertex_count: 0,
            face_count: 0,
            loop_len: 0,
        }
    }
}

/// Which side of a polygon edge a clipping keeps, and what the edge lies on: an edge
/// of the clipped face's own shape, or a plane of the other shape.
#[derive(Clone, Copy, Debug)]
enum EdgeLabel {
    Own(u8, u8),
    Plane(u8),
}

/// A polygon vertex during the labelled clipping, with the label of the edge to the
/// next vertex.
#[derive(Clone, Copy, Debug)]
pub(super) struct LabelledVertex {
    point: Point3<Real>,
    label: VertexLabel,
    next: EdgeLabel,
}

/// One shape in the labelled clipping: its vertices and planes in A's frame, and per
/// plane of the other shape the set of its vertices outside that plane.
struct Side<'a> {
    shape: &'a ConvexPolyhedron,
    points: &'a [Point3<Real>],
    planes: &'a [Plane],
    out: &'a [u128],
    of_b: bool,
}

impl Topology {
    /// Reads the topology off a labelled clipping of the faces of `plan` (B's
    /// vertices and planes in A's frame, and the plan's vertex masks, in `s`).
    /// `None` where a vertex of a face's clipping has no label or the intersection is
    /// too large to keep; whether the labelling is that of the pose is for
    /// [`Topology::validate`] to say.
    pub(super) fn read(
        a: &ConvexPolyhedron,
        b: &ConvexPolyhedron,
        plan: &FacePlan,
        s: &mut OverlapScratch,
    ) -> Option<Topology> {
        let side_a = Side {
            shape: a,
            points: a.vertices(),
            planes: a.planes(),
            out: &s.out_a,
            of_b: false,
        };
        let side_b = Side {
            shape: b,
            points: &s.b_points,
            planes: &s.b_planes,
            out: &s.out_b,
            of_b: true,
        };
        let mut topology = Topology::default();
        let mut labels = [VertexLabel::default(); MAX_VERTICES];
        let mut label_count = 0;
        for (k, planned) in plan.faces.iter().enumerate() {
            let (own, other) = if k < plan.of_a {
                (&side_a, &side_b)
            } else {
                (&side_b, &side_a)
            };
            let face = planned.face();
            let poly = clip_labelled(
                own,
                other,
                face,
                planned.planes(),
                &mut s.labelled,
                &mut s.labelled_distances,
            )?;
            if poly.len() < 3 {
                continue;
            }
            if topology.face_count as usize == MAX_FACES
                || topology.loop_len as usize + poly.len() > MAX_LOOP
            {
                return None;
            }
            let start = topology.loop_len;
            for v in poly.iter() {
                if v.label.kind == Kind::Unlabelled {
                    return None;
                }
                let known = labels[..label_count]
                    .iter()
                    .position(|l| l.key() == v.label.key());
                let index = match known {
                    Some(index) => index,
                    None if label_count < MAX_VERTICES => {
                        labels[label_count] = v.label;
                        label_count += 1;
                        label_count - 1
                    }
                    None => return None,
                };
                topology.loops[topology.loop_len as usize] = index as u8;
                topology.loop_len += 1;
            }
            topology.faces[topology.face_count as usize] = LoopFace {
                face: face as u8,
                of_b: own.of_b,
                start,
                len: poly.len() as u8,
            };
            topology.face_count += 1;
        }
        topology.canonicalise(&labels[..label_count]);
        Some(topology)
    }

    /// Stores `labels` sorted by key, renumbers the loops, and starts each loop at its
    /// least vertex.
    fn canonicalise(&mut self, labels: &[VertexLabel]) {
        // A fixed array: a renewal allocates nothing.
        let mut all = [0u8; MAX_VERTICES];
        let order = &mut all[..labels.len()];
        for (k, o) in order.iter_mut().enumerate() {
            *o = k as u8;
        }
        order.sort_unstable_by_key(|&k| labels[k as usize].key());
        let mut rank = [0u8; MAX_VERTICES];
        for (new, &old) in order.iter().enumerate() {
            self.vertices[new] = labels[old as usize];
            rank[old as usize] = new as u8;
        }
        self.vertex_count = labels.len() as u8;
        for face in &self.faces[..self.face_count as usize] {
            let range = face.start as usize..(face.start + face.len) as usize;
            let entries = &mut self.loops[range];
            for e in entries.iter_mut() {
                *e = rank[*e as usize];
            }
            let least = (0..entries.len()).min_by_key(|&k| entries[k]).unwrap_or(0);
            entries.rotate_left(least);
        }
    }

    /// Whether the clipping found no intersection (edges of the two shapes passing
    /// each other, though no face plane separates them).
    pub(super) fn is_empty(&self) -> bool {
        self.vertex_count == 0
    }

    /// The vertices of B (bits) and planes of B (bits) that evaluating reads.
    pub(super) fn b_parts_used(&self) -> (u128, u64) {
        let mut vertices = 0u128;
        let mut planes = 0u64;
        for l in &self.vertices[..self.vertex_count as usize] {
            match l.kind {
                Kind::VertexOfA => {}
                Kind::VertexOfB => vertices |= 1 << l.inside,
                Kind::EdgeOfA => planes |= 1 << l.plane,
                Kind::EdgeOfB => vertices |= (1 << l.inside) | (1 << l.outside),
                Kind::Unlabelled => unreachable!("a kept topology has every vertex labelled"),
            }
        }
        for f in &self.faces[..self.face_count as usize] {
            if f.of_b {
                planes |= 1 << f.face;
            }
        }
        (vertices, planes)
    }

    /// The overlap at the current pose (B's parts that [`Topology::b_parts_used`]
    /// names in A's frame in `s`; `t` is B's centroid in A's frame).
    pub(super) fn evaluate(
        &self,
        a: &ConvexPolyhedron,
        t: &nalgebra::Vector3<Real>,
        s: &OverlapScratch,
    ) -> Option<OverlapGeometry> {
        let mut points = [Point3::origin(); MAX_VERTICES];
        let n = self.vertex_count as usize;
        for (p, l) in points.iter_mut().zip(&self.vertices[..n]) {
            let (i, o) = (l.inside as usize, l.outside as usize);
            *p = match l.kind {
                Kind::VertexOfA => a.vertices()[i],
                Kind::VertexOfB => s.b_points[i],
                Kind::EdgeOfA => edge_cut(
                    &a.vertices()[i],
                    &a.vertices()[o],
                    &s.b_planes[l.plane as usize],
                ),
                Kind::EdgeOfB => edge_cut(
                    &s.b_points[i],
                    &s.b_points[o],
                    &a.planes()[l.plane as usize],
                ),
                Kind::Unlabelled => unreachable!("a kept topology has every vertex labelled"),
            };
        }
        let points = &points[..n];
        let mut pieces = Pieces::default();
        for f in &self.faces[..self.face_count as usize] {
            let entries = &self.loops[f.start as usize..(f.start + f.len) as usize];
            let normal = if f.of_b {
                s.b_planes[f.face as usize].normal
            } else {
                a.planes()[f.face as usize].normal
            };
            pieces.add_loop(points, entries, &normal, f.of_b);
        }
        summarise(points, &pieces, t)
    }
}

/// The point where the segment from `inside` to `outside` crosses `plane`.
#[inline]
fn edge_cut(inside: &Point3<Real>, outside: &Point3<Real>, plane: &Plane) -> Point3<Real> {
    cut(
        inside,
        plane.distance(inside),
        outside,
        plane.distance(outside),
    )
}

/// Clips face `face` of `own` by the planes (bits) `cut` of `other`, tracking labels,
/// into `poly`. `None` where a label cannot be given.
fn clip_labelled<'p>(
    own: &Side,
    other: &Side,
    face: usize,
    cut_planes: u64,
    buffers: &'p mut [Vec<LabelledVertex>; 2],
    distances: &mut Vec<Real>,
) -> Option<&'p [LabelledVertex]> {
    let loop_ = own.shape.face(face);
    let [poly, output] = buffers;
    poly.clear();
    poly.extend(loop_.iter().enumerate().map(|(k, &v)| {
        let w = loop_[(k + 1) % loop_.len()];
        LabelledVertex {
            point: own.points[v as usize],
            label: VertexLabel {
                kind: if own.of_b {
                    Kind::VertexOfB
                } else {
                    Kind::VertexOfA
                },
                inside: v as u8,
                outside: v as u8,
                plane: 0,
            },
            next: EdgeLabel::Own(v as u8, w as u8),
        }
    }));
    for h in bits(cut_planes) {
        let plane = &other.planes[h];
        distances.clear();
        distances.extend(poly.iter().map(|v| plane.distance(&v.point)));
        // A plane with the whole polygon inside leaves it as it is.
        if distances.iter().all(|&d| d <= 0.0) {
            continue;
        }
        let n = poly.len();
        output.clear();
        for k in 0..n {
            let (p, q) = (&poly[k], &poly[(k + 1) % n]);
            let (dp, dq) = (distances[k], distances[(k + 1) % n]);
            if dp <= 0.0 {
                output.push(*p);
                if dq > 0.0 {
                    output.push(LabelledVertex {
                        point: cut(&p.point, dp, &q.point, dq),
                        label: cut_label(own, other, face, p.next, h),
                        next: EdgeLabel::Plane(h as u8),
                    });
                }
            } else if dq <= 0.0 {
                output.push(LabelledVertex {
                    point: cut(&q.point, dq, &p.point, dp),
                    label: cut_label(own, other, face, p.next, h),
                    next: p.next,
                });
            }
        }
        std::mem::swap(poly, output);
        if poly.len() < 3 {
            break;
        }
    }
    Some(poly)
}

/// The label of the point where a polygon edge on `edge` (in face `face` of `own`)
/// crosses plane `h` of `other`: [`Kind::Unlabelled`] when that point is not a
/// transversal cut of an edge of either shape.
fn cut_label(own: &Side, other: &Side, face: usize, edge: EdgeLabel, h: usize) -> VertexLabel {
    edge_cut_label(own, other, face, edge, h).unwrap_or(VertexLabel {
        kind: Kind::Unlabelled,
        ..VertexLabel::default()
    })
}

fn edge_cut_label(
    own: &Side,
    other: &Side,
    face: usize,
    edge: EdgeLabel,
    h: usize,
) -> Option<VertexLabel> {
    let (edge_of, u, w, plane) = match edge {
        // An edge of the own shape crossing plane h of the other.
        EdgeLabel::Own(u, w) => (own, u, w, h),
        // The line where plane g of the other shape meets this face, crossing plane
        // h: the other shape's edge between faces g and h, crossing this face.
        EdgeLabel::Plane(g) => {
            let masks = other.shape.face_vertex_masks();
            let common = masks[g as usize] & masks[h];
            if common.count_ones() != 2 {
                return None;
            }
            let u = common.trailing_zeros() as u8;
            let w = (127 - common.leading_zeros()) as u8;
            (other, u, w, face)
        }
    };
    // Which endpoint is outside the cutting plane, from the plan's masks (the crossing
    // edge's endpoints lie strictly on opposite sides).
    let outside = edge_of.out[plane];
    let (u_out, w_out) = (outside >> u & 1 == 1, outside >> w & 1 == 1);
    if u_out == w_out {
        return None;
    }
    let (inside, outside) = if u_out { (w, u) } else { (u, w) };
    Some(VertexLabel {
        kind: if edge_of.of_b {
            Kind::EdgeOfB
        } else {
            Kind::EdgeOfA
        },
        inside,
        outside,
        plane: plane as u8,
    })
}

#[cfg(test)]
mod tests {
    use nalgebra::{Rotation3, UnitQuaternion, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    use super::super::{masked, place_b, topology_of_plan};
    use super::*;
    use crate::geometry::generators;

    /// A dodecahedron, a prism of 12 sides and a random hull of 30 points, of
    /// circumradii near 5 mm.
    pub(super) fn three_shapes() -> [ConvexPolyhedron; 3] {
        [
            generators::dodecahedron(0.005).unwrap(),
            generators::prism(12, 0.004, 0.006).unwrap(),
            generators::random_convex(30, 0.005, 0.3, 7).unwrap(),
        ]
    }

    /// A random rotation of B and a translation of the given length in a random
    /// direction.
    pub(super) fn random_pose(rng: &mut Pcg64, length: Real) -> (Rotation3<Real>, Vector3<Real>) {
        let direction = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize();
        let axis = Vector3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
        );
        let rotation = UnitQuaternion::from_scaled_axis(axis).to_rotation_matrix();
        (rotation, direction * length)
    }

    /// Evaluating the topology gives what clipping the plan's faces gives, to
    /// round-off, over shallow and deep overlaps of several shapes; and touching
    /// faces have no topology.
    #[test]
    fn topology_and_clipping_agree() {
        let shapes = three_shapes();
        let mut rng = Pcg64::seed_from_u64(3);
        let mut s = OverlapScratch::default();
        // Shallow overlaps of the pellet shapes (centroids at least 0.88 of the sum
        // of circumradii apart, as in granular contacts), with a topology, and deep
        // ones that have too many vertices or faces to keep one. (The random hull has
        // many small faces: a shallow contact can meet more than a topology keeps.)
        let (mut shallow, mut shallow_with, mut without) = (0, 0, 0);
        for (i, a) in shapes.iter().enumerate() {
            for (j, b) in shapes.iter().enumerate() {
                let pellets = i < 2 && j < 2;
                for _ in 0..600 {
                    let reach = a.circumradius() + b.circumradius();
                    let apart = rng.random_range(0.3..1.0);
                    let (rotation, t) = random_pose(&mut rng, reach * apart);
                    place_b(b, rotation.matrix(), &t, &mut s);
                    masked::plan_masked(a, b, &t, &mut s);
                    if s.plan.separated {
                        continue;
                    }
                    let topology = topology_of_plan(a, b, &t, &mut s).map(|(t, _)| t);
                    let plan = std::mem::take(&mut s.plan);
                    if pellets && apart >= 0.88 {
                        shallow += 1;
                        shallow_with += topology.is_some() as usize;
                    }
                    let Some(topology) = topology else {
                        s.plan = plan;
                        without += 1;
                        continue;
                    };
                    let (faces_a, faces_b) = plan.faces.split_at(plan.of_a);
                    let clipped = masked::overlap_planned(a, b, &t, faces_a, faces_b, &mut s);
                    let evaluated = topology.evaluate(a, &t, &s);
                    s.plan = plan;
                    let (Some(c), Some(e)) = (clipped, evaluated) else {
                        assert!(clipped.is_none() && evaluated.is_none());
                        continue;
                    };
                    let size = a.circumradius();
                    let area = size * size;
                    assert!((c.volume - e.volume).abs() <= 1e-12 * size.powi(3));
                    assert!((c.centroid - e.centroid).norm() <= 1e-11 * size);
                    assert!((c.area_vector() - e.area_vector()).norm() <= 1e-11 * area);
                    assert!((c.depth - e.depth).abs() <= 1e-11 * size);
                    let moment = area * size;
                    assert!(
                        (c.rotation_gradient_a - e.rotation_gradient_a).norm() <= 1e-11 * moment
                    );
                    assert!(
                        (c.rotation_gradient_b - e.rotation_gradient_b).norm() <= 1e-11 * moment
                    );
                }
            }
        }
        // Random poses are in general position: every shallow overlap has a topology.
        assert!(
            shallow > 60 && shallow_with == shallow,
            "{shallow_with} of {shallow}"
        );
        assert!(without > 100, "{without} without");

        // Cubes face to face: their vertices lie on each other's planes.
        let cube = generators::cuboid(0.01, 0.01, 0.01).unwrap();
        let t = Vector3::new(0.0099, 0.002, 0.0);
        place_b(&cube, &nalgebra::Matrix3::identity(), &t, &mut s);
        masked::plan_masked(&cube, &cube, &t, &mut s);
        assert!(!s.plan.separated);
        assert!(topology_of_plan(&cube, &cube, &t, &mut s).is_none());
    }
}
