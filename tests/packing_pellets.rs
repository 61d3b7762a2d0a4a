//! A small fixed bed of the primary seed's pellets (cylinders D = L = 5.5 mm as
//! 20-sided prisms) poured into a tube of 25 mm (N = D_tube / d_pellet = 4.5): the
//! bed comes to rest, and its structure is that of a packed tube at this N.
//!
//! The pellets are softened (E = 0.1 MPa; the static strain under this 9 cm bed is
//! below 1 %) so that the run takes minutes: this is the example scene
//! `examples/fixed_bed/scene.toml` with 200 pellets, fed from 11–20 cm.

use std::path::Path;

use talus::analysis::packing::analyse;
use talus::scene::{Scene, Simulation};

#[test]
fn two_hundred_pellets_at_n_4_5_settle_into_a_wall_ordered_bed() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/fixed_bed/scene.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("young = 1e6 ", "young = 1e5 ")
        .replace("count = 300", "count = 200")
        .replace(
            "min = [-0.0085, -0.0085, 0.16]\nmax = [0.0085, 0.0085, 0.3]",
            "min = [-0.0085, -0.0085, 0.11]\nmax = [0.0085, 0.0085, 0.2]",
        );
    assert!(text.contains("young = 1e5 ") && text.contains("count = 200"));
    assert!(text.contains("0.11]"));
    let scene = Scene::parse(&text, &path).expect("valid scene");
    let mut sim = Simulation::new(&scene);
    while !sim.is_settled() && sim.time() < 1.5 {
        sim.step();
    }
    let p = &sim.world().particles;
    println!(
        "{} pellets: settled = {} at {:.3} s after {} steps of {:.2e} s, largest speed {:.1e} m/s",
        p.len(),
        sim.is_settled(),
        sim.time(),
        sim.steps,
        sim.dt(),
        sim.max_speed()
    );
    assert!(sim.is_settled(), "not at rest by {} s", sim.time());
    assert_eq!(p.len(), 200);
    // Every pellet inside the tube (bounding sphere within a tolerance of its wall).
    for x in &p.position {
        assert!(x.x.hypot(x.y) < 0.0125 && x.z > 0.0, "{x}");
    }

    let packing = analyse(sim.world(), scene.bed.as_ref().unwrap()).unwrap();
    let d = 5.5e-3;
    let radial = &packing.radial;
    let profile: Vec<(f64, f64)> = radial
        .iter()
        .map(|b| ((0.0125 - 0.5 * (b.r_inner + b.r_outer)) / d, b.porosity))
        .collect();
    println!(
        "bed height {:.4} m, porosity {:.3} over {:.4}–{:.4} m, coordination {:.2}",
        packing.bed_height,
        packing.porosity,
        packing.region[0],
        packing.region[1],
        packing.coordination_mean
    );
    println!("eps(distance from the wall / d_p): {profile:.3?}");
    let r = &packing.reactor;
    println!(
        "a_v {:.1} 1/m, d_S {:.3e} m, d_v {:.3e} m, sphericity {:.4}, wall contacts {:.3}, \
         K (Kozeny-Carman) {:.3e} m², K (Ergun) {:.3e} m², beta (Ergun) {:.3e} 1/m",
        r.specific_surface,
        r.sauter_diameter,
        r.volume_equivalent_diameter,
        r.sphericity,
        r.wall_contact_fraction,
        r.permeability_kozeny_carman,
        r.permeability_ergun,
        r.inertial_coefficient_ergun
    );
    // Bed-averaged porosity of random beds of equilateral cylinders at N ≈ 4.5 lies
    // about 0.40–0.45 (wall effect included); a 200-pellet bed scatters about it.
    assert!(
        packing.porosity > 0.36 && packing.porosity < 0.49,
        "{}",
        packing.porosity
    );
    // Towards the wall the porosity rises to 1 (the outermost bin, d/20 wide, holds
    // only the pellets' facets touching the wall).
    let outer: Vec<f64> = profile.iter().rev().take(4).map(|b| b.1).collect();
    assert!(outer[0] > 0.75, "wall bin {}", outer[0]);
    assert!(outer.windows(2).all(|w| w[0] > w[1]), "{outer:?}");
    // Oscillation with a period close to one pellet size: the first minimum about
    // 0.5–0.9 d from the wall, a maximum about one diameter in, the next minimum.
    let extreme = |from: f64, to: f64, lowest: bool| {
        profile
            .iter()
            .filter(|b| b.0 >= from && b.0 <= to)
            .copied()
            .fold(None, |best: Option<(f64, f64)>, b| match best {
                Some(x) if (lowest && x.1 <= b.1) || (!lowest && x.1 >= b.1) => Some(x),
                _ => Some(b),
            })
            .unwrap()
    };
    let min1 = extreme(0.3, 1.0, true);
    let max1 = extreme(min1.0, min1.0 + 0.8, false);
    let min2 = extreme(max1.0, max1.0 + 0.9, true);
    println!("first minimum {min1:.3?}, maximum {max1:.3?}, second minimum {min2:.3?}");
    assert!(min1.1 < 0.35, "first minimum {min1:?}");
    assert!(max1.1 > min1.1 + 0.15, "maximum {max1:?} after {min1:?}");
    assert!(min2.1 < max1.1 - 0.15, "second minimum {min2:?}");
    let period = min2.0 - min1.0;
    assert!(period > 0.7 && period < 1.3, "period {period} d");
}
