//! The packing analysis through the run mode and `talus analyze`: a short run of
//! spheres in a tube writes the packing files, `talus analyze` reads the run back
//! and gives the same figures, bad poses files are refused by line, and the
//! co-simulation component reports the bed height and porosity.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Spheres (d = 5 mm) poured at random into a tube of 20 mm (N = 4), settling
/// under gravity for `end` seconds.
fn scene(end: f64) -> String {
    format!(
        r#"
[simulation]
dt = "auto"
end_time = {end}
gravity = [0.0, 0.0, -9.81]
seed = 4

[materials.glass]
density = 2500.0
young = 1e6
poisson = 0.25
restitution = 0.3
friction = 0.3

[shapes.ball]
kind = "sphere"
radius = 0.0025

[[wall]]
name = "tube"
material = "glass"
geometry = {{ kind = "cylinder", base = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], length = 0.08, radius = 0.01, sides = 64, bottom = true }}

[[inlet]]
shape = "ball"
material = "glass"
min = [-0.0065, -0.0065, 0.005]
max = [0.0065, 0.0065, 0.08]
rate = 3000.0
count = 60

[bed]
base = [0.0, 0.0, 0.0]
radius = 0.01
exclude = 0.005
"#
    )
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("packing-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn talus(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_talus"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn a_run_writes_the_packing_and_analyze_reproduces_it() {
    let dir = scratch("run");
    std::fs::write(dir.join("bed.toml"), scene(0.4)).unwrap();
    let run = talus(&dir, &["run", "bed.toml", "--quiet", "--out", "out"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("bed: 60 particles"), "{stdout}");
    let out = dir.join("out");
    let first = json(&out.join("packing.json"));
    // Settled spheres at N = 4: the correlations for spheres give 0.45–0.47 (de
    // Klerk: 0.375 + 0.355/N); a 60-sphere bed with 13 mm of averaging region
    // scatters about that.
    let porosity = first["porosity"].as_f64().unwrap();
    assert!(porosity > 0.38 && porosity < 0.56, "{porosity}");
    // The radial profile, area-weighted, is the bed average; the wall bin is
    // almost empty (spheres touch the wall at single points).
    let radial = first["radial"].as_array().unwrap();
    let mut weighted = 0.0;
    for b in radial {
        let (r0, r1) = (
            b["r_inner"].as_f64().unwrap(),
            b["r_outer"].as_f64().unwrap(),
        );
        weighted += b["porosity"].as_f64().unwrap() * (r1 * r1 - r0 * r0);
    }
    assert!((weighted / 1e-4 - porosity).abs() < 1e-9);
    let wall = radial.last().unwrap()["porosity"].as_f64().unwrap();
    assert!(wall > 0.95, "{wall}");
    // The exports.
    let poses = std::fs::read_to_string(out.join("poses.csv")).unwrap();
    assert_eq!(poses.lines().count(), 1 + 60);
    assert!(poses.lines().nth(1).unwrap().contains(",0,ball,"));
    let stl = std::fs::read(out.join("bed.stl")).unwrap();
    assert_eq!(
        stl.len(),
        84 + 50 * 60 * 320,
        "60 icospheres of 320 triangles"
    );
    assert!(out.join("packing_radial.csv").exists() && out.join("packing_axial.csv").exists());
    // `talus analyze` reads the run back: the same figures.
    std::fs::remove_file(out.join("packing.json")).unwrap();
    let again = talus(&dir, &["analyze", "out"]);
    assert!(
        again.status.success(),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    assert_eq!(json(&out.join("packing.json")), first);
}

#[test]
fn analyze_refuses_a_broken_poses_file_by_line() {
    let dir = scratch("broken");
    std::fs::write(dir.join("bed.toml"), scene(0.001)).unwrap();
    assert!(
        talus(&dir, &["run", "bed.toml", "--quiet", "--out", "out"])
            .status
            .success()
    );
    let poses = dir.join("out/poses.csv");
    let text = std::fs::read_to_string(&poses).unwrap();
    for (bad, expect) in [
        (
            text.replacen(",0,ball,", ",7,ball,", 1),
            "poses.csv:2: kind 7, but the scene has 1 particle kinds",
        ),
        (
            text.replacen(",0,ball,", ",0,ball,nan", 1),
            "poses.csv:2: field 4 is not a finite number",
        ),
        (
            text.replace("id,kind", "id,type"),
            "poses.csv:1: the header must be",
        ),
    ] {
        std::fs::write(&poses, bad).unwrap();
        let out = talus(&dir, &["analyze", "out"]);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{err}");
    }
}

#[test]
fn the_component_reports_the_bed_height_and_porosity() {
    let dir = scratch("cosim");
    std::fs::write(dir.join("bed.toml"), scene(10.0)).unwrap();
    let mut c = talus::cosim::Component::instantiate(&dir, "bed.toml").unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    c.do_step(0.0, 0.05).unwrap();
    let height = c
        .get_real_vector(c.variable("bed_height").unwrap())
        .unwrap()[0];
    let porosity = c.get_real_vector(c.variable("porosity").unwrap()).unwrap()[0];
    // A second instance, stepped the same way, reports the same.
    let mut c2 = talus::cosim::Component::instantiate(&dir, "bed.toml").unwrap();
    c2.enter_initialization_mode(0.0).unwrap();
    c2.exit_initialization_mode().unwrap();
    c2.do_step(0.0, 0.05).unwrap();
    assert!(height > 0.02 && height < 0.08, "{height}");
    assert!(porosity > 0.3 && porosity < 0.9, "{porosity}");
    assert_eq!(
        c2.get_real_vector(c2.variable("porosity").unwrap())
            .unwrap()[0],
        porosity
    );
}

/// An inlet fed "until a bed height": spheres (d = 5 mm) trickle into the N = 4 tube
/// at 100 per second from 2–4 cm above the target, so that a few are in flight when
/// feeding stops. The inlet stops short of its count, and the settled bed ends at
/// the target plus what was in flight (under a layer: about 13 spheres make one
/// diameter of bed here).
#[test]
fn an_inlet_feeds_until_the_bed_height_is_reached() {
    use talus::analysis::packing::bed_figures;
    use talus::scene::{Scene, Simulation};
    let target = 0.03;
    let d = 0.005;
    let text = scene(3.0)
        .replace(
            "min = [-0.0065, -0.0065, 0.005]\nmax = [0.0065, 0.0065, 0.08]\nrate = 3000.0\ncount = 60",
            &format!(
                "min = [-0.0065, -0.0065, 0.05]\nmax = [0.0065, 0.0065, 0.07]\nrate = 100.0\ncount = 300\nbed_height = {target}"
            ),
        )
        .replace(
            "seed = 4\n",
            "seed = 4\nsettle = { max_speed = 0.005, hold = 0.05 }\n",
        );
    assert!(text.contains("bed_height"));
    let scene = Scene::parse(&text, Path::new("bed.toml")).expect("valid scene");
    let bed = scene.bed.unwrap();
    let mut sim = Simulation::new(&scene);
    while !sim.is_settled() && sim.time() < 3.0 {
        sim.step();
    }
    assert!(sim.is_settled(), "not at rest at {} s", sim.time());
    let inserted = sim.inlets[0].inserted;
    assert_eq!(sim.inlets[0].count, inserted, "the inlet stopped");
    assert!((50..150).contains(&inserted), "{inserted} spheres");
    let (height, porosity) = bed_figures(&sim.world, &bed).unwrap();
    println!("{inserted} spheres, bed height {height:.4} m, porosity {porosity:.3}");
    assert!(
        height > target - 0.5 * d && height < target + 2.0 * d,
        "bed height {height}"
    );
}

/// A bed height to feed to needs the [bed] whose tube it is measured in.
#[test]
fn feeding_to_a_bed_height_needs_a_bed_section() {
    let text = scene(0.1)
        .replace("count = 60", "count = 60\nbed_height = 0.03")
        .replace(
            "[bed]\nbase = [0.0, 0.0, 0.0]\nradius = 0.01\nexclude = 0.005\n",
            "",
        );
    let err = talus::scene::Scene::parse(&text, Path::new("bed.toml")).unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("inlet[0].bed_height") && message.contains("[bed]"),
        "{message}"
    );
}
