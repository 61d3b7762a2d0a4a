//! The structure of a packed bed in a tube: bed height, bed-averaged porosity,
//! radial and axial porosity profiles (also as the cells of a cylindrical grid:
//! [`porosity_map`]), coordination numbers, pellet orientations, and the figures
//! reactor models take ([`ReactorFigures`]: specific surface and
//! its radial profile, Sauter and volume-equivalent diameters, wall contacts,
//! permeabilities).
//!
//! **Volumes.** Every figure of porosity comes from the volumes of the particles
//! clipped to a region: a slab `z₀ ≤ z ≤ z₁` of the tube (z along its axis, from its
//! base) and a disc `ρ ≤ r` about the axis. A particle's clipped volume is the
//! integral over z of the area of its section inside the disc. Sections of a convex
//! polyhedron are convex polygons whose vertices move linearly with z between the
//! heights of the polyhedron's vertices, so there the polygon's area is a quadratic
//! in z and Gauss–Legendre quadrature between vertex heights integrates it exactly;
//! the part of a polygon inside a disc is exact for each z
//! ([`crate::geometry::section::polygon_disc_area`]) but not polynomial in z, so those
//! integrals are adaptive (5-point Gauss–Legendre, halved until two halves agree
//! with the whole to `1e-9` of the particle's volume per unit of its height). The
//! estimated error of the whole region's volume is reported with the figures. A
//! sphere's sections are discs (lens areas, [`super::section::disc_disc_area`]).
//!
//! **Definitions.** The bed height is the top of the highest axial slice whose solid
//! fraction is at least half the median solid fraction of the occupied slices (so
//! particles resting loose on top do not raise it). The bed average and the radial
//! profile cover the tube's full cross-section (radius `R`) between `exclude` above
//! the base and `exclude` below the bed height (default two particle diameters
//! each). Radial bins are annuli of width `bin` from the axis out to `R`, the last
//! one narrower if `R` is not a multiple (a remainder under 1 % of a bin widens
//! it instead); `ε(r) = 1 − V_solid / V_annulus`.
//! Coordination counts the particles whose surfaces are within `gap` of each other
//! (GJK distance for polyhedra). The pellet axis of a polyhedral particle is its
//! template's z axis (a prism's axis); its angle to the tube's axis is binned by
//! `cos θ` (isotropic orientations are uniform in `cos θ`).

pub mod bridges;
mod clipped;
mod coordination;
mod map;
pub mod mesher;
mod near;
mod reactor;

use nalgebra::{Isometry3, Point3, Vector3};
use serde::Serialize;

use crate::Real;
use crate::geometry::Shape;
use crate::geometry::axial_volumes::{AxialBody, Sectors, axis_frame};
use crate::world::World;
use coordination::coordination;
pub use map::{PorosityMap, porosity_map};
pub use reactor::ReactorFigures;
use reactor::SolidShare;

/// A tube: a point on its axis at the bed's base, the axis and the inner radius.
#[derive(Clone, Copy, Debug)]
pub struct Tube {
    /// Centre of the tube's base (z = 0 of the bed frame).
    pub base: Point3<Real>,
    /// Axis, pointing up the bed.
    pub axis: Vector3<Real>,
    /// Inner radius, m.
    pub radius: Real,
}

impl Tube {
    /// The bed frame: world point → (x, y across the axis, z along it from the base).
    pub fn frame(&self) -> Isometry3<Real> {
        axis_frame(&self.base, &self.axis)
    }

    /// Height above the base, along the axis, of the top of particle `i`'s bounding
    /// sphere.
    pub fn top_of(&self, world: &World, i: usize) -> Real {
        let p = &world.particles;
        (p.position[i] - self.base).dot(&self.axis.normalize())
            + world.body_types[p.body_type[i] as usize]
                .shape
                .circumradius()
    }
}

/// Volume-equivalent diameter of the largest particle kind of `world`.
fn largest_diameter(world: &World) -> Real {
    world
        .body_types
        .iter()
        .map(|t| 2.0 * t.shape.equivalent_radius())
        .fold(0.0, Real::max)
}

