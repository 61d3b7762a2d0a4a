//! Particle state in flat arrays (structure of arrays): owned particles first, ghost
//! copies after them.

use std::collections::HashMap;
use std::ops::Range;

use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::Real;

/// Particle state, one entry per particle in every array.
///
/// # Owned and ghost particles
/// The first [`Particles::owned`] entries are the particles this world integrates;
/// the [`Particles::ghosts`] entries after them are copies of particles owned
/// elsewhere (another MPI rank's boundary layer). A ghost is felt by the owned
/// particles it touches and is never integrated; it gets no force of its own, takes
/// no part in wall contacts, and is left out of every output, energy and saved state.
/// Frozen means "part of a bed, at rest for good": an owned particle may be frozen
/// or not, and a ghost carries its owner's flag (a ghost moves nothing here
/// either way; the flag tells which rank counts a pair, see the CPU pair stage).
///
/// # Ids
/// Every particle has a stable id that survives reordering and keys the contact
/// history; [`Particles::index_of`] finds the entry of an id. The map is kept by the
/// methods here: code that writes [`Particles::id`] directly calls
/// [`Particles::reindex`].
#[derive(Clone, Debug, Default)]
pub struct Particles {
    /// Centroid positions.
    pub position: Vec<Point3<Real>>,
    /// Orientations (body frame to world).
    pub orientation: Vec<UnitQuaternion<Real>>,
    /// Linear velocities.
    pub velocity: Vec<Vector3<Real>>,
    /// Angular momenta in the world frame.
    pub angular_momentum: Vec<Vector3<Real>>,
    /// Forces of the current step.
    pub force: Vec<Vector3<Real>>,
    /// Torques about the centroid of the current step.
    pub torque: Vec<Vector3<Real>>,
    /// Index into [`crate::world::World::body_types`].
    pub body_type: Vec<u32>,
    /// Stable identifier (survives reordering; keys the contact history).
    pub id: Vec<u64>,
    /// Whether the particle is frozen (see [`Particles::freeze`]): it keeps its pose,
    /// its velocity and angular momentum are zero, and only particles that are not
    /// frozen feel its contacts.
    pub frozen: Vec<bool>,
    /// The code of the cell that held the particle at the last refresh of the space
    /// order, [`Particles::NO_CELL`] for one made since (see
    /// [`crate::world::SpaceOrder`]): with the id, the key by which its contacts
    /// are summed and the owned particles stored. A ghost carries its owner's.
    pub cell_code: Vec<u64>,
    /// Number of ghost copies at the end of the arrays.
    ghosts: usize,
    /// Entry of each id.
    index: HashMap<u64, u32>,
}

impl Particles {
    /// Number of particles, ghosts included.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Whether entry `i`'s position, velocity, angular momentum, force and torque are
    /// all finite numbers.
    pub fn is_finite(&self, i: usize) -> bool {
        let finite = |v: &[Real]| v.iter().all(|x| x.is_finite());
        finite(self.position[i].coords.as_slice())
            && finite(self.velocity[i].as_slice())
            && finite(self.angular_momentum[i].as_slice())
            && finite(self.force[i].as_slice())
            && finite(self.torque[i].as_slice())
    }

    /// Whether every owned particle [`is_finite`](Self::is_finite): one branch-free
    /// sweep, cheap enough for every step (`x · 0` is 0 for a finite `x` and NaN
    /// otherwise, and a sum holding a NaN is NaN).
    pub fn all_finite(&self) -> bool {
        self.all_finite_in(0..self.owned())
    }

    /// Whether every particle of `range` (owned ones) [`is_finite`](Self::is_finite),
    /// as [`all_finite`](Self::all_finite) looks.
    pub fn all_finite_in(&self, range: Range<usize>) -> bool {
        let r = range;
        all_finite_entries(
            &self.position[r.clone()],
            &self.velocity[r.clone()],
            &self.angular_momentum[r.clone()],
            (&self.force[r.clone()], &self.torque[r]),
        )
    }

    /// Number of owned particles: entries `0..owned()`.
    pub fn owned(&self) -> usize {
        self.len() - self.ghosts
    }

    /// Number of ghost copies: entries `owned()..len()`.
    pub fn ghosts(&self) -> usize {
        self.ghosts
    }

    /// Whether entry `i` is a ghost copy.
    #[inline]
    pub fn is_ghost(&self, i: usize) -> bool {
        i >= self.owned()
    }

    /// Whether entry `i` is moved by nobody here: frozen, or a ghost.
    #[inline]
    pub fn is_passive(&self, i: usize) -> bool {
        self.frozen[i] || self.is_ghost(i)
    }

