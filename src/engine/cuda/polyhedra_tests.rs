//! The device's contacts of polyhedra, run by the host executor, against the CPU
//! backend's: the volume-law contacts of pairs against its pair stage
//! (`pair_geometry`, `pair_force`), the patches against walls against its wall
//! stage's (`facet_geometry` summed by `PatchSet`).

use nalgebra::{Point3, Quaternion, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::device::{Array, Device};
use super::device_body_types::DeviceBodyTypes;
use super::device_pair_contacts::PairContacts;
use super::device_states::DeviceStates;
use super::device_wall_patches::{DeviceWallPatches, Loads, PATCH_SLOTS, polyhedron_wall_contacts};
use super::device_wall_placement::PlacedWalls;
use super::device_wall_slots::WallSlots;
use crate::Real;
use crate::contact::Material;
use crate::contact::TangentialHistory;
use crate::engine::cpu::reference::pair_contact;
use crate::engine::cuda::device::HostDevice;
use crate::engine::laws::ContactLaws;
use crate::engine::params::{REGULARISATION_LENGTH, RoundLaw};
use crate::geometry::{Shape, Sphere, generators};
use crate::world::World;
use crate::world::{BodyType, Wall};

/// A random vector in the cube of half-side `size`.
fn vector(random: &mut Pcg64, size: Real) -> Vector3<Real> {
    Vector3::from_fn(|_, _| random.random_range(-size..size))
}

/// A random orientation.
fn rotation(random: &mut Pcg64) -> UnitQuaternion<Real> {
    let v = vector(random, 1.0);
    UnitQuaternion::from_quaternion(Quaternion::new(
        random.random_range(-1.0..1.0),
        v.x,
        v.y,
        v.z,
    ))
}

/// The pellets' size: the circumradius of the dodecahedron.
const PELLET: Real = 0.005;

fn material(young: Real, restitution: Real, friction: Real) -> Material {
    Material {
        name: format!("e{restitution}"),
        density: 2500.0,
        young,
        poisson: 0.3,
        restitution,
        friction,
        rolling_friction: 0.0,
        rolling_damping: 0.0,
    }
}

/// Pellets of about 5 mm in two materials, isotropic (dodecahedron) and not
/// (cuboid, prism, random hulls), and beads of two sizes; `pairs` pairs of
/// particles at random poses and velocities, from apart to a fifth of a radius
/// deep (a bead's centre inside a pellet at the deepest), most holding a friction
/// spring and a twist.
fn world_of_pairs(pairs: usize, random: &mut Pcg64) -> (World, Vec<TangentialHistory>) {
    let mut world = World {
        materials: vec![material(1e7, 0.5, 0.5), material(5e7, 0.8, 0.3)],
        ..Default::default()
    };
    let r = PELLET;
    let shapes = [
        generators::dodecahedron(r).unwrap(),
        generators::cuboid(1.2 * r, 1.5 * r, 2.0 * r).unwrap(),
        generators::prism(6, 1.6 * r, 1.2 * r).unwrap(),
        generators::random_convex(14, r, 0.3, 1).unwrap(),
        generators::random_convex(20, r, 0.3, 2).unwrap(),
    ];
    for (k, shape) in shapes.into_iter().enumerate() {
        let m = k % 2;
        let shape = Shape::Polyhedron(std::sync::Arc::new(shape));
        world
            .body_types
            .push(BodyType::new(shape, &world.materials[m], m));
    }
    for (m, radius) in [r, 0.6 * r].into_iter().enumerate() {
        let shape = Shape::Sphere(Sphere { radius });
        (world.body_types).push(BodyType::new(shape, &world.materials[m], m));
    }
    let types = world.body_types.len();
    let mut histories = Vec::new();
    for k in 0..pairs {
        let (a, b) = (
            random.random_range(0..types as u32),
            random.random_range(0..types as u32),
        );
        let reach = [a, b]
            .map(|t| world.body_types[t as usize].shape.circumradius())
            .iter()
            .sum::<Real>();
        let xi = Point3::from(vector(random, 0.1));
        let direction = vector(random, 1.0).normalize();
        let xj = xi + direction * reach * random.random_range(0.45..1.05);
        let (id, p) = (2 * k as u64, &mut world.particles);
        p.push(a, xi, rotation(random), id);
        p.push(b, xj, rotation(random), id + 1);
        for n in [2 * k, 2 * k + 1] {
            p.velocity[n] = vector(random, 0.5);
            p.angular_momentum[n] = vector(random, 1e-8);
        }
        histories.push(if k % 4 == 0 {
            TangentialHistory::default()
        } else {
            TangentialHistory {
                spring: vector(random, 1e-5),
                stiffness: random.random_range(1e3..2e3),
                twist: random.random_range(-0.01..0.01),
                ..Default::default()
            }
        });
    }
    (world, histories)
}

#[test]
fn volume_contacts_equal_the_cpu_pair_stage() {
    let (mut random, r) = (Pcg64::seed_from_u64(5), PELLET);
    let pairs = 1500;
    let (world, histories) = world_of_pairs(pairs, &mut random);
    let mut laws = ContactLaws::default();
    laws.prepare(&world, REGULARISATION_LENGTH, RoundLaw::Volume);
    let dt = 2e-6;
    let mut device = HostDevice::new(64);
    let types =
        DeviceBodyTypes::upload(&mut device, &world, REGULARISATION_LENGTH, RoundLaw::Volume)
            .unwrap();
    let mut states = DeviceStates::default();
    states.upload(&mut device, &world.particles).unwrap();
    let list: Vec<(u32, u32)> = (0..pairs as u32).map(|k| (2 * k, 2 * k + 1)).collect();
    let mut contacts = PairContacts::default();
    contacts.set_pairs(&mut device, &list, &histories).unwrap();
    contacts.evaluate(&mut device, &types, &states, dt).unwrap();
    let results = contacts.results(&device).unwrap();
    let kept = contacts.histories(&device).unwrap();
    let (mut touching, mut worst) = (0, [0.0 as Real; 4]);
    // Touching pairs of two spheres, a sphere and a pellet, two pellets.
    let mut kinds = [0; 3];
    let sphere = |i: u32| {
        let t = world.particles.body_type[i as usize] as usize;
        usize::from(world.body_types[t].shape.as_sphere().is_some())
    };
    for (k, &(i, j)) in list.iter().enumerate() {
        let result = pair_contact(&world, i as usize, j as usize, &histories[k], &laws, dt);
        let history = result.history;
        let device = &results[k];
        assert_eq!(result.touching, device.touching, "pair {k}");
        if !result.touching {
            assert_eq!(device.force, Vector3::zeros());
            assert_eq!(kept[k], TangentialHistory::default());
            assert_eq!(result.dissipated, device.dissipated, "pair {k}");
            continue;
        }
        touching += 1;
        kinds[2 - sphere(i) - sphere(j)] += 1;
        // Differences relative to the contact's own figures.
        let relative =
            |a: Real, b: Real, scale: Real| (a - b).abs() / scale.max(Real::MIN_POSITIVE);
        let force = result.force.norm();
        let torque = result.torques[0].norm().max(result.torques[1].norm());
        let energy = result.energy.abs() + result.dissipated.abs();
        let spring = history.spring.norm();
        let apart = |a: Vector3<Real>, b: Vector3<Real>, scale: Real| {
            (a - b).norm() / scale.max(Real::MIN_POSITIVE)
        };
        let differences = [
            apart(result.force, device.force, force),
            (0..2)
                .map(|s| apart(result.torques[s], device.torques[s], torque))
                .fold(0.0, Real::max),
            relative(result.energy, device.energy, energy).max(relative(
                result.dissipated,
                device.dissipated,
                energy,
            )),
            apart(history.spring, kept[k].spring, spring).max(relative(
                history.twist,
                kept[k].twist,
                history.twist.abs(),
            )),
        ];
        // The overlap's round-off is absolute, about 1e-16 of the pellet's size
        // per piece summed: relative to a contact of depth δ it grows as r/δ
        // (the largest differences found over three seeds are 1.4e-13 r/δ).
        let bound = 1e-12 * r / result.depth;
        for (what, d) in ["force", "torques", "energies", "history"]
            .iter()
            .zip(differences)
        {
            assert!(
                d < bound,
                "pair {k}: {what} differ by {d:.1e} at depth {:.1e}",
                result.depth
            );
        }
        for (w, d) in worst.iter_mut().zip(differences) {
            *w = w.max(d);
        }
        assert_eq!(
            history.stiffness == 0.0,
            kept[k].stiffness == 0.0,
            "pair {k}"
        );
    }
    eprintln!(
        "{touching} of {pairs} pairs touch (beads, a bead on a pellet, pellets: {kinds:?}); \
         largest relative differences: force {:.1e}, torques {:.1e}, energies {:.1e}, history \
         {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    assert!((600..1400).contains(&touching), "{touching}");
    assert!(kinds.iter().all(|&k| k > 40), "{kinds:?}");
}

/// A floor of 2 cm squares, two triangles each, and a side wall of two triangles
/// at `x = SIDE`, both facing the particles.
fn floor_and_side() -> Vec<Wall> {
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    let cells = 6;
    for j in 0..=cells {
        for k in 0..=cells {
            vertices.push(Point3::new(
                -0.06 + 0.02 * k as Real,
                -0.06 + 0.02 * j as Real,
                0.0,
            ));
        }
    }
    let at = |j: u32, k: u32| j * (cells + 1) + k;
    for j in 0..cells {
        for k in 0..cells {
            triangles.push([at(j, k), at(j, k + 1), at(j + 1, k + 1)]);
            triangles.push([at(j, k), at(j + 1, k + 1), at(j + 1, k)]);
        }
    }
    let floor = Wall::new("floor", 0, vertices, triangles, 0.01);
    let side = Wall::new(
        "side",
        1,
        vec![
            Point3::new(SIDE, -0.06, -0.01),
            Point3::new(SIDE, 0.06, -0.01),
            Point3::new(SIDE, 0.06, 0.05),
            Point3::new(SIDE, -0.06, 0.05),
        ],
        vec![[0, 2, 1], [0, 3, 2]],
        0.01,
    );
    vec![floor, side]
}

/// Where the side wall stands.
const SIDE: Real = 0.03;

/// 600 pellets of the five shapes over the floor's grid lines and corners, some
/// against the side wall, at heights from touching to half a radius deep.
fn pellets_on_walls(random: &mut Pcg64) -> World {
    let (mut world, _) = world_of_pairs(0, random);
    // The pellets alone (the beads come after them).
    (world.body_types).retain(|t| t.shape.as_polyhedron().is_some());
    world.walls = floor_and_side();
    let types = world.body_types.len() as u32;
    for k in 0..600 {
        let x = random.random_range(-0.05..SIDE - 0.001);
        let y = random.random_range(-0.05..0.05);
        let z = random.random_range(0.4 * PELLET..1.1 * PELLET);
        let p = &mut world.particles;
        p.push(k % types, Point3::new(x, y, z), rotation(random), k as u64);
        p.velocity[k as usize] = vector(random, 0.3);
        p.angular_momentum[k as usize] = vector(random, 1e-8);
    }
    world
}

/// A world's body types, states and walls on a host device, and its patches.
struct OnDevice {
    device: HostDevice,
    types: DeviceBodyTypes,
    states: DeviceStates,
    walls: PlacedWalls,
    patches: DeviceWallPatches,
}

fn on_device(world: &World) -> OnDevice {
    let mut device = HostDevice::new(64);
    let types =
        DeviceBodyTypes::upload(&mut device, world, REGULARISATION_LENGTH, RoundLaw::Volume)
            .unwrap();
    let mut states = DeviceStates::default();
    states.upload(&mut device, &world.particles).unwrap();
    let walls = PlacedWalls::new(&mut device, &world.walls).unwrap();
    let mut patches = DeviceWallPatches::default();
    (patches.find(&mut device, &types, &states.view(), &walls)).unwrap();
    OnDevice {
        device,
        types,
        states,
        walls,
        patches,
    }
}

#[test]
fn wall_patches_are_the_cpu_wall_stages_bit_for_bit() {
    let world = pellets_on_walls(&mut Pcg64::seed_from_u64(11));
    let OnDevice {
        device, patches, ..
    } = on_device(&world);
    let found = patches.patches(&device).unwrap();
    let (mut touching, mut summed, mut sides) = (0, 0, 0);
    for (i, on_device) in found.iter().enumerate() {
        let cpu = crate::engine::cpu::reference::wall_patches(&world, i);
        assert_eq!(&cpu, on_device, "particle {i}");
        touching += usize::from(!cpu.is_empty());
        summed += cpu.iter().filter(|p| p.shares.len() > 1).count();
        sides += cpu.iter().filter(|p| p.wall == 1).count();
    }
    eprintln!(
        "{touching} of 600 pellets touch walls: {summed} patches of several facets, {sides} \
         on the side wall"
    );
    assert!(
        touching > 200 && summed > 50 && sides > 5,
        "{touching} {summed} {sides}"
    );
}

#[test]
fn wall_contacts_are_the_cpu_wall_stages_bit_for_bit() {
    let mut random = Pcg64::seed_from_u64(13);
    let world = pellets_on_walls(&mut random);
    let OnDevice {
        mut device,
        types,
        states,
        walls,
        patches,
    } = on_device(&world);
    // Springs of the step before: for most patches found, one of random stretch,
    // stiffness and twist; for some particles a spring of a plane not touched now.
    let found = patches.patches(&device).unwrap();
    let held: Vec<Vec<(u32, [i64; 4], TangentialHistory)>> = found
        .iter()
        .enumerate()
        .map(|(i, patches)| {
            let mut springs = Vec::new();
            for p in patches {
                if random.random_range(0.0..1.0) < 0.7 {
                    let h = TangentialHistory {
                        spring: vector(&mut random, 2e-5),
                        stiffness: random.random_range(1e3..3e3),
                        twist: random.random_range(-0.02..0.02),
                        ..Default::default()
                    };
                    springs.push((p.wall, p.key, h));
                }
            }
            if i % 5 == 0 && springs.len() < PATCH_SLOTS {
                springs.push((0, [1, 2, 3, 4], TangentialHistory::default()));
            }
            springs
        })
        .collect();
    let n = world.particles.len();
    let ids: Vec<u64> = (0..n as u64).collect();
    let mut keyed: Vec<_> = (held.iter().enumerate())
        .flat_map(|(i, springs)| {
            springs
                .iter()
                .map(move |&(w, key, h)| ((i as u64, w, key), h))
        })
        .collect();
    keyed.sort_by_key(|e| e.0);
    let mut slots = WallSlots::new(&mut device, n, 5).unwrap();
    slots.set_history(&mut device, &ids, &keyed).unwrap();
    slots.turn();
    let zeros = |device: &mut HostDevice, len| {
        let mut a = Array::default();
        a.write(device as &mut dyn Device, &vec![0.0; len]).unwrap();
        a
    };
    let (force, torque) = (zeros(&mut device, 3 * n), zeros(&mut device, 3 * n));
    let mut touching = Array::default();
    touching.write(&mut device, &vec![0u8; n]).unwrap();
    let loads = Loads {
        force: &force,
        torque: &torque,
        touching: &touching,
    };
    let dt = 2e-6;
    let states = states.view();
    polyhedron_wall_contacts(
        &mut device,
        &types,
        &states,
        &walls,
        &patches,
        &slots,
        &loads,
        dt,
    )
    .unwrap();
    let results = slots.contacts(&device).unwrap();
    let mut laws = ContactLaws::default();
    laws.prepare(&world, REGULARISATION_LENGTH, RoundLaw::Volume);
    let (mut made, mut sliding) = (0, 0);
    for (i, on_device) in results.iter().enumerate() {
        let before = |wall: u32, key: [i64; 4]| {
            held[i]
                .iter()
                .find(|h| h.0 == wall && h.1 == key)
                .map_or_else(TangentialHistory::default, |h| h.2)
        };
        let cpu = crate::engine::cpu::reference::wall_contacts(&world, i, &laws, dt, before);
        assert_eq!(&cpu, on_device, "particle {i}");
        made += cpu.len();
        sliding += cpu
            .iter()
            .filter(|c| {
                let h = before(c.wall, c.key);
                h.stiffness > 0.0 && c.history.spring.norm() < 0.999 * h.spring.norm()
            })
            .count();
    }
    eprintln!("{made} wall contacts, {sliding} of them shortening their spring (sliding)");
    assert!(made > 300 && sliding > 10, "{made} {sliding}");
}
