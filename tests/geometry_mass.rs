//! Mass properties of generated shapes against closed forms.

use std::f64::consts::PI;

use talus::geometry::generators::{self, Platonic};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn cube_volume_and_inertia() {
    let a = 0.02;
    let cube = generators::cuboid(a, a, a).unwrap();
    assert!(rel(cube.volume(), a * a * a) < 1e-13);
    let m = cube.volume();
    for k in 0..3 {
        assert!(rel(cube.principal_inertia()[k], m * a * a / 6.0) < 1e-12);
    }
    assert_eq!(
        cube.face_count(),
        6,
        "coplanar triangles merge into squares"
    );
    assert_eq!(cube.vertices().len(), 8);
    assert_eq!(cube.edges().len(), 12);
    assert!(rel(cube.circumradius(), a * 3f64.sqrt() / 2.0) < 1e-13);
}

#[test]
fn cuboid_inertia_and_axes() {
    let (a, b, c) = (0.3, 0.2, 0.1);
    let box_ = generators::cuboid(a, b, c).unwrap();
    let m = box_.volume();
    assert!(rel(m, a * b * c) < 1e-13);
    let i = box_.principal_inertia();
    assert!(rel(i.x, m * (b * b + c * c) / 12.0) < 1e-12);
    assert!(rel(i.y, m * (a * a + c * c) / 12.0) < 1e-12);
    assert!(rel(i.z, m * (a * a + b * b) / 12.0) < 1e-12);
    // The body frame keeps the box axis-aligned.
    for v in box_.vertices() {
        assert!(rel(v.x.abs(), a / 2.0) < 1e-12 && rel(v.y.abs(), b / 2.0) < 1e-12);
    }
}

#[test]
fn rotated_cuboid_is_brought_to_its_principal_frame() {
    use nalgebra::{Point3, UnitQuaternion, Vector3};
    let (a, b, c) = (0.3, 0.2, 0.1);
    let q = UnitQuaternion::from_scaled_axis(Vector3::new(1.0, 2.0, 3.0).normalize() * 0.7);
    let shift = Vector3::new(1.0, -2.0, 0.5);
    let mut pts = Vec::new();
    for sx in [-0.5, 0.5] {
        for sy in [-0.5, 0.5] {
            for sz in [-0.5, 0.5] {
                pts.push(Point3::from(
                    q * Vector3::new(sx * a, sy * b, sz * c) + shift,
                ));
            }
        }
    }
    let p = talus::geometry::ConvexPolyhedron::from_hull(&pts).unwrap();
    let m = p.volume();
    let mut moments: Vec<f64> = p.principal_inertia().iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    let mut expect = [
        m * (a * a + b * b) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (b * b + c * c) / 12.0,
    ];
    expect.sort_by(f64::total_cmp);
    for k in 0..3 {
        assert!(
            rel(moments[k], expect[k]) < 1e-10,
            "{moments:?} vs {expect:?}"
        );
    }
    // body_to_input maps the body frame back onto the input points.
    let centre = p.body_to_input().translation.vector;
    assert!((centre - shift).norm() < 1e-12);
}

#[test]
fn regular_dodecahedron() {
    let r = 0.005;
    let d = generators::dodecahedron(r).unwrap();
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    // Edge length from circumradius: R = a √3 φ / 2.
    let a = 2.0 * r / (3f64.sqrt() * phi);
    let volume = (15.0 + 7.0 * 5f64.sqrt()) / 4.0 * a.powi(3);
    assert!(
        rel(d.volume(), volume) < 1e-12,
        "{} vs {volume}",
        d.volume()
    );
    let inertia = d.volume() * a * a * (95.0 + 39.0 * 5f64.sqrt()) / 300.0;
    for k in 0..3 {
        assert!(rel(d.principal_inertia()[k], inertia) < 1e-12);
    }
    assert_eq!(d.face_count(), 12);
    assert!((0..12).all(|f| d.face(f).len() == 5), "pentagonal faces");
    assert_eq!(d.vertices().len(), 20);
    assert_eq!(d.edges().len(), 30);
    assert!(rel(d.circumradius(), r) < 1e-13);
}