    /// Whether this world counts the pair `[i, j]` (`i` of the smaller id) in its
    /// totals and keeps its history for a saved state. One process counts every
    /// pair. On a rank, a pair of an owned particle and a ghost is held by both
    /// ranks; it counts where its first particle is owned, unless that one is
    /// frozen: its rank then skips the pair (a frozen particle and a ghost move
    /// nothing there), and the rank that owns the second counts it. So the
    /// totals of all ranks add up to one process's.
    pub fn counts_pair(&self, i: usize, j: usize) -> bool {
        if self.is_ghost(i) {
            self.frozen[i] && !self.is_ghost(j)
        } else {
            !(self.frozen[i] && self.is_ghost(j))
        }
    }

    /// The entry of the particle with `id`, if present.
    pub fn index_of(&self, id: u64) -> Option<usize> {
        self.index.get(&id).map(|&i| i as usize)
    }

    /// Appends an owned particle at rest (before the ghosts, if there are any).
    pub fn push(
        &mut self,
        body_type: u32,
        position: Point3<Real>,
        orientation: UnitQuaternion<Real>,
        id: u64,
    ) {
        let at = self.owned();
        self.insert_at(at, body_type, position, orientation, id);
        if self.ghosts > 0 {
            self.reindex();
        }
    }

    /// Appends a ghost copy at rest (its state is set by the caller).
    pub fn push_ghost(
        &mut self,
        body_type: u32,
        position: Point3<Real>,
        orientation: UnitQuaternion<Real>,
        id: u64,
    ) {
        let at = self.len();
        self.insert_at(at, body_type, position, orientation, id);
        self.ghosts += 1;
    }

    fn insert_at(
        &mut self,
        at: usize,
        body_type: u32,
        position: Point3<Real>,
        orientation: UnitQuaternion<Real>,
        id: u64,
    ) {
        self.position.insert(at, position);
        self.orientation.insert(at, orientation);
        self.velocity.insert(at, Vector3::zeros());
        self.angular_momentum.insert(at, Vector3::zeros());
        self.force.insert(at, Vector3::zeros());
        self.torque.insert(at, Vector3::zeros());
        self.body_type.insert(at, body_type);
        self.id.insert(at, id);
        self.frozen.insert(at, false);
        self.cell_code.insert(at, Self::NO_CELL);
        self.index.insert(id, at as u32);
    }

    /// Removes every ghost copy.
    pub fn clear_ghosts(&mut self) {
        let owned = self.owned();
        for &id in &self.id[owned..] {
            self.index.remove(&id);
        }
        self.truncate(owned);
        self.ghosts = 0;
    }

    /// Removes the entries for which `remove` is true, keeping the order of the rest.
    /// Returns how many were removed.
    pub fn remove_where(&mut self, mut remove: impl FnMut(usize) -> bool) -> usize {
        let n = self.len();
        let keep: Vec<bool> = (0..n).map(|i| !remove(i)).collect();
        let removed_ghosts = keep[self.owned()..].iter().filter(|k| !**k).count();
        fn retain<T>(v: &mut Vec<T>, keep: &[bool]) {
            let mut k = keep.iter();
            v.retain(|_| *k.next().expect("one flag per entry"));
        }
        retain(&mut self.position, &keep);
        retain(&mut self.orientation, &keep);
        retain(&mut self.velocity, &keep);
        retain(&mut self.angular_momentum, &keep);
        retain(&mut self.force, &keep);
        retain(&mut self.torque, &keep);
        retain(&mut self.body_type, &keep);
        retain(&mut self.id, &keep);
        retain(&mut self.frozen, &keep);
        retain(&mut self.cell_code, &keep);
        self.ghosts -= removed_ghosts;
        self.reindex();
        n - self.len()
    }

    fn truncate(&mut self, n: usize) {
        self.position.truncate(n);
        self.orientation.truncate(n);
        self.velocity.truncate(n);
        self.angular_momentum.truncate(n);
        self.force.truncate(n);
        self.torque.truncate(n);
        self.body_type.truncate(n);
        self.id.truncate(n);
        self.frozen.truncate(n);
        self.cell_code.truncate(n);
    }

