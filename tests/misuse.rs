//! Scene files a new user might write, each answered with an error that names the
//! field and what is wrong, quickly and without a large allocation (issue 20's list).

use std::path::Path;
use std::time::{Duration, Instant};

use talus::scene::Scene;

fn drum() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/drum/quasi2d.toml");
    std::fs::read_to_string(path).unwrap()
}

/// The error of `text`, which must come within a second.
fn error(text: &str) -> String {
    let start = Instant::now();
    let Err(err) = Scene::parse(text, Path::new("scene.toml")) else {
        panic!("an error expected");
    };
    assert!(
        start.elapsed() < Duration::from_secs(1),
        "took {:?}",
        start.elapsed()
    );
    err.to_string()
}

fn expect(text: &str, fragments: &[&str]) {
    let e = error(text);
    for f in fragments {
        assert!(e.contains(f), "'{f}' not in: {e}");
    }
}

#[test]
fn non_finite_wall_coordinates_are_named() {
    let d = drum();
    expect(
        &d.replace(
            "base = [0.0, 0.0, 0.0], axis",
            "base = [0.0, 0.0, nan], axis",
        ),
        &["wall[0].geometry.base", "finite"],
    );
    expect(
        &d.replace("centre = [0.0, 0.011, 0.0]", "centre = [0.0, inf, 0.0]"),
        &["wall[2].geometry.centre"],
    );
    expect(
        &d.replace(
            "name = \"shell\"",
            "name = \"shell\"\nreference = [nan, 0.0, 0.0]",
        ),
        &["wall[0].reference"],
    );
}

#[test]
fn huge_counts_are_refused_before_anything_is_allocated() {
    let d = drum();
    for sides in ["4294967297", "2147483648", "100000000"] {
        expect(
            &d.replace(
                "radius = 0.15, sides = 120 }\nmotion = { kind = \"rotation\"",
                &format!("radius = 0.15, sides = {sides} }}\nmotion = {{ kind = \"rotation\""),
            ),
            &["wall[0].geometry", "sides", "at most"],
        );
    }
    expect(
        &d.replace(
            "radius = 0.15, sides = 120 }\nmotion = { kind = \"rotation\"",
            "radius = 0.15, sides = 120, segments = 100000 }\nmotion = { kind = \"rotation\"",
        ),
        &["wall[0].geometry", "segments", "ten million"],
    );
    let prism = d.replace(
        "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.005",
        "kind = \"prism\"\nsides = 4294967297\ndiameter = 0.005\nlength = 0.005",
    );
    expect(&prism, &["shapes.dodecahedron", "sides", "at most"]);
    let hull = d.replace(
        "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.005",
        "kind = \"random_convex\"\npoints = 1000000000\nradius = 0.005\njitter = 0.1\nseed = 1",
    );
    expect(&hull, &["shapes.dodecahedron", "points", "at most"]);
}

#[test]
fn lattices_of_billions_of_sites_are_refused() {
    let d = drum();
    let lattice = d.find("[[particles]]").unwrap();
    let (head, tail) = d.split_at(lattice);
    let max = tail.lines().find(|l| l.starts_with("max = ")).unwrap();
    for bad in ["max = [1e9, 0.011, 0.15]", "max = [0.1, 0.05, 100000.0]"] {
        expect(
            &format!("{head}{}", tail.replacen(max, bad, 1)),
            &["particles[0].max", "sites", "at most"],
        );
    }
    // A particle of 50 nm in a drum of centimetres: 1e15 sites.
    expect(
        &d.replace("circumradius = 0.005", "circumradius = 5e-8"),
        &["particles[0].max", "sites"],
    );
}

#[test]
fn thread_counts_beyond_the_components_limit_are_refused() {
    let d = drum().replace("seed = 11", "seed = 11\nthreads = 100000");
    expect(&d, &["simulation.threads", "1024"]);
}

#[test]
fn an_inlet_of_a_billion_particles_is_refused() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/fixed_bed/scene.toml");
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("count = 300"));
    expect(
        &text.replace("count = 300", "count = 1000000000"),
        &["inlet[0].count", "at most"],
    );
}

#[test]
fn a_tiny_end_time_prints_as_a_number_not_300_digits() {
    let text = drum().replace("end_time = 4.0", "end_time = 1e-300");
    assert!(text.contains("1e-300"));
    let scene = Scene::parse(&text, Path::new("scene.toml")).unwrap();
    let plan = scene.plan.to_string();
    let line = plan.lines().find(|l| l.contains("end time")).unwrap();
    assert!(line.contains("end time 1e-300 s"), "{line}");
    assert!(line.len() < 200, "{line}");
}
