//! ParaView frames of particles (`output::vtk::write_particles`): spheres as
//! icospheres, or as points with their radius (`[output] spheres = "points"`) before
//! the polyhedra's faces, each cell carrying its particle's fields.

use std::path::Path;

mod common;
use common::read_vtk;

use talus::output::vtk::write_particles;
use talus::scene::Scene;
use talus::scene::spec::SphereFrames;

const MIXED: &str = r#"
[simulation]
dt = 1e-5
end_time = 0.01
[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
[shapes.bead]
kind = "sphere"
radius = 0.003
[shapes.rock]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.004
[[particles]]
kind = "lattice"
shape = "rock"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [0.02, 0.02, 0.01]
[[particles]]
kind = "lattice"
shape = "bead"
material = "glass"
min = [0.0, 0.0, 0.02]
max = [0.02, 0.02, 0.03]
[output]
spheres = "points"
"#;

/// The piece's counts in the XML head: (points, verts, polys).
fn counts(path: &Path) -> (usize, usize, usize) {
    let bytes = std::fs::read(path).unwrap();
    let head = String::from_utf8_lossy(&bytes[..800.min(bytes.len())]).to_string();
    let count = |key: &str| {
        let s = &head[head.find(key).unwrap() + key.len()..];
        s[..s.find('"').unwrap()].parse::<usize>().unwrap()
    };
    (
        count("NumberOfPoints=\""),
        count("NumberOfVerts=\""),
        count("NumberOfPolys=\""),
    )
}

#[test]
fn spheres_are_written_as_points_with_their_radius_or_as_icospheres() {
    let scene = Scene::parse(MIXED, Path::new("mixed.toml")).unwrap();
    assert_eq!(scene.spec.output.spheres, SphereFrames::Points);
    let world = &scene.world;
    let p = &world.particles;
    let is_bead = |i: usize| {
        world.body_types[p.body_type[i] as usize]
            .shape
            .as_sphere()
            .is_some()
    };
    let beads: Vec<usize> = (0..p.len()).filter(|&i| is_bead(i)).collect();
    let rocks: Vec<usize> = (0..p.len()).filter(|&i| !is_bead(i)).collect();
    assert!(
        beads.len() >= 4 && rocks.len() >= 4,
        "{} {}",
        beads.len(),
        rocks.len()
    );
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("vtk_frames");
    std::fs::create_dir_all(&dir).unwrap();

    let points = dir.join("points.vtp");
    write_particles(world, &points, true).unwrap();
    // A dodecahedron: 12 pentagons of 5 points each.
    let polys = 12 * rocks.len();
    assert_eq!(
        counts(&points),
        (beads.len() + 5 * polys, beads.len(), polys)
    );
    let arrays = read_vtk(&points);
    let get = |n: &str| &arrays.iter().find(|a| a.0 == n).unwrap().1;
    // The beads' cells come first, in the particles' order, then the rocks' faces.
    let ids: Vec<f64> = beads
        .iter()
        .map(|&i| p.id[i] as f64)
        .chain(rocks.iter().flat_map(|&i| [p.id[i] as f64; 12]))
        .collect();
    assert_eq!(get("id"), &ids);
    assert_eq!(get("velocity").len(), 3 * (beads.len() + polys));
    // The first points are the beads' centres (single precision), with their radius;
    // the faces' points have radius 0.
    let xyz = get("points");
    for (k, &i) in beads.iter().enumerate() {
        for c in 0..3 {
            assert_eq!(xyz[3 * k + c], p.position[i][c] as f32 as f64);
        }
    }
    let radius = get("radius");
    assert_eq!(radius.len(), beads.len() + 5 * polys);
    assert!(radius[..beads.len()].iter().all(|&r| r == 0.003f32 as f64));
    assert!(radius[beads.len()..].iter().all(|&r| r == 0.0));

    let surfaces = dir.join("surfaces.vtp");
    write_particles(world, &surfaces, false).unwrap();
    let (n, verts, polys_ico) = counts(&surfaces);
    assert_eq!((verts, polys_ico), (0, 80 * beads.len() + polys));
    assert_eq!(n, 3 * 80 * beads.len() + 5 * polys);
    assert!(read_vtk(&surfaces).iter().all(|a| a.0 != "radius"));
    // A bead as a point takes a small part of its icosphere's bytes.
    let size = |f: &Path| std::fs::metadata(f).unwrap().len() as f64;
    assert!(size(&points) < 0.5 * size(&surfaces));
}
