use super::*;
use crate::contact::Material;
use crate::geometry::Sphere;
use crate::geometry::generators::cuboid;
use crate::world::BodyType;
use std::f64::consts::PI;
use std::sync::Arc;

fn world_of(shape: Shape, placements: &[(Point3<Real>, UnitQuaternion<Real>)]) -> World {
    let material = Material {
        name: "m".into(),
        density: 1000.0,
        young: 1e6,
        poisson: 0.3,
        restitution: 0.5,
        friction: 0.0,
        rolling_friction: 0.0,
        rolling_damping: 0.0,
    };
    let mut world = World {
        materials: vec![material.clone()],
        body_types: vec![BodyType::new(shape, &material, 0)],
        ..World::default()
    };
    for (k, (x, q)) in placements.iter().enumerate() {
        world.particles.push(0, *x, *q, k as u64);
    }
    world
}

fn tube(radius: Real) -> Tube {
    Tube {
        base: Point3::new(0.3, -0.2, 0.0),
        axis: Vector3::z(),
        radius,
    }
}

/// Volume of a sphere of radius a (centred on the axis) inside the cylinder ρ ≤ r.
fn sphere_in_cylinder(a: Real, r: Real) -> Real {
    4.0 / 3.0 * PI * (a.powi(3) - (a * a - r * r).max(0.0).powf(1.5))
}

#[test]
fn a_column_of_spheres_has_its_closed_form_profile() {
    let a = 1.0;
    let t = tube(1.5);
    let column: Vec<_> = (0..5)
        .map(|k| {
            let z = (2 * k + 1) as Real * a;
            (Point3::new(0.3, -0.2, z), UnitQuaternion::identity())
        })
        .collect();
    let world = world_of(Shape::Sphere(Sphere::new(a).unwrap()), &column);
    // The region holds the three middle spheres whole; bins of 0.13 cut them.
    let options = PackingOptions {
        bin: Some(0.13),
        region: Some((2.0, 8.0)),
        ..Default::default()
    };
    let p = analyse(&world, &Bed { tube: t, options }).unwrap();
    assert!((p.porosity - (1.0 - 4.0 / (6.0 * 2.25))).abs() < 1e-12);
    for b in &p.radial {
        let solid = 3.0 * (sphere_in_cylinder(a, b.r_outer) - sphere_in_cylinder(a, b.r_inner));
        let annulus = PI * (b.r_outer.powi(2) - b.r_inner.powi(2)) * 6.0;
        assert!(
            (1.0 - b.porosity - solid / annulus).abs() < 1e-8,
            "{b:?}: {}",
            solid / annulus
        );
    }
    assert_eq!(p.radial.len(), 12);
    assert!((p.radial[11].r_outer - 1.5).abs() < 1e-15);
    assert!(p.radial[11].porosity == 1.0, "beyond the spheres");
    // A radius 10.005 bins wide: the remainder widens the last bin.
    let options = PackingOptions {
        bin: Some(1.5 / 10.005),
        ..options
    };
    let q = analyse(&world, &Bed { tube: t, options }).unwrap();
    assert_eq!(q.radial.len(), 10);
    assert_eq!(q.radial[9].r_outer, 1.5);
    assert!((q.radial[9].r_inner - 9.0 * 1.5 / 10.005).abs() < 1e-15);
    // Touching spheres: the ends have one neighbour, the others two.
    assert_eq!(p.coordination, vec![0, 2, 3]);
    assert!(p.orientation_order.is_none());
    // Five spheres stacked, 10 high: the height ends where the top sphere's
    // section falls below half the column's median section, 0.2 below its pole
    // in slices of d/10 = 0.2.
    assert!((p.bed_height - 9.8).abs() < 1e-9, "{}", p.bed_height);
}

