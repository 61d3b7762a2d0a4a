//! Exact overlap volume of convex polyhedra: closed forms, symmetry, invariance,
//! agreement with GJK and Monte Carlo, the gradient property, and hard cases.

mod common;

use common::{box_overlap, monte_carlo_overlap, pose};
use nalgebra::{Isometry3, Vector3};
use proptest::prelude::*;
use talus::geometry::generators::{self, Platonic};
use talus::geometry::gjk::{GjkResult, gjk};
use talus::geometry::overlap::overlap;

const SQRT2: f64 = std::f64::consts::SQRT_2;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Axis-aligned boxes: the overlap is the product of the interval overlaps.
    #[test]
    fn axis_aligned_cuboids(
        s1 in prop::array::uniform3(0.1f64..2.0),
        s2 in prop::array::uniform3(0.1f64..2.0),
        c in prop::array::uniform3(-1.5f64..1.5),
    ) {
        let a = generators::cuboid(s1[0], s1[1], s1[2]).unwrap();
        let b = generators::cuboid(s2[0], s2[1], s2[2]).unwrap();
        let truth = box_overlap([0.0; 3], s1, c, s2);
        let got = overlap(&a, &b, &pose(c, [0.0; 3])).map_or(0.0, |o| o.volume);
        prop_assert!((got - truth).abs() <= 1e-12 * (1.0 + truth), "{got} vs {truth}");
    }

    /// The same boxes with a common rotation applied to both world poses.
    #[test]
    fn rotated_cuboid_pairs(
        s1 in prop::array::uniform3(0.1f64..2.0),
        s2 in prop::array::uniform3(0.1f64..2.0),
        c in prop::array::uniform3(-1.5f64..1.5),
        rot in prop::array::uniform3(-3.0f64..3.0),
        shift in prop::array::uniform3(-10.0f64..10.0),
    ) {
        let a = generators::cuboid(s1[0], s1[1], s1[2]).unwrap();
        let b = generators::cuboid(s2[0], s2[1], s2[2]).unwrap();
        let motion = pose(shift, rot);
        let pa = motion * pose([0.0; 3], [0.0; 3]);
        let pb = motion * pose(c, [0.0; 3]);
        let truth = box_overlap([0.0; 3], s1, c, s2);
        let got = overlap(&a, &b, &(pa.inverse() * pb)).map_or(0.0, |o| o.volume);
        prop_assert!((got - truth).abs() <= 1e-10 * (1.0 + truth), "{got} vs {truth}");
    }

    /// Swapping A and B gives the same volume and centroid, and the opposite normal.
    #[test]
    fn symmetric_in_a_and_b(
        t in prop::array::uniform3(-0.012f64..0.012),
        r1 in prop::array::uniform3(-3.0f64..3.0),
        r2 in prop::array::uniform3(-3.0f64..3.0),
    ) {
        let a = generators::dodecahedron(0.01).unwrap();
        let b = generators::prism(20, 0.012, 0.01).unwrap();
        let pa = pose([0.0; 3], r1);
        let pb = pose(t, r2);
        let ab = overlap(&a, &b, &(pa.inverse() * pb));
        let ba = overlap(&b, &a, &(pb.inverse() * pa));
        match (ab, ba) {
            (None, None) => {}
            (Some(x), Some(y)) => {
                prop_assert!((x.volume - y.volume).abs() <= 1e-12 * 1e-6 + 1e-9 * x.volume);
                let cx = pa * x.centroid;
                let cy = pb * y.centroid;
                prop_assert!((cx - cy).norm() <= 1e-9 * 0.01, "{cx} vs {cy}");
                // The area vectors are opposite. Their directions are compared only
                // where the vector is above round-off. It is zero when no small motion
                // changes the volume: the dodecahedron (circumradius 0.01) fits between
                // the prism's sides (apothem 0.0119), and a shift across the prism's
                // axis leaves both caps cutting it alike. There it is ~1e-20 m² against
                // faces of ~1e-4 m², and its direction is noise no force depends on.
                let round_off = 1e-9 * 1e-4;
                let ax = pa * x.area_vector();
                let ay = pb * y.area_vector();
                prop_assert!((ax + ay).norm() <= round_off + 1e-7 * x.area, "{ax} vs {ay}");
                if x.area > 1e3 * round_off {
                    let (nx, ny) = (pa * x.normal, pb * y.normal);
                    prop_assert!((nx + ny).norm() <= 1e-7, "{nx} vs {ny}");
                }
                prop_assert!((x.area - y.area).abs() <= round_off + 1e-8 * x.area);
            }
            (x, y) => {
                // Only allowed at a touching configuration.
                let v = x.or(y).unwrap().volume;
                prop_assert!(v < 1e-18, "one-sided overlap {v}");
            }
        }
    }

    /// Overlap exists exactly when GJK finds the shapes intersecting.
    #[test]
    fn zero_exactly_when_gjk_says_apart(
        t in prop::array::uniform3(-0.025f64..0.025),
        r1 in prop::array::uniform3(-3.0f64..3.0),
        r2 in prop::array::uniform3(-3.0f64..3.0),
        seed in 0u64..1000,
    ) {
        let a = generators::dodecahedron(0.01).unwrap();
        let b = generators::random_convex(24, 0.01, 0.3, seed).unwrap();
        let rel = pose([0.0; 3], r1).inverse() * pose(t, r2);
        let o = overlap(&a, &b, &rel);
        match gjk(&a, &b, &rel, None) {
            GjkResult::Separated { distance, .. } => {
                prop_assert!(distance > 0.0);
                prop_assert!(o.is_none(), "GJK says {distance:e} apart, overlap {:?}", o);
            }
            GjkResult::Intersecting => {
                // Touching within round-off may still give no volume.
                if o.is_none() {
                    let deeper = pose([0.0; 3], r1).inverse() * pose([t[0] * 0.999, t[1] * 0.999, t[2] * 0.999], r2);
                    prop_assert!(overlap(&a, &b, &deeper).is_some(), "GJK intersecting but no overlap at t = {t:?}");
                }
            }
        }
    }

    /// The contact normal times area is the gradient of the overlap volume with respect
    /// to B's translation (with a minus sign): a central finite difference agrees.
    #[test]
    fn normal_is_the_volume_gradient(
        t in prop::array::uniform3(-0.014f64..0.014),
        r1 in prop::array::uniform3(-3.0f64..3.0),
        r2 in prop::array::uniform3(-3.0f64..3.0),
    ) {
        let a = generators::dodecahedron(0.01).unwrap();
        let b = generators::prism(20, 0.011, 0.009).unwrap();
        let rel = pose([0.0; 3], r1).inverse() * pose(t, r2);
        let Some(o) = overlap(&a, &b, &rel) else { return Ok(()) };
        prop_assume!(o.volume > 1e-10);
        let h = 1e-8;
        let mut grad = Vector3::zeros();
        for k in 0..3 {
            let mut dp = Vector3::zeros();
            dp[k] = h;
            let plus = Isometry3::from_parts((rel.translation.vector + dp).into(), rel.rotation);
            let minus = Isometry3::from_parts((rel.translation.vector - dp).into(), rel.rotation);
            let vp = overlap(&a, &b, &plus).map_or(0.0, |o| o.volume);
            let vm = overlap(&a, &b, &minus).map_or(0.0, |o| o.volume);
            grad[k] = (vp - vm) / (2.0 * h);
        }
        let expected = -o.area_vector();
        prop_assert!((grad - expected).norm() <= 1e-5 * o.area + 1e-12, "fd {grad} vs {expected}");
        // Rotating B about its centroid, and A about its own (= turning B's pose about
        // A's origin the other way).
        let (mut rot_b, mut rot_a) = (Vector3::zeros(), Vector3::zeros());
        for k in 0..3 {
            let mut w = Vector3::zeros();
            w[k] = h / 0.01;
            let turn = |w: Vector3<f64>| nalgebra::UnitQuaternion::from_scaled_axis(w);
            let spin_b = |w: Vector3<f64>| Isometry3::from_parts(rel.translation, turn(w) * rel.rotation);
            let vol = |p: &Isometry3<f64>| overlap(&a, &b, p).map_or(0.0, |o| o.volume);
            rot_b[k] = (vol(&spin_b(w)) - vol(&spin_b(-w))) / (2.0 * w[k]);
            let spin_a = |w: Vector3<f64>| Isometry3::from_parts(nalgebra::Translation3::identity(), turn(-w)) * rel;
            rot_a[k] = (vol(&spin_a(w)) - vol(&spin_a(-w))) / (2.0 * w[k]);
        }
        let scale = o.area * 0.01;
        prop_assert!((rot_b - o.rotation_gradient_b).norm() <= 1e-4 * scale + 1e-14, "fd {rot_b} vs {}", o.rotation_gradient_b);
        prop_assert!((rot_a - o.rotation_gradient_a).norm() <= 1e-4 * scale + 1e-14, "fd {rot_a} vs {}", o.rotation_gradient_a);
        // Angular momentum balance: the torques and the force's moment cancel. When B
        // lies wholly inside A every term is zero up to the round-off of moments of
        // 1 cm faces (each ~1e-6 m³, eps 2e-16): hence the absolute floor.
        let t = rel.translation.vector;
        let balance = o.rotation_gradient_a + o.rotation_gradient_b + t.cross(&expected);
        prop_assert!(balance.norm() <= 1e-9 * scale + 1e-18, "{balance}");
    }
}

