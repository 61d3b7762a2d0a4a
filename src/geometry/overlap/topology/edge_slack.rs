//! The slack of a pair whose clipping found no intersection though no face plane
//! separates them (edges passing each other): it stays empty while no vertex crosses
//! a plane of the other shape (the plan's slack) and no edge crosses an edge of the
//! other (this slack). An empty topology has no vertex for [`super::validity`] to
//! test.

use nalgebra::Point3;

use super::super::OverlapScratch;
use super::super::masked::Slack;
use crate::Real;
use crate::geometry::ConvexPolyhedron;

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
pub(in super::super) fn edge_slack(
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
pub(in super::super) struct NearEdge {
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
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    use super::super::super::{masked, place_b};
    use super::super::tests::{random_pose, three_shapes};
    use super::*;

    /// The edge slack, which skips pairs of edges whose balls lie farther apart than
    /// the smallest distances so far, is bit for bit the slack of every pair of near
    /// edges, over overlapping poses of three shapes; and some pairs are near.
    #[test]
    fn edge_slack_is_that_of_every_near_pair() {
        let shapes = three_shapes();
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
