//! A kept overlap plan answers bit for bit what a fresh overlap answers, along paths
//! of small random motions through touching, overlapping and separated poses, and it
//! is really kept for most steps of a slow path.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::{
    Kept, OverlapCache, OverlapGeometry, OverlapScratch, overlap, overlap_cached,
    overlap_cached_with, overlap_with,
};
use crate::Real;
use crate::geometry::{ConvexPolyhedron, generators};

fn bits(o: &Option<OverlapGeometry>) -> Option<Vec<u64>> {
    o.map(|o| {
        [
            o.volume,
            o.area,
            o.depth,
            o.centroid.x,
            o.centroid.y,
            o.centroid.z,
            o.normal.x,
            o.normal.y,
            o.normal.z,
            o.rotation_gradient_a.x,
            o.rotation_gradient_a.y,
            o.rotation_gradient_a.z,
            o.rotation_gradient_b.x,
            o.rotation_gradient_b.y,
            o.rotation_gradient_b.z,
        ]
        .map(Real::to_bits)
        .to_vec()
    })
}

fn small_vector(rng: &mut Pcg64, size: Real) -> Vector3<Real> {
    Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    ) * size
}

/// Walks B about A from a shallow overlap along `direction`, with steps of `step`
/// metres and `turn` radians and now and then a jump; returns (kept, renewed,
/// overlapping, overlapping by a kept topology, renewed to the topology kept before)
/// step counts after checking every step bit for bit.
fn walk(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    seed: u64,
    step: Real,
    turn: Real,
) -> [usize; 5] {
    walk_from(a, b, 0.8, seed, step, turn)
}

/// [`walk`] from centroids `start` of the sum of the circumradii apart.
fn walk_from(
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    start: Real,
    seed: u64,
    step: Real,
    turn: Real,
) -> [usize; 5] {
    let mut rng = Pcg64::seed_from_u64(seed);
    let reach = a.circumradius() + b.circumradius();
    let direction = small_vector(&mut rng, 1.0).normalize();
    let mut rotation = UnitQuaternion::from_scaled_axis(small_vector(&mut rng, 3.0));
    let mut translation = direction * start * reach;
    let mut cache = OverlapCache::default();
    let mut counts = [0; 5];
    // The kept path places only the parts of B its plan reads: its scratch is filled
    // with another pose's B before each step, so that a part it fails to place shows.
    let mut scratch = OverlapScratch::default();
    let elsewhere = Isometry3::from_parts(
        Translation3::from(-direction * 0.7 * reach),
        UnitQuaternion::from_scaled_axis(Vector3::new(1.0, 2.0, -0.5)),
    );
    for k in 0..3000 {
        if k % 500 == 499 {
            // A jump: the plan must be renewed, not trusted.
            translation += small_vector(&mut rng, 0.05 * reach);
        }
        // Drift outwards and back so that the pair separates and meets again.
        let breathe = if (k / 1000) % 2 == 0 { 1.0 } else { -1.0 };
        translation += small_vector(&mut rng, step) + direction * (breathe * 0.3 * step);
        rotation = UnitQuaternion::from_scaled_axis(small_vector(&mut rng, turn)) * rotation;
        let pose = Isometry3::from_parts(Translation3::from(translation), rotation);
        let kept_before = (cache.translation, cache.slack);
        let topology_before = match &cache.decisions {
            Kept::Topology(topology) => Some(topology.clone()),
            _ => None,
        };
        overlap_with(a, b, &elsewhere, &mut scratch);
        let cached = overlap_cached_with(a, b, &pose, &mut cache, &mut scratch);
        let fresh = overlap(a, b, &pose);
        assert_eq!(bits(&cached), bits(&fresh), "step {k}");
        let kept = kept_before == (cache.translation, cache.slack) && cache.slack.margin > 0.0;
        counts[if kept { 0 } else { 1 }] += 1;
        counts[2] += fresh.is_some() as usize;
        counts[3] += (fresh.is_some() && matches!(cache.decisions, Kept::Topology(_))) as usize;
        if let (false, Kept::Topology(topology)) = (kept, &cache.decisions) {
            counts[4] += usize::from(topology_before.as_ref() == Some(topology));
        }
    }
    counts
}