/// Common rigid motion of both bodies changes nothing.
#[test]
fn invariant_under_common_rigid_motion() {
    let a = generators::dodecahedron(0.01).unwrap();
    let b = generators::random_convex(30, 0.008, 0.2, 3).unwrap();
    let pa = pose([0.001, 0.0, 0.0], [0.1, 0.2, 0.3]);
    let pb = pose([0.012, 0.004, -0.002], [-0.4, 0.5, 0.1]);
    let base = overlap(&a, &b, &(pa.inverse() * pb)).unwrap();
    for (shift, rot) in [
        ([1.0, 2.0, 3.0], [0.3, -1.0, 2.0]),
        ([-50.0, 0.0, 7.0], [2.5, 0.0, 0.0]),
    ] {
        let m = pose(shift, rot);
        let (qa, qb) = (m * pa, m * pb);
        let moved = overlap(&a, &b, &(qa.inverse() * qb)).unwrap();
        assert!((moved.volume - base.volume).abs() <= 1e-9 * base.volume);
        assert!((moved.centroid - base.centroid).norm() <= 1e-9 * 0.01);
        assert!((moved.normal - base.normal).norm() <= 1e-8);
    }
}

/// Sliding one shape through the other: the volume is continuous, and each increment
/// matches the gradient to second order.
#[test]
fn continuous_as_one_shape_slides_through_the_other() {
    let a = generators::dodecahedron(0.01).unwrap();
    let b = generators::prism(20, 0.008, 0.012).unwrap();
    let dir = Vector3::new(1.0, 0.3, -0.2).normalize();
    let rot = [0.3, 0.7, -0.2];
    let steps = 4000;
    let span = 0.04;
    let h = span / steps as f64;
    let mut prev: Option<(f64, Vector3<f64>)> = None;
    let mut seen_max: f64 = 0.0;
    for k in 0..=steps {
        let s = -span / 2.0 + k as f64 * h;
        let t = dir * s;
        let o = overlap(&a, &b, &pose([t.x, t.y, t.z], rot));
        let (v, g) = o.map_or((0.0, Vector3::zeros()), |o| (o.volume, -o.area_vector()));
        seen_max = seen_max.max(v);
        if let Some((pv, pg)) = prev {
            // Trapezoid rule on the gradient along the path.
            let predicted = pv + 0.5 * (pg + g).dot(&dir) * h;
            assert!(
                (v - predicted).abs() <= 1e-3 * h * 1e-4 + 2e-13,
                "step {k}: {v} vs {predicted}"
            );
        }
        prev = Some((v, g));
    }
    assert!(
        seen_max > 0.5 * b.volume(),
        "the prism passed through the dodecahedron"
    );
}

