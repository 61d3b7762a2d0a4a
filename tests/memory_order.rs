//! A particle's motion does not depend on where it is stored: the same world with
//! its particles stored in reverse order moves every particle to the same bits.
//! (A rank of a domain decomposition stores its own particles first and copies of
//! its neighbours' after them, whatever their ids; see `engine/neighbours.rs`.)

use std::ops::ControlFlow;
use std::path::Path;

use talus::scene::{Scene, Simulation};
use talus::world::Particles;

/// Reverses the order of the particles in every array.
fn reverse(p: &mut Particles) {
    p.position.reverse();
    p.orientation.reverse();
    p.velocity.reverse();
    p.angular_momentum.reverse();
    p.force.reverse();
    p.torque.reverse();
    p.body_type.reverse();
    p.id.reverse();
    p.frozen.reverse();
    p.cell_code.reverse();
    p.reindex();
}

/// Runs `scene` to `start`, then from there twice to `end`: as stored and with the
/// particles reversed; compares every particle's state by id, the contacts, and
/// the walls' forces (summed over particles in storage order: equal to round-off).
fn same_motion_in_reverse(name: &str, overrides: &str, start: f64, end: f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    let text = std::fs::read_to_string(&path).unwrap() + overrides;
    let scene = Scene::parse(&text, &path).unwrap();
    let mut stored = Simulation::new(&scene);
    let _ = stored.advance_to(start, |_, _| ControlFlow::<()>::Continue(()));
    let mut reversed = Simulation::new(&scene);
    reversed.restore(&stored.snapshot()).unwrap();
    stored.edit_world(|_| {});
    reversed.edit_world(|w| reverse(&mut w.particles));
    let (a, b) = (&stored.world().particles, &reversed.world().particles);
    assert_ne!(a.id, b.id, "stored in another order");
    for sim in [&mut stored, &mut reversed] {
        let _ = sim.advance_to(end, |_, _| ControlFlow::<()>::Continue(()));
    }
    let (a, b) = (&stored.world().particles, &reversed.world().particles);
    assert_eq!(a.len(), b.len());
    assert!(a.len() > 50, "{name}: {} particles", a.len());
    let contacts = stored.stats().pair_contacts;
    assert!(contacts > 20, "{name}: {contacts} contacts");
    assert_eq!(contacts, reversed.stats().pair_contacts);
    for i in 0..a.len() {
        let j = b.index_of(a.id[i]).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(a.position[i].coords.as_slice()),
            bits(b.position[j].coords.as_slice()),
            "{name}: particle {}",
            a.id[i]
        );
        assert_eq!(
            bits(a.orientation[i].coords.as_slice()),
            bits(b.orientation[j].coords.as_slice())
        );
        assert_eq!(
            bits(a.velocity[i].as_slice()),
            bits(b.velocity[j].as_slice())
        );
        assert_eq!(
            bits(a.angular_momentum[i].as_slice()),
            bits(b.angular_momentum[j].as_slice())
        );
    }
    for (wa, wb) in stored.world().walls.iter().zip(&reversed.world().walls) {
        let scale = wa.force.norm().max(1e-300);
        assert!(
            (wa.force - wb.force).norm() <= 1e-12 * scale,
            "{name}: wall {} force {} against {}",
            wa.name,
            wa.force,
            wb.force
        );
    }
}

#[test]
fn polyhedra_in_a_box_move_alike_stored_in_reverse() {
    same_motion_in_reverse("examples/settling_box/scene.toml", "", 0.1, 0.11);
}

#[test]
fn a_turning_drum_moves_alike_stored_in_reverse() {
    same_motion_in_reverse("examples/drum/quasi2d.toml", "", 0.05, 0.06);
}

#[test]
fn hertz_spheres_move_alike_stored_in_reverse() {
    same_motion_in_reverse(
        "examples/fluid_bed/pour.toml",
        "\n[contact]\nlaw = \"hertz_mindlin\"\nrolling = \"elastic_plastic\"\n",
        0.14,
        0.142,
    );
}
