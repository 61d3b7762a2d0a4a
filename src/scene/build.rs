//! From the scene as written to a validated [`Scene`]: materials, shapes, body types,
//! walls, particles and inlets, each problem reported with its field.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use nalgebra::{Point3, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_pcg::Pcg64;

use super::error::{FieldError, FieldPath};
use super::spec::*;
use crate::Real;
use crate::contact::Material;
use crate::geometry::surfaces::{self, Surface};
use crate::geometry::{Shape, mesh_io};
use crate::world::{BodyType, Inlet, Wall, WallMotion, World, random_orientation};

type Result<T> = std::result::Result<T, FieldError>;

/// What the builder produces besides the world.
pub(super) struct Built {
    pub world: World,
    pub inlets: Vec<Inlet>,
    pub next_id: u64,
    /// The shape name of each body type.
    pub shape_names: Vec<String>,
}

/// The most worker threads a scene or the Component's `threads` parameter may ask for.
pub const MAX_THREADS: usize = 1024;

/// The most sites a lattice may have: ten million particles is beyond what one
/// process steps in a day, and counting the sites of a box of kilometres would spin.
pub const MAX_LATTICE_SITES: usize = 10_000_000;

/// The most particles one inlet may insert.
pub const MAX_INLET_COUNT: usize = 100_000_000;

pub(super) fn finite(path: FieldPath, values: &[Real]) -> Result<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(FieldError::new(path, "must be finite"))
    }
}

pub(super) fn positive(path: FieldPath, value: Real) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(FieldError::new(path, format!("{value} must be positive")))
    }
}

/// The unit vector along `v`, which must be finite and non-zero.
pub(super) fn direction(path: FieldPath, v: &[Real; 3]) -> Result<Vector3<Real>> {
    let v = Vector3::from(*v);
    if v.norm() > 0.0 && v.norm().is_finite() {
        Ok(v.normalize())
    } else {
        Err(FieldError::new(path, "must be a non-zero vector"))
    }
}

