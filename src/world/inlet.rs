//! Inlets: sources that insert particles into a box at a rate.
//!
//! Each inserted particle gets a uniformly random orientation and a random position
//! whose bounding sphere lies inside the box and clears every other particle's
//! bounding sphere and every wall facet, so no contact starts overlapped. A particle
//! that finds no free place in [`PLACEMENT_ATTEMPTS`] tries is carried over to the
//! next step (the inlet falls behind its rate rather than overlap).

use nalgebra::{Point3, Quaternion, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use std::ops::Range;

use super::{Particles, World};
use crate::Real;
use crate::geometry::sphere::closest_point_on_triangle;

/// Random positions tried per particle and step.
pub const PLACEMENT_ATTEMPTS: usize = 64;

/// The bounding sphere of a particle an inlet must place clear of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obstacle {
    pub centre: Point3<Real>,
    pub radius: Real,
}

impl Obstacle {
    /// The bounding sphere of `world`'s particle `k`.
    pub fn of(world: &World, k: usize) -> Self {
        let p = &world.particles;
        Obstacle {
            centre: p.position[k],
            radius: world.body_types[p.body_type[k] as usize]
                .shape
                .circumradius(),
        }
    }
}

/// A particle an inlet placed, before it is inserted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedParticle {
    pub body_type: u32,
    pub position: Point3<Real>,
    pub orientation: UnitQuaternion<Real>,
    pub velocity: Vector3<Real>,
    pub id: u64,
}

impl PlacedParticle {
    /// Appends it to the owned particles, at rest but for its velocity.
    pub fn push_into(&self, particles: &mut Particles) {
        particles.push(self.body_type, self.position, self.orientation, self.id);
        let i = particles.owned() - 1;
        particles.velocity[i] = self.velocity;
    }
}

/// A particle source.
#[derive(Clone, Debug)]
pub struct Inlet {
    /// Body type of the inserted particles.
    pub body_type: u32,
    /// Lower corner of the insertion box.
    pub min: Point3<Real>,
    /// Upper corner.
    pub max: Point3<Real>,
    /// Particles per second.
    pub rate: Real,
    /// Total to insert (lowered to what was inserted when the inlet stops early).
    pub count: usize,
    /// Bed height at which feeding stops (see [`Inlet::stop`]).
    pub stop_height: Option<Real>,
    /// Whether the box follows the bed (see [`Inlet::offset`]).
    pub above_bed: bool,
    /// Shift of the insertion box, set from outside (the bed height along the bed's
    /// axis for an inlet fed `above_bed`).
    pub offset: Vector3<Real>,
    /// Velocity of inserted particles.
    pub velocity: Vector3<Real>,
    /// Start time.
    pub start: Real,
    /// Inserted so far.
    pub inserted: usize,
    rng: Pcg64,
}

