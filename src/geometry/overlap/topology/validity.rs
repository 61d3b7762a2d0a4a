//! Whether a topology is the current one, and how far the pair may move before it
//! could stop being so.
//!
//! Every vertex of a topology is the meeting point of three planes (a vertex of one
//! shape, or an edge of one shape cut by a plane of the other). Evaluated at a pose,
//! the topology is that pose's intersection P when each of its vertices lies inside
//! every other plane of both shapes by more than the coplanarity tolerance: the
//! vertices are then vertices of P, the loops' edges are edges of P, and a closed
//! surface of P's vertices and edges on the sphere that bounds P is all of it. So the
//! test reads only the topology's own vertices: a vertex of either shape far from the
//! other's boundary may lie on any extended face plane without changing anything.
//!
//! A fresh overlap reads a topology off its clipping and keeps it only if it passes
//! this test; a kept one is tested again at the pose where its slack runs out, and
//! kept on if it passes: both then answer the same topology bit for bit.
//!
//! The slack: a vertex of a shape and a plane of the other move apart by no more than
//! the relative displacement `δ` of the material at the vertex. An edge cut `x` (the
//! edge `e` from `u` to `v` crossing plane `g`) slides along its edge: `d(·, g)` is
//! linear along the edge with slope `D = e · n_g`, and changes by at most `δ`
//! everywhere, so the cut moves by at most `δ / D` of the edge, and its distance to
//! another plane `h` changes by at most `δ (1 + |e · n_h| / D)`. Each test's miss,
//! divided by that factor, is a [`Slack`] entry with the edge's farther endpoint as
//! its lever.

use nalgebra::{Point3, Vector3};

use super::super::OverlapScratch;
use super::super::masked::Slack;
use super::{Kind, Topology};
use crate::Real;
use crate::geometry::{ConvexPolyhedron, Plane, polygon};

impl Topology {
    /// The slack within which the topology stays the current one, or `None` where at
    /// the current pose it is not (a vertex within the tolerance `tol` of another
    /// plane, or no vertex at all: an empty topology has its own slack,
    /// [`super::edge_slack`]). All of B's planes, and the vertices of B that
    /// [`Topology::b_parts_used`] names, in A's frame in `s`; `t` is B's centroid in
    /// A's frame.
    pub(in super::super) fn validate(
        &self,
        a: &ConvexPolyhedron,
        t: &Vector3<Real>,
        tol: Real,
        s: &OverlapScratch,
    ) -> Option<Slack> {
        let n = self.vertex_count as usize;
        if n == 0 {
            return None;
        }
        let pivot = Point3::from(0.5 * t);
        let lever = |p: &Point3<Real>| (p - pivot).norm();
        let (planes_a, planes_b) = (a.planes(), &s.b_planes[..]);
        let mut slack = Slack::NONE;
        for l in &self.vertices[..n] {
            let (i, o, plane) = (l.inside as usize, l.outside as usize, l.plane as usize);
            let entry = match l.kind {
                Kind::VertexOfA => {
                    let p = &a.vertices()[i];
                    vertex_slack(p, lever(p), planes_b, tol)?
                }
                Kind::VertexOfB => {
                    let p = &s.b_points[i];
                    vertex_slack(p, lever(p), planes_a, tol)?
                }
                Kind::EdgeOfA => {
                    let ends = [&a.vertices()[i], &a.vertices()[o]];
                    cut_slack(ends, ends.map(lever), planes_b, plane, tol)?
                }
                Kind::EdgeOfB => {
                    let ends = [&s.b_points[i], &s.b_points[o]];
                    cut_slack(ends, ends.map(lever), planes_a, plane, tol)?
                }
                Kind::Unlabelled => unreachable!("a kept topology has every vertex labelled"),
            };
            slack = slack.min(entry);
        }
        Some(slack)
    }
}

/// The slack of a vertex `p` (at `lever` from the pivot) inside every one of the
/// other shape's `planes`; `None` where it is not inside by more than `tol`.
fn vertex_slack(p: &Point3<Real>, lever: Real, planes: &[Plane], tol: Real) -> Option<Slack> {
    let depth = planes
        .iter()
        .fold(Real::INFINITY, |m, h| m.min(-h.distance(p)));
    miss_slack(depth - tol, lever)
}

