//! The fluid a coupled CFD code lays over the world: its grid, what it sets per cell
//! (velocity, pressure gradient) and what it gets back (solid volume fraction, mean
//! particle velocity, the momentum the particles took from it).

use std::ops::Range;

use nalgebra::{Point3, Vector3};

use super::{BodyType, CellShares, Particles};
use crate::Real;
use crate::fluid::{DragLaw, DragShape, FluidGrid, FluidProperties, ShapeCorrection};

/// The drag model of a scene: fluid, law, shape correction and each body type's
/// shape as the drag sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct DragModel {
    /// Density and viscosity.
    pub properties: FluidProperties,
    /// The drag law.
    pub law: DragLaw,
    /// The shape correction for non-spherical particles.
    pub correction: ShapeCorrection,
    /// Per body type.
    pub shapes: Vec<DragShape>,
}

/// What the fluid exchanged with the particles since it was last read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MomentumExchange {
    /// Per owned particle: the drag of the last force evaluation, N.
    pub drag: Vec<Vector3<Real>>,
    /// Per cell: the impulse of the drag the particles received, N s.
    pub impulse: Vec<Vector3<Real>>,
    /// Simulated time the impulses were summed over, s.
    pub elapsed: Real,
}

impl MomentumExchange {
    /// The mean force the particles put on cell `c` of the fluid since the sums were
    /// last started (minus the drag they received there, averaged over the time);
    /// zero when no time passed.
    pub fn source(&self, c: usize) -> Vector3<Real> {
        let t = self.elapsed;
        if t > 0.0 {
            -self.impulse[c] / t
        } else {
            Vector3::zeros()
        }
    }
}

/// A particle's volume in one cell and the momentum it brings there (its velocity
/// times that volume): what the cell's solid fraction and mean particle velocity
/// are summed from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellContribution {
    /// The cell's flat index.
    pub cell: u32,
    /// The particle's id.
    pub id: u64,
    /// Its volume in the cell, m³.
    pub volume: Real,
    /// Its velocity times that volume, m⁴/s.
    pub momentum: Vector3<Real>,
}

/// The fluid field of a coupled scene.
///
/// # Invariant
/// `velocity`, `pressure_gradient`, `solid_fraction`, `particle_velocity` and
/// `exchange.impulse` have one entry per cell of `grid` (its flat order).
#[derive(Clone, Debug, PartialEq)]
pub struct FluidField {
    /// The cells.
    pub grid: FluidGrid,
    /// How the fluid acts on particles.
    pub model: DragModel,
    /// Input per cell: the fluid's (interstitial) velocity, m/s.
    pub velocity: Vec<Vector3<Real>>,
    /// Input per cell: the pressure gradient, Pa/m (hydrostatic: density × gravity).
    pub pressure_gradient: Vec<Vector3<Real>>,
    /// Each particle's volume per cell, at the last update.
    pub shares: CellShares,
    /// Output per cell: solid volume fraction at the last update.
    pub solid_fraction: Vec<Real>,
    /// Output per cell: volume-weighted mean particle velocity at the last update.
    pub particle_velocity: Vec<Vector3<Real>>,
    /// The exchange since it was last read.
    pub exchange: MomentumExchange,
}

/// What a particle reads of the fluid: its voidage, velocity and pressure gradient,
/// averaged over the cells it lies in by its volume in each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalFluid {
    /// Fluid volume fraction.
    pub voidage: Real,
    /// Fluid velocity.
    pub velocity: Vector3<Real>,
    /// Pressure gradient.
    pub pressure_gradient: Vector3<Real>,
}

/// What the fluid does to one particle: the drag of the last force evaluation, the
/// slip (the fluid's velocity at the particle less the particle's) and the local
/// void fraction; outside the grid no drag, no slip and a voidage of 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParticleFluid {
    /// Drag, N.
    pub drag: Vector3<Real>,
    /// Fluid velocity at the particle less its own, m/s.
    pub slip: Vector3<Real>,
    /// Fluid volume fraction at the particle.
    pub voidage: Real,
}

impl FluidField {
    /// The fluid at owned particle `i` of `particles` ([`ParticleFluid`]).
    pub fn at_particle(&self, particles: &Particles, i: usize) -> ParticleFluid {
        let v = particles.velocity[i];
        let (u, voidage) = self
            .local(i, particles.id[i], &particles.position[i])
            .map_or((v, 1.0), |l| (l.velocity, l.voidage));
        ParticleFluid {
            drag: self.exchange.drag.get(i).copied().unwrap_or_default(),
            slip: u - v,
            voidage,
        }
    }

    /// A field on `grid` with uniform inputs and no particles yet.
    pub fn new(
        grid: FluidGrid,
        model: DragModel,
        velocity: Vector3<Real>,
        pressure_gradient: Vector3<Real>,
    ) -> Self {
        let n = grid.len();
        FluidField {
            grid,
            model,
            velocity: vec![velocity; n],
            pressure_gradient: vec![pressure_gradient; n],
            shares: CellShares::default(),
            solid_fraction: vec![0.0; n],
            particle_velocity: vec![Vector3::zeros(); n],
            exchange: MomentumExchange {
                impulse: vec![Vector3::zeros(); n],
                ..Default::default()
            },
        }
    }