/// Random convex pairs against a Monte Carlo estimate (4 standard errors).
#[test]
fn agrees_with_monte_carlo_on_random_convex_pairs() {
    for seed in 0..6u64 {
        let a = generators::random_convex(20 + seed as usize, 0.01, 0.4, seed).unwrap();
        let b = generators::random_convex(30, 0.009, 0.4, 100 + seed).unwrap();
        let rel = pose(
            [0.008, -0.004 + 0.001 * seed as f64, 0.003],
            [seed as f64, 1.0, -0.5],
        );
        let exact = overlap(&a, &b, &rel).map_or(0.0, |o| o.volume);
        let (mc, se) = monte_carlo_overlap(&a, &b, &rel, 400_000, seed);
        assert!(exact > 0.0);
        assert!(
            (exact - mc).abs() <= 4.0 * se,
            "seed {seed}: exact {exact:e}, MC {mc:e} ± {se:e}"
        );
    }
}

/// Shapes of 65 to 128 vertices and at most 64 faces (a 40-gon prism: 80 vertices,
/// 42 faces) take the bit-mask path with 128-bit vertex sets: the closed form of
/// coaxial prisms, Monte Carlo at random poses, also against a 20-vertex shape.
#[test]
fn prisms_of_80_vertices() {
    let (d, l) = (0.01, 0.012);
    let a = generators::prism(40, d, l).unwrap();
    assert_eq!((a.vertices().len(), a.face_count()), (80, 42));
    // The axis: the normal of a cap (the face of 40 vertices).
    let cap = (0..a.face_count())
        .find(|&f| a.face(f).len() == 40)
        .unwrap();
    let axis = a.planes()[cap].normal;
    for s in [0.1, 0.5, 0.93] {
        let rel = Isometry3::translation(axis.x * s * l, axis.y * s * l, axis.z * s * l);
        let o = overlap(&a, &a, &rel).unwrap();
        let exact = a.volume() * (1.0 - s);
        assert!(
            (o.volume - exact).abs() < 1e-12 * a.volume(),
            "shift {s}: {:e} vs {exact:e}",
            o.volume
        );
        // A flat face-to-face contact (the flush sides left out): the cap area, along
        // the axis from A towards B.
        let cap_area = a.volume() / l;
        assert!(
            (o.area_vector() - axis * cap_area).norm() < 1e-9 * cap_area,
            "{} vs {}",
            o.area_vector(),
            axis * cap_area
        );
    }
    let dodecahedron = generators::platonic(Platonic::Dodecahedron, 0.006).unwrap();
    let cases = [
        (&a, &a, pose([0.006, 0.003, -0.004], [0.4, -1.1, 0.3])),
        (&a, &a, pose([-0.002, 0.009, 0.001], [2.1, 0.5, -0.8])),
        (
            &a,
            &dodecahedron,
            pose([0.004, -0.005, 0.006], [0.1, 0.9, 1.7]),
        ),
        (
            &dodecahedron,
            &a,
            pose([0.008, 0.001, 0.0], [-0.6, 0.2, 0.4]),
        ),
    ];
    for (k, (a, b, rel)) in cases.iter().enumerate() {
        let exact = overlap(a, b, rel).map_or(0.0, |o| o.volume);
        let (mc, se) = monte_carlo_overlap(a, b, rel, 400_000, 40 + k as u64);
        assert!(exact > 0.0);
        assert!(
            (exact - mc).abs() <= 4.0 * se,
            "case {k}: exact {exact:e}, MC {mc:e} ± {se:e}"
        );
    }
}

