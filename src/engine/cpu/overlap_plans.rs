//! The candidate pairs' overlap plans, and which of them keep a contact.
//!
//! The pair stage asks for a plan's lines a few pairs ahead ([`super::prefetch`]),
//! and for the rest of it and the contact's shapes where the plan keeps a contact.
//! Reading that off the plan itself was a load of a line asked for only a few pairs
//! before: where most candidates lie apart (a pair beyond its bounding spheres costs
//! a few nanoseconds), it had not arrived, and that load held up the sweep (scene (d)
//! of `talus bench`: a third of the pair sweep's samples with 20 shapes, a fifth
//! with a body type per particle). One bit per pair, kept beside the plans, tells it
//! from a word in the caches.

use std::sync::atomic::{AtomicU64, Ordering};

use super::blocks::BLOCK;
use crate::geometry::overlap::OverlapCache;

/// The plans of the list's pairs, and per block of [`BLOCK`] pairs a word whose bit
/// `k` says whether the plan of the block's pair `k` keeps a contact.
///
/// # Invariant
/// Between pair stages, bit `k % BLOCK` of `keeps_contact[k / BLOCK]` is
/// `plans[k].keeps_contact()`. The pair stage writes a block's word once its pairs
/// are evaluated; other blocks read it only as a hint of what to fetch (relaxed
/// atomics: what a racing read sees changes no answer).
#[derive(Debug, Default)]
pub(super) struct OverlapPlans {
    plans: Vec<OverlapCache>,
    keeps_contact: Vec<AtomicU64>,
}

impl Clone for OverlapPlans {
    fn clone(&self) -> Self {
        OverlapPlans {
            plans: self.plans.clone(),
            keeps_contact: (self.keeps_contact.iter())
                .map(|w| AtomicU64::new(w.load(Ordering::Relaxed)))
                .collect(),
        }
    }
}

impl OverlapPlans {
    /// `len` plans that keep nothing (none where `len` is zero).
    pub(super) fn reset(&mut self, len: usize) {
        self.plans.clear();
        self.plans.resize(len, OverlapCache::default());
        self.keeps_contact.clear();
        self.keeps_contact
            .resize_with(len.div_ceil(BLOCK), AtomicU64::default);
    }

    /// How many pairs have a plan (none in a world of spheres).
    pub(super) fn len(&self) -> usize {
        self.plans.len()
    }

    /// The plans to evaluate, and the words to read and write which keep a contact.
    pub(super) fn split(&mut self) -> (&mut [OverlapCache], &[AtomicU64]) {
        (&mut self.plans, &self.keeps_contact)
    }
}

/// Whether bit `k % BLOCK` of `words[k / BLOCK]` is set: a hint only.
#[inline(always)]
pub(super) fn keeps_contact(words: &[AtomicU64], k: usize) -> bool {
    words[k / BLOCK].load(Ordering::Relaxed) >> (k % BLOCK) & 1 == 1
}

/// The word of a block whose pairs `evaluated` (bits) now keep a contact where
/// `kept` says, the others as `word` said.
#[inline(always)]
pub(super) fn record(word: &AtomicU64, evaluated: u64, kept: u64) {
    let before = word.load(Ordering::Relaxed);
    word.store(before & !evaluated | kept & evaluated, Ordering::Relaxed);
}

#[cfg(test)]
mod tests {
    use nalgebra::{Point3, UnitQuaternion, Vector3};

    use super::*;
    use crate::contact::Material;
    use crate::engine::cpu::test_pool;
    use crate::engine::{Backend, CpuBackend};
    use crate::geometry::{Shape, generators};
    use crate::world::{BodyType, World};

    /// After every step, on one thread (the fused sweep) and on two (blocks in
    /// parallel), each pair's bit says what its plan says, and the scene has pairs
    /// of both kinds: a 4 × 4 × 4 lattice of rocks pressed together, spinning apart.
    #[test]
    fn the_bits_say_what_the_plans_keep_step_after_step() {
        for threads in [1, 2] {
            test_pool(threads).install(|| {
                let mut world = pressed_rocks();
                let (mut engine, dt) = (CpuBackend::default(), 1e-6);
                engine.initialise(&mut world, dt);
                let mut seen = [false; 2];
                for _ in 0..200 {
                    engine.step(&mut world, dt);
                    let plans = &mut engine.contacts.overlap_plans;
                    let (cache, words) = plans.split();
                    assert!(!cache.is_empty());
                    for (k, plan) in cache.iter().enumerate() {
                        assert_eq!(keeps_contact(words, k), plan.keeps_contact(), "pair {k}");
                        seen[usize::from(plan.keeps_contact())] = true;
                    }
                }
                assert_eq!(seen, [true; 2], "{threads} threads: pairs of both kinds");
            });
        }
    }

    fn pressed_rocks() -> World {
        let material = Material::of_tests("rock", 2500.0, 1e7, 0.25);
        let rock = generators::random_convex(14, 0.005, 0.3, 3).unwrap();
        let mut world = World {
            body_types: vec![BodyType::new(Shape::Polyhedron(rock.into()), &material, 0)],
            materials: vec![material],
            gravity: Vector3::zeros(),
            ..World::default()
        };
        for id in 0..64u64 {
            let (i, j, k) = (id % 4, id / 4 % 4, id / 16);
            let at = Point3::new(i as f64, j as f64, k as f64) * 0.0085;
            let turn = Vector3::new(id as f64, 0.7 * id as f64, 1.3 * id as f64);
            (world.particles).push(0, at, UnitQuaternion::from_scaled_axis(turn), id);
        }
        world
    }

    #[test]
    fn the_bits_follow_the_pairs_evaluated() {
        let mut plans = OverlapPlans::default();
        plans.reset(130);
        let (cache, words) = plans.split();
        assert_eq!((cache.len(), words.len()), (130, 3));
        record(&words[2], 0b11, 0b10);
        assert!(!keeps_contact(words, 128) && keeps_contact(words, 129));
        // Pair 129 not evaluated again keeps its bit; pair 128 now keeps a contact.
        record(&words[2], 0b01, 0b01);
        assert!(keeps_contact(words, 128) && keeps_contact(words, 129));
        record(&words[2], 0b10, 0);
        assert!(keeps_contact(words, 128) && !keeps_contact(words, 129));
        let copy = plans.clone();
        plans.reset(130);
        assert!(!keeps_contact(plans.split().1, 128), "reset keeps nothing");
        let mut copy = copy;
        assert!(keeps_contact(copy.split().1, 128), "a clone keeps the bits");
    }
}