    /// Splits every owned particle's volume among the cells again: the shares, the
    /// solid fractions and the mean particle velocities (each cell's sums in
    /// particle id order: the same bits on any thread count, any number of ranks
    /// and whatever the order the particles are stored in).
    pub fn update(&mut self, particles: &Particles, types: &[BodyType]) {
        self.shares = CellShares::compute(&self.grid, particles, types);
        let contributions = self.contributions(particles);
        self.add_up(0..self.grid.len(), &contributions);
    }

    /// What each owned particle with a row of the shares brings to each of its
    /// cells, in particle id order, then cell order.
    pub fn contributions(&self, particles: &Particles) -> Vec<CellContribution> {
        let mut out = Vec::new();
        for i in particles.owned_by_id() {
            let id = particles.id[i];
            let Some((cells, volumes)) = self.shares.of(i, id) else {
                continue;
            };
            for (&cell, &volume) in cells.iter().zip(volumes) {
                out.push(CellContribution {
                    cell,
                    id,
                    volume,
                    momentum: particles.velocity[i] * volume,
                });
            }
        }
        out
    }

    /// Sets the solid fraction and the mean particle velocity of the `cells` from
    /// `contributions` (all in those cells), each cell's summed in the order given.
    pub fn add_up(&mut self, cells: Range<usize>, contributions: &[CellContribution]) {
        let mut volume = vec![0.0; cells.len()];
        let mut momentum = vec![Vector3::zeros(); cells.len()];
        for c in contributions {
            let k = c.cell as usize - cells.start;
            volume[k] += c.volume;
            momentum[k] += c.momentum;
        }
        for ((c, s), m) in cells.zip(&volume).zip(&momentum) {
            self.solid_fraction[c] = s / self.grid.cell_volume(c);
            self.particle_velocity[c] = if *s > 0.0 { m / *s } else { Vector3::zeros() };
        }
    }

    /// Forgets what it kept of the owned particles that were removed (`removed`: by
    /// their index before; `particles`: the rest, in their order): the others keep
    /// their drag and their rows of the shares.
    pub fn particles_removed(&mut self, removed: &[bool], particles: &Particles) {
        let mut i = 0;
        self.exchange.drag.retain(|_| {
            i += 1;
            !removed.get(i - 1).copied().unwrap_or(false)
        });
        self.shares = self.shares.keep(&particles.id[..particles.owned()], &[]);
    }

    /// Follows the owned particles into a new order (`places[k]`: the index before
    /// of the particle now at `k`, see [`Particles::reorder_owned`]).
    pub fn particles_reordered(&mut self, places: &[u32], particles: &Particles) {
        let drag = &self.exchange.drag;
        if !drag.is_empty() {
            // Particles added since the last force evaluation have no drag yet.
            let of = |k: &u32| drag.get(*k as usize).copied().unwrap_or_default();
            self.exchange.drag = places.iter().map(of).collect();
        }
        self.shares = self.shares.keep(&particles.id[..particles.owned()], &[]);
    }

    /// Visits each cell particle `i` (of `id`, at `position`) lies in with its weight
    /// there (its volume in the cell over its volume in the grid): through its shares
    /// when they are up to date, else the cell of its centroid with weight 1. Visits
    /// nothing outside the grid. The fluid is read and the drag given back with
    /// these weights.
    pub fn weights(
        &self,
        i: usize,
        id: u64,
        position: &Point3<Real>,
        mut visit: impl FnMut(usize, Real),
    ) {
        match self.shares.of(i, id) {
            Some((cells, volumes)) => {
                let total: Real = volumes.iter().sum();
                for (&c, &v) in cells.iter().zip(volumes) {
                    visit(c as usize, v / total);
                }
            }
            None => {
                if let Some(c) = self.grid.cell_of(position) {
                    visit(c, 1.0);
                }
            }
        }
    }

    /// The fluid at particle `i`, averaged over its cells by its [`Self::weights`];
    /// `None` outside the grid.
    pub fn local(&self, i: usize, id: u64, position: &Point3<Real>) -> Option<LocalFluid> {
        let mut local = LocalFluid {
            voidage: 0.0,
            velocity: Vector3::zeros(),
            pressure_gradient: Vector3::zeros(),
        };
        let mut inside = false;
        self.weights(i, id, position, |c, w| {
            inside = true;
            local.voidage += w * (1.0 - self.solid_fraction[c]).max(0.0);
            local.velocity += self.velocity[c] * w;
            local.pressure_gradient += self.pressure_gradient[c] * w;
        });
        inside.then_some(local)
    }

    /// The mean force the particles put on cell `c` of the fluid since the sums were
    /// last started ([`MomentumExchange::source`]).
    pub fn momentum_source(&self, c: usize) -> Vector3<Real> {
        self.exchange.source(c)
    }

    /// Starts the sums of the exchange again.
    pub fn restart_exchange(&mut self) {
        self.exchange.impulse.fill(Vector3::zeros());
        self.exchange.elapsed = 0.0;
    }
}
