//! What ranks send each other, as 64-bit words: floating-point numbers by their bits
//! (a ghost is the owner's particle to the bit), integers as they are. MPI moves
//! the words; the exchange among threads moves them too, so that the tests of ranks
//! on threads go through the same encoding.

use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::backend::ContactHistory;
use crate::world::{CellContribution, ParticleFluid, ShareRow};

/// A value that travels between ranks.
pub trait Message: Sized + Send + 'static {
    /// Appends the value's words.
    fn encode(&self, out: &mut Vec<u64>);

    /// Reads a value back from the words `encode` wrote.
    fn decode(words: &mut Words<'_>) -> Self;
}

/// A cursor over received words.
pub struct Words<'a> {
    words: &'a [u64],
    at: usize,
}

impl<'a> Words<'a> {
    /// A cursor at the start of `words`.
    pub fn new(words: &'a [u64]) -> Self {
        Words { words, at: 0 }
    }

    /// The next word. Ranks only decode what ranks of the same build encoded, so
    /// running out is a bug, not bad input.
    pub fn next_word(&mut self) -> u64 {
        let word = *self
            .words
            .get(self.at)
            .expect("a message holds the words its type encodes");
        self.at += 1;
        word
    }

    /// Whether every word was read.
    pub fn is_done(&self) -> bool {
        self.at == self.words.len()
    }
}

/// Encodes a list of messages (its length first).
pub fn encode_list<T: Message>(list: &[T]) -> Vec<u64> {
    let mut out = vec![list.len() as u64];
    for m in list {
        m.encode(&mut out);
    }
    out
}

/// Decodes what [`encode_list`] wrote.
pub fn decode_list<T: Message>(words: &[u64]) -> Vec<T> {
    let mut w = Words::new(words);
    let n = w.next_word() as usize;
    let list = (0..n).map(|_| T::decode(&mut w)).collect();
    assert!(w.is_done(), "a message ends where its list does");
    list
}

impl Message for u64 {
    fn encode(&self, out: &mut Vec<u64>) {
        out.push(*self);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        words.next_word()
    }
}

impl Message for bool {
    fn encode(&self, out: &mut Vec<u64>) {
        out.push(u64::from(*self));
    }
    fn decode(words: &mut Words<'_>) -> Self {
        words.next_word() != 0
    }
}

impl Message for Real {
    fn encode(&self, out: &mut Vec<u64>) {
        out.push(self.to_bits());
    }
    fn decode(words: &mut Words<'_>) -> Self {
        Real::from_bits(words.next_word())
    }
}

impl Message for Vector3<Real> {
    fn encode(&self, out: &mut Vec<u64>) {
        out.extend(self.iter().map(|x| x.to_bits()));
    }
    fn decode(words: &mut Words<'_>) -> Self {
        Vector3::from_fn(|_, _| Real::decode(words))
    }
}

impl Message for Point3<Real> {
    fn encode(&self, out: &mut Vec<u64>) {
        self.coords.encode(out);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        Point3::from(Vector3::decode(words))
    }
}

impl Message for UnitQuaternion<Real> {
    fn encode(&self, out: &mut Vec<u64>) {
        out.extend(self.coords.iter().map(|x| x.to_bits()));
    }
    fn decode(words: &mut Words<'_>) -> Self {
        let c: [Real; 4] = std::array::from_fn(|_| Real::decode(words));
        // The stored coordinates as they were: no normalisation, which could move
        // the last bit.
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(c[3], c[0], c[1], c[2]))
    }
}

impl<A: Message, B: Message> Message for (A, B) {
    fn encode(&self, out: &mut Vec<u64>) {
        self.0.encode(out);
        self.1.encode(out);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        let a = A::decode(words);
        (a, B::decode(words))
    }
}

impl<T: Message> Message for Vec<T> {
    fn encode(&self, out: &mut Vec<u64>) {
        out.push(self.len() as u64);
        for m in self {
            m.encode(out);
        }
    }
    fn decode(words: &mut Words<'_>) -> Self {
        let n = words.next_word() as usize;
        (0..n).map(|_| T::decode(words)).collect()
    }
}

impl Message for TangentialHistory {
    fn encode(&self, out: &mut Vec<u64>) {
        self.spring.encode(out);
        self.stiffness.encode(out);
        self.twist.encode(out);
        self.rolling.encode(out);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        TangentialHistory {
            spring: Vector3::decode(words),
            stiffness: Real::decode(words),
            twist: Real::decode(words),
            rolling: Vector3::decode(words),
        }
    }
}

