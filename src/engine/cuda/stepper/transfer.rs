//! What crosses between a [`DeviceWorld`] and the host: the particles, the walls
//! and the clock, the figures of the last evaluation, the contact history both ways,
//! and the device memory it holds.

use nalgebra::{Point3, Quaternion, UnitQuaternion, Vector3};

use super::{DeviceWorld, in_order, points, quaternions, roles, vectors};
use crate::Real;
use crate::engine::backend::ContactHistory;
use crate::engine::cuda::device::{Array, Device, DeviceError};
use crate::engine::cuda::device_wall_slots::{history_of, history_row};
use crate::world::World;

impl DeviceWorld {
    /// Bytes of device memory the stepper holds: particles, body types, the list,
    /// the pairs' history and results, the walls, and on a rank its halo and the
    /// scratch of its figures (buffers have room to grow by half).
    pub fn device_bytes(&self) -> usize {
        let d = self.device.as_ref();
        let (p, t, q) = (&self.particles, &self.types, &self.pairs);
        let doubles = [
            &p.position,
            &p.velocity,
            &p.orientation,
            &p.angular_momentum,
            &p.force,
            &p.torque,
            &t.mass,
            &t.inertia,
            &q.history,
            &q.old_history,
            &q.results,
            &q.terms,
        ];
        let bytes = [&p.role, &p.touching, &q.touching];
        doubles.iter().map(|a| a.bytes(d)).sum::<usize>()
            + bytes.iter().map(|a| a.bytes(d)).sum::<usize>()
            + p.body_type.bytes(d)
            + t.laws.bytes(d)
            + p.id.bytes(d)
            + p.cell_code.bytes(d)
            + self.list.bytes(d)
            + self.walls.bytes(d)
            + self.sums.bytes(d)
            + self.readback.device.bytes(d)
            + self.halo.bytes(d)
            + self.figures.bytes(d)
    }

    /// The elastic energy held in the contacts and the energy they dissipated over
    /// the last step, J (the CPU backend's `StepStats::elastic_energy` and
    /// `dissipated`, the same terms summed in a tree: equal to round-off; of the
    /// evaluation's read-back).
    pub fn energies(&self) -> (Real, Real) {
        let e = self.readback.sums();
        (e[0], e[1])
    }

    /// The figures of the last force evaluation: contacts (pairs and walls), the
    /// pairs', candidate pairs, elastic energy and dissipation, list builds (of
    /// the evaluation's read-back; the pairs' figures of those the world counts,
    /// see `Particles::counts_pair`).
    pub fn stats(&self) -> crate::engine::StepStats {
        let e = self.readback.sums();
        let pair_contacts = e[3] as usize;
        crate::engine::StepStats {
            contacts: pair_contacts + e[2] as usize,
            pair_contacts,
            candidate_pairs: e[4] as usize,
            integrated: 0,
            elastic_energy: e[0],
            dissipated: e[1],
            fluid_work: 0.0,
            list_builds: self.list.builds,
        }
    }

    /// Gives the device back, its buffers released.
    pub fn into_device(mut self) -> Box<dyn Device> {
        self.device.clear();
        self.device
    }

    /// Sets the tangential history (of a restored state, or of the stepper this one
    /// replaces): the pairs' is carried into the list at its next build (which
    /// this forces), the walls' patches into their slots.
    pub fn set_history(&mut self, history: &ContactHistory) -> Result<(), DeviceError> {
        let width = self.history_width();
        let d = self.device.as_mut();
        let keys: Vec<u64> = history.pairs.iter().flat_map(|(k, _)| [k.0, k.1]).collect();
        let springs: Vec<Real> = (history.pairs.iter())
            .flat_map(|(_, h)| history_row(h).into_iter().take(width))
            .collect();
        self.list.old_keys.write(d, &keys)?;
        self.list.old_pair_count = history.pairs.len();
        self.list.pending = true;
        self.list.invalidate();
        self.stale = None;
        self.pairs.old_history.write(d, &springs)?;
        let ids = self.particles.id.read(d)?;
        self.walls.set_history(d, &ids, &history.walls)
    }

    /// Takes the particles appended to `world` since the stepper saw it last (an
    /// inlet's: after every other entry, their ids above every other, the host
    /// world up to date): their
    /// state goes after the others' (the arrays uploaded whole only where a buffer
    /// has no room left), they start without wall contacts, and the list is built
    /// again at the next evaluation, the pairs' history carried by their ids.
    pub fn append(&mut self, world: &World) -> Result<(), DeviceError> {
        let p = &world.particles;
        let (from, n) = (self.n, p.len());
        self.order.extend(from..n);
        self.slot_of.extend((from..n).map(|k| k as u32));
        self.owned = p.owned();
        let (d, a, order) = (self.device.as_mut(), &mut self.particles, &self.order[..]);
        let at = (order, from);
        grow(d, &mut a.position, at, |e| {
            points(&in_order(&p.position, e))
        })?;
        grow(d, &mut a.velocity, at, |e| {
            vectors(&in_order(&p.velocity, e))
        })?;
        grow(d, &mut a.orientation, at, |e| {
            quaternions(&in_order(&p.orientation, e))
        })?;
        grow(d, &mut a.angular_momentum, at, |e| {
            vectors(&in_order(&p.angular_momentum, e))
        })?;
        grow(d, &mut a.force, at, |e| vectors(&in_order(&p.force, e)))?;
        grow(d, &mut a.torque, at, |e| vectors(&in_order(&p.torque, e)))?;
        grow(d, &mut a.body_type, at, |e| in_order(&p.body_type, e))?;
        grow(d, &mut a.role, at, |e| roles(p, e.iter().copied()))?;
        grow(d, &mut a.id, at, |e| in_order(&p.id, e))?;
        grow(d, &mut a.cell_code, at, |e| in_order(&p.cell_code, e))?;
        a.touching.resize(d, n)?;
        self.walls.grow(d, n)?;
        self.n = n;
        self.list.invalidate();
        self.stale = None;
        Ok(())
    }