fn lookup<'a, T>(
    map: &'a BTreeMap<String, T>,
    name: &str,
    what: &str,
    path: FieldPath,
) -> Result<(usize, &'a T)> {
    map.iter()
        .enumerate()
        .find(|(_, (k, _))| k.as_str() == name)
        .map(|(i, (_, v))| (i, v))
        .ok_or_else(|| {
            let known: Vec<&str> = map.keys().map(String::as_str).collect();
            FieldError::new(
                path,
                format!(
                    "unknown {what} '{name}' (defined: {})",
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        })
}

pub(super) struct Builder<'a> {
    spec: &'a SceneSpec,
    dir: &'a Path,
    shapes: Vec<Shape>,
    body_types: BTreeMap<(usize, usize), u32>,
    world: World,
}

impl<'a> Builder<'a> {
    pub fn new(spec: &'a SceneSpec, dir: &'a Path) -> Self {
        Builder {
            spec,
            dir,
            shapes: Vec::new(),
            body_types: BTreeMap::new(),
            world: World::default(),
        }
    }

    pub fn build(mut self) -> Result<Built> {
        let sim = &self.spec.simulation;
        finite(FieldPath::root("simulation").key("gravity"), &sim.gravity)?;
        if sim.threads > MAX_THREADS {
            return Err(FieldError::new(
                FieldPath::root("simulation").key("threads"),
                format!(
                    "{} threads; give 0 (all cores) to {MAX_THREADS}",
                    sim.threads
                ),
            ));
        }
        self.world.gravity = sim.gravity.into();
        self.materials()?;
        self.shapes()?;
        let mut next_id = 0;
        let mut rng = Pcg64::seed_from_u64(sim.seed);
        for (g, group) in self.spec.particles.iter().enumerate() {
            self.particle_group(g, group, &mut rng, &mut next_id)?;
        }
        let mut inlets = Vec::new();
        for (k, inlet) in self.spec.inlets.iter().enumerate() {
            inlets.push(self.inlet(k, inlet)?);
        }
        // Walls last: their facet grids are sized by the largest particle.
        let cell = self.largest_diameter();
        let mut names = std::collections::BTreeSet::new();
        for (k, w) in self.spec.walls.iter().enumerate() {
            let path = FieldPath::root("wall").index(k);
            if !names.insert(w.name.as_str()) {
                return Err(FieldError::new(
                    path.key("name"),
                    format!("wall name '{}' is used twice", w.name),
                ));
            }
            let wall = self.wall(&path, w, cell)?;
            self.world.walls.push(wall);
        }
        if let Some(fluid) = &self.spec.fluid {
            self.world.fluid = Some(super::fluid::build_fluid(fluid, &self.world, self.dir)?);
        }
        let names: Vec<&String> = self.spec.shapes.keys().collect();
        let mut shape_names = vec![String::new(); self.world.body_types.len()];
        for (&(shape, _), &t) in &self.body_types {
            shape_names[t as usize] = names[shape].clone();
        }
        Ok(Built {
            world: self.world,
            shape_names,
            inlets,
            next_id,
        })
    }

    fn largest_diameter(&self) -> Real {
        let d = self
            .world
            .body_types
            .iter()
            .map(|t| 2.0 * t.shape.circumradius())
            .fold(0.0, Real::max);
        if d > 0.0 { d } else { 1.0 }
    }

    fn materials(&mut self) -> Result<()> {
        if self.spec.materials.is_empty() {
            return Err(FieldError::new(
                FieldPath::root("materials"),
                "at least one material is needed",
            ));
        }
        for (name, m) in &self.spec.materials {
            let material = Material {
                name: name.clone(),
                density: m.density,
                young: m.young,
                poisson: m.poisson,
                restitution: m.restitution,
                friction: m.friction,
                rolling_friction: m.rolling_friction,
                rolling_damping: m.rolling_damping,
            };
            material.validate().map_err(|e| {
                let crate::contact::MaterialError::Invalid { field, .. } = &e;
                FieldError::new(
                    FieldPath::root("materials").key(name).key(field),
                    e.to_string(),
                )
            })?;
            self.world.materials.push(material);
        }
        Ok(())
    }

    /// Builds each shape table; tables that say the same (a generated scene that
    /// names one shape per particle group, say) share one template, so that the
    /// pair stage reads it from the caches and the time step and the laws' rows see
    /// it once. A spec is known by its `Debug` text, in which a number reads back as
    /// the same bits.
    fn shapes(&mut self) -> Result<()> {
        let mut built: HashMap<String, usize> = HashMap::new();
        for (name, spec) in &self.spec.shapes {
            let key = format!("{spec:?}");
            if let Some(&s) = built.get(&key) {
                self.shapes.push(self.shapes[s].clone());
                continue;
            }
            let shape = spec
                .build(self.dir)
                .map_err(|e| FieldError::new(FieldPath::root("shapes").key(name), e.to_string()))?;
            built.insert(key, self.shapes.len());
            self.shapes.push(shape);
        }
        Ok(())
    }

    /// The body type of (shape, material), created on first use.
    fn body_type(&mut self, path: &FieldPath, shape: &str, material: &str) -> Result<u32> {
        let (s, _) = lookup(&self.spec.shapes, shape, "shape", path.key("shape"))?;
        let (m, _) = lookup(
            &self.spec.materials,
            material,
            "material",
            path.key("material"),
        )?;
        if let Some(&t) = self.body_types.get(&(s, m)) {
            return Ok(t);
        }
        let t = self.world.body_types.len() as u32;
        self.world.body_types.push(BodyType::new(
            self.shapes[s].clone(),
            &self.world.materials[m],
            m,
        ));
        self.body_types.insert((s, m), t);
        Ok(t)
    }

    /// Orientation of a particle whose shape is turned by `r` from how it was given.
    fn orientation(&self, body_type: u32, r: UnitQuaternion<Real>) -> UnitQuaternion<Real> {
        match &self.world.body_types[body_type as usize].shape {
            Shape::Polyhedron(p) => r * p.body_to_input().rotation,
            Shape::Sphere(_) => r,
        }
    }

    fn particle_group(
        &mut self,
        g: usize,
        group: &ParticleGroupSpec,
        rng: &mut Pcg64,
        next_id: &mut u64,
    ) -> Result<()> {
        let path = FieldPath::root("particles").index(g);
        match group {
            ParticleGroupSpec::Lattice {
                shape,
                material,
                min,
                max,
                spacing,
                count,
                random_orientation: random,
                velocity,
                inside,
            } => {
                let t = self.body_type(&path, shape, material)?;
                finite(path.key("min"), min)?;
                finite(path.key("max"), max)?;
                finite(path.key("velocity"), velocity)?;
                let r = self.world.body_types[t as usize].shape.circumradius();
                let a = spacing.unwrap_or(2.1 * r);
                positive(path.key("spacing"), a)?;
                // Sites per axis, counted in floats: a box of 1e9 m must not wrap.
                let n: Vec<Real> = (0..3)
                    .map(|k| {
                        let span = max[k] - min[k] - 2.0 * r;
                        if span < 0.0 {
                            0.0
                        } else {
                            (span / a).floor() + 1.0
                        }
                    })
                    .collect();
                let sites: Real = n.iter().product();
                if sites > MAX_LATTICE_SITES as Real {
                    return Err(FieldError::new(
                        path.key("max"),
                        format!(
                            "the lattice would have {sites:.3e} sites ({} × {} × {} at spacing {a:.3e} m); \
                             at most {MAX_LATTICE_SITES:.0e}",
                            n[0], n[1], n[2]
                        ),
                    ));
                }
                let n: Vec<usize> = n.iter().map(|&k| k as usize).collect();
                if n.contains(&0) {
                    return Err(FieldError::new(
                        path.key("max"),
                        format!(
                            "the box is smaller than one particle (circumscribed diameter {})",
                            2.0 * r
                        ),
                    ));
                }
                let keep = match inside {
                    Some(c) => Some(self.cylinder_region(&path.key("inside"), c, r)?),
                    None => None,
                };
                let limit = count.unwrap_or(usize::MAX);
                let mut placed = 0;
                'fill: for z in 0..n[2] {
                    for y in 0..n[1] {
                        for x in 0..n[0] {
                            if placed >= limit {
                                break 'fill;
                            }
                            let pos = Point3::new(
                                min[0] + r + a * x as Real,
                                min[1] + r + a * y as Real,
                                min[2] + r + a * z as Real,
                            );
                            if keep.as_ref().is_some_and(|k| !k.contains(&pos)) {
                                continue;
                            }
                            let q = if *random {
                                random_orientation(rng)
                            } else {
                                self.orientation(t, UnitQuaternion::identity())
                            };
                            self.push(
                                t,
                                pos,
                                q,
                                Vector3::from(*velocity),
                                Vector3::zeros(),
                                next_id,
                            );
                            placed += 1;
                        }
                    }
                }
                if let Some(c) = count
                    && placed < *c
                {
                    return Err(FieldError::new(
                        path.key("count"),
                        format!("only {placed} particles fit in the box at spacing {a}"),
                    ));
                }
            }
            ParticleGroupSpec::List {
                shape,
                material,
                bodies,
            } => {
                let t = self.body_type(&path, shape, material)?;
                for (b, body) in bodies.iter().enumerate() {
                    let bp = path.key("bodies").index(b);
                    for (field, v) in [
                        ("position", &body.position),
                        ("rotation", &body.rotation),
                        ("velocity", &body.velocity),
                        ("angular_velocity", &body.angular_velocity),
                    ] {
                        finite(bp.key(field), v)?;
                    }
                    let q = self.orientation(
                        t,
                        UnitQuaternion::from_scaled_axis(Vector3::from(body.rotation)),
                    );
                    self.push(
                        t,
                        body.position.into(),
                        q,
                        body.velocity.into(),
                        body.angular_velocity.into(),
                        next_id,
                    );
                }
            }
            ParticleGroupSpec::File {
                shape,
                material,
                file,
            } => {
                let t = self.body_type(&path, shape, material)?;
                let full = self.dir.join(file);
                let poses = super::poses::read_poses(&full)
                    .map_err(|e| FieldError::new(path.key("file"), e))?;
                for pose in poses {
                    self.push(
                        t,
                        pose.position,
                        pose.orientation,
                        pose.velocity,
                        pose.angular_velocity,
                        next_id,
                    );
                }
            }
        }
        Ok(())
    }

    fn cylinder_region(
        &self,
        path: &FieldPath,
        c: &CylinderRegionSpec,
        particle_radius: Real,
    ) -> Result<CylinderRegion> {
        finite(path.key("centre"), &c.centre)?;
        finite(path.key("axis"), &c.axis)?;
        positive(path.key("radius"), c.radius)?;
        let axis = direction(path.key("axis"), &c.axis)?;
        if !(c.fill > 0.0 && c.fill <= 1.0) {
            return Err(FieldError::new(
                path.key("fill"),
                format!("{} is not in (0, 1]", c.fill),
            ));
        }
        // "Down" is gravity across the axis; without gravity, any fill below 1 has no
        // bottom to start from.
        let g = self.world.gravity - axis * axis.dot(&self.world.gravity);
        if c.fill < 1.0 && !(g.norm() > 0.0) {
            return Err(FieldError::new(
                path.key("fill"),
                "needs gravity across the cylinder's axis to tell its bottom",
            ));
        }
        Ok(CylinderRegion {
            centre: Point3::from(c.centre),
            axis,
            inner: c.radius - particle_radius,
            down: if g.norm() > 0.0 {
                g.normalize()
            } else {
                Vector3::zeros()
            },
            // Height of the fill line above the centre, from the segment's area.
            level: c.radius * segment_level(c.fill),
        })
    }

    fn push(
        &mut self,
        t: u32,
        x: Point3<Real>,
        q: UnitQuaternion<Real>,
        v: Vector3<Real>,
        w: Vector3<Real>,
        next_id: &mut u64,
    ) {
        let p = &mut self.world.particles;
        p.push(t, x, q, *next_id);
        *next_id += 1;
        let last = p.len() - 1;
        p.velocity[last] = v;
        // Angular momentum L = R I Rᵀ ω.
        let inertia = self.world.body_types[t as usize].inertia;
        p.angular_momentum[last] = q * q.inverse_transform_vector(&w).component_mul(&inertia);
    }

    fn inlet(&mut self, k: usize, spec: &InletSpec) -> Result<Inlet> {
        let path = FieldPath::root("inlet").index(k);
        let t = self.body_type(&path, &spec.shape, &spec.material)?;
        finite(path.key("min"), &spec.min)?;
        finite(path.key("max"), &spec.max)?;
        finite(path.key("velocity"), &spec.velocity)?;
        positive(path.key("rate"), spec.rate)?;
        if spec.count > MAX_INLET_COUNT {
            return Err(FieldError::new(
                path.key("count"),
                format!(
                    "{} particles; an inlet inserts at most {MAX_INLET_COUNT:.0e}",
                    spec.count
                ),
            ));
        }
        if let Some(h) = spec.bed_height {
            positive(path.key("bed_height"), h)?;
        }
        for (key, used) in [
            ("bed_height", spec.bed_height.is_some()),
            ("above_bed", spec.above_bed),
        ] {
            if used && self.spec.bed.is_none() {
                return Err(FieldError::new(
                    path.key(key),
                    "needs a [bed] section: the bed height is measured in its tube",
                ));
            }
        }
        let r = self.world.body_types[t as usize].shape.circumradius();
        for i in 0..3 {
            if spec.max[i] - spec.min[i] < 2.0 * r {
                return Err(FieldError::new(
                    path.key("max"),
                    format!(
                        "the insertion box is narrower than one particle (circumscribed diameter {})",
                        2.0 * r
                    ),
                ));
            }
        }
        let mut inlet = Inlet::new(
            t,
            spec.min.into(),
            spec.max.into(),
            spec.rate,
            spec.count,
            spec.velocity.into(),
            spec.start,
            self.spec.simulation.seed.wrapping_add(1 + k as u64),
        );
        inlet.stop_height = spec.bed_height;
        inlet.above_bed = spec.above_bed;
        Ok(inlet)
    }

    fn wall(&self, path: &FieldPath, w: &WallSpec, cell: Real) -> Result<Wall> {
        let (material, _) = lookup(
            &self.spec.materials,
            &w.material,
            "material",
            path.key("material"),
        )?;
        if let Some(r) = &w.reference {
            finite(path.key("reference"), r)?;
        }
        let gpath = path.key("geometry");
        let surface = self.surface(&gpath, &w.geometry)?;
        if surface.triangles.is_empty() {
            return Err(FieldError::new(gpath, "the wall has no facets"));
        }
        if let MotionSpec::Attached { to } = &w.motion {
            let mpath = path.key("motion").key("to");
            let Some(k) = self.world.walls.iter().position(|l| &l.name == to) else {
                return Err(FieldError::new(
                    mpath,
                    format!("no wall named '{to}' is listed before this one"),
                ));
            };
            if w.reference.is_some() {
                return Err(FieldError::new(
                    path.key("reference"),
                    "an attached wall shares its leader's reference point",
                ));
            }
            let leader = &self.world.walls[k];
            let mut wall = Wall::new(&w.name, material, surface.vertices, surface.triangles, cell)
                .with_reference(leader.reference());
            wall.motion = WallMotion::Attached(k);
            wall.pose = leader.pose;
            wall.velocity = leader.velocity;
            wall.angular_velocity = leader.angular_velocity;
            return Ok(wall);
        }
        let (motion, pivot) = motion(&path.key("motion"), &w.motion)?;
        let reference = match (w.reference, pivot) {
            (Some(r), Some(p)) if (Vector3::from(r) - p.coords).norm() > 0.0 => {
                return Err(FieldError::new(
                    path.key("reference"),
                    "a rotating wall turns about its reference point: give the rotation's point only",
                ));
            }
            (Some(r), _) => Point3::from(r),
            (None, Some(p)) => p,
            (None, None) => Point3::origin(),
        };
        Ok(
            Wall::new(&w.name, material, surface.vertices, surface.triangles, cell)
                .with_reference(reference)
                .with_motion(motion),
        )
    }

    fn surface(&self, path: &FieldPath, g: &WallGeometrySpec) -> Result<Surface> {
        for (key, value) in g.points() {
            finite(path.key(key), value)?;
        }
        let err = |e: crate::geometry::GeometryError| FieldError::new(path.clone(), e.to_string());
        let v = |a: &[Real; 3]| Vector3::from(*a);
        let p = |a: &[Real; 3]| Point3::from(*a);
        match g {
            WallGeometrySpec::Mesh { file, scale, flip } => {
                positive(path.key("scale"), *scale)?;
                let mesh = mesh_io::read_mesh(&self.dir.join(file))
                    .map_err(|e| FieldError::new(path.key("file"), e.to_string()))?;
                let s = Surface {
                    vertices: mesh.vertices.iter().map(|x| x * *scale).collect(),
                    triangles: mesh.triangles.iter().map(|t| t.map(|i| i as u32)).collect(),
                };
                Ok(if *flip { s.flipped() } else { s })
            }
            WallGeometrySpec::Plane {
                centre,
                normal,
                size,
            } => surfaces::plane(p(centre), v(normal), *size).map_err(err),
            WallGeometrySpec::Box { min, max, open_top } => {
                surfaces::box_inside(p(min), p(max), *open_top).map_err(err)
            }
            WallGeometrySpec::Disc {
                centre,
                normal,
                radius,
                inner_radius,
                sides,
            } => surfaces::disc(p(centre), v(normal), *radius, *inner_radius, *sides).map_err(err),
            WallGeometrySpec::Cylinder {
                base,
                axis,
                length,
                radius,
                sides,
                segments,
                bottom,
                top,
            } => surfaces::cylinder_inside(
                p(base),
                v(axis),
                *length,
                *radius,
                *sides,
                *segments,
                *bottom,
                *top,
            )
            .map_err(err),
            WallGeometrySpec::Cone {
                base,
                axis,
                length,
                radius_bottom,
                radius_top,
                sides,
                segments,
            } => surfaces::frustum_inside(
                p(base),
                v(axis),
                *length,
                *radius_bottom,
                *radius_top,
                *sides,
                *segments,
            )
            .map_err(err),
        }
    }
}