impl Message for ContactHistory {
    fn encode(&self, out: &mut Vec<u64>) {
        out.push(self.pairs.len() as u64);
        for ((a, b), h) in &self.pairs {
            out.extend([*a, *b]);
            h.encode(out);
        }
        out.push(self.walls.len() as u64);
        for ((id, wall, plane), h) in &self.walls {
            out.extend([*id, u64::from(*wall)]);
            out.extend(plane.iter().map(|&x| x as u64));
            h.encode(out);
        }
    }
    fn decode(words: &mut Words<'_>) -> Self {
        let n = words.next_word() as usize;
        let pairs = (0..n)
            .map(|_| {
                let key = (words.next_word(), words.next_word());
                (key, TangentialHistory::decode(words))
            })
            .collect();
        let n = words.next_word() as usize;
        let walls = (0..n)
            .map(|_| {
                let id = words.next_word();
                let wall = words.next_word() as u32;
                let plane = std::array::from_fn(|_| words.next_word() as i64);
                ((id, wall, plane), TangentialHistory::decode(words))
            })
            .collect();
        ContactHistory { pairs, walls }
    }
}

impl<T: Message> Message for Option<T> {
    fn encode(&self, out: &mut Vec<u64>) {
        out.push(u64::from(self.is_some()));
        if let Some(m) = self {
            m.encode(out);
        }
    }
    fn decode(words: &mut Words<'_>) -> Self {
        (words.next_word() != 0).then(|| T::decode(words))
    }
}

impl Message for ShareRow {
    fn encode(&self, out: &mut Vec<u64>) {
        out.push(self.cells.len() as u64);
        out.extend(self.cells.iter().map(|&c| u64::from(c)));
        self.volumes.iter().for_each(|v| v.encode(out));
    }
    fn decode(words: &mut Words<'_>) -> Self {
        let n = words.next_word() as usize;
        let cells = (0..n).map(|_| words.next_word() as u32).collect();
        let volumes = (0..n).map(|_| Real::decode(words)).collect();
        ShareRow { cells, volumes }
    }
}

impl Message for CellContribution {
    fn encode(&self, out: &mut Vec<u64>) {
        out.extend([u64::from(self.cell), self.id]);
        self.volume.encode(out);
        self.momentum.encode(out);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        CellContribution {
            cell: words.next_word() as u32,
            id: words.next_word(),
            volume: Real::decode(words),
            momentum: Vector3::decode(words),
        }
    }
}

impl Message for ParticleFluid {
    fn encode(&self, out: &mut Vec<u64>) {
        self.drag.encode(out);
        self.slip.encode(out);
        self.voidage.encode(out);
    }
    fn decode(words: &mut Words<'_>) -> Self {
        ParticleFluid {
            drag: Vector3::decode(words),
            slip: Vector3::decode(words),
            voidage: Real::decode(words),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value comes back with its bits: negative zero, a subnormal, a negative
    /// patch offset, a quaternion as stored (not renormalised).
    #[test]
    fn messages_come_back_to_the_bit() {
        let h = TangentialHistory {
            spring: Vector3::new(-0.0, 5e-324, 1.0 / 3.0),
            stiffness: 1e300,
            twist: -2.5,
            rolling: Vector3::new(0.1, -0.2, 0.3),
        };
        let history = ContactHistory {
            pairs: vec![((3, u64::MAX), h)],
            walls: vec![((7, 2, [-1, i64::MIN, 0, i64::MAX]), h)],
        };
        let q = UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(0.6, 0.8, 1e-17, 0.0));
        let list = vec![
            (history.clone(), (q, true)),
            (ContactHistory::default(), (q, false)),
        ];
        let words = encode_list(&list);
        let back: Vec<(ContactHistory, (UnitQuaternion<Real>, bool))> = decode_list(&words);
        assert_eq!(back.len(), 2);
        assert_eq!(back[0].0, history);
        assert_eq!(back[1].0, ContactHistory::default());
        let bits = |h: &TangentialHistory| h.spring.map(Real::to_bits);
        assert_eq!(bits(&back[0].0.pairs[0].1), bits(&h));
        assert_eq!(
            back[0].1.0.coords.map(Real::to_bits),
            q.coords.map(Real::to_bits)
        );
        assert!(back[0].1.1 && !back[1].1.1);
    }

    /// The fluid's messages: a row or none, a cell's contribution, what the fluid
    /// does to a particle.
    #[test]
    fn fluid_messages_come_back_to_the_bit() {
        let row = ShareRow {
            cells: vec![0, 7, u32::MAX],
            volumes: vec![1e-9, -0.0, 5e-324],
        };
        let rows = vec![Some(row.clone()), None, Some(ShareRow::default())];
        assert_eq!(decode_list::<Option<ShareRow>>(&encode_list(&rows)), rows);
        let c = CellContribution {
            cell: 12,
            id: u64::MAX,
            volume: 1.0 / 3.0,
            momentum: Vector3::new(-1e-300, 0.0, 2.0),
        };
        let f = ParticleFluid {
            drag: Vector3::new(1.0, -2.0, 1e-20),
            slip: Vector3::new(0.5, 0.25, -0.125),
            voidage: 0.4,
        };
        let list = vec![(c, f)];
        assert_eq!(
            decode_list::<(CellContribution, ParticleFluid)>(&encode_list(&list)),
            list
        );
    }
}