#[test]
fn rotated_square_prisms_make_an_octagon() {
    // Concentric unit cubes, one turned 45° about z: a regular octagon prism.
    let cube = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    let o = overlap(
        &cube,
        &cube,
        &pose([0.0, 0.0, 0.3], [0.0, 0.0, std::f64::consts::FRAC_PI_4]),
    )
    .unwrap();
    let truth = 2.0 * (SQRT2 - 1.0) * 0.7;
    assert!((o.volume - truth).abs() < 1e-14, "{} vs {truth}", o.volume);
    assert!((o.normal - Vector3::z()).norm() < 1e-12);
    assert!((o.area - 2.0 * (SQRT2 - 1.0)).abs() < 1e-13);
    assert!((o.depth - 0.7).abs() < 1e-14);
}

// ---- Hard cases -------------------------------------------------------------------

#[test]
fn parallel_face_to_face() {
    // B covers A's extent in z and lies flush with A's +y face: the only gradient is
    // along x (the flush face must not push sideways).
    let a = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    let b = generators::cuboid(0.6, 0.8, 1.2).unwrap();
    for delta in [0.3, 1e-3, 1e-6] {
        let o = overlap(&a, &b, &pose([0.8 - delta, 0.1, -0.05], [0.0; 3])).unwrap();
        let truth = delta * 0.8;
        assert!((o.volume - truth).abs() < 1e-15, "{} vs {truth}", o.volume);
        assert!((o.normal - Vector3::x()).norm() < 1e-12, "{delta}: {o:?}");
        assert!((o.area - 0.8).abs() < 1e-12);
        assert!((o.depth - delta).abs() < 1e-14);
    }
}

