//! The structure of a packed bed in a tube: bed height, bed-averaged porosity,
//! radial and axial porosity profiles, coordination numbers and pellet orientations.
//!
//! **Volumes.** Every figure of porosity comes from the volumes of the particles
//! clipped to a region: a slab `z₀ ≤ z ≤ z₁` of the tube (z along its axis, from its
//! base) and a disc `ρ ≤ r` about the axis. A particle's clipped volume is the
//! integral over z of the area of its section inside the disc. Sections of a convex
//! polyhedron are convex polygons whose vertices move linearly with z between the
//! heights of the polyhedron's vertices, so there the polygon's area is a quadratic
//! in z and Gauss–Legendre quadrature between vertex heights integrates it exactly;
//! the part of a polygon inside a disc is exact for each z
//! ([`super::section::polygon_disc_area`]) but not polynomial in z, so those
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
//! one narrower if `R` is not a multiple; `ε(r) = 1 − V_solid / V_annulus`.
//! Coordination counts the particles whose surfaces are within `gap` of each other
//! (GJK distance for polyhedra). The pellet axis of a polyhedral particle is its
//! template's z axis (a prism's axis); its angle to the tube's axis is binned by
//! `cos θ` (isotropic orientations are uniform in `cos θ`).

use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use serde::Serialize;

use super::section::{convex_section, disc_disc_area, polygon_area, polygon_disc_area};
use crate::Real;
use crate::geometry::Shape;
use crate::geometry::gjk::{PointShape, gjk};
use crate::world::World;

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
        let turn = UnitQuaternion::rotation_between(&self.axis, &Vector3::z()).unwrap_or_else(
            // Axis along −z: half a turn about x.
            || UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
        );
        Isometry3::from_parts((turn * -self.base.coords).into(), turn)
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
}

/// A particle placed in the bed frame.
enum Body<'a> {
    Polyhedron {
        vertices: Vec<Point3<Real>>,
        edges: &'a [[u32; 2]],
        volume: Real,
    },
    Sphere {
        centre: Point3<Real>,
        radius: Real,
    },
}

