//! Generated wall surfaces: planes, boxes, discs, cylinders (tubes and drums) and
//! cones (hoppers).
//!
//! Every surface is a triangle soup oriented for [`super::wall`]: each facet is
//! counter-clockwise seen from the side the particles are on, so `(b − a) × (c − a)`
//! points into the granular space. Curved surfaces are inscribed polygons with
//! vertices on the exact surface; a particle therefore meets the wall no later than it
//! would meet the smooth surface.

use nalgebra::{Point3, Unit, Vector3};

use super::GeometryError;
use crate::Real;

/// A triangulated surface: vertices and facets (indices into the vertices).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surface {
    /// Vertex positions.
    pub vertices: Vec<Point3<Real>>,
    /// Facets, counter-clockwise seen from the particle side.
    pub triangles: Vec<[u32; 3]>,
}

impl Surface {
    /// Appends another surface.
    pub fn append(&mut self, other: Surface) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(other.vertices);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|v| v + base)));
    }

    /// Total facet area.
    pub fn area(&self) -> Real {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// Turns every facet over (the particle side changes).
    pub fn flipped(mut self) -> Surface {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
        self
    }

    fn quad(&mut self, corners: [Point3<Real>; 4]) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(corners);
        self.triangles.push([base, base + 1, base + 2]);
        self.triangles.push([base, base + 2, base + 3]);
    }
}

/// Two unit vectors completing `n` to a right-handed frame (`u × v = n`).
pub fn tangent_frame(n: &Unit<Vector3<Real>>) -> (Vector3<Real>, Vector3<Real>) {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = helper.cross(n).normalize();
    (u, n.cross(&u))
}

fn positive(field: &'static str, value: Real) -> Result<(), GeometryError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(GeometryError::InvalidParameter {
            name: field,
            value,
            reason: "must be positive",
        })
    }
}

fn direction(field: &'static str, v: &Vector3<Real>) -> Result<Unit<Vector3<Real>>, GeometryError> {
    let n = v.norm();
    if n.is_finite() && n > 0.0 {
        Ok(Unit::new_unchecked(v / n))
    } else {
        Err(GeometryError::InvalidParameter {
            name: field,
            value: n,
            reason: "must be a non-zero finite vector",
        })
    }
}

/// The most polygon sides of a generated surface, and the most facets of one: a
/// drum of 120 sides has 480 facets, and ten million facets take a gigabyte before
/// the facet grid.
pub const MAX_SIDES: usize = 100_000;
pub const MAX_FACETS: usize = 10_000_000;

fn sides_ok(sides: usize) -> Result<(), GeometryError> {
    if sides < 3 {
        Err(GeometryError::InvalidParameter {
            name: "sides",
            value: sides as Real,
            reason: "must be at least 3",
        })
    } else if sides > MAX_SIDES {
        Err(GeometryError::InvalidParameter {
            name: "sides",
            value: sides as Real,
            reason: "must be at most 100 000",
        })
    } else {
        Ok(())
    }
}

/// A square patch of edge `size` centred at `centre`, particles on the side `normal`
/// points to.
pub fn plane(
    centre: Point3<Real>,
    normal: Vector3<Real>,
    size: Real,
) -> Result<Surface, GeometryError> {
    positive("size", size)?;
    let n = direction("normal", &normal)?;
    let (u, v) = tangent_frame(&n);
    let h = 0.5 * size;
    let mut s = Surface::default();
    s.quad([
        centre - u * h - v * h,
        centre + u * h - v * h,
        centre + u * h + v * h,
        centre - u * h + v * h,
    ]);
    Ok(s)
}