#[test]
fn edge_to_edge_crossing() {
    // Cube A turned 45° about x (top edge along x), cube B turned 45° about y (bottom
    // edge along y), edges crossing at depth δ: V = 2δ³/3.
    let s = 1.0;
    let cube = generators::cuboid(s, s, s).unwrap();
    let pa = pose([0.0; 3], [std::f64::consts::FRAC_PI_4, 0.0, 0.0]);
    for delta in [0.05, 1e-3] {
        let z = 2.0 * s / SQRT2 - delta;
        let pb = pose([0.0, 0.0, z], [0.0, std::f64::consts::FRAC_PI_4, 0.0]);
        let o = overlap(&cube, &cube, &(pa.inverse() * pb)).unwrap();
        let truth = 2.0 * delta.powi(3) / 3.0;
        assert!(
            (o.volume - truth).abs() < 1e-12 * truth + 1e-16,
            "{} vs {truth}",
            o.volume
        );
        assert!(((pa * o.normal) - Vector3::z()).norm() < 1e-9);
    }
}

#[test]
fn vertex_into_face() {
    // A cube standing on a vertex (body diagonal vertical) pushed δ into a flat face:
    // the overlap is the corner tetrahedron, V = √3 δ³ / 2.
    let cube = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    let slab = generators::cuboid(4.0, 4.0, 1.0).unwrap();
    let diag = Vector3::new(1.0, 1.0, 1.0).normalize();
    let rot = nalgebra::UnitQuaternion::rotation_between(&-diag, &-Vector3::z()).unwrap();
    let half_diag = 3f64.sqrt() / 2.0;
    for delta in [0.1, 1e-4] {
        let pb = Isometry3::from_parts(
            nalgebra::Translation3::new(0.0, 0.0, 0.5 + half_diag - delta),
            rot,
        );
        let o = overlap(&slab, &cube, &pb).unwrap();
        let truth = 3f64.sqrt() * delta.powi(3) / 2.0;
        // δ itself is known to ~1e-16 absolute (it is a difference of O(1) numbers).
        let tol = truth * 3.0 * 1e-15 / delta;
        assert!((o.volume - truth).abs() < tol, "{} vs {truth}", o.volume);
        assert!((o.normal - Vector3::z()).norm() < 1e-9);
        assert!((o.depth - delta).abs() < 1e-12);
    }
}

#[test]
fn coincident_identical_shapes() {
    for shape in [
        generators::dodecahedron(0.01).unwrap(),
        generators::cuboid(1.0, 2.0, 3.0).unwrap(),
        generators::prism(20, 5.5e-3, 5.5e-3).unwrap(),
    ] {
        let o = overlap(&shape, &shape, &Isometry3::identity()).unwrap();
        assert!(
            (o.volume - shape.volume()).abs() < 1e-12 * shape.volume(),
            "{} vs {}",
            o.volume,
            shape.volume()
        );
        assert!(o.normal.iter().all(|x| x.is_finite()));
        assert!((o.normal.norm() - 1.0).abs() < 1e-12);
        assert!(o.centroid.coords.norm() < 1e-12 * shape.circumradius());
    }
}

#[test]
fn one_shape_inside_the_other() {
    let big = generators::dodecahedron(1.0).unwrap();
    let small = generators::platonic(Platonic::Icosahedron, 0.1).unwrap();
    let o = overlap(&big, &small, &pose([0.2, -0.1, 0.15], [0.3, 0.2, 0.1])).unwrap();
    assert!((o.volume - small.volume()).abs() < 1e-14);
    assert!((o.centroid.coords - Vector3::new(0.2, -0.1, 0.15)).norm() < 1e-12);
    // Moving either shape does not change the volume: the area vector (∂V/∂x) is
    // zero to round-off against faces of ~0.5 m².
    assert!(o.area < 1e-13, "area {}", o.area);
    let o = overlap(
        &small,
        &big,
        &pose([0.2, -0.1, 0.15], [0.3, 0.2, 0.1]).inverse(),
    )
    .unwrap();
    assert!((o.volume - small.volume()).abs() < 1e-14);
    assert!(o.area < 1e-13, "area {}", o.area);
}