#[test]
fn platonic_solids_by_circumradius() {
    let r = 1.0;
    // (kind, faces, vertices, volume at unit circumradius)
    let cases = [
        (Platonic::Tetrahedron, 4, 4, 8.0 / (9.0 * 3f64.sqrt())),
        (Platonic::Cube, 6, 8, 8.0 / (3.0 * 3f64.sqrt())),
        (Platonic::Octahedron, 8, 6, 4.0 / 3.0),
        (Platonic::Icosahedron, 20, 12, 2.536_150_710_120_409_5),
    ];
    for (kind, faces, verts, volume) in cases {
        let p = generators::platonic(kind, r).unwrap();
        assert_eq!(p.face_count(), faces, "{kind:?}");
        assert_eq!(p.vertices().len(), verts, "{kind:?}");
        assert!(
            rel(p.volume(), volume) < 1e-12,
            "{kind:?}: {} vs {volume}",
            p.volume()
        );
        assert!(rel(p.circumradius(), r) < 1e-13);
    }
}

#[test]
fn prism_cylinder_against_polygon_prism_formula() {
    // The primary seed's pellet: 20-gon, D = L = 5.5 mm, 42 vertices, 80 triangles.
    let (n, d, l) = (20usize, 5.5e-3, 5.5e-3);
    let mesh = generators::prism_mesh(n, d, l).unwrap();
    assert_eq!(mesh.vertices.len(), 42);
    assert_eq!(mesh.triangles.len(), 80);
    let p = generators::prism(n, d, l).unwrap();
    assert_eq!(p.face_count(), n + 2, "side quads and two n-gon caps");
    assert_eq!(
        p.vertices().len(),
        2 * n,
        "cap centres are not vertices of the solid"
    );
    let r = d / 2.0;
    let nf = n as f64;
    let area = 0.5 * nf * r * r * (2.0 * PI / nf).sin();
    let volume = area * l;
    assert!(rel(p.volume(), volume) < 1e-12);
    // Polar moment of a regular n-gon per unit area: R²/6 (1 + 2 cos²(π/n)).
    let polar = r * r / 6.0 * (1.0 + 2.0 * (PI / nf).cos().powi(2));
    let izz = volume * polar;
    let ixx = volume * (polar / 2.0 + l * l / 12.0);
    let i = p.principal_inertia();
    assert!(rel(i.z, izz) < 1e-12, "{} vs {izz}", i.z);
    assert!(rel(i.x, ixx) < 1e-12 && rel(i.y, ixx) < 1e-12);
}

#[test]
fn icosphere_converges_to_the_sphere() {
    let r = 1.0;
    let exact_v = 4.0 / 3.0 * PI;
    let exact_i = 0.4 * exact_v;
    let mut last_err = f64::INFINITY;
    for (level, triangles) in [(2, 320), (3, 1280), (4, 5120), (5, 20480)] {
        let mesh = generators::icosphere_mesh(level, r).unwrap();
        assert_eq!(mesh.triangles.len(), triangles);
        let p = generators::icosphere(level, r).unwrap();
        assert_eq!(p.face_count(), triangles);
        let err = rel(p.volume(), exact_v);
        // Inscribed: always below, and the error falls about fourfold per level.
        assert!(p.volume() < exact_v);
        assert!(err < last_err / 3.5, "level {level}: {err} vs {last_err}");
        let ierr = rel(p.principal_inertia().x, exact_i * p.volume() / exact_v);
        assert!(ierr < 4.0 * err, "level {level}: inertia error {ierr}");
        last_err = err;
    }
    assert!(last_err < 1e-3, "{last_err}");
}

#[test]
fn random_convex_is_reproducible() {
    let a = generators::random_convex(40, 0.01, 0.3, 7).unwrap();
    let b = generators::random_convex(40, 0.01, 0.3, 7).unwrap();
    let c = generators::random_convex(40, 0.01, 0.3, 8).unwrap();
    assert_eq!(a.vertices(), b.vertices());
    assert_ne!(a.vertices(), c.vertices());
    let shift = a.body_to_input().translation.vector.norm();
    assert!(a.circumradius() <= 0.013 + shift);
    // Principal frame: inertia tensor diagonal by construction; volume positive.
    assert!(a.volume() > 0.0);
    assert!(a.equivalent_radius() < a.circumradius());
}

#[test]
fn sphere_shape() {
    use talus::geometry::{Shape, Sphere};
    let s = Shape::Sphere(Sphere::new(0.5).unwrap());
    assert!(rel(s.volume(), 4.0 / 3.0 * PI * 0.125) < 1e-15);
    assert!(rel(s.principal_inertia().x, 0.4 * s.volume() * 0.25) < 1e-15);
    assert!(Sphere::new(-1.0).is_err());
    assert!(Sphere::new(f64::NAN).is_err());
}