/// The inside of the axis-aligned box `[min, max]`, optionally without its top
/// (the face at `max.z`).
pub fn box_inside(
    min: Point3<Real>,
    max: Point3<Real>,
    open_top: bool,
) -> Result<Surface, GeometryError> {
    for k in 0..3 {
        positive("max - min", max[k] - min[k])?;
    }
    let (x, y, z) = (
        Vector3::x() * (max.x - min.x),
        Vector3::y() * (max.y - min.y),
        Vector3::z() * (max.z - min.z),
    );
    let mut s = Surface::default();
    // Each face as (corner, u, v) with u × v pointing into the box.
    let mut face = |a: Point3<Real>, u: Vector3<Real>, v: Vector3<Real>| {
        s.quad([a, a + u, a + u + v, a + v]);
    };
    face(min, x, y); // bottom, +z
    if !open_top {
        face(min + z, y, x); // top, −z
    }
    face(min, z, x); // y = min, +y
    face(min + y, x, z); // y = max, −y
    face(min, y, z); // x = min, +x
    face(min + x, z, y); // x = max, −x
    Ok(s)
}

/// A regular `sides`-gon disc of circumradius `radius` (and optional hole of radius
/// `inner`), particles on the side `normal` points to.
pub fn disc(
    centre: Point3<Real>,
    normal: Vector3<Real>,
    radius: Real,
    inner: Real,
    sides: usize,
) -> Result<Surface, GeometryError> {
    positive("radius", radius)?;
    sides_ok(sides)?;
    if !(inner >= 0.0 && inner < radius) {
        return Err(GeometryError::InvalidParameter {
            name: "inner_radius",
            value: inner,
            reason: "must lie in [0, radius)",
        });
    }
    let n = direction("normal", &normal)?;
    let (u, v) = tangent_frame(&n);
    let ring = |r: Real, k: usize| {
        let a = std::f64::consts::TAU * k as Real / sides as Real;
        centre + (u * a.cos() + v * a.sin()) * r
    };
    let mut s = Surface::default();
    if inner == 0.0 {
        s.vertices.push(centre);
        s.vertices.extend((0..sides).map(|k| ring(radius, k)));
        for k in 0..sides {
            let (a, b) = (1 + k as u32, 1 + ((k + 1) % sides) as u32);
            s.triangles.push([0, a, b]);
        }
    } else {
        for k in 0..sides {
            let k1 = (k + 1) % sides;
            s.quad([
                ring(inner, k),
                ring(radius, k),
                ring(radius, k1),
                ring(inner, k1),
            ]);
        }
    }
    Ok(s)
}

/// The inside of a cone frustum (a hopper when `radius_top > radius_bottom`, a tube
/// when they are equal) around the axis from `base` along `axis` over `length`, with
/// `segments` rings of facets along the axis. Caps are added separately with [`disc`].
pub fn frustum_inside(
    base: Point3<Real>,
    axis: Vector3<Real>,
    length: Real,
    radius_bottom: Real,
    radius_top: Real,
    sides: usize,
    segments: usize,
) -> Result<Surface, GeometryError> {
    positive("length", length)?;
    positive("radius", radius_bottom.max(radius_top))?;
    if !(radius_bottom >= 0.0 && radius_top >= 0.0) {
        return Err(GeometryError::InvalidParameter {
            name: "radius",
            value: radius_bottom.min(radius_top),
            reason: "must not be negative",
        });
    }
    sides_ok(sides)?;
    let n = direction("axis", &axis)?;
    let (u, v) = tangent_frame(&n);
    let segments = segments.max(1);
    if segments.saturating_mul(sides).saturating_mul(2) > MAX_FACETS {
        return Err(GeometryError::InvalidParameter {
            name: "segments",
            value: segments as Real,
            reason: "sides × segments × 2 facets must be at most ten million",
        });
    }
    let point = |k: usize, s: usize| {
        let a = std::f64::consts::TAU * k as Real / sides as Real;
        let f = s as Real / segments as Real;
        let r = radius_bottom + (radius_top - radius_bottom) * f;
        base + n.into_inner() * (length * f) + (u * a.cos() + v * a.sin()) * r
    };
    let mut s = Surface::default();
    for seg in 0..segments {
        for k in 0..sides {
            let k1 = (k + 1) % sides;
            // Counter-clockwise seen from the axis (inside).
            s.quad([
                point(k, seg),
                point(k, seg + 1),
                point(k1, seg + 1),
                point(k1, seg),
            ]);
        }
    }
    // Drop the degenerate facets of a pointed end.
    s.triangles.retain(|t| {
        let [a, b, c] = t.map(|i| s.vertices[i as usize]);
        (b - a).cross(&(c - a)).norm() > 0.0
    });
    Ok(s)
}