    /// Stores the owned particles in a new order: entry `k` becomes the particle
    /// that was at `places[k]`, for `places` a permutation of `0..owned()`. The
    /// ghosts keep their places.
    pub fn reorder_owned(&mut self, places: &[u32]) {
        assert_eq!(places.len(), self.owned(), "one entry per owned particle");
        fn apply<T: Copy>(v: &mut [T], places: &[u32]) {
            let moved: Vec<T> = places.iter().map(|&k| v[k as usize]).collect();
            v[..places.len()].copy_from_slice(&moved);
        }
        apply(&mut self.position, places);
        apply(&mut self.orientation, places);
        apply(&mut self.velocity, places);
        apply(&mut self.angular_momentum, places);
        apply(&mut self.force, places);
        apply(&mut self.torque, places);
        apply(&mut self.body_type, places);
        apply(&mut self.id, places);
        apply(&mut self.frozen, places);
        apply(&mut self.cell_code, places);
        self.reindex();
    }

    /// The owned particles alone (what a saved state holds).
    pub fn owned_only(&self) -> Particles {
        let mut p = self.clone();
        p.clear_ghosts();
        p
    }

    /// Rebuilds the id map after [`Particles::id`] was written directly.
    pub fn reindex(&mut self) {
        self.index.clear();
        self.index
            .extend(self.id.iter().enumerate().map(|(i, &id)| (id, i as u32)));
    }

    /// Freezes particle `i`: it stops and is no longer integrated; its contacts with
    /// other frozen particles are skipped and its wall contacts too, while a particle
    /// that is not frozen still rests on it. What a long packing run uses for the
    /// buried part of a bed, whose structure no longer changes (see `[bed] freeze`).
    pub fn freeze(&mut self, i: usize) {
        self.frozen[i] = true;
        self.velocity[i] = Vector3::zeros();
        self.angular_momentum[i] = Vector3::zeros();
    }

    /// Number of frozen (owned) particles.
    pub fn frozen_count(&self) -> usize {
        self.frozen[..self.owned()].iter().filter(|&&f| f).count()
    }
}

/// Whether every entry of these slices of the particles' state is finite, as
/// [`Particles::all_finite`] looks: for a caller that holds some of the arrays
/// borrowed (the closing kick checks the chunk it kicked).
pub(crate) fn all_finite_entries(
    position: &[Point3<Real>],
    velocity: &[Vector3<Real>],
    angular_momentum: &[Vector3<Real>],
    (force, torque): (&[Vector3<Real>], &[Vector3<Real>]),
) -> bool {
    // Four running sums taken in turn, so that four chains of adds overlap instead
    // of each add waiting on the one before.
    fn zeros<T>(v: &[T], coords: impl Fn(&T) -> &Vector3<Real>) -> Real {
        let mut sums = [Vector3::zeros(); 4];
        let chunks = v.chunks_exact(4);
        for x in chunks.remainder() {
            sums[0] += coords(x) * 0.0;
        }
        for chunk in chunks {
            for (sum, x) in sums.iter_mut().zip(chunk) {
                *sum += coords(x) * 0.0;
            }
        }
        sums.iter().map(|s| s.x + s.y + s.z).sum()
    }
    fn vector(x: &Vector3<Real>) -> &Vector3<Real> {
        x
    }
    (zeros(position, |x: &Point3<Real>| &x.coords)
        + zeros(velocity, vector)
        + zeros(angular_momentum, vector)
        + zeros(force, vector)
        + zeros(torque, vector))
        == 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `all_finite` agrees with `is_finite` of every entry: large finite values do not
    /// overflow it, one NaN or infinity anywhere is seen, ghosts are not checked.
    #[test]
    fn all_finite_sees_one_bad_number_anywhere() {
        let mut p = Particles::default();
        for k in 0..5 {
            p.push(
                0,
                Point3::new(1e300, -1e300, k as Real),
                UnitQuaternion::identity(),
                k,
            );
        }
        p.velocity[1] = Vector3::new(1e308, 1e308, 1e308);
        p.position[2] = Point3::new(1e308, 1e308, 1e308);
        assert!(p.all_finite());
        p.push_ghost(
            0,
            Point3::new(Real::NAN, 0.0, 0.0),
            UnitQuaternion::identity(),
            9,
        );
        assert!(p.all_finite(), "a ghost is not checked");
        for bad in [Real::NAN, Real::INFINITY, Real::NEG_INFINITY] {
            for field in 0..5 {
                let mut q = p.clone();
                let v = match field {
                    0 => &mut q.position[3].coords,
                    1 => &mut q.velocity[3],
                    2 => &mut q.angular_momentum[3],
                    3 => &mut q.force[3],
                    _ => &mut q.torque[3],
                };
                v.y = bad;
                assert!(!q.all_finite(), "{bad} in field {field}");
                assert!(!q.is_finite(3));
            }
        }
    }
}