#[test]
fn a_column_of_turned_cubes_has_its_closed_form_profile() {
    let s = 1.0;
    let cube = Arc::new(cuboid(s, s, s).unwrap());
    let t = tube(0.9);
    // Four cubes face to face, each turned about the axis by its own angle: the
    // part of a square inside a centred disc does not depend on the turn.
    let column: Vec<_> = (0..4)
        .map(|k| {
            (
                Point3::new(0.3, -0.2, 0.5 + k as Real),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.4 * k as Real),
            )
        })
        .collect();
    let world = world_of(Shape::Polyhedron(cube), &column);
    // The region cuts the first and last cube: 0.25 … 3.6.
    let options = PackingOptions {
        bin: Some(0.07),
        slice: Some(0.1),
        region: Some((0.25, 3.6)),
        ..Default::default()
    };
    let p = analyse(&world, &Bed { tube: t, options }).unwrap();
    let height = 3.35;
    // Square of half-side h = 0.5 inside a disc of radius r (r ≤ h√2).
    let square_in_disc = |r: Real| {
        let h = 0.5 * s;
        if r <= h {
            PI * r * r
        } else if r >= h * 2f64.sqrt() {
            s * s
        } else {
            let half = (h / r).acos();
            PI * r * r - 4.0 * r * r * (half - half.sin() * half.cos())
        }
    };
    let porosity = 1.0 - s * s * height / (PI * 0.81 * height);
    assert!((p.porosity - porosity).abs() < 1e-12, "{}", p.porosity);
    for b in &p.radial {
        let solid = (square_in_disc(b.r_outer) - square_in_disc(b.r_inner)) * height;
        let annulus = PI * (b.r_outer.powi(2) - b.r_inner.powi(2)) * height;
        assert!((1.0 - b.porosity - solid / annulus).abs() < 1e-8, "{b:?}");
    }
    // The area-weighted profile is the bed average.
    let weighted: Real = p
        .radial
        .iter()
        .map(|b| b.porosity * (b.r_outer.powi(2) - b.r_inner.powi(2)))
        .sum::<Real>()
        / 0.81;
    assert!((weighted - p.porosity).abs() < 1e-12);
    // Face-to-face neighbours; axes along the tube.
    assert_eq!(p.coordination, vec![0, 2, 2]);
    assert_eq!(p.orientation_cos[9], 4);
    assert!((p.orientation_order.unwrap() - 1.0).abs() < 1e-12);
    assert!((p.bed_height - 4.0).abs() < 1e-9);
    // The axial profile: one cube's cross-section in every slice below 4.
    for slice in &p.axial {
        assert!((slice.porosity - (1.0 - 1.0 / (PI * 0.81))).abs() < 1e-12);
    }
}

#[test]
fn tilted_cubes_are_integrated_exactly_where_the_disc_does_not_cut() {
    let cube = Arc::new(cuboid(1.0, 1.0, 1.0).unwrap());
    let q = UnitQuaternion::from_euler_angles(0.3, 0.7, 1.1);
    let world = world_of(
        Shape::Polyhedron(cube),
        &[
            (Point3::new(0.3, -0.2, 2.0), q),
            (Point3::new(0.3, -0.2, 3.9), q),
        ],
    );
    // A tube wide enough that no disc cuts a cube: whole volumes, to round-off.
    let options = PackingOptions {
        bin: Some(1.0),
        region: Some((0.0, 6.0)),
        ..Default::default()
    };
    let p = analyse(
        &world,
        &Bed {
            tube: tube(3.0),
            options,
        },
    )
    .unwrap();
    assert!((p.solid_volume - 2.0).abs() < 1e-13, "{}", p.solid_volume);
}

#[test]
fn a_random_bed_profile_integrates_to_its_average() {
    // Randomly turned cubes at random places in a tube: bins cut them every way.
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    let cube = Arc::new(cuboid(0.3, 0.2, 0.25).unwrap());
    // Circumscribed spheres apart, so the cubes never overlap.
    let mut placements: Vec<(Point3<Real>, UnitQuaternion<Real>)> = Vec::new();
    while placements.len() < 40 {
        let (x, y): (Real, Real) = (rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5));
        let c = Point3::new(0.3 + x, -0.2 + y, rng.random_range(0.3..3.0));
        if placements.iter().all(|(o, _)| (o - c).norm() > 0.425) {
            let axis = Vector3::new(rng.random(), rng.random(), rng.random());
            placements.push((c, UnitQuaternion::from_scaled_axis(axis * 3.0)));
        }
    }
    let world = world_of(Shape::Polyhedron(cube), &placements);
    let options = PackingOptions {
        bin: Some(0.05),
        region: Some((0.5, 2.5)),
        ..Default::default()
    };
    let p = analyse(
        &world,
        &Bed {
            tube: tube(1.0),
            options,
        },
    )
    .unwrap();
    let weighted: Real = p
        .radial
        .iter()
        .map(|b| b.porosity * (b.r_outer.powi(2) - b.r_inner.powi(2)))
        .sum();
    assert!((weighted - p.porosity).abs() < 1e-12);
    assert!(p.volume_error < 1e-9 * p.solid_volume, "{}", p.volume_error);
    // Against midpoint sampling of the region on a fine grid.
    let solid = |x: &Point3<Real>| {
        placements.iter().any(|(c, q)| {
            let local = q.inverse() * (x - c);
            local.x.abs() <= 0.15 && local.y.abs() <= 0.1 && local.z.abs() <= 0.125
        })
    };
    let n = 120;
    let (mut hits, mut total) = (0usize, 0usize);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let (x, y) = (
                    -1.0 + 2.0 * (i as Real + 0.5) / n as Real,
                    -1.0 + 2.0 * (j as Real + 0.5) / n as Real,
                );
                if x * x + y * y > 1.0 {
                    continue;
                }
                total += 1;
                let z = 0.5 + 2.0 * (k as Real + 0.5) / n as Real;
                if solid(&Point3::new(0.3 + x, -0.2 + y, z)) {
                    hits += 1;
                }
            }
        }
    }
    let sampled = 1.0 - hits as Real / total as Real;
    assert!(
        (sampled - p.porosity).abs() < 3e-3,
        "{sampled} {}",
        p.porosity
    );
}