/// The inside of a closed or open cylinder: mantle from `base` along `axis` over
/// `length`, with the bottom and/or top caps.
#[allow(clippy::too_many_arguments)]
pub fn cylinder_inside(
    base: Point3<Real>,
    axis: Vector3<Real>,
    length: Real,
    radius: Real,
    sides: usize,
    segments: usize,
    bottom: bool,
    top: bool,
) -> Result<Surface, GeometryError> {
    let mut s = frustum_inside(base, axis, length, radius, radius, sides, segments)?;
    let n = axis.normalize();
    if bottom {
        s.append(disc(base, n, radius, 0.0, sides)?);
    }
    if top {
        // Built with the mantle's frame, then turned over, so the rings coincide.
        s.append(disc(base + n * length, n, radius, 0.0, sides)?.flipped());
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every facet faces `inside`, and the surface has the expected area.
    fn faces(s: &Surface, inside: Point3<Real>, area: Real, tol: Real) {
        for t in &s.triangles {
            let [a, b, c] = t.map(|v| s.vertices[v as usize]);
            let n = (b - a).cross(&(c - a));
            let centroid = Point3::from((a.coords + b.coords + c.coords) / 3.0);
            assert!(n.dot(&(inside - centroid)) > 0.0, "facet {t:?} faces away");
        }
        assert!(
            (s.area() / area - 1.0).abs() < tol,
            "area {} vs {area}",
            s.area()
        );
    }

    #[test]
    fn generated_surfaces_face_the_particles() {
        let (lo, hi) = (Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 2.0, 3.0));
        let centre = Point3::new(0.5, 1.0, 1.5);
        faces(&box_inside(lo, hi, false).unwrap(), centre, 22.0, 1e-12);
        faces(&box_inside(lo, hi, true).unwrap(), centre, 20.0, 1e-12);
        let up = Vector3::z();
        faces(
            &plane(Point3::origin(), up, 2.0).unwrap(),
            Point3::new(0.3, 0.2, 1.0),
            4.0,
            1e-12,
        );
        let n = 64;
        let polygon = |r: Real| 0.5 * n as Real * r * r * (std::f64::consts::TAU / n as Real).sin();
        faces(
            &disc(Point3::origin(), up, 1.0, 0.0, n).unwrap(),
            Point3::new(0.0, 0.0, 1.0),
            polygon(1.0),
            1e-12,
        );
        faces(
            &disc(Point3::origin(), up, 1.0, 0.5, n).unwrap(),
            Point3::new(0.0, 0.0, 1.0),
            polygon(1.0) - polygon(0.5),
            1e-12,
        );
        // A closed drum along x: mantle (perimeter × length) and two caps.
        let drum =
            cylinder_inside(Point3::origin(), Vector3::x(), 2.0, 1.0, n, 3, true, true).unwrap();
        let side = n as Real * 2.0 * (std::f64::consts::PI / n as Real).sin();
        faces(
            &drum,
            Point3::new(1.0, 0.0, 0.0),
            side * 2.0 + 2.0 * polygon(1.0),
            1e-12,
        );
        // A hopper: every facet faces the axis.
        let hopper = frustum_inside(Point3::origin(), up, 1.0, 0.1, 1.0, n, 4).unwrap();
        for t in &hopper.triangles {
            let [a, b, c] = t.map(|v| hopper.vertices[v as usize]);
            let n = (b - a).cross(&(c - a));
            let centroid = (a.coords + b.coords + c.coords) / 3.0;
            let axis_point = Vector3::new(0.0, 0.0, centroid.z);
            assert!(n.dot(&(axis_point - centroid)) > 0.0);
        }
        // Bad parameters are named.
        let e = box_inside(hi, lo, false).unwrap_err().to_string();
        assert!(e.contains("max - min"), "{e}");
        assert!(
            disc(Point3::origin(), Vector3::zeros(), 1.0, 0.0, 8)
                .unwrap_err()
                .to_string()
                .contains("normal")
        );
    }
}