#[test]
fn overlap_of_1e_minus_12_of_the_particle_size() {
    let a = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    let delta = 1e-12;
    let o = overlap(&a, &a, &pose([1.0 - delta, 0.3, 0.2], [0.0; 3])).unwrap();
    let truth = delta * 0.7 * 0.8;
    // Round-off in the plane distances is ~1e-16 of the size: the volume is right to
    // that, times the contact area.
    assert!((o.volume - truth).abs() < 1e-15, "{} vs {truth}", o.volume);
    assert!((o.normal - Vector3::x()).norm() < 1e-9);
    // Dodecahedra touching face to face at the same depth.
    let d = generators::dodecahedron(0.01).unwrap();
    let plane = d.planes()[0];
    let n = plane.normal;
    let flip = nalgebra::UnitQuaternion::rotation_between(&n, &-n).unwrap_or_else(|| {
        nalgebra::UnitQuaternion::from_axis_angle(
            &nalgebra::Unit::new_normalize(n.cross(&Vector3::x())),
            std::f64::consts::PI,
        )
    });
    let t = n * (2.0 * plane.offset - 1e-12 * 0.01);
    let o = overlap(&d, &d, &Isometry3::from_parts(t.into(), flip)).unwrap();
    assert!(o.volume > 0.0 && o.volume < 1e-12 * 0.01 * 0.01 * 0.01 * 10.0);
    assert!((o.normal - n).norm() < 1e-6, "{} vs {n}", o.normal);
}

#[test]
fn sliver_faces() {
    // A cube with one corner shaved by 1e-6 of its size: a tiny triangular face and
    // three pentagons with a sliver edge.
    let e = 1e-6;
    let mut pts = Vec::new();
    for x in [-0.5, 0.5] {
        for y in [-0.5, 0.5] {
            for z in [-0.5, 0.5] {
                if x > 0.0 && y > 0.0 && z > 0.0 {
                    pts.push(nalgebra::Point3::new(0.5 - e, 0.5, 0.5));
                    pts.push(nalgebra::Point3::new(0.5, 0.5 - e, 0.5));
                    pts.push(nalgebra::Point3::new(0.5, 0.5, 0.5 - e));
                } else {
                    pts.push(nalgebra::Point3::new(x, y, z));
                }
            }
        }
    }
    let shaved = talus::geometry::ConvexPolyhedron::from_hull(&pts).unwrap();
    assert_eq!(shaved.face_count(), 7);
    let cube = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    // Poses are given in the input frame of the shaved cube; its body frame is
    // shifted (and possibly turned) from it by a negligible amount.
    let input_to_body = shaved.body_to_input().inverse();
    for (t, truth) in [
        ([0.7, 0.6, 0.65], 0.3 * 0.4 * 0.35),
        ([0.0, 0.0, 0.999], 0.001),
    ] {
        let o = overlap(&shaved, &cube, &(input_to_body * pose(t, [0.0; 3]))).unwrap();
        // The shaved corner holds e³/6 of volume.
        assert!((o.volume - truth).abs() < 1e-15, "{} vs {truth}", o.volume);
    }
}

#[test]
fn shapes_of_20480_facets() {
    // Two level-5 icospheres: the volume lies between the lenses of the inscribed and
    // the circumscribed spheres.
    let r = 1.0;
    let ico = generators::icosphere(5, r).unwrap();
    let r_in = ico
        .planes()
        .iter()
        .map(|p| p.offset)
        .fold(f64::INFINITY, f64::min);
    let lens = |r: f64, d: f64| {
        std::f64::consts::PI * (2.0 * r - d).powi(2) * (d * d + 4.0 * d * r) / (12.0 * d)
    };
    for (d, rot) in [(1.9, [0.0, 0.0, 0.0]), (1.2, [0.4, 0.2, 0.9])] {
        let o = overlap(&ico, &ico, &pose([d, 0.0, 0.0], rot)).unwrap();
        assert!(
            o.volume >= lens(r_in, d) && o.volume <= lens(r, d),
            "{} not in [{}, {}]",
            o.volume,
            lens(r_in, d),
            lens(r, d)
        );
        assert!((o.normal - Vector3::x()).norm() < 2e-3);
    }
    let o = overlap(&ico, &ico, &pose([3.0, 0.0, 0.0], [0.0; 3]));
    assert!(o.is_none());
}

