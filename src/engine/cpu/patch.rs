//! Wall patches: the facets of one wall that a particle touches, merged by plane, so
//! that a flat wall made of many triangles acts as one contact whatever its
//! triangulation.

use nalgebra::{Point3, Vector3};

use super::dispatch::ContactGeometry;
use crate::Real;

/// How the facets of one plane combine into the patch's contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Merge {
    /// Polyhedra: the facets' prisms tile the patch; their volumes, area vectors and
    /// rotation gradients add.
    Sum,
    /// Spheres: the deepest facet of a flat patch is the plane contact (a facet the
    /// centre projects into gives it at once: [`PatchSet::add_face`]).
    Deepest,
}

/// A facet's plane as its patches' keys are made from it: facets sharing a plane (to
/// 1e-9 in the unit normal and 1e-9 of a particle's bounding radius in offset) share a
/// key. The normal's part of the key is the same for every particle and is rounded
/// once, when the facet is placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct FacetPlane {
    normal: [i64; 3],
    /// Signed distance of the plane from the origin along the normal.
    offset: Real,
}

impl FacetPlane {
    /// The plane of unit normal `n` through `point`.
    pub(super) fn new(n: &Vector3<Real>, point: &Point3<Real>) -> Self {
        FacetPlane {
            normal: n.map(|x| (x * 1e9).round() as i64).into(),
            offset: n.dot(&point.coords),
        }
    }

    /// The key of a patch on this plane for a particle of bounding radius `radius`.
    #[inline]
    pub(super) fn key(&self, radius: Real) -> [i64; 4] {
        let [x, y, z] = self.normal;
        [x, y, z, (self.offset / radius * 1e9).round() as i64]
    }
}

/// The patches of one particle against one wall, being assembled. Buffers are kept
/// between uses: after the first few steps assembling allocates nothing.
#[derive(Clone, Debug, Default)]
pub(super) struct PatchSet {
    /// The patches in use, in the order they were opened.
    patches: Vec<Patch>,
    /// Facets of each patch with their shares of the overlap (volumes); entries past
    /// `patches.len()` are spare buffers.
    shares: Vec<Vec<(u32, Real)>>,
}

/// One patch being assembled.
#[derive(Clone, Copy, Debug)]
struct Patch {
    key: [i64; 4],
    /// The merged contact.
    geometry: ContactGeometry,
    /// Whether `geometry` is a sphere's contact with the plane, found on a facet
    /// the centre projects into: no other facet of the plane can change it.
    face: bool,
}

impl PatchSet {
    /// Empties the set, keeping its buffers.
    pub(super) fn clear(&mut self) {
        self.patches.clear();
    }

    /// The index of the patch of plane `key`, if it is open.
    #[inline]
    fn find(&self, key: &[i64; 4]) -> Option<usize> {
        self.patches.iter().position(|p| p.key == *key)
    }

    /// Opens the patch of plane `key` with facet `f`'s contact `g`.
    #[inline]
    fn open(&mut self, key: [i64; 4], f: u32, g: ContactGeometry, face: bool) {
        let k = self.patches.len();
        self.patches.push(Patch {
            key,
            geometry: g,
            face,
        });
        if self.shares.len() == k {
            self.shares.push(Vec::new());
        }
        self.shares[k].clear();
        self.shares[k].push((f, g.volume));
    }

    /// Adds facet `f`'s contact `g` to the patch of plane `key`.
    #[inline]
    pub(super) fn add(&mut self, key: [i64; 4], f: u32, g: ContactGeometry, merge: Merge) {
        let Some(k) = self.find(&key) else {
            self.open(key, f, g, false);
            return;
        };
        let (acc, shares) = (&mut self.patches[k].geometry, &mut self.shares[k]);
        match merge {
            Merge::Sum => {
                let v = acc.volume + g.volume;
                acc.point =
                    Point3::from((acc.point.coords * acc.volume + g.point.coords * g.volume) / v);
                let sum = acc.normal * acc.area + g.normal * g.area;
                acc.area = sum.norm();
                acc.normal = sum / acc.area;
                acc.volume = v;
                acc.depth = acc.depth.max(g.depth);
                acc.rotation_gradient = acc
                    .rotation_gradient
                    .zip(g.rotation_gradient)
                    .map(|(a, b)| a + b);
                shares.push((f, g.volume));
            }
            Merge::Deepest => {
                if g.depth > acc.depth {
                    *acc = g;
                    shares.clear();
                    shares.push((f, 1.0));
                }
            }
        }
    }

    /// Whether the patch of plane `key` holds a sphere's face contact
    /// ([`Self::add_face`]): its other facets need not be looked at.
    #[inline]
    pub(super) fn has_face(&self, key: &[i64; 4]) -> bool {
        self.patches.iter().any(|p| p.face && p.key == *key)
    }

    /// Makes facet `f`'s face contact `g` of a sphere (its centre projects into the
    /// facet: `geometry::sphere::sphere_on_face`) the contact of the patch of plane
    /// `key`: the plane's contact, which the edge and vertex contacts of the
    /// patch's other facets merely approach ([`Merge::Deepest`] to round-off).
    #[inline]
    pub(super) fn add_face(&mut self, key: [i64; 4], f: u32, g: ContactGeometry) {
        let Some(k) = self.find(&key) else {
            self.open(key, f, g, true);
            return;
        };
        self.patches[k].geometry = g;
        self.patches[k].face = true;
        self.shares[k].clear();
        self.shares[k].push((f, 1.0));
    }

    /// The patches in the order they were opened: key, geometry, facet shares.
    pub(super) fn iter(
        &self,
    ) -> impl Iterator<Item = ([i64; 4], &ContactGeometry, &[(u32, Real)])> {
        self.patches
            .iter()
            .zip(&self.shares)
            .map(|(p, shares)| (p.key, &p.geometry, shares.as_slice()))
    }
}
