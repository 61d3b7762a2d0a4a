//! What the pair stage reads of each body type without reading its shape.
//!
//! Where each particle has a shape of its own (scanned rocks), every read of a shape
//! misses the caches: the bounding radius, read for every particle every step, and
//! the chain that a contact follows (body type → template → its vertices and
//! planes), each link waiting on the one before. The table holds each type's
//! bounding radius and where its contact data lie, so that the radii cost a look-up
//! in a small array and the pair stage can ask for a contact's shapes a few pairs
//! ahead ([`super::prefetch`]). Only where the shapes' contact data exceed
//! [`CACHED_SHAPE_BYTES`]: below, they stay in the caches, and asking for them cost
//! the dense bed of one shape (`talus bench` (a)) 5 % of a step.

use std::collections::HashSet;
use std::ops::Range;

use super::huge_pages::back_with_huge_pages;
use crate::Real;
use crate::geometry::Shape;
use crate::world::World;

/// The most bytes of the distinct shapes' contact data for which the pair and wall
/// stages do not prefetch them: a few of a core's 1–2 MB of level-2 cache, which the
/// stages share with the kept plans they stream through.
const CACHED_SHAPE_BYTES: usize = 256 * 1024;

/// One row per body type of the world it was made for. It is made anew whenever the
/// contact laws are (see [`crate::engine::laws::ContactLaws::prepare`]), whose inputs
/// include every type's shape by address and every sphere's radius: all a row is
/// made from, as a template never changes behind its `Arc`.
#[derive(Clone, Debug, Default)]
pub(super) struct TypeTable {
    rows: Vec<TypeRow>,
    /// Whether a contact's shapes are to be fetched ahead (the distinct shapes'
    /// contact data exceed [`CACHED_SHAPE_BYTES`]).
    fetch_shapes: bool,
}

#[derive(Clone, Debug)]
struct TypeRow {
    /// Bounding radius about the centroid.
    radius: Real,
    /// Where the overlap of a kept contact reads the shape (none for a sphere).
    contact_memory: [Range<usize>; 3],
}

impl TypeTable {
    /// Makes the rows of `world`'s body types.
    pub(super) fn make(&mut self, world: &World) {
        self.rows.clear();
        self.rows.extend(world.body_types.iter().map(|t| TypeRow {
            radius: t.shape.circumradius(),
            contact_memory: match &t.shape {
                Shape::Polyhedron(p) => p.contact_memory(),
                Shape::Sphere(_) => [0..0, 0..0, 0..0],
            },
        }));
        // Each distinct template once, known by where it lies (a sphere's empty
        // ranges add nothing).
        let mut seen = HashSet::new();
        let bytes: usize = self
            .rows
            .iter()
            .filter(|r| seen.insert(r.contact_memory[0].start))
            .flat_map(|r| r.contact_memory.iter().map(ExactSizeIterator::len))
            .sum();
        self.fetch_shapes = bytes > CACHED_SHAPE_BYTES;
        if self.fetch_shapes {
            back_with_huge_pages(self.rows.iter().flat_map(|r| r.contact_memory.clone()));
        }
    }

    /// Whether a contact's shapes are worth fetching ahead: they do not all stay in
    /// the caches.
    #[inline]
    pub(super) fn fetch_shapes(&self) -> bool {
        self.fetch_shapes
    }

    /// The bounding radius of body type `t`.
    #[inline]
    pub(super) fn radius(&self, t: u32) -> Real {
        self.rows[t as usize].radius
    }

    /// The address ranges a contact reads of body type `t`'s shape (nothing may be
    /// read through them).
    #[inline]
    pub(super) fn contact_memory(&self, t: u32) -> &[Range<usize>; 3] {
        &self.rows[t as usize].contact_memory
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::contact::Material;
    use crate::geometry::{Sphere, generators};
    use crate::world::BodyType;

    fn world_of(shapes: &[Shape]) -> World {
        let material = Material::of_tests("m", 2000.0, 1e7, 0.25);
        let body_types = shapes
            .iter()
            .map(|s| BodyType::new(s.clone(), &material, 0))
            .collect();
        World {
            materials: vec![material],
            body_types,
            ..Default::default()
        }
    }

    /// A row holds its type's bounding radius, and its shape's contact memory holds
    /// the template and its vertices and planes; a sphere has none.
    #[test]
    fn rows_hold_radius_and_where_a_contact_reads() {
        let rock = Arc::new(generators::random_convex(14, 0.005, 0.3, 7).unwrap());
        let ball = Sphere::new(0.003).unwrap();
        let world = world_of(&[Shape::Polyhedron(rock.clone()), Shape::Sphere(ball)]);
        let mut table = TypeTable::default();
        table.make(&world);
        assert_eq!(table.radius(0), rock.circumradius());
        assert_eq!(table.radius(1), 0.003);
        let [template, vertices, planes] = table.contact_memory(0).clone();
        assert_eq!(template.start, Arc::as_ptr(&rock).addr());
        assert_eq!(vertices.start, rock.vertices().as_ptr().addr());
        assert_eq!(vertices.len(), 24 * rock.vertices().len());
        assert_eq!(planes.start, rock.planes().as_ptr().addr());
        assert_eq!(planes.len(), 32 * rock.face_count());
        assert!(table.contact_memory(1).iter().all(|r| r.is_empty()));
    }

    /// Shapes are fetched ahead only where their distinct contact data exceed what
    /// stays in the caches: not for 20 shapes, even named by thousands of body types,
    /// but for a thousand distinct ones.
    #[test]
    fn shapes_are_fetched_where_they_exceed_the_caches() {
        let rocks: Vec<Shape> = (0..1000)
            .map(|seed| {
                Shape::Polyhedron(
                    generators::random_convex(14, 0.005, 0.3, seed)
                        .unwrap()
                        .into(),
                )
            })
            .collect();
        let mut table = TypeTable::default();
        let shared: Vec<Shape> = (0..5000).map(|k| rocks[k % 20].clone()).collect();
        table.make(&world_of(&shared));
        assert!(!table.fetch_shapes());
        table.make(&world_of(&rocks));
        assert!(table.fetch_shapes());
    }
}