    /// Takes the particles' frozen flags, velocities and angular momenta from
    /// `world` (some frozen, or their velocities set, on the host); the list
    /// stays (pairs of frozen particles drop out of the contacts, not the list).
    pub fn motion_from_host(&mut self, world: &World) -> Result<(), DeviceError> {
        let (d, a, p) = (self.device.as_mut(), &mut self.particles, &world.particles);
        let order = &self.order;
        a.role.write(d, &roles(p, order.iter().copied()))?;
        a.velocity
            .write(d, &vectors(&in_order(&p.velocity, order)))?;
        a.angular_momentum
            .write(d, &vectors(&in_order(&p.angular_momentum, order)))
    }

    /// Takes the walls' poses, velocities and motions from `world` (moved by the
    /// host or set from outside) and uploads what moved.
    pub fn walls_from_host(&mut self, world: &World) -> Result<(), DeviceError> {
        self.walls.set_from(self.device.as_mut(), world)
    }

    /// Copies the walls' poses, velocities, forces, torques and facet forces (of
    /// the evaluation's read-back) and the clock into `world`.
    pub fn walls_to_host(&self, world: &mut World) {
        world.time = self.time;
        self.walls.to_host(&self.readback, world);
    }

    /// Particle–wall contacts at the last force evaluation (read back from the
    /// device).
    pub fn wall_contacts(&mut self) -> Result<usize, DeviceError> {
        self.walls.contact_count(self.device.as_mut())
    }

    /// Copies the particles' state and forces, the walls and the clock into
    /// `world` (the world the stepper was made from, or a copy of it).
    pub fn download(&self, world: &mut World) -> Result<(), DeviceError> {
        self.particles_to_host(world)?;
        self.walls_to_host(world);
        Ok(())
    }

    /// Copies the particles' state and forces into `world` (which holds the
    /// stepper's particles at their host entries).
    pub fn particles_to_host(&self, world: &mut World) -> Result<(), DeviceError> {
        let (d, a) = (self.device.as_ref(), &self.particles);
        let p = &mut world.particles;
        let order = &self.order;
        let vectors = |x: &Array<Real>, into: &mut [Vector3<Real>]| -> Result<(), DeviceError> {
            let values = x.read(d)?;
            for (&i, v) in order.iter().zip(values.chunks_exact(3)) {
                into[i] = Vector3::from_column_slice(v);
            }
            Ok(())
        };
        vectors(&a.velocity, &mut p.velocity)?;
        vectors(&a.angular_momentum, &mut p.angular_momentum)?;
        vectors(&a.force, &mut p.force)?;
        vectors(&a.torque, &mut p.torque)?;
        for (&i, x) in order.iter().zip(a.position.read(d)?.chunks_exact(3)) {
            p.position[i] = Point3::new(x[0], x[1], x[2]);
        }
        for (&i, q) in order.iter().zip(a.orientation.read(d)?.chunks_exact(4)) {
            p.orientation[i] =
                UnitQuaternion::new_unchecked(Quaternion::new(q[3], q[0], q[1], q[2]));
        }
        Ok(())
    }

    /// Whether each particle (in the host world's order) touched another at the
    /// last force evaluation (frozen ones count as touching).
    pub fn touching(&self) -> Result<Vec<bool>, DeviceError> {
        let flags = self.particles.touching.read(self.device.as_ref())?;
        let mut touching = vec![false; flags.len()];
        for (&i, t) in self.order.iter().zip(flags) {
            touching[i] = t != 0;
        }
        Ok(touching)
    }

    /// The pairs' tangential history, sorted by the particles' ids (pairs apart,
    /// whose history is empty, left out): the CPU backend's
    /// [`crate::engine::Backend::contact_history`]. A history set since the last
    /// build ([`Self::set_history`]) is the history until the next build carries
    /// it into the list.
    pub fn contact_history(&self) -> Result<ContactHistory, DeviceError> {
        let d = self.device.as_ref();
        let (keys, history) = if self.list.pending {
            (&self.list.old_keys, &self.pairs.old_history)
        } else {
            (&self.list.keys, &self.pairs.history)
        };
        let (keys, history) = (keys.read(d)?, history.read(d)?);
        let width = self.history_width();
        let pairs = keys
            .chunks_exact(2)
            .zip(history.chunks_exact(width))
            .map(|(k, h)| ((k[0], k[1]), history_of(h)))
            .filter(|(_, h)| !h.is_empty())
            .collect();
        let ids = self.particles.id.read(d)?;
        let walls = self.walls.history(d, &ids)?;
        Ok(ContactHistory { pairs, walls })
    }
}

/// Grows `array` from the values of device slots `..from` to those of every slot
/// of `order` (each slot's host entry), `values` giving the values of host entries
/// in the order asked: the new slots' appended where the buffer has room, all of
/// them uploaded again where not, in the device's order (the host's differs once
/// it stores the particles in the space order: uploaded in the host's order, a
/// pour from an inlet onto a bed stored so scrambled the device's particles).
fn grow<T: bytemuck::Pod>(
    device: &mut dyn Device,
    array: &mut Array<T>,
    (order, from): (&[usize], usize),
    values: impl Fn(&[usize]) -> Vec<T>,
) -> Result<(), DeviceError> {
    if !array.append(device, &values(&order[from..]))? {
        array.write(device, &values(order))?;
    }
    Ok(())
}