impl Body<'_> {
    fn place<'a>(world: &'a World, i: usize, frame: &Isometry3<Real>) -> Body<'a> {
        let p = &world.particles;
        let pose = frame * Isometry3::from_parts(p.position[i].coords.into(), p.orientation[i]);
        match &world.body_types[p.body_type[i] as usize].shape {
            Shape::Polyhedron(poly) => Body::Polyhedron {
                vertices: poly.vertices().iter().map(|v| pose * v).collect(),
                edges: poly.edges(),
                volume: poly.volume(),
            },
            Shape::Sphere(s) => Body::Sphere {
                centre: pose * Point3::origin(),
                radius: s.radius,
            },
        }
    }

    fn z_range(&self) -> (Real, Real) {
        match self {
            Body::Polyhedron { vertices, .. } => vertices
                .iter()
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v.z), hi.max(v.z))
                }),
            Body::Sphere { centre, radius } => (centre.z - radius, centre.z + radius),
        }
    }

    fn volume(&self) -> Real {
        match self {
            Body::Polyhedron { volume, .. } => *volume,
            Body::Sphere { radius, .. } => 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
        }
    }

    /// Heights between which the sections' areas inside the discs of `radii` are
    /// smooth (sorted).
    fn breakpoints(&self, lo: Real, hi: Real, radii: &[Real]) -> Vec<Real> {
        let mut z = vec![lo, hi];
        match self {
            Body::Polyhedron { vertices, .. } => {
                z.extend(vertices.iter().map(|v| v.z).filter(|&z| z > lo && z < hi));
            }
            // Where the section's circle starts or stops meeting a radial circle
            // (section radius |δ − r| or δ + r, δ the centre's distance from the
            // axis), the lens area has a kink: split there.
            Body::Sphere { centre, radius } => {
                let delta = centre.x.hypot(centre.y);
                for &r in radii {
                    for s in [(delta - r).abs(), delta + r] {
                        if s < *radius {
                            let h = (radius * radius - s * s).sqrt();
                            z.extend(
                                [centre.z - h, centre.z + h]
                                    .into_iter()
                                    .filter(|&z| z > lo && z < hi),
                            );
                        }
                    }
                }
            }
        }
        z.sort_by(Real::total_cmp);
        z.dedup();
        z
    }

    /// Adds `weight` × (area of the section at `z` inside each disc of `radii`).
    fn add_section_areas(&self, z: Real, radii: &[Real], weight: Real, out: &mut [Real]) {
        match self {
            Body::Polyhedron {
                vertices, edges, ..
            } => {
                let poly = convex_section(vertices, edges, z);
                if poly.is_empty() {
                    return;
                }
                let full = polygon_area(&poly);
                let reach = poly.iter().map(|p| p[0].hypot(p[1])).fold(0.0, Real::max);
                for (o, &r) in out.iter_mut().zip(radii) {
                    *o += weight
                        * if r >= reach {
                            full
                        } else {
                            polygon_disc_area(&poly, r)
                        };
                }
            }
            Body::Sphere { centre, radius } => {
                let s2 = radius * radius - (z - centre.z).powi(2);
                if s2 <= 0.0 {
                    return;
                }
                for (o, &r) in out.iter_mut().zip(radii) {
                    *o += weight * disc_disc_area([centre.x, centre.y], s2.sqrt(), r);
                }
            }
        }
    }

    /// Volumes inside each disc of `radii` between heights `lo` and `hi`, and the
    /// estimated quadrature error.
    fn clipped_volumes(&self, lo: Real, hi: Real, radii: &[Real]) -> (Vec<Real>, Real) {
        let mut out = vec![0.0; radii.len()];
        let (zmin, zmax) = self.z_range();
        let (lo, hi) = (lo.max(zmin), hi.min(zmax));
        if !(hi > lo) {
            return (out, 0.0);
        }
        let tolerance = 1e-9 * self.volume() / (zmax - zmin);
        let mut error = 0.0;
        let z = self.breakpoints(lo, hi, radii);
        let q = Quadrature {
            radii,
            tolerance,
            depth: 0,
        };
        for w in z.windows(2) {
            let whole = self.gauss(w[0], w[1], radii);
            error += self.adapt((w[0], w[1]), whole, &q, &mut out);
        }
        (out, error)
    }

    fn gauss(&self, lo: Real, hi: Real, radii: &[Real]) -> Vec<Real> {
        const NODES: [Real; 5] = [
            0.0,
            -0.538_469_310_105_683_1,
            0.538_469_310_105_683_1,
            -0.906_179_845_938_664,
            0.906_179_845_938_664,
        ];
        const WEIGHTS: [Real; 5] = [
            0.568_888_888_888_888_9,
            0.478_628_670_499_366_5,
            0.478_628_670_499_366_5,
            0.236_926_885_056_189_1,
            0.236_926_885_056_189_1,
        ];
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let mut out = vec![0.0; radii.len()];
        for (x, w) in NODES.iter().zip(WEIGHTS) {
            self.add_section_areas(mid + half * x, radii, w * half, &mut out);
        }
        out
    }

    /// Adds the integral over [lo, hi] to `out` (`whole`: its 5-point estimate),
    /// halving until the halves agree with the whole; returns the error estimate.
    fn adapt(
        &self,
        span: (Real, Real),
        whole: Vec<Real>,
        q: &Quadrature,
        out: &mut [Real],
    ) -> Real {
        let (lo, hi) = span;
        let mid = 0.5 * (lo + hi);
        let (left, right) = (self.gauss(lo, mid, q.radii), self.gauss(mid, hi, q.radii));
        let diff = whole
            .iter()
            .zip(left.iter().zip(&right))
            .map(|(w, (l, r))| (l + r - w).abs())
            .fold(0.0, Real::max);
        if diff <= q.tolerance * (hi - lo) || q.depth >= 20 {
            for (o, (l, r)) in out.iter_mut().zip(left.iter().zip(&right)) {
                *o += l + r;
            }
            return diff;
        }
        let deeper = Quadrature {
            depth: q.depth + 1,
            ..*q
        };
        self.adapt((lo, mid), left, &deeper, out) + self.adapt((mid, hi), right, &deeper, out)
    }
}

