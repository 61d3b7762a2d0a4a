//! Recursive coordinate bisection: a tiling of space, balanced cost, the same boxes
//! for any storage order, ghosts that hold every partner in reach.

use nalgebra::{Point3, Vector3};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::decomposition::Decomposition;
use crate::Real;

/// `n` centroids spread unevenly over a 2.5 × 0.5 × 2 box (denser at small x).
fn cloud(n: usize, seed: u64) -> Vec<Point3<Real>> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let u: Real = rng.random();
            Point3::new(
                2.5 * u * u,
                0.5 * rng.random::<Real>(),
                2.0 * rng.random::<Real>(),
            )
        })
        .collect()
}

/// Depth of the bisection tree of `ranks` leaves.
fn depth(ranks: usize) -> Real {
    (ranks as Real).log2().ceil()
}

/// Points on every split plane and corner, and random ones around the cloud.
fn probes(d: &Decomposition, seed: u64) -> Vec<Point3<Real>> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut out: Vec<Point3<Real>> = (0..2000)
        .map(|_| Point3::from(Vector3::from_fn(|_, _| rng.random_range(-1.0..3.0))))
        .collect();
    for r in 0..d.ranks() {
        let b = d.subdomain(r);
        for corner in [b.lo, b.hi] {
            let c = corner.map(|v| if v.is_finite() { v } else { 0.5 });
            out.push(Point3::from(c));
            for a in 0..3 {
                let mut on_face = Point3::from(rng.random::<[Real; 3]>());
                on_face[a] = c[a];
                out.push(on_face);
            }
        }
    }
    out
}

#[test]
fn every_point_of_space_has_one_owner() {
    let centroids = cloud(1000, 1);
    for ranks in 1..=7 {
        let d = Decomposition::bisect(&centroids, &vec![1.0; 1000], ranks);
        assert_eq!(d.ranks(), ranks);
        for x in centroids.iter().chain(&probes(&d, 2)) {
            let holding: Vec<usize> = (0..ranks).filter(|&r| d.subdomain(r).contains(x)).collect();
            assert_eq!(holding, vec![d.owner(x)], "{ranks} ranks: {x}");
        }
    }
}

#[test]
fn each_rank_gets_an_equal_share_of_the_cost() {
    let centroids = cloud(1000, 3);
    // Uniform cost: counts within the tree's depth of the mean.
    for ranks in 2..=7 {
        let d = Decomposition::bisect(&centroids, &vec![1.0; 1000], ranks);
        let mut count = vec![0.0; ranks];
        for x in &centroids {
            count[d.owner(x)] += 1.0;
        }
        let mean = 1000.0 / ranks as Real;
        for c in &count {
            assert!((c - mean).abs() <= depth(ranks), "{ranks} ranks: {count:?}");
        }
        let most = count.iter().copied().fold(0.0, Real::max);
        assert!((d.imbalance(&centroids, &vec![1.0; 1000]) - most / mean).abs() < 1e-12);
    }
    // Particles with x < 0.625 (half of them: x = 2.5 u²) cost four times as much:
    // the cost balances, the counts do not (2 ranks: about 310 against 690).
    let cost: Vec<Real> = centroids
        .iter()
        .map(|x| if x.x < 0.625 { 4.0 } else { 1.0 })
        .collect();
    let total: Real = cost.iter().sum();
    for ranks in 2..=5 {
        let d = Decomposition::bisect(&centroids, &cost, ranks);
        let mut share = vec![0.0; ranks];
        for (x, c) in centroids.iter().zip(&cost) {
            share[d.owner(x)] += c;
        }
        for s in &share {
            assert!(
                (s - total / ranks as Real).abs() <= 4.0 * depth(ranks),
                "{ranks} ranks: {share:?}"
            );
        }
        assert!(d.imbalance(&centroids, &cost) < 1.0 + 4.0 * depth(ranks) * ranks as Real / total);
    }
    let two = Decomposition::bisect(&centroids, &cost, 2);
    let cheap_rank = two.owner(&Point3::new(2.4, 0.25, 1.0));
    let on_cheap = centroids
        .iter()
        .filter(|x| two.owner(x) == cheap_rank)
        .count();
    assert!(
        on_cheap > 600,
        "the cheap side holds more particles: {on_cheap}"
    );
}