#[test]
fn size_ratio_of_100() {
    // A small dodecahedron centred on a face of a large one: central symmetry makes
    // the overlap exactly half of it.
    let big = generators::dodecahedron(1.0).unwrap();
    let small = generators::dodecahedron(0.01).unwrap();
    let plane = big.planes()[3];
    let face_centre = big.face(3).iter().fold(Vector3::zeros(), |a, &v| {
        a + big.vertices()[v as usize].coords
    }) / 5.0;
    for rot in [[0.0, 0.0, 0.0], [0.3, 1.1, -0.7]] {
        let o = overlap(
            &big,
            &small,
            &pose([face_centre.x, face_centre.y, face_centre.z], rot),
        )
        .unwrap();
        assert!(
            (o.volume - small.volume() / 2.0).abs() < 1e-12 * small.volume(),
            "{} vs {}",
            o.volume,
            small.volume() / 2.0
        );
        assert!((o.normal - plane.normal).norm() < 1e-9);
        let o2 = overlap(
            &small,
            &big,
            &pose([face_centre.x, face_centre.y, face_centre.z], rot).inverse(),
        )
        .unwrap();
        assert!((o2.volume - o.volume).abs() < 1e-12 * small.volume());
    }
}

// ---- Large meshes (the culled, local-clipping path) ---------------------------------

#[test]
fn large_meshes_agree_with_monte_carlo() {
    let ico = generators::icosphere(2, 0.01).unwrap();
    let cube = generators::cuboid(0.012, 0.012, 0.012).unwrap();
    let cases = [
        (&ico, &ico, pose([0.016, 0.002, -0.001], [0.3, 1.2, -0.7])),
        (&ico, &ico, pose([0.008, -0.004, 0.003], [2.0, 0.1, 0.4])),
        (&ico, &cube, pose([0.009, 0.004, 0.0], [0.2, 0.3, 0.4])),
        (&cube, &ico, pose([-0.004, 0.0, 0.012], [0.0, 0.0, 0.0])),
    ];
    for (k, (a, b, rel)) in cases.iter().enumerate() {
        let exact = overlap(a, b, rel).map_or(0.0, |o| o.volume);
        let (mc, se) = monte_carlo_overlap(a, b, rel, 400_000, k as u64);
        assert!(exact > 0.0);
        assert!(
            (exact - mc).abs() <= 4.0 * se,
            "case {k}: exact {exact:e}, MC {mc:e} ± {se:e}"
        );
    }
}

#[test]
fn large_meshes_coincident_nested_and_gradient() {
    let ico = generators::icosphere(2, 1.0).unwrap();
    let o = overlap(&ico, &ico, &Isometry3::identity()).unwrap();
    assert!((o.volume - ico.volume()).abs() < 1e-12 * ico.volume());
    let small = generators::cuboid(0.2, 0.3, 0.1).unwrap();
    let o = overlap(&ico, &small, &pose([0.1, 0.2, -0.3], [0.5, 0.0, 1.0])).unwrap();
    assert!((o.volume - small.volume()).abs() < 1e-14);
    // The area vector is the volume gradient here too.
    let rel = pose([1.5, 0.2, -0.1], [0.3, -0.2, 0.9]);
    let o = overlap(&ico, &ico, &rel).unwrap();
    let h = 1e-7;
    let mut grad = Vector3::zeros();
    for k in 0..3 {
        let mut dp = Vector3::zeros();
        dp[k] = h;
        let plus = Isometry3::from_parts((rel.translation.vector + dp).into(), rel.rotation);
        let minus = Isometry3::from_parts((rel.translation.vector - dp).into(), rel.rotation);
        grad[k] = (overlap(&ico, &ico, &plus).unwrap().volume
            - overlap(&ico, &ico, &minus).unwrap().volume)
            / (2.0 * h);
    }
    assert!(
        (grad + o.area_vector()).norm() < 1e-5 * o.area,
        "{grad} vs {}",
        -o.area_vector()
    );
}