/// What an adaptive integration is after: the discs, the tolerance per unit of
/// height, and how often the interval was halved already.
#[derive(Clone, Copy)]
struct Quadrature<'a> {
    radii: &'a [Real],
    tolerance: Real,
    depth: usize,
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
    bodies: Vec<Body<'a>>,
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
        Ok(Placed {
            bodies: (0..world.particles.len())
                .filter(|&i| keep(i))
                .map(|i| Body::place(world, i, &frame))
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
                *v += b.clipped_volumes(z.0, z.1, &[self.tube.radius]).0[0];
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

    /// Solid volume inside each disc of `radii` between `z0` and `z1`, and the
    /// estimated quadrature error.
    fn volumes(&self, z0: Real, z1: Real, radii: &[Real]) -> (Vec<Real>, Real) {
        let mut inside = vec![0.0; radii.len()];
        let mut error = 0.0;
        for b in &self.bodies {
            let (v, e) = b.clipped_volumes(z0, z1, radii);
            error += e;
            for (acc, x) in inside.iter_mut().zip(v) {
                *acc += x;
            }
        }
        (inside, error)
    }
}

/// Bed height and bed-averaged porosity only (no profiles, coordination or
/// orientations): cheap enough to follow a bed while it is being tapped.
pub fn bed_figures(world: &World, bed: &Bed) -> Result<(Real, Real), String> {
    let placed = Placed::new(world, bed, |_| true)?;
    let (_, height) = placed.axial();
    let (z0, z1) = placed.region(height, bed.options.region)?;
    let (v, _) = placed.volumes(z0, z1, &[placed.tube.radius]);
    Ok((height, 1.0 - v[0] / (placed.area() * (z1 - z0))))
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
    let from = last.map_or(Real::NEG_INFINITY, |h| {
        h - FEED_WINDOW * largest_diameter(world)
    });
    let placed = Placed::new(world, bed, |i| {
        member.get(i) == Some(&true) && bed.tube.top_of(world, i) > from
    })?;
    Ok(placed.axial_above(from).1)
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
    let bins = (radius / bin).ceil() as usize;
    let radii: Vec<Real> = (1..=bins).map(|k| (k as Real * bin).min(radius)).collect();
    let (inside, volume_error) = placed.volumes(z0, z1, &radii);
    let height = z1 - z0;
    let mut radial = Vec::with_capacity(bins);
    let mut previous = (0.0, 0.0);
    for (k, &r) in radii.iter().enumerate() {
        let annulus = std::f64::consts::PI * (r * r - previous.0 * previous.0) * height;
        radial.push(RadialBin {
            r_inner: previous.0,
            r_outer: r,
            porosity: 1.0 - (inside[k] - previous.1) / annulus,
        });
        previous = (r, inside[k]);
    }
    let solid_volume = inside.last().copied().unwrap_or(0.0);
    let d = placed.diameter;
    let (coordination_mean, coordination) =
        coordination(world, bed.options.gap.unwrap_or(d / 1000.0));
    let (orientation_cos, orientation_order) = orientations(world, &placed.tube.axis);
    let slice = placed.slice;
    Ok(Packing {
        particles: world.particles.len(),
        diameter: d,
        tube_radius: radius,
        tube_to_particle: 2.0 * radius / d,
        bed_height,
        region: [z0, z1],
        porosity: 1.0 - solid_volume / (placed.area() * height),
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
    })
}

/// Contacts per particle: surfaces within `gap` (a cell grid on the centres finds
/// the candidates).
fn coordination(world: &World, gap: Real) -> (Real, Vec<usize>) {
    let p = &world.particles;
    let n = p.len();
    let reach = |i: usize| {
        world.body_types[p.body_type[i] as usize]
            .shape
            .circumradius()
    };
    let cell = 2.0 * (0..n).map(reach).fold(0.0, Real::max) + gap;
    let key = |x: &Point3<Real>| {
        [
            (x.x / cell).floor() as i64,
            (x.y / cell).floor() as i64,
            (x.z / cell).floor() as i64,
        ]
    };
    let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
    for i in 0..n {
        grid.entry(key(&p.position[i])).or_default().push(i);
    }
    let mut count = vec![0usize; n];
    for i in 0..n {
        let k = key(&p.position[i]);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                        continue;
                    };
                    for &j in list.iter().filter(|&&j| j > i) {
                        if (p.position[j] - p.position[i]).norm() > reach(i) + reach(j) + gap {
                            continue;
                        }
                        if surface_distance(world, i, j) <= gap {
                            count[i] += 1;
                            count[j] += 1;
                        }
                    }
                }
            }
        }
    }
    let mean = count.iter().sum::<usize>() as Real / n.max(1) as Real;
    let mut histogram = vec![0usize; count.iter().max().map_or(0, |m| m + 1)];
    for c in count {
        histogram[c] += 1;
    }
    (mean, histogram)
}

