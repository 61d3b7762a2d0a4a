//! The packing analysis through the run mode and `talus analyze`: a short run of
//! spheres in a tube writes the packing files, `talus analyze` reads the run back
//! and gives the same figures, bad poses files are refused by line, and the
//! co-simulation component reports the bed height and porosity.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::Picture;

use talus::analysis::packing::Bed;

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
bridge = 0.2
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

/// The shells of a closed, oriented STL: asserts every edge is shared by exactly
/// two facets in opposite directions; returns the mesh and the vertices of each
/// shell (the components of its edge graph).
fn closed_shells(path: &Path) -> (talus::geometry::TriMesh, Vec<Vec<nalgebra::Point3<f64>>>) {
    use std::collections::HashMap;
    let mesh = talus::geometry::mesh_io::read_stl(path).unwrap();
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &mesh.triangles {
        for e in 0..3 {
            *edges.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
        }
    }
    for (&(u, v), &count) in &edges {
        assert_eq!(count, 1, "edge {u}-{v} in {count} facets the same way");
        assert_eq!(edges.get(&(v, u)), Some(&1), "edge {u}-{v} open");
    }
    let mut shell: Vec<usize> = (0..mesh.vertices.len()).collect();
    fn root(shell: &mut [usize], mut v: usize) -> usize {
        while shell[v] != v {
            shell[v] = shell[shell[v]];
            v = shell[v];
        }
        v
    }
    for &(u, v) in edges.keys() {
        let (a, b) = (root(&mut shell, u), root(&mut shell, v));
        shell[a] = b;
    }
    let mut points: HashMap<usize, Vec<nalgebra::Point3<f64>>> = HashMap::new();
    for (v, x) in mesh.vertices.iter().enumerate() {
        points.entry(root(&mut shell, v)).or_default().push(*x);
    }
    (mesh, points.into_values().collect())
}

/// The STL of a capped bed: closed, oriented shells ([`closed_shells`]), `shells`
/// of them, every two at least `gap` apart (GJK between their hulls; the STL's
/// single precision allows 1e-3 of the gap).
fn check_capped_stl(path: &Path, gap: f64, shells: usize) {
    use talus::geometry::ConvexPolyhedron;
    use talus::geometry::gjk::gjk;
    let (_, points) = closed_shells(path);
    assert_eq!(points.len(), shells);
    let hulls: Vec<ConvexPolyhedron> = points
        .iter()
        .map(|p| ConvexPolyhedron::from_hull(p).unwrap())
        .collect();
    for (a, ha) in hulls.iter().enumerate() {
        for hb in &hulls[a + 1..] {
            let b_in_a = ha.body_to_input().inverse() * hb.body_to_input();
            let d = gjk(ha, hb, &b_in_a, None).distance();
            assert!(d > gap * 0.999, "two capped particles {d} apart");
        }
    }
}

