use std::path::Path;
use talus::scene::{Scene, Simulation};
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let scene = Scene::load(Path::new(&path)).unwrap();
    let mut sim = Simulation::new(&scene);
    let mut k = 0;
    while !sim.is_finished() {
        sim.step();
        k += 1;
        if k % 4000 == 0 {
            let m = sim.world.body_types[0].mass;
            let total = sim.world.kinetic_energy()
                + m * 9.81 * sim.world.particles.position[0].z
                + sim.engine.elastic_energy;
            println!(
                "t {:.4} total {:.9e} KE {:.3e} v {:?} w {:?}",
                sim.time(),
                total,
                sim.world.kinetic_energy(),
                sim.world.particles.velocity[0].as_slice(),
                sim.world.angular_velocity(0).as_slice()
            );
        }
        if false {
            let p = &sim.world.particles;
            let w = sim.world.angular_velocity(0);
            println!(
                "t {:.5} z {:.6} v {:.3e} {:.3e} {:.3e} w {:.3e} {:.3e} {:.3e} F {:.4e} {:.4e} {:.4e} T {:.3e} {:.3e} {:.3e} contacts {} E {:.3e}",
                sim.time(),
                p.position[0].z,
                p.velocity[0].x,
                p.velocity[0].y,
                p.velocity[0].z,
                w.x,
                w.y,
                w.z,
                p.force[0].x,
                p.force[0].y,
                p.force[0].z,
                p.torque[0].x,
                p.torque[0].y,
                p.torque[0].z,
                sim.engine.contacts,
                sim.world.kinetic_energy()
            );
        }
    }
}