/// Distance between the surfaces of particles `i` and `j` (0 when they overlap).
fn surface_distance(world: &World, i: usize, j: usize) -> Real {
    let p = &world.particles;
    let shape = |k: usize| &world.body_types[p.body_type[k] as usize].shape;
    let pose = |k: usize| Isometry3::from_parts(p.position[k].coords.into(), p.orientation[k]);
    let j_in_i = pose(i).inverse() * pose(j);
    match (shape(i), shape(j)) {
        (Shape::Sphere(a), Shape::Sphere(b)) => {
            ((p.position[j] - p.position[i]).norm() - a.radius - b.radius).max(0.0)
        }
        (Shape::Polyhedron(a), Shape::Polyhedron(b)) => gjk(&**a, &**b, &j_in_i, None).distance(),
        (Shape::Polyhedron(a), Shape::Sphere(s)) => {
            let centre = PointShape(Point3::origin());
            (gjk(&**a, &centre, &j_in_i, None).distance() - s.radius).max(0.0)
        }
        (Shape::Sphere(s), Shape::Polyhedron(b)) => {
            let centre = PointShape(Point3::origin());
            (gjk(&**b, &centre, &j_in_i.inverse(), None).distance() - s.radius).max(0.0)
        }
    }
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
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::geometry::Sphere;
    use crate::geometry::generators::cuboid;
    use crate::world::BodyType;
    use std::f64::consts::PI;
    use std::sync::Arc;

    fn world_of(shape: Shape, placements: &[(Point3<Real>, UnitQuaternion<Real>)]) -> World {
        let material = Material {
            name: "m".into(),
            density: 1000.0,
            young: 1e6,
            poisson: 0.3,
            restitution: 0.5,
            friction: 0.0,
        };
        let mut world = World {
            materials: vec![material.clone()],
            body_types: vec![BodyType::new(shape, &material, 0)],
            ..World::default()
        };
        for (k, (x, q)) in placements.iter().enumerate() {
            world.particles.push(0, *x, *q, k as u64);
        }
        world
    }

    fn tube(radius: Real) -> Tube {
        Tube {
            base: Point3::new(0.3, -0.2, 0.0),
            axis: Vector3::z(),
            radius,
        }
    }

    /// Volume of a sphere of radius a (centred on the axis) inside the cylinder ρ ≤ r.
    fn sphere_in_cylinder(a: Real, r: Real) -> Real {
        4.0 / 3.0 * PI * (a.powi(3) - (a * a - r * r).max(0.0).powf(1.5))
    }

    #[test]
    fn a_column_of_spheres_has_its_closed_form_profile() {
        let a = 1.0;
        let t = tube(1.5);
        let column: Vec<_> = (0..5)
            .map(|k| {
                let z = (2 * k + 1) as Real * a;
                (Point3::new(0.3, -0.2, z), UnitQuaternion::identity())
            })
            .collect();
        let world = world_of(Shape::Sphere(Sphere::new(a).unwrap()), &column);
        // The region holds the three middle spheres whole; bins of 0.13 cut them.
        let options = PackingOptions {
            bin: Some(0.13),
            region: Some((2.0, 8.0)),
            ..Default::default()
        };
        let p = analyse(&world, &Bed { tube: t, options }).unwrap();
        assert!((p.porosity - (1.0 - 4.0 / (6.0 * 2.25))).abs() < 1e-12);
        for b in &p.radial {
            let solid = 3.0 * (sphere_in_cylinder(a, b.r_outer) - sphere_in_cylinder(a, b.r_inner));
            let annulus = PI * (b.r_outer.powi(2) - b.r_inner.powi(2)) * 6.0;
            assert!(
                (1.0 - b.porosity - solid / annulus).abs() < 1e-8,
                "{b:?}: {}",
                solid / annulus
            );
        }
        assert_eq!(p.radial.len(), 12);
        assert!((p.radial[11].r_outer - 1.5).abs() < 1e-15);
        assert!(p.radial[11].porosity == 1.0, "beyond the spheres");
        // Touching spheres: the ends have one neighbour, the others two.
        assert_eq!(p.coordination, vec![0, 2, 3]);
        assert!(p.orientation_order.is_none());
        // Five spheres stacked, 10 high: the height ends where the top sphere's
        // section falls below half the column's median section, 0.2 below its pole
        // in slices of d/10 = 0.2.
        assert!((p.bed_height - 9.8).abs() < 1e-9, "{}", p.bed_height);
    }

    #[test]
    fn a_column_of_turned_cubes_has_its_closed_form_profile() {
        let s = 1.0;
        let cube = Arc::new(cuboid(s, s, s).unwrap());
        let t = tube(0.9);
        // Four cubes face to face, each turned about the axis by its own angle: the
        // part of a square inside a centred disc does not depend on the turn.
        let column: Vec<_> = (0..4)
            .map(|k| {
                (
                    Point3::new(0.3, -0.2, 0.5 + k as Real),
                    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.4 * k as Real),
                )
            })
            .collect();
        let world = world_of(Shape::Polyhedron(cube), &column);
        // The region cuts the first and last cube: 0.25 … 3.6.
        let options = PackingOptions {
            bin: Some(0.07),
            slice: Some(0.1),
            region: Some((0.25, 3.6)),
            ..Default::default()
        };
        let p = analyse(&world, &Bed { tube: t, options }).unwrap();
        let height = 3.35;
        // Square of half-side h = 0.5 inside a disc of radius r (r ≤ h√2).
        let square_in_disc = |r: Real| {
            let h = 0.5 * s;
            if r <= h {
                PI * r * r
            } else if r >= h * 2f64.sqrt() {
                s * s
            } else {
                let half = (h / r).acos();
                PI * r * r - 4.0 * r * r * (half - half.sin() * half.cos())
            }
        };
        let porosity = 1.0 - s * s * height / (PI * 0.81 * height);
        assert!((p.porosity - porosity).abs() < 1e-12, "{}", p.porosity);
        for b in &p.radial {
            let solid = (square_in_disc(b.r_outer) - square_in_disc(b.r_inner)) * height;
            let annulus = PI * (b.r_outer.powi(2) - b.r_inner.powi(2)) * height;
            assert!((1.0 - b.porosity - solid / annulus).abs() < 1e-8, "{b:?}");
        }
        // The area-weighted profile is the bed average.
        let weighted: Real = p
            .radial
            .iter()
            .map(|b| b.porosity * (b.r_outer.powi(2) - b.r_inner.powi(2)))
            .sum::<Real>()
            / 0.81;
        assert!((weighted - p.porosity).abs() < 1e-12);
        // Face-to-face neighbours; axes along the tube.
        assert_eq!(p.coordination, vec![0, 2, 2]);
        assert_eq!(p.orientation_cos[9], 4);
        assert!((p.orientation_order.unwrap() - 1.0).abs() < 1e-12);
        assert!((p.bed_height - 4.0).abs() < 1e-9);
        // The axial profile: one cube's cross-section in every slice below 4.
        for slice in &p.axial {
            assert!((slice.porosity - (1.0 - 1.0 / (PI * 0.81))).abs() < 1e-12);
        }
    }

    #[test]
    fn tilted_cubes_are_integrated_exactly_where_the_disc_does_not_cut() {
        let cube = Arc::new(cuboid(1.0, 1.0, 1.0).unwrap());
        let q = UnitQuaternion::from_euler_angles(0.3, 0.7, 1.1);
        let world = world_of(
            Shape::Polyhedron(cube),
            &[
                (Point3::new(0.3, -0.2, 2.0), q),
                (Point3::new(0.3, -0.2, 3.9), q),
            ],
        );
        // A tube wide enough that no disc cuts a cube: whole volumes, to round-off.
        let options = PackingOptions {
            bin: Some(1.0),
            region: Some((0.0, 6.0)),
            ..Default::default()
        };
        let p = analyse(
            &world,
            &Bed {
                tube: tube(3.0),
                options,
            },
        )
        .unwrap();
        assert!((p.solid_volume - 2.0).abs() < 1e-13, "{}", p.solid_volume);
    }

    #[test]
    fn a_random_bed_profile_integrates_to_its_average() {
        // Randomly turned cubes at random places in a tube: bins cut them every way.
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let cube = Arc::new(cuboid(0.3, 0.2, 0.25).unwrap());
        // Circumscribed spheres apart, so the cubes never overlap.
        let mut placements: Vec<(Point3<Real>, UnitQuaternion<Real>)> = Vec::new();
        while placements.len() < 40 {
            let (x, y): (Real, Real) = (rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5));
            let c = Point3::new(0.3 + x, -0.2 + y, rng.random_range(0.3..3.0));
            if placements.iter().all(|(o, _)| (o - c).norm() > 0.425) {
                let axis = Vector3::new(rng.random(), rng.random(), rng.random());
                placements.push((c, UnitQuaternion::from_scaled_axis(axis * 3.0)));
            }
        }
        let world = world_of(Shape::Polyhedron(cube), &placements);
        let options = PackingOptions {
            bin: Some(0.05),
            region: Some((0.5, 2.5)),
            ..Default::default()
        };
        let p = analyse(
            &world,
            &Bed {
                tube: tube(1.0),
                options,
            },
        )
        .unwrap();
        let weighted: Real = p
            .radial
            .iter()
            .map(|b| b.porosity * (b.r_outer.powi(2) - b.r_inner.powi(2)))
            .sum();
        assert!((weighted - p.porosity).abs() < 1e-12);
        assert!(p.volume_error < 1e-9 * p.solid_volume, "{}", p.volume_error);
        // Against midpoint sampling of the region on a fine grid.
        let solid = |x: &Point3<Real>| {
            placements.iter().any(|(c, q)| {
                let local = q.inverse() * (x - c);
                local.x.abs() <= 0.15 && local.y.abs() <= 0.1 && local.z.abs() <= 0.125
            })
        };
        let n = 120;
        let (mut hits, mut total) = (0usize, 0usize);
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let (x, y) = (
                        -1.0 + 2.0 * (i as Real + 0.5) / n as Real,
                        -1.0 + 2.0 * (j as Real + 0.5) / n as Real,
                    );
                    if x * x + y * y > 1.0 {
                        continue;
                    }
                    total += 1;
                    let z = 0.5 + 2.0 * (k as Real + 0.5) / n as Real;
                    if solid(&Point3::new(0.3 + x, -0.2 + y, z)) {
                        hits += 1;
                    }
                }
            }
        }
        let sampled = 1.0 - hits as Real / total as Real;
        assert!(
            (sampled - p.porosity).abs() < 3e-3,
            "{sampled} {}",
            p.porosity
        );
    }
}