/// Settings of the analysis (see the module docs); `None` takes the default.
#[derive(Clone, Copy, Debug, Default)]
pub struct PackingOptions {
    /// Radial bin width (default d/20).
    pub bin: Option<Real>,
    /// Axial slice thickness (default d/10).
    pub slice: Option<Real>,
    /// Excluded at the base and below the bed height (default 2 d).
    pub exclude: Option<Real>,
    /// Contact gap for coordination (default d/1000).
    pub gap: Option<Real>,
    /// Region to analyse instead of the one derived from the bed height.
    pub region: Option<(Real, Real)>,
    /// Gap between capped particles (default d/100; see [`mesher`]); also the
    /// reach of the bridges.
    pub cap_gap: Option<Real>,
    /// Bridge diameter over the particle diameter; `None`: no bridged bed (see
    /// [`bridges`]).
    pub bridge: Option<Real>,
}

impl Bed {
    /// The gap of the capped bed: the option, or a hundredth of the largest
    /// volume-equivalent diameter.
    pub fn cap_gap(&self, world: &World) -> Real {
        self.options
            .cap_gap
            .unwrap_or_else(|| largest_diameter(world) / 100.0)
    }
}

/// One radial bin.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RadialBin {
    /// Inner radius, m.
    pub r_inner: Real,
    /// Outer radius, m.
    pub r_outer: Real,
    /// Porosity.
    pub porosity: Real,
    /// Particle surface per annulus volume, 1/m (see [`ReactorFigures`]).
    pub specific_surface: Real,
}

/// One axial slice.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct AxialSlice {
    /// Lower edge, m above the base.
    pub z_lower: Real,
    /// Upper edge.
    pub z_upper: Real,
    /// Porosity over the tube's cross-section.
    pub porosity: Real,
}

/// The packing figures, written as `packing.json` (profiles also as CSV).
#[derive(Clone, Debug, Serialize)]
pub struct Packing {
    /// Particles in the world.
    pub particles: usize,
    /// Volume-equivalent diameter d of the largest particle kind, m.
    pub diameter: Real,
    /// Tube radius R, m, and the ratio N = 2R/d.
    pub tube_radius: Real,
    /// Tube-to-particle diameter ratio.
    pub tube_to_particle: Real,
    /// Bed height, m above the base.
    pub bed_height: Real,
    /// The region of the bed average and the radial profile, m above the base.
    pub region: [Real; 2],
    /// Bed-averaged porosity over the region.
    pub porosity: Real,
    /// Estimated error of the solid volume in the region (quadrature), m³.
    pub volume_error: Real,
    /// Solid volume in the region, m³.
    pub solid_volume: Real,
    /// Radial profile over the region.
    pub radial: Vec<RadialBin>,
    /// Axial profile over the whole tube.
    pub axial: Vec<AxialSlice>,
    /// Mean coordination number (particle–particle contacts per particle).
    pub coordination_mean: Real,
    /// Particles with 0, 1, 2, ... contacts.
    pub coordination: Vec<usize>,
    /// Polyhedral particles per bin of |cos θ| (10 bins from 0 to 1), θ the angle
    /// between the pellet axis and the tube's axis.
    pub orientation_cos: Vec<usize>,
    /// Order parameter ⟨(3 cos²θ − 1)/2⟩ (0 isotropic, 1 along the axis, −½ across).
    pub orientation_order: Option<Real>,
    /// What reactor models need besides the porosity, over the region.
    pub reactor: ReactorFigures,
}

/// A bed to analyse: the tube and the settings.
#[derive(Clone, Copy, Debug)]
pub struct Bed {
    /// The tube.
    pub tube: Tube,
    /// The settings.
    pub options: PackingOptions,
}

/// Bodies placed in the bed frame with the derived lengths.
struct Placed<'a> {
    bodies: Vec<AxialBody<'a>>,
    /// Each body's surface over its volume.
    surface_ratio: Vec<Real>,
    tube: Tube,
    diameter: Real,
    bin: Real,
    slice: Real,
    exclude: Real,
}