/// The STL of a bridged bed: closed and oriented ([`closed_shells`]), in fewer
/// shells than particles (bridges join them), enclosing the particles' volume give
/// or take their overlaps and the bridges' necks (a few per cent).
fn check_bridged_stl(path: &Path, particles: usize, particle_volume: f64) {
    let (mesh, shells) = closed_shells(path);
    assert!(shells.len() < particles / 2, "{} shells", shells.len());
    let enclosed: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.vertices[v].coords);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    let ratio = enclosed / particle_volume;
    assert!(
        ratio > 0.97 && ratio < 1.1,
        "enclosed {ratio} of the particles"
    );
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
    // Both profiles at once on the cells of a cylindrical grid (radial bins × axial
    // slices): every cell of the first slab above the region's start, weighted by
    // its annulus, gives that slab's porosity in packing_axial.csv.
    let cells = std::fs::read_to_string(out.join("packing_cells.csv")).unwrap();
    let rows: Vec<Vec<f64>> = cells
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let axial = first["axial"].as_array().unwrap();
    assert_eq!(rows.len(), radial.len() * axial.len());
    for (j, s) in axial.iter().enumerate() {
        let weighted: f64 = rows
            .iter()
            .filter(|r| r[1] == j as f64)
            .map(|r| r[9] * (r[4] * r[4] - r[3] * r[3]))
            .sum();
        let expected = s["porosity"].as_f64().unwrap();
        assert!(
            (weighted / 1e-4 - expected).abs() < 1e-7,
            "slab {j}: {weighted}"
        );
    }
    // The capped bed for a CFD mesher: 60 closed shells, every two at least the
    // gap (d/100) apart, and the contacts they were capped at.
    check_capped_stl(&out.join("bed_caps.stl"), 5e-5, 60);
    // The bridged bed: one closed surface of the particles and their bridges.
    let icosphere = talus::geometry::ConvexPolyhedron::from_convex_mesh(
        &talus::geometry::generators::icosphere_mesh(2, 0.0025).unwrap(),
    )
    .unwrap()
    .volume();
    check_bridged_stl(&out.join("bed_bridges.stl"), 60, 60.0 * icosphere);
    let contacts = std::fs::read_to_string(out.join("contacts.csv")).unwrap();
    let rows: Vec<Vec<f64>> = contacts
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(
        rows.len() > 60,
        "a settled bed has contacts: {}",
        rows.len()
    );
    for r in &rows {
        let n = (r[5] * r[5] + r[6] * r[6] + r[7] * r[7]).sqrt();
        assert!(
            (n - 1.0).abs() < 1e-8 && r[8] <= 5e-5 && r[0] < r[1],
            "{r:?}"
        );
    }
    // Both profiles plotted: a title, the profile and the bed average in their
    // colours.
    for name in ["packing_radial.png", "packing_axial.png"] {
        let plot = Picture::read(&out.join(name));
        assert_eq!((plot.width, plot.height), (800, 500), "{name}");
        assert!(plot.dark(0..40) > 300, "{name}: a title");
        assert!(
            plot.count([31, 119, 180], 40, 40..450) > 300,
            "{name}: the profile"
        );
        assert!(
            plot.count([214, 39, 40], 40, 40..450) > 200,
            "{name}: the average"
        );
    }
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
    let inserted = sim.inlets()[0].inserted;
    assert_eq!(sim.inlets()[0].count, inserted, "the inlet stopped");
    assert!((50..150).contains(&inserted), "{inserted} spheres");
    let figures = bed_figures(sim.world(), &bed).unwrap();
    let (height, porosity) = (figures.height, figures.porosity);
    println!("{inserted} spheres, bed height {height:.4} m, porosity {porosity:.3}");
    assert!(
        height > target - 0.5 * d && height < target + 2.0 * d,
        "bed height {height}"
    );
}

/// A bed height to feed to, and a box riding above the bed, need the [bed] whose
/// tube the bed height is measured in.
#[test]
fn feeding_by_the_bed_needs_a_bed_section() {
    for (line, field) in [
        ("bed_height = 0.03", "inlet[0].bed_height"),
        ("above_bed = true", "inlet[0].above_bed"),
    ] {
        let text = scene(0.1)
            .replace("count = 60", &format!("count = 60\n{line}"))
            .replace(
                "[bed]\nbase = [0.0, 0.0, 0.0]\nradius = 0.01\nexclude = 0.005\nbridge = 0.2\n",
                "",
            );
        let err = talus::scene::Scene::parse(&text, Path::new("bed.toml")).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains(field) && message.contains("[bed]"),
            "{message}"
        );
    }
}

/// A particle's position and orientation.
type Pose = (nalgebra::Point3<f64>, nalgebra::UnitQuaternion<f64>);

/// A 15 cm bed of spheres (d = 5 mm) at N = 4 fed at 400 per second from a box
/// that rides 2–5 cm above the bed surface, as far as the bed height of the [bed],
/// with or without freezing the spheres more than 2 cm below the bed height;
/// returns the settled simulation, each frozen sphere's pose when it froze (by id:
/// the particles are stored anew as the space order is refreshed), and the bed.
fn fill_from_above(
    freeze: bool,
) -> (
    talus::scene::Simulation,
    std::collections::BTreeMap<u64, Pose>,
    Bed,
) {
    let scene = scene_fed_from_above(freeze);
    let mut sim = talus::scene::Simulation::new(&scene);
    let mut frozen_at = std::collections::BTreeMap::new();
    while !sim.is_settled() && sim.time() < 3.0 {
        sim.step();
        let p = &sim.world().particles;
        for i in (0..p.len()).filter(|&i| p.frozen[i]) {
            (frozen_at.entry(p.id[i])).or_insert((p.position[i], p.orientation[i]));
        }
    }
    assert!(sim.is_settled(), "not at rest at {} s", sim.time());
    (sim, frozen_at, scene.bed.expect("a [bed]"))
}

