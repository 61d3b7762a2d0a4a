//! Scene files: errors name the file, line and field; valid scenes build the world
//! they describe; prescribed wall motion and inlets do what the scene says.

use std::path::Path;

use nalgebra::{Point3, UnitQuaternion, Vector3};
use talus::scene::{Scene, SceneError, Simulation};

const BASE: &str = r#"
[simulation]
dt = 1e-5
end_time = 0.01

[materials.steel]
density = 7800.0
young = 2e11
poisson = 0.3
restitution = 0.5
friction = 0.3

[shapes.ball]
kind = "sphere"
radius = 0.005

[shapes.cube]
kind = "cuboid"
size = [0.01, 0.01, 0.01]
"#;

fn parse(extra: &str) -> Result<Scene, SceneError> {
    Scene::parse(&format!("{BASE}{extra}"), Path::new("dir/scene.toml"))
}

/// Line (1-based) of the first line of `BASE + extra` containing `needle`.
fn line_of(extra: &str, needle: &str) -> usize {
    format!("{BASE}{extra}")
        .lines()
        .position(|l| l.contains(needle))
        .unwrap()
        + 1
}

fn assert_error(extra: &str, needle_line: &str, words: &[&str]) {
    let e = parse(extra).expect_err("scene should be rejected");
    let text = e.to_string();
    assert!(text.starts_with("dir/scene.toml:"), "{text}");
    assert_eq!(e.line(), line_of(extra, needle_line), "{text}");
    for w in words {
        assert!(text.contains(w), "'{w}' missing from: {text}");
    }
}