#[test]
fn the_boxes_do_not_depend_on_storage_order() {
    let centroids = cloud(500, 4);
    let cost: Vec<Real> = (0..500).map(|i| 1.0 + (i % 7) as Real).collect();
    let mut order: Vec<usize> = (0..500).collect();
    order.shuffle(&mut Pcg64::seed_from_u64(5));
    let shuffled: Vec<Point3<Real>> = order.iter().map(|&i| centroids[i]).collect();
    let shuffled_cost: Vec<Real> = order.iter().map(|&i| cost[i]).collect();
    for ranks in [2, 3, 4, 6] {
        assert_eq!(
            Decomposition::bisect(&centroids, &cost, ranks),
            Decomposition::bisect(&shuffled, &shuffled_cost, ranks)
        );
    }
}

/// Every two particles within `reach` of each other meet on the rank that owns
/// either: the other is there, owned or as a ghost.
#[test]
fn ghosts_bring_every_partner_in_reach() {
    let centroids = cloud(600, 6);
    let reach = 0.15;
    let d = Decomposition::bisect(&centroids, &vec![1.0; 600], 5);
    let owner: Vec<usize> = centroids.iter().map(|x| d.owner(x)).collect();
    let ghosts: Vec<Vec<usize>> = centroids
        .iter()
        .zip(&owner)
        .map(|(x, &o)| d.ghost_ranks(x, o, reach))
        .collect();
    let mut across = 0;
    for i in 0..centroids.len() {
        for j in 0..centroids.len() {
            if i != j && (centroids[i] - centroids[j]).norm() <= reach && owner[i] != owner[j] {
                across += 1;
                assert!(
                    ghosts[j].contains(&owner[i]),
                    "{j} is missing on rank {}",
                    owner[i]
                );
            }
        }
        for &r in &ghosts[i] {
            assert!(r != owner[i] && d.subdomain(r).distance(&centroids[i]) <= reach);
        }
    }
    assert!(across > 100, "few pairs across boxes: {across}");
    let with_ghosts = ghosts.iter().filter(|g| !g.is_empty()).count();
    assert!(with_ghosts < 300, "{with_ghosts} of 600 particles copied");
}

#[test]
fn more_ranks_than_particles_or_places_leave_boxes_empty() {
    let few = cloud(3, 7);
    let d = Decomposition::bisect(&few, &[1.0; 3], 5);
    let mut owners: Vec<usize> = few.iter().map(|x| d.owner(x)).collect();
    owners.sort();
    owners.dedup();
    assert_eq!(owners.len(), 3, "each particle alone");
    assert!((d.imbalance(&few, &[1.0; 3]) - 5.0 / 3.0).abs() < 1e-12);
    for x in probes(&d, 8) {
        assert_eq!((0..5).filter(|&r| d.subdomain(r).contains(&x)).count(), 1);
    }
    // All particles on one point: one rank holds them, the space is still tiled.
    let same = vec![Point3::new(0.1, 0.2, 0.3); 10];
    let d = Decomposition::bisect(&same, &[1.0; 10], 3);
    let o = d.owner(&same[0]);
    assert!((d.imbalance(&same, &[1.0; 10]) - 3.0).abs() < 1e-12, "{o}");
    for x in probes(&d, 9) {
        assert_eq!((0..3).filter(|&r| d.subdomain(r).contains(&x)).count(), 1);
    }
    // No particles at all.
    let d = Decomposition::bisect(&[], &[], 4);
    for x in probes(&d, 10) {
        assert_eq!((0..4).filter(|&r| d.subdomain(r).contains(&x)).count(), 1);
    }
}