impl<'a> Placed<'a> {
    /// The particles of `world` that `keep` accepts, placed in the bed frame.
    fn new(world: &'a World, bed: &Bed, keep: impl Fn(usize) -> bool) -> Result<Self, String> {
        let (tube, options) = (&bed.tube, &bed.options);
        if !(0..world.particles.len()).any(&keep) {
            return Err("the bed has no particles".into());
        }
        if !(tube.radius > 0.0) || !(tube.axis.norm() > 0.0) {
            return Err("the tube needs a positive radius and a non-zero axis".into());
        }
        let tube = Tube {
            axis: tube.axis.normalize(),
            ..*tube
        };
        let diameter = largest_diameter(world);
        let bin = options.bin.unwrap_or(diameter / 20.0);
        let slice = options.slice.unwrap_or(diameter / 10.0);
        for (name, v) in [("bin", bin), ("slice", slice)] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(format!("{name} = {v} must be positive"));
            }
        }
        let frame = tube.frame();
        // By id: the same sums whatever the order the particles are stored in (one
        // process stores them in the space order, ranks gather them by id).
        let p = &world.particles;
        let kept = p.by_id((0..p.len()).filter(|&i| keep(i)).collect());
        // Per body type once: a polyhedron's surface sums its faces.
        let ratio: Vec<Real> = world
            .body_types
            .iter()
            .map(|t| t.shape.surface_area() / t.shape.volume())
            .collect();
        Ok(Placed {
            bodies: kept
                .iter()
                .map(|&i| clipped::place(world, i, &frame))
                .collect(),
            surface_ratio: kept
                .iter()
                .map(|&i| ratio[world.particles.body_type[i] as usize])
                .collect(),
            tube,
            diameter,
            bin,
            slice,
            exclude: options.exclude.unwrap_or(2.0 * diameter),
        })
    }

    fn area(&self) -> Real {
        std::f64::consts::PI * self.tube.radius * self.tube.radius
    }

    /// Solid fraction per axial slice over the tube's cross-section, and the bed
    /// height they give.
    fn axial(&self) -> (Vec<Real>, Real) {
        self.axial_above(0.0)
    }

    /// [`Self::axial`] over the slices above `from` only (those below read 0, and
    /// the bodies must include every one that reaches above `from`).
    fn axial_above(&self, from: Real) -> (Vec<Real>, Real) {
        let slice = self.slice;
        let top = self
            .bodies
            .iter()
            .map(|b| b.z_range().1)
            .fold(0.0, Real::max);
        let slices = (top / slice).ceil().max(1.0) as usize;
        let mut solid = vec![0.0; slices];
        let lowest = (from.max(0.0) / slice).floor() as usize;
        for b in &self.bodies {
            let (lo, hi) = b.z_range();
            let first = ((lo.max(0.0) / slice).floor() as usize).max(lowest);
            let last = ((hi / slice).ceil() as usize).min(slices);
            for (k, v) in solid.iter_mut().enumerate().take(last).skip(first) {
                let z = (k as Real * slice, (k + 1) as Real * slice);
                *v += b
                    .clipped_volumes(z.0, z.1, &[self.tube.radius], Sectors(1))
                    .0[0];
            }
        }
        let fractions: Vec<Real> = solid.iter().map(|v| v / (self.area() * slice)).collect();
        let mut occupied: Vec<Real> = fractions.iter().copied().filter(|&f| f > 0.0).collect();
        occupied.sort_by(Real::total_cmp);
        let median = occupied.get(occupied.len() / 2).copied().unwrap_or(0.0);
        let height = fractions
            .iter()
            .rposition(|&f| f >= 0.5 * median)
            .map_or(0.0, |k| (k + 1) as Real * slice);
        (fractions, height)
    }

    /// The region of the averages.
    fn region(
        &self,
        bed_height: Real,
        given: Option<(Real, Real)>,
    ) -> Result<(Real, Real), String> {
        let (z0, z1) = given.unwrap_or((self.exclude, bed_height - self.exclude));
        if z1 > z0 {
            Ok((z0, z1))
        } else {
            Err(format!(
                "the region [{z0:.4e}, {z1:.4e}] m is empty: the bed ({bed_height:.4e} m high) \
                 is not taller than twice the excluded layer ({:.4e} m)",
                self.exclude
            ))
        }
    }

    /// The solid's share inside each disc of `radii` between `z0` and `z1`, and the
    /// estimated quadrature error of its volume.
    fn volumes(&self, z0: Real, z1: Real, radii: &[Real]) -> (Vec<SolidShare>, Real) {
        let mut inside = vec![SolidShare::default(); radii.len()];
        let mut error = 0.0;
        for (b, ratio) in self.bodies.iter().zip(&self.surface_ratio) {
            let (v, e) = b.clipped_volumes(z0, z1, radii, Sectors(1));
            error += e;
            let whole = b.volume();
            for (acc, x) in inside.iter_mut().zip(v) {
                acc.volume += x;
                acc.surface += x * ratio;
                acc.count += x / whole;
            }
        }
        (inside, error)
    }

    /// Of the bodies with their centroid between `z0` and `z1`, the share reaching
    /// within `gap` of the tube wall.
    fn wall_contact_fraction(&self, z0: Real, z1: Real, gap: Real) -> Real {
        let inside = self
            .bodies
            .iter()
            .filter(|b| (z0..=z1).contains(&b.centroid().z));
        let (mut all, mut touching) = (0usize, 0usize);
        for b in inside {
            all += 1;
            touching += usize::from(b.reach() >= self.tube.radius - gap);
        }
        if all == 0 {
            0.0
        } else {
            touching as Real / all as Real
        }
    }
}