/// The scene of [`fill_from_above`].
fn scene_fed_from_above(freeze: bool) -> talus::scene::Scene {
    let freeze = if freeze {
        "freeze = { depth = 0.02, max_speed = 0.01 }\n"
    } else {
        ""
    };
    let text = scene(3.0)
        .replace("length = 0.08", "length = 0.3")
        .replace(
            "min = [-0.0065, -0.0065, 0.005]\nmax = [0.0065, 0.0065, 0.08]\nrate = 3000.0\ncount = 60",
            "min = [-0.0065, -0.0065, 0.02]\nmax = [0.0065, 0.0065, 0.05]\nrate = 400.0\n\
             count = 2000\nbed_height = 0.15\nabove_bed = true",
        )
        .replace("exclude = 0.005\n", &format!("exclude = 0.005\n{freeze}"))
        .replace(
            "seed = 4\n",
            "seed = 4\nsettle = { max_speed = 0.005, hold = 0.05 }\n",
        );
    assert!(text.contains("above_bed = true"));
    talus::scene::Scene::parse(&text, Path::new("bed.toml")).expect("valid scene")
}

/// A state saved while part of the bed is frozen and the inlet box has risen
/// restores both: stepping on from the restored state gives the same bits.
#[test]
fn frozen_particles_and_the_raised_box_survive_a_saved_state() {
    use talus::scene::{StateReader, StateWriter};
    let scene = scene_fed_from_above(true);
    let mut sim = talus::scene::Simulation::new(&scene);
    while sim.world().particles.frozen_count() < 20 {
        sim.step();
        assert!(sim.time() < 1.0, "nothing froze");
    }
    let mut writer = StateWriter::default();
    sim.write_state(7, &mut writer);
    let bytes = writer.into_bytes();
    let run_on = |sim: &mut talus::scene::Simulation| {
        for _ in 0..3000 {
            sim.step();
        }
        let p = &sim.world().particles;
        let bits: Vec<u64> = p
            .position
            .iter()
            .flat_map(|x| x.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
            .collect();
        (bits, p.frozen.clone(), sim.inlets()[0].offset)
    };
    let first = run_on(&mut sim);
    let mut restored = talus::scene::Simulation::new(&scene);
    let mut reader = StateReader::new(&bytes);
    restored.read_state(7, &mut reader).unwrap();
    assert!(reader.is_done());
    assert!(restored.world().particles.frozen_count() >= 20);
    assert!(restored.inlets()[0].offset.z > 0.0);
    assert_eq!(run_on(&mut restored), first);
}

/// A long bed fed from above with its buried part frozen (what makes the seed's
/// 1.26 m bed affordable, `examples/fixed_bed/seed_bed.toml`): the inlet stops at
/// the bed height and its box rose with the bed; most spheres froze, each below the
/// freezing depth and without moving after it froze; and the bed is the bed that the
/// same fill gives without freezing (height within one diameter, porosity within
/// 0.02; this pair of runs measured 0.484 and 0.483, heights 0.1635 and 0.1655 m).
#[test]
fn a_bed_fed_from_above_with_its_buried_part_frozen() {
    use talus::analysis::packing::bed_figures;
    let (target, depth, d) = (0.15, 0.02, 0.005);
    let mut figures = Vec::new();
    for freeze in [true, false] {
        let (sim, frozen_at, bed) = fill_from_above(freeze);
        let inlet = &sim.inlets()[0];
        let measured = bed_figures(sim.world(), &bed).unwrap();
        let (height, porosity) = (measured.height, measured.porosity);
        let p = &sim.world().particles;
        let frozen = p.frozen_count();
        println!(
            "freeze {freeze}: {} spheres, {frozen} frozen, bed height {height:.4} m, \
             porosity {porosity:.3}, box raised by {:.4} m, {} steps",
            inlet.inserted, inlet.offset.z, sim.steps
        );
        // Feeding stopped at the height; what was in flight then (the box, 6 d
        // tall, holds a layer or two) landed on top: measured 2.7 and 3.1 d.
        assert_eq!(inlet.count, inlet.inserted, "the inlet stopped");
        assert!(
            height > target && height < target + 4.0 * d,
            "height {height}"
        );
        // The box rose with the bed: the last spheres fell as far as the first.
        assert!(inlet.offset.z > target - 2.0 * d, "{}", inlet.offset.z);
        if freeze {
            // Frozen: more than `depth` below the height measured while feeding
            // (over the top 10 d, every 5 ms), which differs from the final one by
            // less than a diameter; none in the surface layers.
            assert!(frozen > p.len() / 2, "{frozen} of {}", p.len());
            for (x, _) in p.position.iter().zip(&p.frozen).filter(|(_, f)| **f) {
                assert!(x.z + 0.5 * d < height - depth + d, "frozen at {x}");
            }
            for (&id, pose) in &frozen_at {
                let i = p.index_of(id).unwrap();
                assert_eq!(
                    (p.position[i], p.orientation[i]),
                    *pose,
                    "sphere {id} moved"
                );
            }
            assert_eq!(frozen, frozen_at.len());
        } else {
            assert_eq!(frozen, 0);
        }
        figures.push((height, porosity));
    }
    let [(h1, e1), (h0, e0)] = figures[..] else {
        unreachable!()
    };
    assert!((h1 - h0).abs() < d, "heights {h1} and {h0}");
    assert!((e1 - e0).abs() < 0.02, "porosities {e1} and {e0}");
}

/// The reactor figures of a tube of pellets (20-gon prisms, D = L = 5.5 mm): the
/// Sauter diameter and sphericity those of the prism's closed form, and the
/// component's bed outputs the full analysis's numbers.
#[test]
fn the_reactor_figures_of_a_pellet_tube_reach_the_component() {
    use std::f64::consts::PI;
    use talus::analysis::packing::analyse;
    use talus::cosim::Component;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("tests/scenes/tube_bed.toml")).unwrap()
        + "\n[bed]\nbase = [0.0, 0.0, 0.0]\nradius = 0.0125\nexclude = 0.004\n";
    let dir = std::env::temp_dir().join(format!("talus-reactor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("tube.toml"), text).unwrap();
    let mut c = Component::instantiate(&dir, "tube.toml").unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    let read = |name: &str| c.get_real_vector(c.variable(name).unwrap()).unwrap()[0];
    let bed = c.scene().bed.unwrap();
    let packing = analyse(c.simulation().unwrap().world(), &bed).unwrap();
    let r = &packing.reactor;
    // A regular 20-gon prism of circumradius a and length L.
    let (n, a, l) = (20.0, 0.00275, 0.0055);
    let polygon = 0.5 * n * a * a * (2.0 * PI / n).sin();
    let volume = polygon * l;
    let surface = 2.0 * polygon + n * 2.0 * a * (PI / n).sin() * l;
    let d_v = (6.0 * volume / PI).cbrt();
    assert!((r.sauter_diameter / (6.0 * volume / surface) - 1.0).abs() < 1e-12);
    assert!((r.volume_equivalent_diameter / d_v - 1.0).abs() < 1e-12);
    assert!((r.sphericity - PI * d_v * d_v / surface).abs() < 1e-12);
    assert!(
        (r.specific_surface / ((1.0 - packing.porosity) * surface / volume) - 1.0).abs() < 1e-12
    );
    println!(
        "lattice of pellets: porosity {:.4}, a_v {:.1} 1/m, wall contacts {:.3}, K {:.3e} m²",
        packing.porosity, r.specific_surface, r.wall_contact_fraction, r.permeability_kozeny_carman
    );
    // The component's quick figures integrate the one full disc, the analysis all
    // the radial bins at once: the same volumes to the quadrature's tolerance.
    for (name, full) in [
        ("porosity", packing.porosity),
        ("specific_surface", r.specific_surface),
        ("permeability", r.permeability_kozeny_carman),
    ] {
        assert!(
            (read(name) / full - 1.0).abs() < 1e-9,
            "{name}: {} against {full}",
            read(name)
        );
    }
    assert!(r.permeability_ergun > r.permeability_kozeny_carman);
}