#[test]
fn kept_plans_answer_bit_for_bit() {
    let dodecahedron = generators::dodecahedron(0.005).unwrap();
    let prism = generators::prism(20, 5.5e-3, 5.5e-3).unwrap();
    let cube = generators::cuboid(0.01, 0.01, 0.01).unwrap();
    for (name, shape) in [("dodecahedron", &dodecahedron), ("prism", &prism)] {
        for seed in 0..4 {
            let [kept, renewed, overlapping, by_topology, _] = walk(shape, shape, seed, 1e-8, 1e-6);
            // A slow walk keeps its plan most of the time, and renews it at the jumps
            // that come while the shapes overlap (a separation stands as long as its
            // plane separates) and whenever a vertex comes near a plane.
            assert!(
                kept > renewed,
                "{name} {seed}: kept {kept}, renewed {renewed}"
            );
            assert!(renewed >= 2, "{name} {seed}: renewed {renewed}");
            assert!(
                overlapping > 100,
                "{name} {seed}: overlapping {overlapping}"
            );
            // Away from touching, the overlap is evaluated from its topology.
            assert!(
                by_topology > overlapping / 2,
                "{name} {seed}: {by_topology} of {overlapping} by topology"
            );
            // A fast one renews it often; the answers stay the same.
            walk(shape, shape, seed, 1e-5, 1e-3);
        }
    }
    // Ten times faster, the pair outruns its topology's slack now and then, and most
    // of these renewals find the topology still valid (they then skip the plan); also
    // for a random hull of 14 points, whose small faces meet at all angles.
    let hull = generators::random_convex(14, 0.005, 0.3, 2).unwrap();
    for (name, shape, start) in [
        ("dodecahedron", &dodecahedron, 0.8),
        ("prism", &prism, 0.8),
        ("random hull", &hull, 0.6),
    ] {
        let (mut renewed, mut same, mut by_topology) = (0, 0, 0);
        for seed in 0..4 {
            let counts = walk_from(shape, shape, start, seed, 1e-7, 1e-5);
            (renewed, same, by_topology) = (
                renewed + counts[1],
                same + counts[4],
                by_topology + counts[3],
            );
        }
        assert!(
            by_topology > 4000,
            "{name}: {by_topology} steps by topology"
        );
        assert!(
            2 * same > renewed,
            "{name}: {same} of {renewed} renewals kept the topology"
        );
    }
    // A plan is for its two shapes: the same slot and pose with other shapes renews it.
    let pose = Isometry3::from_parts(
        Translation3::new(0.0085, 0.0, 0.0),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -0.7, 1.1)),
    );
    let mut cache = OverlapCache::default();
    for (a, b) in [(&dodecahedron, &dodecahedron), (&cube, &dodecahedron)] {
        let cached = overlap_cached(a, b, &pose, &mut cache);
        assert_eq!(bits(&cached), bits(&overlap(a, b, &pose)));
        assert!(cached.is_some());
    }
    // Flush faces: cubes of equal orientation side by side, sliding along each other.
    let mut cache = OverlapCache::default();
    for k in 0..200 {
        let pose = Isometry3::translation(0.0099, 1e-5 * k as Real, 2e-6 * k as Real);
        let cached = overlap_cached(&cube, &cube, &pose, &mut cache);
        assert_eq!(
            bits(&cached),
            bits(&overlap(&cube, &cube, &pose)),
            "cube step {k}"
        );
        assert!(cached.is_some());
    }
}

/// A separation is kept while one plane separates the shapes, however close other
/// vertices come to other planes: two dodecahedra with a 1 mm gap across a face plane
/// of one, jostled by up to 0.4 mm and 5 mrad in all, keep their first plan (and
/// answer as a fresh overlap does), and renew it once the gap has closed.
#[test]
fn a_separation_stands_while_its_plane_separates() {
    let d = generators::dodecahedron(0.005).unwrap();
    let face = d.planes()[0];
    let (gap, mut rng) = (1e-3, Pcg64::seed_from_u64(7));
    // Every vertex of B lies within its circumradius of its centre: B's centre a
    // circumradius and the gap beyond A's face plane leaves that plane separating.
    let mut translation = face.normal * (face.offset + d.circumradius() + gap);
    let mut rotation = UnitQuaternion::from_scaled_axis(small_vector(&mut rng, 3.0));
    let mut cache = OverlapCache::default();
    let mut renewed = 0;
    for k in 0..200 {
        let before = (cache.translation, cache.slack);
        let pose = Isometry3::from_parts(Translation3::from(translation), rotation);
        let cached = overlap_cached(&d, &d, &pose, &mut cache);
        assert_eq!(bits(&cached), bits(&overlap(&d, &d, &pose)), "step {k}");
        assert!(cached.is_none());
        renewed += usize::from(before != (cache.translation, cache.slack));
        translation += small_vector(&mut rng, 2e-6);
        rotation = UnitQuaternion::from_scaled_axis(small_vector(&mut rng, 2.5e-5)) * rotation;
    }
    assert_eq!(
        renewed, 1,
        "a separation renewed {renewed} times in 200 steps"
    );
    // Closing the gap renews the plan, which finds the contact.
    translation -= face.normal * 1.5 * gap;
    let pose = Isometry3::from_parts(Translation3::from(translation), rotation);
    let cached = overlap_cached(&d, &d, &pose, &mut cache);
    assert_eq!(bits(&cached), bits(&overlap(&d, &d, &pose)));
    assert!(cached.is_some());
}