/// The figures [`bed_figures`] gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BedFigures {
    /// Bed height, m above the base.
    pub height: Real,
    /// Bed-averaged porosity over the region.
    pub porosity: Real,
    /// Specific surface area over the region, 1/m ([`ReactorFigures`]).
    pub specific_surface: Real,
    /// Kozeny–Carman permeability over the region, m² ([`ReactorFigures`]).
    pub permeability: Real,
}

/// Bed height, bed-averaged porosity, specific surface and permeability only (no
/// profiles, coordination or orientations): cheap enough to follow a bed while it
/// is being tapped.
pub fn bed_figures(world: &World, bed: &Bed) -> Result<BedFigures, String> {
    let placed = Placed::new(world, bed, |_| true)?;
    let (_, height) = placed.axial();
    let (z0, z1) = placed.region(height, bed.options.region)?;
    let (v, _) = placed.volumes(z0, z1, &[placed.tube.radius]);
    let bed_volume = placed.area() * (z1 - z0);
    let porosity = 1.0 - v[0].volume / bed_volume;
    let reactor = ReactorFigures::new(bed_volume, porosity, v[0], 0.0);
    Ok(BedFigures {
        height,
        porosity,
        specific_surface: reactor.specific_surface,
        permeability: reactor.permeability_kozeny_carman,
    })
}

/// Bed height of the particles that `member` marks: while a bed is fed, those
/// touching something, so that particles in flight above it do not count.
///
/// Given the `last` height measured, only the slices from [`FEED_WINDOW`] diameters
/// below it up are integrated (the threshold, half the median solid fraction, then
/// comes from the bulk just below the surface): a measurement costs what the top
/// layers cost, however long the bed. Without `last`, or with a bed shorter than
/// the window, it is what [`analyse`] gives.
pub fn bed_height_of(
    world: &World,
    bed: &Bed,
    member: &[bool],
    last: Option<Real>,
) -> Result<Real, String> {
    let from = measured_from(world, last);
    let placed = Placed::new(world, bed, |i| {
        member.get(i) == Some(&true) && bed.tube.top_of(world, i) > from
    })?;
    Ok(placed.axial_above(from).1)
}

/// The level above which [`bed_height_of`] integrates a bed last measured at
/// `last`: a particle whose top lies below it takes no part.
pub fn measured_from(world: &World, last: Option<Real>) -> Real {
    last.map_or(Real::NEG_INFINITY, |h| {
        h - FEED_WINDOW * largest_diameter(world)
    })
}