impl Inlet {
    /// A new inlet; `seed` makes its sequence reproducible.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        body_type: u32,
        min: Point3<Real>,
        max: Point3<Real>,
        rate: Real,
        count: usize,
        velocity: Vector3<Real>,
        start: Real,
        seed: u64,
    ) -> Self {
        Inlet {
            body_type,
            min,
            max,
            rate,
            count,
            stop_height: None,
            above_bed: false,
            offset: Vector3::zeros(),
            velocity,
            start,
            inserted: 0,
            rng: Pcg64::seed_from_u64(seed),
        }
    }

    /// The state of the inlet's random generator, as bytes.
    pub fn rng_state(&self) -> Vec<u8> {
        serde_json::to_vec(&self.rng).expect("a PCG state always serialises")
    }

    /// Restores a state from [`Inlet::rng_state`].
    pub fn set_rng_state(&mut self, bytes: &[u8]) -> Result<(), serde_json::Error> {
        self.rng = serde_json::from_slice(bytes)?;
        Ok(())
    }

    /// Stops feeding: nothing more is inserted.
    pub fn stop(&mut self) {
        self.count = self.inserted;
    }

    /// Whether every particle has been inserted.
    pub fn is_done(&self) -> bool {
        self.inserted >= self.count
    }

    /// Whether particles may be due at time `t` (started, not done).
    pub fn is_due(&self, t: Real) -> bool {
        !self.is_done() && t >= self.start
    }

    /// Inserts the particles due by time `t` into `world`, giving them ids from
    /// `next_id` on; returns how many were inserted.
    pub fn insert_due(&mut self, world: &mut World, t: Real, next_id: &mut u64) -> usize {
        if !self.is_due(t) {
            return 0;
        }
        let obstacles = self.obstacles(world, 0..world.particles.len());
        let placed = self.place_due(world, obstacles, t, next_id);
        for particle in &placed {
            particle.push_into(&mut world.particles);
        }
        placed.len()
    }

    /// The bounding spheres of `world`'s particles `among` that reach into the range
    /// of centres the inlet draws from: only they can be in the way (found once per
    /// call, not once per attempt: a long bed is far below).
    pub fn obstacles(&self, world: &World, among: Range<usize>) -> Vec<Obstacle> {
        let radius = self.radius(world);
        let (a, b) = self.centre_range(radius);
        let (lo, hi) = (a.inf(&b), a.sup(&b)); // every centre drawn lies in there
        among
            .map(|k| Obstacle::of(world, k))
            .filter(|o| {
                let reach = radius + o.radius;
                let x = o.centre.coords;
                (x - x.sup(&lo).inf(&hi)).norm_squared() < reach * reach
            })
            .collect()
    }

    /// Places the particles due by time `t` clear of the `obstacles` (in any order)
    /// and of `world`'s walls, with ids from `next_id` on, without inserting them.
    /// The same inlet state, obstacles and walls place the same particles to the
    /// bit: how the ranks of a decomposed run insert as one process does.
    pub fn place_due(
        &mut self,
        world: &World,
        mut obstacles: Vec<Obstacle>,
        t: Real,
        next_id: &mut u64,
    ) -> Vec<PlacedParticle> {
        if !self.is_due(t) {
            return Vec::new();
        }
        let due = (((t - self.start) * self.rate).floor() as usize + 1).min(self.count);
        let radius = self.radius(world);
        let mut placed = Vec::new();
        while self.inserted < due {
            let Some(position) = self.free_position(world, radius, &obstacles) else {
                break;
            };
            let orientation = random_orientation(&mut self.rng);
            placed.push(PlacedParticle {
                body_type: self.body_type,
                position,
                orientation,
                velocity: self.velocity,
                id: *next_id,
            });
            obstacles.push(Obstacle {
                centre: position,
                radius,
            });
            *next_id += 1;
            self.inserted += 1;
        }
        placed
    }

    /// The bounding radius of the inserted particles.
    fn radius(&self, world: &World) -> Real {
        world.body_types[self.body_type as usize]
            .shape
            .circumradius()
    }

    /// The box the centre of a particle of bounding radius `radius` is drawn from.
    fn centre_range(&self, radius: Real) -> (Vector3<Real>, Vector3<Real>) {
        (
            self.min.coords + self.offset + Vector3::repeat(radius),
            self.max.coords + self.offset - Vector3::repeat(radius),
        )
    }

    /// A random centre in the box whose ball of `radius` is free (see [`is_free`]),
    /// checking the `obstacles` near the box.
    fn free_position(
        &mut self,
        world: &World,
        radius: Real,
        obstacles: &[Obstacle],
    ) -> Option<Point3<Real>> {
        let (lo, hi) = self.centre_range(radius);
        for _ in 0..PLACEMENT_ATTEMPTS {
            let x = Point3::from(lo.zip_map(&hi, |a, b| {
                if b > a {
                    self.rng.random_range(a..b)
                } else {
                    0.5 * (a + b)
                }
            }));
            if is_free_of(world, obstacles.iter().copied(), &x, radius) {
                return Some(x);
            }
        }
        None
    }
}

/// Whether a ball at `x` of radius `r` clears every particle's bounding sphere and
/// every wall facet.
pub fn is_free(world: &World, x: &Point3<Real>, r: Real) -> bool {
    let balls = (0..world.particles.len()).map(|k| Obstacle::of(world, k));
    is_free_of(world, balls, x, r)
}

/// [`is_free`] against the `obstacles` only (and every wall facet).
fn is_free_of(
    world: &World,
    obstacles: impl Iterator<Item = Obstacle>,
    x: &Point3<Real>,
    r: Real,
) -> bool {
    for o in obstacles {
        let reach = r + o.radius;
        if (o.centre - x).norm_squared() < reach * reach {
            return false;
        }
    }
    let mut facets = Vec::new();
    for wall in &world.walls {
        let local = wall.pose.inverse_transform_point(x);
        wall.grid.query(&local, r, &mut facets);
        for &f in &facets {
            let t = wall.triangles[f as usize].map(|v| wall.vertices[v as usize]);
            let (c, _) = closest_point_on_triangle(&t, &local);
            if (c - local).norm_squared() < r * r {
                return false;
            }
        }
    }
    true
}

/// A uniformly distributed rotation (normalised Gaussian quaternion).
pub fn random_orientation(rng: &mut impl Rng) -> UnitQuaternion<Real> {
    loop {
        let q = Quaternion::new(gaussian(rng), gaussian(rng), gaussian(rng), gaussian(rng));
        if q.norm() > 1e-6 {
            return UnitQuaternion::from_quaternion(q);
        }
    }
}

/// A standard normal sample (Box–Muller).
fn gaussian(rng: &mut impl Rng) -> Real {
    let u: Real = rng.random_range(Real::MIN_POSITIVE..1.0);
    let v: Real = rng.random_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}