/// The sites a lattice keeps inside a cylinder.
struct CylinderRegion {
    centre: Point3<Real>,
    axis: Vector3<Real>,
    /// Largest distance of a particle centre from the axis.
    inner: Real,
    /// Unit vector of gravity across the axis.
    down: Vector3<Real>,
    /// Height of the fill line above the axis (against `down`).
    level: Real,
}

impl CylinderRegion {
    fn contains(&self, x: &Point3<Real>) -> bool {
        let d = x - self.centre;
        let radial = d - self.axis * self.axis.dot(&d);
        radial.norm() <= self.inner && -radial.dot(&self.down) <= self.level
    }
}

/// The height `y/R` of the chord below which a circle of unit radius holds the area
/// fraction `fill`: solves `(θ − sin θ)/2π = fill` for the central angle θ by
/// bisection (monotonic), then `y = −cos(θ/2)`.
fn segment_level(fill: Real) -> Real {
    let (mut lo, mut hi) = (0.0, std::f64::consts::TAU);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if (mid - mid.sin()) / std::f64::consts::TAU < fill {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let theta = 0.5 * (lo + hi);
    -(0.5 * theta).cos()
}

/// The wall motion of a spec, and the point a rotation turns about.
fn motion(path: &FieldPath, m: &MotionSpec) -> Result<(WallMotion, Option<Point3<Real>>)> {
    Ok(match m {
        MotionSpec::Fixed => (WallMotion::Fixed, None),
        MotionSpec::Linear { velocity } => {
            finite(path.key("velocity"), velocity)?;
            (
                WallMotion::Constant {
                    velocity: (*velocity).into(),
                    angular_velocity: Vector3::zeros(),
                },
                None,
            )
        }
        MotionSpec::Rotation {
            axis,
            point,
            rpm,
            rate,
        } => {
            finite(path.key("point"), point)?;
            let axis = direction(path.key("axis"), axis)?;
            let rate = match (rpm, rate) {
                (Some(rpm), None) => rpm * std::f64::consts::TAU / 60.0,
                (None, Some(r)) => *r,
                _ => {
                    return Err(FieldError::new(
                        path.clone(),
                        "give exactly one of `rpm` and `rate`",
                    ));
                }
            };
            finite(
                path.key(if rpm.is_some() { "rpm" } else { "rate" }),
                &[rate],
            )?;
            (
                WallMotion::Constant {
                    velocity: Vector3::zeros(),
                    angular_velocity: axis * rate,
                },
                Some(Point3::from(*point)),
            )
        }
        MotionSpec::Oscillation {
            amplitude,
            frequency,
        } => {
            finite(path.key("amplitude"), amplitude)?;
            positive(path.key("frequency"), *frequency)?;
            (
                WallMotion::Oscillation {
                    amplitude: (*amplitude).into(),
                    frequency: *frequency,
                },
                None,
            )
        }
        MotionSpec::Table { keys } => {
            if keys.is_empty() {
                return Err(FieldError::new(path.key("keys"), "needs at least one key"));
            }
            for (k, key) in keys.iter().enumerate() {
                let kp = path.key("keys").index(k);
                finite(kp.key("time"), &[key.time])?;
                finite(kp.key("velocity"), &key.velocity)?;
                finite(kp.key("angular_velocity"), &key.angular_velocity)?;
                if k > 0 && key.time < keys[k - 1].time {
                    return Err(FieldError::new(
                        kp.key("time"),
                        "keys must be in increasing time",
                    ));
                }
            }
            (WallMotion::Table(keys.clone()), None)
        }
        MotionSpec::External { input } => (WallMotion::External(*input), None),
        MotionSpec::Attached { .. } => unreachable!("attached walls are built by Builder::wall"),
    })
}
