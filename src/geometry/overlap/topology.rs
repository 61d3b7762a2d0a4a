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
//! the boundaries of two convex polyhedra meet other than transversally. While every
//! vertex stays off the other shape's planes (the bit-mask plan's margin) and every
//! edge pair that could meet stays apart (the edge margin computed here), the topology
//! is that of the current pose, and P is evaluated from it directly: each vertex of P
//! once, by one cut of an edge, instead of the repeated cuts of clipping every face.
//!
//! The labels are read off a Sutherland–Hodgman clipping that tracks, for every
//! polygon vertex, what it lies on. They are put in a canonical order (vertices sorted
//! by label, each loop starting at its least vertex), so the topology is a function of
//! the combinatorial type alone: a fresh overlap and a kept one evaluate the same
//! topology in the same order, bit for bit.
//!
//! Touching configurations (a vertex within the coplanarity tolerance of a plane of
//! the other shape, flush faces) have no such labelling; the plan is clipped as it is
//! there.

use nalgebra::Point3;

use super::masked::{FacePlan, Slack, bits};
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
    /// `None` where the configuration has no labelling (see the module docs) or the
    /// intersection is too large to keep.
    pub(super) fn read(
        a: &ConvexPolyhedron,
        b: &ConvexPolyhedron,
        plan: &FacePlan,
        s: &mut OverlapScratch,
    ) -> Option<Topology> {
        // A vertex on a plane of the other shape: touching, flush or degenerate.
        if s.on_a.iter().chain(&s.on_b).any(|&m| m != 0) {
            return None;
        }
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

/// The slack of the edge pairs that could meet: the smallest distance between an
/// edge of A and an edge of B, and that distance per unit lever of B's edge (the
/// farther endpoint from the plan's pivot, whose inverse distances are in `s`).
/// Edges with both endpoints outside one plane of the other shape (by the plan's
/// masks, which hold while the plan does) cannot meet. Within this slack no edge
/// crosses an edge: the distance of two segments changes by no more than the
/// farthest displacement of a point of the moving one.
///
/// A pair of edges whose balls (about their midpoints) are farther apart than
/// either smallest so far cannot lower it and is skipped: the same slack, with the
/// exact distance of a few pairs only.
pub(super) fn edge_slack(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    s: &mut OverlapScratch,
) -> Slack {
    let near_b = &mut s.near_edges;
    near_b.clear();
    let inverse = &s.inverse_lever_b;
    near_b.extend(
        near_edges(b.edges(), &s.out_b).map(|&[u, w]| NearEdge::new([u, w], &s.b_points, inverse)),
    );
    let mut slack = Slack::NONE;
    for &[u, w] in near_edges(a.edges(), &s.out_a) {
        let (p0, p1) = (a.vertices()[u as usize], a.vertices()[w as usize]);
        let (mid, half) = (nalgebra::center(&p0, &p1), 0.5 * (p1 - p0).norm());
        for e in near_b.iter() {
            // The segments are no closer than their balls are (to round-off, which
            // the slack's tolerance covers).
            let needed = half + e.half + slack.margin.max(slack.per_lever * e.lever);
            if (mid - e.mid).norm_squared() >= needed * needed {
                continue;
            }
            let (q0, q1) = (
                s.b_points[e.ends[0] as usize],
                s.b_points[e.ends[1] as usize],
            );
            let distance = segment_distance(&p0, &p1, &q0, &q1);
            slack = slack.min(Slack {
                margin: distance,
                per_lever: distance * e.inverse_lever,
            });
        }
    }
    slack
}

/// An edge of B that could meet A, in A's frame, with its ball and lever.
#[derive(Clone, Copy, Debug)]
pub(super) struct NearEdge {
    ends: [u32; 2],
    mid: Point3<Real>,
    half: Real,
    /// The farther endpoint's distance from the plan's pivot, and its inverse.
    lever: Real,
    inverse_lever: Real,
}

impl NearEdge {
    fn new(ends: [u32; 2], points: &[Point3<Real>], inverse_lever: &[Real]) -> Self {
        let (q0, q1) = (points[ends[0] as usize], points[ends[1] as usize]);
        let [u, w] = ends.map(|k| k as usize);
        let inverse_lever = inverse_lever[u].min(inverse_lever[w]);
        NearEdge {
            ends,
            mid: nalgebra::center(&q0, &q1),
            half: 0.5 * (q1 - q0).norm(),
            lever: 1.0 / inverse_lever,
            inverse_lever,
        }
    }
}

/// The edges of a shape that could meet the other: those with no plane of the other
/// shape having both endpoints outside (`out`: per plane, the vertices outside; a
/// shape on the bit-mask path has at most 128 vertices and 64 faces).
fn near_edges<'e>(edges: &'e [[u32; 2]], out: &[u128]) -> impl Iterator<Item = &'e [u32; 2]> {
    // Per vertex, the planes it lies outside: an edge is near when its two
    // endpoints share none.
    let mut outside = [0u64; 128];
    for (k, &m) in out.iter().enumerate() {
        let mut m = m;
        while m != 0 {
            outside[m.trailing_zeros() as usize] |= 1 << k;
            m &= m - 1;
        }
    }
    edges
        .iter()
        .filter(move |e| outside[e[0] as usize] & outside[e[1] as usize] == 0)
}

