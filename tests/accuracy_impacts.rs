//! The reference impacts `talus check` and `talus run` state (`talus::accuracy`):
//! built from a scene's own kinds and wall materials, at its time step, they
//! realise the requested restitution to within what the step allows, and their
//! errors fall as the step shrinks.

use std::path::Path;

use talus::Real;
use talus::accuracy::{Feature, Impact, impact_speed, impacts};
use talus::scene::Scene;

/// The settling box example (dodecahedra of PLA on a steel box, e = 0.1) with the
/// time step `dt` (seconds, or "auto").
fn settling_box(dt: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/settling_box/scene.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("dt = \"auto\"", &format!("dt = {dt}"));
    Scene::parse(&text, &path).unwrap()
}

fn at(found: &[Impact], feature: Feature) -> &Impact {
    found.iter().find(|i| i.feature == feature).unwrap()
}

/// At the suggested step, the worst over where in a step the contact begins
/// (measured: face −11.4 %, edge −1.03 %, vertex −0.77 %; the face impact's error
/// is −2.3 % if the contact happens to begin at the start of a step).
#[test]
fn at_the_suggested_step_the_impacts_realise_their_restitution() {
    let scene = settling_box("\"auto\"");
    // A fall across the box, 0.12 m high, and the inlet's 0.5 m/s.
    let speed = impact_speed(&scene);
    assert!(
        (speed - (2.0 * 9.81 * 0.12 as Real).sqrt()).abs() < 1e-12,
        "{speed}"
    );
    let found = impacts(&scene, speed);
    assert_eq!(found.len(), 3);
    for i in &found {
        println!("{i:?}");
        assert_eq!(i.requested, 0.1);
        let bound = if i.feature == Feature::Face {
            0.13
        } else {
            0.012
        };
        assert!(i.restitution_error().abs() < bound, "{i:?}");
        assert!(i.energy_error.abs() < 2e-3, "{i:?}");
        assert!(i.contact_steps > 20, "{i:?}");
    }
}

/// The impacts' restitution errors, worst over the phase of the first contact, fall
/// in proportion to the step (measured from 1 to 1/8 of the suggested step: face
/// −11.4, −5.8, −3.0, −1.7 %; edge −1.03, −0.52, −0.26, −0.14 %); the edge and
/// vertex energy accounts fall with its square (3.2e-5, 7.9e-6, 2.0e-6, 5.0e-7: an
/// impact alone on its body is booked exactly to second order).
#[test]
fn the_errors_fall_as_the_step_shrinks() {
    let suggested = settling_box("\"auto\"").dt;
    let run = |f: Real| {
        let scene = settling_box(&(f * suggested).to_string());
        impacts(&scene, impact_speed(&scene))
    };
    let (coarse, fine, finest) = (run(0.5), run(0.25), run(0.125));
    for feature in [Feature::Edge, Feature::Vertex] {
        let (a, b) = (at(&coarse, feature), at(&fine, feature));
        let ratio = a.restitution_error() / b.restitution_error();
        assert!((1.7..2.4).contains(&ratio), "{feature:?}: {a:?} / {b:?}");
        let ratio = a.energy_error / b.energy_error;
        assert!((3.2..5.0).contains(&ratio), "{feature:?}: {a:?} / {b:?}");
    }
    for (a, b) in [(&coarse, &fine), (&fine, &finest)] {
        let (a, b) = (at(a, Feature::Face), at(b, Feature::Face));
        let ratio = a.restitution_error() / b.restitution_error();
        assert!((1.7..2.4).contains(&ratio), "face: {a:?} / {b:?}");
    }
}

/// A scene of Hertz spheres on two wall materials: one impact per material, each
/// asking for the mean restitution of the sphere's and the wall's material.
#[test]
fn a_sphere_is_dropped_once_on_each_wall_material() {
    let text = r#"
[simulation]
dt = "auto"
end_time = 1.0
gravity = [0.0, 0.0, -9.81]

[contact]
law = "hertz_mindlin"

[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5

[materials.rubber]
density = 1100.0
young = 1e7
poisson = 0.45
restitution = 0.9
friction = 0.8

[shapes.ball]
kind = "sphere"
radius = 0.005

[[wall]]
name = "floor"
material = "glass"
geometry = { kind = "plane", centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.2 }

[[wall]]
name = "pad"
material = "rubber"
geometry = { kind = "plane", centre = [0.0, 0.0, 0.2], normal = [0.0, 0.0, -1.0], size = 0.2 }

[[particles]]
kind = "list"
shape = "ball"
material = "glass"
bodies = [{ position = [0.0, 0.0, 0.1] }]
"#;
    let scene = Scene::parse(text, Path::new("balls.toml")).unwrap();
    let found = impacts(&scene, 1.0);
    assert_eq!(found.len(), 2);
    for (i, requested) in found.iter().zip([0.5, 0.7]) {
        println!("{i:?}");
        assert_eq!(i.feature, Feature::Sphere);
        assert_eq!(i.requested, requested);
        // Hertz–Mindlin's damping, as LIGGGHTS and EDEM have it, realises a
        // restitution of its own above the one asked for (`validation_hertz`;
        // measured here: 0.549 for 0.5, 0.718 for 0.7): the check shows it.
        assert!(
            i.restitution_error() > 0.0 && i.restitution_error() < 0.12,
            "{i:?}"
        );
        assert!(i.energy_error.abs() < 2e-3, "{i:?}");
    }
}
