//! A step of the CPU backend allocates nothing once its buffers have grown: every
//! heap allocation of the process is counted, and the steps that keep their
//! neighbour lists are checked. (A list build may allocate: it happens once every
//! few dozen steps.)

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use talus::scene::{Scene, Simulation};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// Dodecahedra and spheres settling on the floor of a box of STL-like facets: pair
/// contacts of both kinds and wall patches of many facets.
const SCENE: &str = r#"
[simulation]
dt = 1e-5
end_time = 1.0
gravity = [0.0, 0.0, -9.81]
seed = 3

[contact]
regularisation = 0.2

[materials.pla]
density = 1500.0
young = 1e6
poisson = 0.1
restitution = 0.3
friction = 0.5

[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.005

[shapes.ball]
kind = "sphere"
radius = 0.004

[[wall]]
name = "box"
material = "pla"
geometry = { kind = "box", min = [-0.001, -0.001, 0.0], max = [0.048, 0.048, 0.1], open_top = true }

[[particles]]
kind = "lattice"
shape = "dodecahedron"
material = "pla"
min = [0.0, 0.0, -0.0004]
max = [0.046, 0.046, 0.018]
spacing = 0.0088

[[particles]]
kind = "lattice"
shape = "ball"
material = "pla"
min = [0.0, 0.0, 0.019]
max = [0.046, 0.046, 0.04]
spacing = 0.0079
"#;

#[test]
fn steps_that_keep_their_lists_allocate_nothing() {
    let scene = Scene::parse(SCENE, Path::new("box.toml")).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let (kept, allocating) = pool.install(|| {
        let mut sim = Simulation::new(&scene);
        for _ in 0..1500 {
            sim.step();
        }
        let (mut kept, mut allocating) = (0, Vec::new());
        for step in 0..300 {
            let builds = sim.stats().list_builds;
            let before = ALLOCATIONS.load(Ordering::SeqCst);
            sim.step();
            let allocations = ALLOCATIONS.load(Ordering::SeqCst) - before;
            if sim.stats().list_builds == builds {
                kept += 1;
                if allocations > 0 {
                    allocating.push((step, allocations, sim.stats().contacts));
                }
            }
        }
        assert!(sim.stats().pair_contacts >= 5, "{:?}", sim.stats());
        assert!(sim.stats().contacts > sim.stats().pair_contacts + 10);
        (kept, allocating)
    });
    println!("{kept} steps kept their lists; of them allocating: {allocating:?}");
    assert!(kept > 150, "{kept} of 300 steps kept their lists");
    // Measured: none of them allocates. A buffer may still grow when the contacts
    // outnumber every step before, or rayon's job queues when the pool is busy: a
    // few steps in 300 are allowed, where a step that built a vector per particle
    // (the wall stage before its chunks kept buffers) allocated in every one.
    assert!(
        allocating.len() <= 3,
        "steps that allocated (step, allocations, contacts): {allocating:?} of {kept}"
    );
}