/// Depth of the part of a bed that [`bed_height_of`] integrates, in particle
/// diameters below the last height: several layers of bulk under the surface layer.
pub const FEED_WINDOW: Real = 10.0;

/// Analyses the particles of `world` packed in the bed's tube.
pub fn analyse(world: &World, bed: &Bed) -> Result<Packing, String> {
    let placed = Placed::new(world, bed, |_| true)?;
    let (fractions, bed_height) = placed.axial();
    let (z0, z1) = placed.region(bed_height, bed.options.region)?;
    let (radius, bin) = (placed.tube.radius, placed.bin);
    let radii = radial_bins(radius, bin);
    let bins = radii.len();
    let (inside, volume_error) = placed.volumes(z0, z1, &radii);
    let height = z1 - z0;
    let mut radial = Vec::with_capacity(bins);
    let mut previous = (0.0, SolidShare::default());
    for (k, &r) in radii.iter().enumerate() {
        let annulus = std::f64::consts::PI * (r * r - previous.0 * previous.0) * height;
        radial.push(RadialBin {
            r_inner: previous.0,
            r_outer: r,
            porosity: 1.0 - (inside[k].volume - previous.1.volume) / annulus,
            specific_surface: (inside[k].surface - previous.1.surface) / annulus,
        });
        previous = (r, inside[k]);
    }
    let solid = inside.last().copied().unwrap_or_default();
    let solid_volume = solid.volume;
    let d = placed.diameter;
    let gap = bed.options.gap.unwrap_or(d / 1000.0);
    let (coordination_mean, coordination) = coordination(world, gap);
    let bed_volume = placed.area() * height;
    let porosity = 1.0 - solid_volume / bed_volume;
    let reactor = ReactorFigures::new(
        bed_volume,
        porosity,
        solid,
        placed.wall_contact_fraction(z0, z1, gap),
    );
    let (orientation_cos, orientation_order) = orientations(world, &placed.tube.axis);
    let slice = placed.slice;
    Ok(Packing {
        particles: world.particles.len(),
        diameter: d,
        tube_radius: radius,
        tube_to_particle: 2.0 * radius / d,
        bed_height,
        region: [z0, z1],
        porosity,
        volume_error,
        solid_volume,
        radial,
        axial: fractions
            .iter()
            .enumerate()
            .map(|(k, f)| AxialSlice {
                z_lower: k as Real * slice,
                z_upper: (k + 1) as Real * slice,
                porosity: 1.0 - f,
            })
            .collect(),
        coordination_mean,
        coordination,
        orientation_cos,
        orientation_order,
        reactor,
    })
}

/// The outer radii of the radial bins of width `bin` out to `radius`: a remainder
/// under 1 % of a bin (a radius given to a few digits: R/bin = 60.001) widens the
/// last bin instead of making a sliver whose porosity reads 1.
fn radial_bins(radius: Real, bin: Real) -> Vec<Real> {
    let bins = (radius / bin - 0.01).ceil().max(1.0) as usize;
    (1..bins).map(|k| k as Real * bin).chain([radius]).collect()
}

/// Histogram of |cos θ| (10 bins) and the order parameter over polyhedral particles.
fn orientations(world: &World, axis: &Vector3<Real>) -> (Vec<usize>, Option<Real>) {
    let p = &world.particles;
    let mut histogram = vec![0usize; 10];
    let (mut order, mut count) = (0.0, 0usize);
    for i in 0..p.len() {
        if let Shape::Polyhedron(_) = world.body_types[p.body_type[i] as usize].shape {
            let c = (p.orientation[i] * Vector3::z()).dot(axis).abs().min(1.0);
            histogram[((c * 10.0) as usize).min(9)] += 1;
            order += 0.5 * (3.0 * c * c - 1.0);
            count += 1;
        }
    }
    (histogram, (count > 0).then(|| order / count as Real))
}

#[cfg(test)]
mod bridge_tests;
#[cfg(test)]
mod tests;