/// Distance between the segments `p0 p1` and `q0 q1` (closest points by clamping the
/// parameters of the lines' closest approach, Ericson 2005, §5.1.9).
fn segment_distance(
    p0: &Point3<Real>,
    p1: &Point3<Real>,
    q0: &Point3<Real>,
    q1: &Point3<Real>,
) -> Real {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (c, b) = (d1.dot(&r), d1.dot(&d2));
    let denom = a * e - b * b;
    let mut s = if denom > 0.0 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

#[cfg(test)]
mod tests {
    use nalgebra::{Rotation3, UnitQuaternion, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    use super::super::{masked, place_b};
    use super::*;
    use crate::geometry::generators;

    /// The edge slack, which skips pairs of edges whose balls lie farther apart than
    /// the smallest distances so far, is bit for bit the slack of every pair of near
    /// edges, over overlapping poses of three shapes; and some pairs are near.
    #[test]
    fn edge_slack_is_that_of_every_near_pair() {
        let shapes = [
            generators::dodecahedron(0.005).unwrap(),
            generators::prism(12, 0.004, 0.006).unwrap(),
            generators::random_convex(30, 0.005, 0.3, 7).unwrap(),
        ];
        let mut rng = Pcg64::seed_from_u64(11);
        let mut s = OverlapScratch::default();
        let mut compared = 0;
        for a in &shapes {
            for b in &shapes {
                for _ in 0..200 {
                    let reach = a.circumradius() + b.circumradius();
                    let length = reach * rng.random_range(0.5..1.0);
                    let (rotation, t) = random_pose(&mut rng, length);
                    place_b(b, rotation.matrix(), &t, &mut s);
                    masked::plan_masked(a, b, &t, &mut s);
                    if s.plan.separated {
                        continue;
                    }
                    let mut every = Slack::NONE;
                    let near_b: Vec<_> = near_edges(b.edges(), &s.out_b).copied().collect();
                    for &[u, w] in near_edges(a.edges(), &s.out_a) {
                        let (p0, p1) = (a.vertices()[u as usize], a.vertices()[w as usize]);
                        for &[x, y] in &near_b {
                            let (q0, q1) = (s.b_points[x as usize], s.b_points[y as usize]);
                            let distance = segment_distance(&p0, &p1, &q0, &q1);
                            let inverse =
                                s.inverse_lever_b[x as usize].min(s.inverse_lever_b[y as usize]);
                            every = every.min(Slack {
                                margin: distance,
                                per_lever: distance * inverse,
                            });
                        }
                    }
                    compared += usize::from(every.margin.is_finite());
                    assert_eq!(edge_slack(a, b, &mut s), every);
                }
            }
        }
        assert!(compared > 500, "{compared} poses with near edges");
    }

    /// A random rotation of B and a translation of the given length in a random
    /// direction.
    fn random_pose(rng: &mut Pcg64, length: Real) -> (Rotation3<Real>, Vector3<Real>) {
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
        let shapes = [
            generators::dodecahedron(0.005).unwrap(),
            generators::prism(12, 0.004, 0.006).unwrap(),
            generators::random_convex(30, 0.005, 0.3, 7).unwrap(),
        ];
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
                    let plan = std::mem::take(&mut s.plan);
                    let topology = Topology::read(a, b, &plan, &mut s);
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
        let plan = std::mem::take(&mut s.plan);
        assert!(!plan.separated);
        assert!(Topology::read(&cube, &cube, &plan, &mut s).is_none());
    }

    #[test]
    fn segment_distance_of_crossing_skew_and_parallel_segments() {
        let cases = [
            // Skew, closest points inside both: the gap along z.
            (
                [-1., 0., 0.],
                [1., 0., 0.],
                [0., -1., 0.5],
                [0., 1., 0.5],
                0.5,
            ),
            // Closest approach beyond the end of the second: endpoint to segment.
            (
                [-1., 0., 0.],
                [1., 0., 0.],
                [3., -1., 0.],
                [3., 1., 0.],
                2.0,
            ),
            // Parallel, overlapping in extent.
            (
                [0., 0., 0.],
                [2., 0., 0.],
                [1., 0.3, 0.],
                [3., 0.3, 0.],
                0.3,
            ),
            // Parallel, apart along their line.
            ([0., 0., 0.], [1., 0., 0.], [4., 0., 0.], [5., 0., 0.], 3.0),
        ];
        for (p0, p1, q0, q1, expected) in cases {
            let [p0, p1, q0, q1] = [p0, p1, q0, q1].map(Point3::from);
            let d = segment_distance(&p0, &p1, &q0, &q1);
            assert!((d - expected).abs() < 1e-15, "{d} vs {expected}");
        }
    }
}
