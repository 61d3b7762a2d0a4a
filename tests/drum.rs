//! The rotating drum: drive torque against the bed's gravitational moment, its sign
//! under reversal, the empty drum, no leakage, power against fill level, attached
//! end caps, and the drum's files and co-simulation outputs.
//!
//! The drum is the quasi-2D kind of the primary seed scaled down for test time: 12 cm
//! across, 9 mm thick, one layer of soft 8 mm beads, walls with end plates attached
//! to the shell.

use std::path::{Path, PathBuf};

mod common;
use common::Picture;

use talus::Real;
use talus::analysis::{Drum, FlowSigns, Regime};
use talus::scene::{Scene, Simulation};

/// The drum scene: `fill` of the cross-section, the shell's motion as a TOML inline
/// table, `sides` facets around.
fn drum_scene(fill: Real, motion: &str) -> String {
    format!(
        r#"
[simulation]
dt = "auto"
end_time = 100.0
gravity = [0.0, 0.0, -9.81]
seed = 5

[materials.bead]
density = 2500.0
young = 3e5
poisson = 0.25
restitution = 0.5
friction = 0.5

[shapes.bead]
kind = "sphere"
radius = 0.004

[[wall]]
name = "shell"
material = "bead"
geometry = {{ kind = "cylinder", base = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], length = 0.009, radius = 0.06, sides = 72 }}
motion = {motion}

[[wall]]
name = "front"
material = "bead"
geometry = {{ kind = "disc", centre = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0], radius = 0.06, sides = 72 }}
motion = {{ kind = "attached", to = "shell" }}

[[wall]]
name = "back"
material = "bead"
geometry = {{ kind = "disc", centre = [0.0, 0.009, 0.0], normal = [0.0, -1.0, 0.0], radius = 0.06, sides = 72 }}
motion = {{ kind = "attached", to = "shell" }}

[[particles]]
kind = "lattice"
shape = "bead"
material = "bead"
min = [-0.06, 0.0, -0.06]
max = [0.06, 0.009, 0.06]
inside = {{ centre = [0.0, 0.0045, 0.0], axis = [0.0, 1.0, 0.0], radius = 0.06, fill = {fill} }}

[drum]
walls = ["shell", "front", "back"]
axis = [0.0, 1.0, 0.0]
sample_interval = 0.01
"#
    )
}

fn spin(rate: Real) -> String {
    format!(
        "{{ kind = \"rotation\", axis = [0.0, 1.0, 0.0], point = [0.0, 0.0045, 0.0], rate = {rate} }}"
    )
}

