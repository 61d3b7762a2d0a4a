//! What ranks send each other of a particle: its state (for a ghost or a migrant)
//! and, when it changes owner, its contact history.

use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::Real;
use crate::engine::backend::ContactHistory;
use crate::engine::wire::{Message, Words};
use crate::world::{Particles, ShareRow};

/// A particle's state as it travels between ranks.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleRecord {
    /// Stable id.
    pub id: u64,
    /// Body type index.
    pub body_type: u32,
    /// Frozen (part of a bed at rest).
    pub frozen: bool,
    /// Centroid.
    pub position: Point3<Real>,
    /// Orientation.
    pub orientation: UnitQuaternion<Real>,
    /// Linear velocity.
    pub velocity: Vector3<Real>,
    /// Angular momentum (world frame).
    pub angular_momentum: Vector3<Real>,
    /// Code of its cell in the space order (see [`crate::world::SpaceOrder`]).
    pub cell_code: u64,
}

impl ParticleRecord {
    /// Particle `i`'s state.
    pub fn of(p: &Particles, i: usize) -> Self {
        ParticleRecord {
            id: p.id[i],
            body_type: p.body_type[i],
            frozen: p.frozen[i],
            position: p.position[i],
            orientation: p.orientation[i],
            velocity: p.velocity[i],
            angular_momentum: p.angular_momentum[i],
            cell_code: p.cell_code[i],
        }
    }

    /// Appends it to the owned particles.
    pub fn push_into(&self, p: &mut Particles) {
        p.push(self.body_type, self.position, self.orientation, self.id);
        let i = p.owned() - 1;
        self.set_state(p, i);
    }

    /// Writes the motion state, the frozen flag (a ghost's may change between
    /// steps, by the host's bed measurement) and the cell code into entry `i`.
    pub(super) fn set_state(&self, p: &mut Particles, i: usize) {
        p.position[i] = self.position;
        p.orientation[i] = self.orientation;
        p.velocity[i] = self.velocity;
        p.angular_momentum[i] = self.angular_momentum;
        p.frozen[i] = self.frozen;
        p.cell_code[i] = self.cell_code;
    }
}

impl Message for ParticleRecord {
    fn encode(&self, out: &mut Vec<u64>) {
        out.extend([self.id, u64::from(self.body_type), u64::from(self.frozen)]);
        out.push(self.cell_code);
        self.position.encode(out);
        self.orientation.encode(out);
        self.velocity.encode(out);
        self.angular_momentum.encode(out);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        ParticleRecord {
            id: words.next_word(),
            body_type: words.next_word() as u32,
            frozen: words.next_word() != 0,
            cell_code: words.next_word(),
            position: Point3::decode(words),
            orientation: UnitQuaternion::decode(words),
            velocity: Vector3::decode(words),
            angular_momentum: Vector3::decode(words),
        }
    }
}

impl Message for Migrant {
    fn encode(&self, out: &mut Vec<u64>) {
        self.particle.encode(out);
        self.history.encode(out);
        self.fluid_share.encode(out);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        let particle = ParticleRecord::decode(words);
        let history = ContactHistory::decode(words);
        Migrant {
            particle,
            history,
            fluid_share: Option::decode(words),
        }
    }
}

/// A particle changing owner, with the history of its pairs and wall patches and,
/// with a coupled fluid, its row of the fluid's cell shares (so that it reads the
/// fluid and gives back its drag through the same cells as in one process until
/// the shares are computed again).
#[derive(Clone, Debug)]
pub(super) struct Migrant {
    pub(super) particle: ParticleRecord,
    pub(super) history: ContactHistory,
    pub(super) fluid_share: Option<ShareRow>,
}

/// The entries of `history` that concern particle `id`.
pub(super) fn history_of(history: &ContactHistory, id: u64) -> ContactHistory {
    ContactHistory {
        pairs: history
            .pairs
            .iter()
            .filter(|((a, b), _)| *a == id || *b == id)
            .copied()
            .collect(),
        walls: history
            .walls
            .iter()
            .filter(|(key, _)| key.0 == id)
            .copied()
            .collect(),
    }
}