#[test]
fn errors_name_file_line_and_field() {
    // A misspelt key (serde) points at the key.
    assert_error(
        "[[wall]]\nname = \"floor\"\nmaterial = \"steel\"\ngeometry = { kind = \"plane\", centre = [0, 0, 0], normal = [0, 0, 1], sise = 1.0 }\n",
        "sise",
        &["sise"],
    );
    // An unknown material, found after parsing.
    assert_error(
        "[[wall]]\nname = \"floor\"\nmaterial = \"stone\"\ngeometry = { kind = \"plane\", centre = [0, 0, 0], normal = [0, 0, 1], size = 1.0 }\n",
        "stone",
        &["wall[0].material", "unknown material 'stone'", "steel"],
    );
    // A value out of range inside an inline table.
    assert_error(
        "[[wall]]\nname = \"drum\"\nmaterial = \"steel\"\ngeometry = { kind = \"cylinder\", base = [0, 0, 0], axis = [0, 0, 1], length = 0.1, radius = -0.1 }\n",
        "radius = -0.1",
        &["wall[0].geometry", "radius"],
    );
    assert_error(
        "[[wall]]\nname = \"drum\"\nmaterial = \"steel\"\ngeometry = { kind = \"plane\", centre = [0, 0, 0], normal = [0, 0, 1], size = 1.0 }\nmotion = { kind = \"rotation\", axis = [1, 0, 0], rpm = 10, rate = 1 }\n",
        "motion =",
        &["wall[0].motion", "exactly one of `rpm` and `rate`"],
    );
    // A material parameter.
    let bad_material =
        "[materials.soft]\ndensity = 1000.0\nyoung = 1e6\npoisson = 0.7\nrestitution = 0.5\n";
    assert_error(
        bad_material,
        "poisson = 0.7",
        &["materials.soft.poisson", "0.7"],
    );
    // Rolling resistance belongs to Hertz–Mindlin, and its coefficient is checked.
    assert_error(
        "[contact]\nrolling = \"elastic_plastic\"\n",
        "rolling =",
        &["contact.rolling", "hertz_mindlin"],
    );
    assert_error(
        "[contact]\nlaw = \"hertz_mindlin\"\n[materials.rough]\ndensity = 1000.0\nyoung = 1e6\npoisson = 0.3\nrestitution = 0.5\nrolling_friction = -0.1\n",
        "rolling_friction",
        &["materials.rough.rolling_friction", "-0.1"],
    );
    assert_error(
        "[contact]\nlaw = \"hertz\"\n",
        "law =",
        &["hertz", "hertz_mindlin"],
    );
    // A shape that cannot be built.
    assert_error(
        "[shapes.bad]\nkind = \"prism\"\nsides = 2\ndiameter = 0.01\nlength = 0.01\n",
        "[shapes.bad]",
        &["shapes.bad", "sides"],
    );
    // A missing mesh file names the file.
    let e = parse("[[wall]]\nname = \"w\"\nmaterial = \"steel\"\ngeometry = { kind = \"mesh\", file = \"nowhere.stl\" }\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("wall[0].geometry.file") && e.contains("nowhere.stl"),
        "{e}"
    );
    // Particles referring to an unknown shape; a lattice that cannot hold the count.
    assert_error(
        "[[particles]]\nkind = \"lattice\"\nshape = \"ball\"\nmaterial = \"steel\"\nmin = [0, 0, 0]\nmax = [0.1, 0.1, 0.1]\ncount = 100000\n",
        "count = 100000",
        &["particles[0].count", "only"],
    );
    assert_error(
        "[[inlet]]\nshape = \"pebble\"\nmaterial = \"steel\"\nmin = [0, 0, 0]\nmax = [0.1, 0.1, 0.1]\nrate = 10.0\ncount = 3\n",
        "pebble",
        &["inlet[0].shape", "unknown shape 'pebble'", "ball, cube"],
    );
    // Two walls of one name.
    let wall = |name: &str| {
        format!(
            "[[wall]]\nname = \"{name}\"\nmaterial = \"steel\"\ngeometry = {{ kind = \"plane\", centre = [0, 0, 0], normal = [0, 0, 1], size = 1.0 }}\n"
        )
    };
    let twice = format!("{}{}", wall("a"), wall("a"));
    let e = parse(&twice).unwrap_err();
    assert!(e.to_string().contains("used twice"), "{e}");
    assert_eq!(
        e.line(),
        twice
            .lines()
            .skip(3)
            .position(|l| l.contains("name"))
            .unwrap()
            + 4
            + BASE.lines().count()
    );
    // Simulation settings.
    let e = Scene::parse(&BASE.replace("dt = 1e-5", "dt = -1.0"), Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("simulation.dt") && e.starts_with("s.toml:3:"),
        "{e}"
    );
    let e = Scene::parse(
        &BASE.replace("dt = 1e-5", "dt = \"fast\""),
        Path::new("s.toml"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("s.toml:3:"), "{e}");
    // Malformed TOML.
    let e = Scene::parse("[simulation\n", Path::new("s.toml")).unwrap_err();
    assert!(matches!(e, SceneError::Syntax { line: 1, .. }), "{e}");
}

#[test]
fn a_valid_scene_builds_what_it_describes() {
    let scene = parse(
        r#"
[[wall]]
name = "box"
material = "steel"
geometry = { kind = "box", min = [0, 0, 0], max = [0.1, 0.1, 0.1] }

[[particles]]
kind = "lattice"
shape = "ball"
material = "steel"
min = [0, 0, 0]
max = [0.1, 0.1, 0.05]
spacing = 0.02

[[particles]]
kind = "list"
shape = "cube"
material = "steel"
bodies = [{ position = [0.05, 0.05, 0.08], rotation = [0, 0, 0.3], velocity = [1, 0, 0], angular_velocity = [0, 0, 2] }]

[[particles]]
kind = "lattice"
shape = "ball"
material = "steel"
min = [0, 0, 0.06]
max = [0.1, 0.1, 0.075]
count = 3
"#,
    )
    .unwrap();
    let w = &scene.world;
    // 5 × 5 × 3 balls (bounding spheres inside, spacing 0.02), a cube, 3 more balls.
    assert_eq!(w.particles.len(), 75 + 1 + 3);
    assert_eq!(w.body_types.len(), 2, "ball+steel is one body type");
    assert_eq!(w.walls[0].triangles.len(), 12);
    let p = &w.particles;
    assert!((0..75).all(|i| p.body_type[i] == p.body_type[0]));
    let ids: std::collections::BTreeSet<u64> = p.id.iter().copied().collect();
    assert_eq!(ids.len(), p.len());
    // The listed cube keeps its angular velocity (stored as angular momentum).
    let cube = 75;
    assert!((w.angular_velocity(cube) - Vector3::new(0.0, 0.0, 2.0)).norm() < 1e-12);
    assert_eq!(p.velocity[cube], Vector3::new(1.0, 0.0, 0.0));
    let plan = scene.plan.to_string();
    assert!(plan.contains("sphere–sphere"), "{plan}");
    assert!(plan.contains("tangential history: kept"), "{plan}");
    assert!(plan.contains("wall kinematics: none"), "{plan}");
    assert!(plan.contains("sphere contacts: volume law"), "{plan}");
}

#[test]
fn a_step_above_the_suggested_one_is_warned_about() {
    let extra = "[[particles]]\nkind = \"lattice\"\nshape = \"cube\"\nmaterial = \"steel\"\nmin = [0, 0, 0]\nmax = [0.05, 0.05, 0.05]\n";
    let scene = parse(extra).unwrap();
    let suggested = scene.suggested.as_ref().unwrap().dt;
    assert!(suggested < 1e-5);
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(scene.warnings[0].contains("above the suggested"));
    let auto = Scene::parse(
        &format!("{}{extra}", BASE.replace("dt = 1e-5", "dt = \"auto\"")),
        Path::new("s.toml"),
    )
    .unwrap();
    assert_eq!(auto.dt, suggested);
    assert!(auto.warnings.is_empty());
}

fn wall_scene(motion: &str) -> Simulation {
    let text = format!(
        "{BASE}[[wall]]\nname = \"w\"\nmaterial = \"steel\"\ngeometry = {{ kind = \"cylinder\", base = [0, 0, 0], axis = [0, 0, 1], length = 0.1, radius = 0.2, sides = 12 }}\nmotion = {motion}\n"
    );
    let scene = Scene::parse(&text, Path::new("s.toml")).unwrap();
    Simulation::new(&scene)
}

#[test]
fn prescribed_wall_motion() {
    // Rotation at 30 rpm about an axis through (0.1, 0, 0): after 0.5 s, a quarter turn.
    let mut sim =
        wall_scene("{ kind = \"rotation\", axis = [0, 0, 1], point = [0.1, 0, 0], rpm = 30 }");
    let start: Vec<Point3<f64>> = (0..12)
        .map(|f| sim.world().walls[0].facet_world(f)[0])
        .collect();
    for _ in 0..50_000 {
        sim.step();
    }
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
    let pivot = Point3::new(0.1, 0.0, 0.0);
    for (f, x0) in start.iter().enumerate() {
        let expected = pivot + turn * (x0 - pivot);
        let got = sim.world().walls[0].facet_world(f)[0];
        assert!((got - expected).norm() < 1e-9, "{got} vs {expected}");
    }
    assert_eq!(sim.world().walls[0].reference(), pivot);
    // Oscillation: back where it started after whole periods, displaced by the
    // amplitude after a quarter period.
    let mut sim =
        wall_scene("{ kind = \"oscillation\", amplitude = [0, 0, 0.002], frequency = 25 }");
    for _ in 0..1000 {
        sim.step();
    }
    let z = sim.world().walls[0].pose.translation.vector.z;
    assert!((z - 0.002).abs() < 1e-8, "quarter period: {z}");
    for _ in 0..3000 {
        sim.step();
    }
    let z = sim.world().walls[0].pose.translation.vector.z;
    assert!(z.abs() < 1e-8, "one period: {z}");
    // A table: linear ramp of the velocity from 0 to 1 m/s over 0.01 s, then held:
    // displacement 0.005 m at 0.01 s and 0.015 m at 0.02 s.
    let mut sim = wall_scene(
        "{ kind = \"table\", keys = [{ time = 0.0, velocity = [1e-9, 0, 0] }, { time = 0.01, velocity = [1, 0, 0] }] }",
    );
    for _ in 0..1000 {
        sim.step();
    }
    let x = sim.world().walls[0].pose.translation.vector.x;
    assert!((x - 0.005).abs() < 1e-8, "ramp: {x}");
    for _ in 0..1000 {
        sim.step();
    }
    let x = sim.world().walls[0].pose.translation.vector.x;
    assert!((x - 0.015).abs() < 1e-8, "held: {x}");
    assert!((sim.world().walls[0].velocity.x - 1.0).abs() < 1e-12);
}

#[test]
fn inlets_insert_at_their_rate_without_overlap() {
    let text = format!(
        "{BASE}[[inlet]]\nshape = \"cube\"\nmaterial = \"steel\"\nmin = [0, 0, 0]\nmax = [0.12, 0.12, 0.12]\nrate = 20000.0\ncount = 40\nvelocity = [0, 0, -1]\n"
    );
    let scene = Scene::parse(&text, Path::new("s.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    assert_eq!(
        sim.world().particles.len(),
        1,
        "one particle is due at t = 0"
    );
    for _ in 0..100 {
        sim.step();
    }
    // 20000/s over 1 ms: 20 or 21 due (one at t = 0; the step count lands on 1 ms
    // within round-off); all fit easily.
    let n = sim.world().particles.len();
    assert!(n == 20 || n == 21, "{n}");
    for _ in 0..200 {
        sim.step();
    }
    assert_eq!(sim.world().particles.len(), 40);
    assert!(sim.inlets_done());
    // At insertion every bounding sphere was inside the box and clear of the others:
    // check on a fresh scene right after each insertion.
    let mut sim = Simulation::new(&scene);
    let r = 0.005 * 3f64.sqrt();
    let mut checked = 0;
    let mut n = sim.world().particles.len();
    while !sim.inlets_done() {
        sim.step();
        let p = &sim.world().particles;
        for i in n..p.len() {
            let x = p.position[i];
            assert!(
                x.iter().all(|&c| c >= r - 1e-12 && c <= 0.12 - r + 1e-12),
                "{x}"
            );
            for y in &p.position[..i] {
                assert!((x - y).norm() >= 2.0 * r, "overlap at insertion");
            }
            checked += 1;
        }
        n = p.len();
    }
    assert_eq!(checked, 39);
}

/// Shape tables that say the same share one template (what the pair stage reads
/// from the caches); tables that differ in any number do not, and each (shape table,
/// material) is still a body type of its own.
#[test]
fn shape_tables_that_say_the_same_share_a_template() {
    let rock = |name: &str, seed: u64| {
        format!(
            "[shapes.{name}]\nkind = \"random_convex\"\npoints = 14\nradius = 0.005\n\
             jitter = 0.3\nseed = {seed}\n"
        )
    };
    let group = |shape: &str, x: f64| {
        format!(
            "[[particles]]\nkind = \"list\"\nshape = \"{shape}\"\nmaterial = \"steel\"\n\
             bodies = [{{ position = [{x}, 0, 0] }}]\n"
        )
    };
    let text = [
        rock("a", 7),
        rock("b", 7),
        rock("c", 8),
        "[shapes.cube2]\nkind = \"cuboid\"\nsize = [0.01, 0.01, 0.01]\n".into(),
        group("a", 0.0),
        group("b", 0.02),
        group("c", 0.04),
        group("cube", 0.06),
        group("cube2", 0.08),
    ]
    .concat();
    let scene = parse(&text).unwrap();
    let w = &scene.world;
    let template = |k: usize| {
        let t = &w.body_types[w.particles.body_type[k] as usize];
        std::ptr::from_ref(t.shape.as_polyhedron().unwrap())
    };
    assert_eq!(w.body_types.len(), 5, "a body type per shape table");
    assert_eq!(template(0), template(1), "a and b say the same");
    assert_ne!(template(0), template(2), "c has another seed");
    assert_eq!(template(3), template(4), "cube and cube2 say the same");
    assert_ne!(template(0), template(3));
}