/// The slack of the cut of the edge `ends` (inside, outside; at `levers` from the
/// pivot) by plane `cut` of the other shape's `planes`: its ends strictly on either
/// side, and the cut point inside every other plane, by more than `tol`.
fn cut_slack(
    ends: [&Point3<Real>; 2],
    levers: [Real; 2],
    planes: &[Plane],
    cut: usize,
    tol: Real,
) -> Option<Slack> {
    let [u, v] = ends;
    let (du, dv) = (planes[cut].distance(u), planes[cut].distance(v));
    let ends = miss_slack(-du - tol, levers[0])?.min(miss_slack(dv - tol, levers[1])?);
    // The point `edge_cut` gives, from the distances at hand.
    let x = polygon::cut(u, du, v, dv);
    let (edge, slope) = (v - u, dv - du);
    let mut margin = Real::INFINITY;
    for (k, h) in planes.iter().enumerate() {
        if k == cut {
            continue;
        }
        let miss = -h.distance(&x) - tol;
        if !(miss > 0.0) {
            return None;
        }
        // The cut slides along the edge as plane `cut` moves (module docs).
        margin = margin.min(miss * slope / (slope + edge.dot(&h.normal).abs()));
    }
    Some(ends.min(miss_slack(margin, levers[0].max(levers[1]))?))
}

/// One test's slack: its miss `miss` (positive) at `lever` from the pivot.
fn miss_slack(miss: Real, lever: Real) -> Option<Slack> {
    (miss > 0.0).then(|| Slack {
        margin: miss,
        per_lever: miss / lever.max(Real::MIN_POSITIVE),
    })
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix3, UnitQuaternion, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    use super::super::super::{OverlapScratch, masked, place_b, topology_of_plan};
    use super::super::tests::{random_pose, three_shapes};
    use super::*;

    /// A random unit vector.
    fn direction(rng: &mut Pcg64) -> Vector3<Real> {
        Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize()
    }

    /// The topology read afresh at the pose (`rotation`, `t`) of B in A.
    fn fresh(
        a: &ConvexPolyhedron,
        b: &ConvexPolyhedron,
        rotation: &Matrix3<Real>,
        t: &Vector3<Real>,
        s: &mut OverlapScratch,
    ) -> Option<(Topology, Slack)> {
        place_b(b, rotation, t, s);
        masked::plan_masked(a, b, t, s);
        if s.plan.separated {
            return None;
        }
        topology_of_plan(a, b, t, s)
    }

    /// The slack is sound: moved to the edge of its slack (99 % of it, split at
    /// random between a displacement of the pivot and a turn about it), a pair reads
    /// the same topology afresh, and it is valid there; over shallow overlaps of a
    /// dodecahedron, a prism and a random hull of 30 points. And it is not empty.
    #[test]
    fn a_topology_holds_to_the_edge_of_its_slack() {
        let shapes = three_shapes();
        let mut rng = Pcg64::seed_from_u64(5);
        let mut s = OverlapScratch::default();
        let (mut moves, mut poses) = (0, 0);
        for a in &shapes {
            for b in &shapes {
                for _ in 0..300 {
                    let reach = a.circumradius() + b.circumradius();
                    let length = reach * rng.random_range(0.8..1.0);
                    let (rotation, t) = random_pose(&mut rng, length);
                    let rotation = *rotation.matrix();
                    let Some((topology, slack)) = fresh(a, b, &rotation, &t, &mut s) else {
                        continue;
                    };
                    if topology.is_empty() {
                        continue;
                    }
                    poses += 1;
                    assert!(slack.margin > 0.0 && slack.per_lever > 0.0);
                    for _ in 0..10 {
                        // a / margin + turn / per_lever = 0.99.
                        let share = rng.random_range(0.0..1.0);
                        let a_pivot = 0.99 * share * slack.margin;
                        let turn = 0.99 * (1.0 - share) * slack.per_lever;
                        let spin = UnitQuaternion::from_scaled_axis(direction(&mut rng) * turn);
                        let spin = *spin.to_rotation_matrix().matrix();
                        // Every point x of B goes to spin (x − c) + c + a_pivot d.
                        let pivot = 0.5 * t;
                        let moved_t = spin * (t - pivot) + pivot + direction(&mut rng) * a_pivot;
                        let moved = fresh(a, b, &(spin * rotation), &moved_t, &mut s);
                        let Some((again, _)) = moved else {
                            panic!("no topology at the edge of the slack {slack:?}");
                        };
                        assert_eq!(again, topology, "slack {slack:?}");
                        moves += 1;
                    }
                }
            }
        }
        assert!(poses > 300, "{poses} poses with a topology");
        assert!(moves == 10 * poses);
    }
}