fn load(text: &str) -> Scene {
    Scene::parse(text, Path::new("drum.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// Time means of the drive torque, minus the gravitational moment, and the power.
#[derive(Debug, Default)]
struct Means {
    drive: Real,
    moment: Real,
    power: Real,
}

/// Runs `sim` to time `until`, averaging from `from`.
fn run(sim: &mut Simulation, drum: &Drum, from: Real, until: Real) -> Means {
    let mut m = Means::default();
    let mut span = 0.0;
    while sim.time() < until {
        sim.step();
        if sim.time() > from {
            let dt = sim.dt();
            let (drive, _, power) = drum.torques(sim.world());
            m.drive += drive * dt;
            m.moment += drum.gravity_moment(sim.world()) * dt;
            m.power += power * dt;
            span += dt;
        }
    }
    Means {
        drive: m.drive / span,
        moment: m.moment / span,
        power: m.power / span,
    }
}

#[test]
fn the_drive_torque_balances_the_gravitational_moment_and_reverses_with_the_drum() {
    // 3 rad/s (Froude number 0.055, rolling), reversed at 3 s over 0.2 s.
    let motion = "{ kind = \"table\", keys = [\
        { time = 3.0, angular_velocity = [0.0, 3.0, 0.0] }, \
        { time = 3.2, angular_velocity = [0.0, -3.0, 0.0] }] }";
    // A table turns the drum about its reference point: put it on the axis.
    let text = drum_scene(0.4, motion).replace(
        "motion = { kind = \"table\"",
        "reference = [0.0, 0.0045, 0.0]\nmotion = { kind = \"table\"",
    );
    let scene = load(&text);
    let drum = scene.drum.clone().expect("a drum");
    let mut sim = Simulation::new(&scene);
    let forward = run(&mut sim, &drum, 1.0, 3.0);
    let backward = run(&mut sim, &drum, 4.2, 6.2);
    // Steady rolling: the drive torque balances the bed's gravitational moment
    // (the bed's angular momentum changes little over two seconds).
    for m in [&forward, &backward] {
        assert!((m.drive - m.moment).abs() < 0.03 * m.moment.abs(), "{m:?}");
    }
    // The drum lifts the bed on the side it turns up: the torque follows the sense
    // of rotation, and the power is positive both ways.
    assert!(
        forward.drive > 0.0 && backward.drive < 0.0,
        "{forward:?} {backward:?}"
    );
    assert!(forward.power > 0.0 && backward.power > 0.0);
    // The two 2 s windows see different beds of 53 beads (the magnitudes differed by
    // 21 % and 29 % in two runs that differ only in the round-off of the force sums),
    // so "about the same" is all a test can ask here; each window's balance above is
    // the sharp check.
    assert!(
        (forward.drive + backward.drive).abs() < 0.35 * forward.drive,
        "the mirrored flow should need a torque of about the same size: {forward:?} {backward:?}"
    );
    // Power = drive torque × angular speed (the last step may reach into the ramp).
    assert!((forward.power - 3.0 * forward.drive).abs() < 1e-3 * forward.power);
}

#[test]
fn an_empty_drum_needs_no_torque() {
    let scene = load(&drum_scene(0.001, &spin(3.0)));
    assert_eq!(scene.world.particles.len(), 0);
    let drum = scene.drum.clone().unwrap();
    let mut sim = Simulation::new(&scene);
    let m = run(&mut sim, &drum, 0.0, 0.1);
    assert_eq!((m.drive, m.moment, m.power), (0.0, 0.0, 0.0));
}

#[test]
fn no_particle_leaves_the_drum_in_five_revolutions_at_45_rpm() {
    let scene = load(&drum_scene(0.4, &spin(45.0 * std::f64::consts::TAU / 60.0)));
    let n = scene.world.particles.len();
    assert!(n > 40, "{n} particles");
    let mut sim = Simulation::new(&scene);
    let end = 5.0 * 60.0 / 45.0;
    let radius = 0.004;
    let mut steps = 0;
    while sim.time() < end {
        sim.step();
        steps += 1;
        if steps % 50 == 0 || sim.time() >= end {
            let p = &sim.world().particles;
            assert_eq!(p.len(), n);
            for (i, x) in p.position.iter().enumerate() {
                assert!(x.iter().all(|c| c.is_finite()), "particle {i} at {x}");
                // The centre stays inside the drum, overlapping the walls by less
                // than a tenth of its radius.
                let r = x.x.hypot(x.z);
                assert!(
                    r < 0.06 - 0.9 * radius,
                    "particle {i} at r = {r} at t = {}",
                    sim.time()
                );
                assert!(
                    x.y > 0.9 * radius && x.y < 0.009 - 0.9 * radius,
                    "particle {i} at y = {} at t = {}",
                    x.y,
                    sim.time()
                );
            }
        }
    }
}

#[test]
fn the_power_draw_grows_with_the_fill_level() {
    let mut power = Vec::new();
    for fill in [0.2, 0.4] {
        let scene = load(&drum_scene(fill, &spin(3.0)));
        let drum = scene.drum.clone().unwrap();
        let mut sim = Simulation::new(&scene);
        power.push((
            fill,
            scene.world.particles.len(),
            run(&mut sim, &drum, 1.0, 2.5).power,
        ));
    }
    // Below half full the bed's mass grows with the fill faster than its centre's
    // distance from the axis shrinks: for a flat bed filling the fraction f of the
    // cross-section (central angle θ, θ − sin θ = 2π f) that distance is
    // 4 R sin³(θ/2) / 3(θ − sin θ), 0.743 R at f = 0.2 and 0.507 R at f = 0.4; at the
    // same angle of repose the torque, and the power, grow by (0.4 · 0.507) /
    // (0.2 · 0.743) = 1.36.
    let ratio = power[1].2 / power[0].2;
    assert!(ratio > 1.2 && ratio < 1.6, "{power:?}: ratio {ratio}");
}

#[test]
fn attached_walls_move_with_their_leader() {
    let scene = load(&drum_scene(0.2, &spin(2.0)));
    let mut sim = Simulation::new(&scene);
    for _ in 0..100 {
        sim.step();
    }
    let w = &sim.world().walls;
    for cap in &w[1..] {
        assert_eq!(cap.pose, w[0].pose);
        assert_eq!(cap.angular_velocity, w[0].angular_velocity);
    }
    // Turned by ω t about y.
    let angle = w[0].pose.rotation.angle();
    assert!((angle - 2.0 * sim.time()).abs() < 1e-9, "{angle}");
}

#[test]
fn drum_and_attachment_errors_name_the_field() {
    let base = drum_scene(0.2, &spin(2.0));
    for (from, to, expect) in [
        (
            "to = \"shell\" }\n\n[[wall]]\nname = \"back\"",
            "to = \"back\" }\n\n[[wall]]\nname = \"back\"",
            "wall[1].motion.to: no wall named 'back' is listed before this one",
        ),
        (
            "walls = [\"shell\", \"front\", \"back\"]",
            "walls = [\"shell\", \"lid\"]",
            "drum.walls[1]: no wall named 'lid'",
        ),
        (
            "axis = [0.0, 1.0, 0.0]\nsample",
            "axis = [0.0, 0.0, 0.0]\nsample",
            "drum.axis: must be a non-zero vector",
        ),
        (
            "fill = 0.2",
            "fill = 1.5",
            "particles[0].inside.fill: 1.5 is not in (0, 1]",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let text = base.replace(from, to);
        let err = Scene::parse(&text, Path::new("drum.toml"))
            .err()
            .unwrap_or_else(|| panic!("{to} was accepted"))
            .to_string();
        assert!(err.contains(expect), "{err}");
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("drum-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_run_writes_the_drum_files() {
    let dir = scratch("run");
    let text = drum_scene(0.4, &spin(3.0))
        .replace("end_time = 100.0", "end_time = 0.6")
        .replace(
            "[drum]",
            "[output]\ncsv_interval = 0.05\n\n[drum]\naverage_after = 0.3",
        );
    std::fs::write(dir.join("drum.toml"), text).unwrap();
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_talus"))
        .args(["run", "drum.toml", "--quiet", "--out", "out"])
        .current_dir(&dir)
        .status()
        .unwrap();
    assert!(status.success());
    let out = dir.join("out");
    let csv = std::fs::read_to_string(out.join("drum.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert_eq!(
        header,
        "time,revolutions,angular_speed,drive_torque,power,gravity_moment,shell_torque,\
         front_torque,back_torque,angle_of_repose"
    );
    assert_eq!(csv.lines().count(), 1 + 13, "rows at 0, 0.05, ..., 0.6");
    // Each row: drive torque = −(sum of the walls' axial torques), power = T ω.
    for line in csv.lines().skip(2) {
        let x: Vec<Real> = line
            .split(',')
            .take(9)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!((x[3] + x[6] + x[7] + x[8]).abs() <= 1e-9 * x[3].abs().max(1e-12));
        assert!((x[4] - 3.0 * x[3]).abs() <= 1e-6 * x[4].abs().max(1e-12));
    }
    // walls.csv ends with the same drive torque and power.
    let walls = std::fs::read_to_string(out.join("walls.csv")).unwrap();
    assert!(
        walls
            .lines()
            .next()
            .unwrap()
            .ends_with(",drive_torque,drive_power")
    );
    for (w, d) in walls.lines().zip(csv.lines()).skip(1) {
        let w: Vec<&str> = w.rsplitn(3, ',').collect();
        let d: Vec<&str> = d.split(',').collect();
        assert_eq!((w[1], w[0]), (d[3], d[4]));
    }
    // The plots, as a person sees them: a title (text in the top strip), the field's
    // cells in viridis with both ends of the colour bar, the grey of cells no
    // particle reached, the black rim; the torque curves in their colours.
    let field = Picture::read(&out.join("drum_field.png"));
    assert_eq!((field.width, field.height), (822, 684));
    assert!(field.dark(0..44) > 300, "a title");
    let body = 44..684;
    assert!(
        field.count([68, 1, 84], 2, body.clone()) > 100,
        "the bar's low end"
    );
    assert!(
        field.count([254, 232, 37], 2, body.clone()) > 100,
        "the bar's high end"
    );
    assert!(
        field.count([215, 215, 215], 0, body.clone()) > 1000,
        "empty cells"
    );
    assert!(field.dark(body) > 3000, "rim, axes and labels");
    let torque = Picture::read(&out.join("drum_torque.png"));
    assert_eq!((torque.width, torque.height), (800, 500));
    assert!(
        torque.count([31, 119, 180], 40, 40..450) > 300,
        "the drive torque"
    );
    assert!(
        torque.count([214, 39, 40], 40, 40..450) > 300,
        "the gravitational moment"
    );
    let field = std::fs::read_to_string(out.join("drum_field.csv")).unwrap();
    assert!(field.lines().count() > 10);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("drum.json")).unwrap()).unwrap();
    assert!((json["average_from"].as_f64().unwrap() - 0.3).abs() < 1e-4);
    assert!((json["angular_speed"].as_f64().unwrap() - 3.0).abs() < 1e-9);
    assert!(json["drive_torque"].as_f64().unwrap() > 0.0);
    // The signs of the regime: a bed lying in the lower half, carried up by the
    // shell (spheres rolling on it carry less than its speed) under a surface.
    let signs = &json["flow_signs"];
    let co_rotation = signs["co_rotation"].as_f64().unwrap();
    assert!(co_rotation > 0.05 && co_rotation < 1.05, "{signs}");
    let coverage = signs["rim_coverage"].as_f64().unwrap();
    assert!(coverage > 0.2 && coverage < 0.7, "{signs}");
    assert!(
        signs["surface_curvature"].as_f64().unwrap() > 0.0,
        "{signs}"
    );
    // The regime named from them and the fraction in flight, as `Regime::of` names
    // it.
    let read = |k: &str| signs[k].as_f64();
    let named = Regime::of(
        &FlowSigns {
            co_rotation: read("co_rotation"),
            rim_coverage: coverage,
            at_rest: read("at_rest").unwrap(),
            surface_curvature: read("surface_curvature"),
        },
        json["airborne_fraction"].as_f64(),
    )
    .unwrap();
    assert_eq!(json["regime"].as_str(), Some(named.name()), "{json}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["drum"]["samples"], json["samples"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_component_reports_the_drive_torque_and_the_angle_of_repose() {
    let dir = scratch("cosim");
    let text = drum_scene(0.4, "{ kind = \"external\" }").replace(
        "motion = { kind = \"external\" }",
        "reference = [0.0, 0.0045, 0.0]\nmotion = { kind = \"external\" }",
    );
    std::fs::write(dir.join("drum.toml"), text).unwrap();
    let mut c = talus::cosim::Component::instantiate(&dir, "drum.toml").unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    let spin = c.variable("shell.angular_velocity").unwrap();
    c.set_real_vector(spin, &[0.0, 3.0, 0.0]).unwrap();
    let (drive, power, angle) = (
        c.variable("drive_torque").unwrap(),
        c.variable("drive_power").unwrap(),
        c.variable("angle_of_repose").unwrap(),
    );
    let mut t = 0.0;
    let mut sums = (0.0, 0.0);
    for k in 0..20 {
        c.do_step(t, 0.1).unwrap();
        t += 0.1;
        // Drive torque = −Σ (mean wall torques about the axis point) · axis.
        let mut expected = 0.0;
        for w in ["shell", "front", "back"] {
            expected -= c
                .get_real_vector(c.variable(&format!("{w}.torque")).unwrap())
                .unwrap()[1];
        }
        let d = c.get_real_vector(drive).unwrap()[0];
        assert!((d - expected).abs() <= 1e-12 * expected.abs().max(1e-12));
        let p = c.get_real_vector(power).unwrap()[0];
        assert!((p - 3.0 * d).abs() <= 1e-9 * p.abs().max(1e-12));
        if k >= 10 {
            sums.0 += d;
            sums.1 += c.get_real_vector(angle).unwrap()[0];
        }
    }
    // Turning forward lifts the bed: a positive drive torque and an inclined surface.
    assert!(sums.0 > 0.0);
    let angle = sums.1 / 10.0;
    assert!(
        angle > 5f64.to_radians() && angle < 45f64.to_radians(),
        "{}",
        angle.to_degrees()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