/// A separating plane tested again at a new pose gives the slack the plan gave it
/// (to round-off), and no slack once a vertex of the other shape has come within
/// twice the tolerance: over random separated poses of a dodecahedron and a prism.
#[test]
fn a_separating_plane_is_tested_again_as_the_plan_made_it() {
    use super::{masked, place_b, tolerance};
    let dodecahedron = generators::dodecahedron(0.005).unwrap();
    let prism = generators::prism(12, 0.004, 0.006).unwrap();
    let mut rng = Pcg64::seed_from_u64(23);
    let mut s = OverlapScratch::default();
    let mut compared = 0;
    for (a, b) in [(&dodecahedron, &prism), (&prism, &dodecahedron)] {
        let tol = tolerance(a, b);
        for _ in 0..400 {
            let reach = a.circumradius() + b.circumradius();
            let t = small_vector(&mut rng, 1.0).normalize() * reach * rng.random_range(0.7..1.0);
            let rotation = UnitQuaternion::from_scaled_axis(small_vector(&mut rng, 3.0));
            let rotation = rotation.to_rotation_matrix().into_inner();
            place_b(b, &rotation, &t, &mut s);
            masked::plan_masked(a, b, &t, &mut s);
            if !s.plan.separated {
                continue;
            }
            let planned = s.plan.slack;
            let again = masked::separation_slack(a, b, &rotation, &t, s.plan.separating, tol);
            let Some(again) = again else {
                // Within twice the tolerance of the plane: a margin of order tol.
                assert!(planned.margin <= tol, "{planned:?}");
                continue;
            };
            let close = |x: Real, y: Real| (x - y).abs() <= 1e-9 * x.abs().max(y.abs());
            assert!(close(again.margin, planned.margin), "{again:?} {planned:?}");
            assert!(
                close(again.per_lever, planned.per_lever),
                "{again:?} {planned:?}"
            );
            compared += 1;
            // Pushed across the plane by more than its margin: no longer separating.
            let (of_b, k) = s.plan.separating;
            let normal = if of_b {
                rotation * b.planes()[k as usize].normal
            } else {
                a.planes()[k as usize].normal
            };
            // B's vertices move with B; A's vertices leave a plane of B as B moves
            // against the normal.
            let push = if of_b { normal } else { -normal } * 1.5 * planned.margin;
            let moved = masked::separation_slack(a, b, &rotation, &(t + push), (of_b, k), tol);
            assert!(moved.is_none());
        }
    }
    assert!(compared > 200, "{compared} separated poses");
}

/// Kept and fresh answers agree bit for bit between unlike shapes too: every pair of
/// six (with the cube's and the hexagonal prism's parallel faces, and random hulls of
/// small faces at all angles), from deep to shallow, slow and fast.
#[test]
fn unlike_shapes_answer_bit_for_bit() {
    let shapes = [
        generators::dodecahedron(0.005).unwrap(),
        generators::prism(20, 5.5e-3, 5.5e-3).unwrap(),
        generators::cuboid(0.008, 0.008, 0.008).unwrap(),
        generators::random_convex(14, 0.005, 0.3, 2).unwrap(),
        generators::random_convex(30, 0.005, 0.3, 9).unwrap(),
        generators::prism(6, 4e-3, 8e-3).unwrap(),
    ];
    let mut total = [0; 5];
    for (i, a) in shapes.iter().enumerate() {
        for (j, b) in shapes.iter().enumerate() {
            let seed = (6 * i + j) as u64;
            for (start, step, turn) in [(0.6, 1e-7, 1e-5), (0.75, 1e-5, 1e-3)] {
                let counts = walk_from(a, b, start, seed, step, turn);
                total = std::array::from_fn(|k| total[k] + counts[k]);
            }
        }
    }
    let [_, renewed, overlapping, by_topology, same] = total;
    assert!(overlapping > 80_000, "{total:?}");
    assert!(by_topology > overlapping / 2, "{total:?}");
    assert!(same > renewed / 5, "{total:?}");
}
