//! Resolves a scene's `[drum]` and `[bed]` sections against the built world.

use nalgebra::Point3;

use super::build::{direction, finite, positive};
use super::error::{FieldError, FieldPath};
use super::spec::{BedSpec, DrumSpec};
use crate::Real;
use crate::analysis::Drum;
use crate::analysis::packing::{Bed, PackingOptions, Tube};
use crate::world::World;

/// The drum of `spec`: wall names to indices, the axis and the drum's extent from
/// the walls' vertices, the defaults that depend on the particles.
pub(super) fn resolve_drum(spec: &DrumSpec, world: &World) -> Result<Drum, FieldError> {
    let path = FieldPath::root("drum");
    if spec.walls.is_empty() {
        return Err(FieldError::new(path.key("walls"), "name at least one wall"));
    }
    let mut walls = Vec::new();
    for (k, name) in spec.walls.iter().enumerate() {
        let Some(w) = world.walls.iter().position(|w| &w.name == name) else {
            return Err(FieldError::new(
                path.key("walls").index(k),
                format!("no wall named '{name}'"),
            ));
        };
        if walls.contains(&w) {
            return Err(FieldError::new(
                path.key("walls").index(k),
                format!("wall '{name}' is named twice"),
            ));
        }
        walls.push(w);
    }
    let axis = direction(path.key("axis"), &spec.axis)?;
    let first = &world.walls[walls[0]];
    let origin = first.reference();
    // Extent of the walls about the axis through the first wall's reference point.
    let (mut radius, mut lo, mut hi) = (0.0 as Real, Real::INFINITY, Real::NEG_INFINITY);
    for &w in &walls {
        let wall = &world.walls[w];
        for v in &wall.vertices {
            let d = wall.pose * v - origin;
            let along = d.dot(&axis);
            radius = radius.max((d - axis * along).norm());
            lo = lo.min(along);
            hi = hi.max(along);
        }
    }
    let length = hi - lo;
    if !(radius > 0.0) {
        return Err(FieldError::new(
            path.key("walls"),
            "the walls do not surround the axis (no vertex off the axis)",
        ));
    }
    let diameter = world
        .body_types
        .iter()
        .map(|t| 2.0 * t.shape.circumradius())
        .fold(0.0, Real::max);
    if !(diameter > 0.0) {
        return Err(FieldError::new(
            path.clone(),
            "the scene has no particle kinds",
        ));
    }
    for (name, v) in [
        ("slice", spec.slice),
        ("cell", spec.cell),
        ("sample_interval", Some(spec.sample_interval)),
    ] {
        if let Some(x) = v {
            positive(path.key(name), x)?;
        }
    }
    if let Some(t) = spec.average_after
        && !(t >= 0.0 && t.is_finite())
    {
        return Err(FieldError::new(
            path.key("average_after"),
            format!("{t} must be a non-negative time"),
        ));
    }
    let centre = origin + axis * (0.5 * (lo + hi));
    let inverse = first.pose.inverse();
    Ok(Drum {
        walls,
        axis_local: inverse * axis,
        centre_local: inverse * Point3::from(centre.coords),
        radius,
        length,
        slice: spec
            .slice
            .unwrap_or(length)
            .min(length.max(Real::MIN_POSITIVE)),
        cell: spec.cell.unwrap_or(diameter),
        diameter,
        sample_interval: spec.sample_interval,
        average_after: spec.average_after,
    })
}

/// The bed of `spec`, every length checked.
pub(super) fn resolve_bed(spec: &BedSpec) -> Result<Bed, FieldError> {
    let path = FieldPath::root("bed");
    finite(path.key("base"), &spec.base)?;
    let axis = direction(path.key("axis"), &spec.axis)?;
    for (name, v) in [
        ("radius", Some(spec.radius)),
        ("bin", spec.bin),
        ("slice", spec.slice),
        ("gap", spec.gap),
    ] {
        if let Some(x) = v {
            positive(path.key(name), x)?;
        }
    }
    if let Some(x) = spec.exclude
        && !(x >= 0.0 && x.is_finite())
    {
        return Err(FieldError::new(
            path.key("exclude"),
            format!("{x} must be non-negative"),
        ));
    }
    if let Some(f) = &spec.freeze {
        let path = path.key("freeze");
        positive(path.key("depth"), f.depth)?;
        positive(path.key("max_speed"), f.max_speed)?;
    }
    if let Some(g) = spec.cap_gap {
        positive(path.key("cap_gap"), g)?;
    }
    if let Some(b) = spec.bridge
        && !(b > 0.0 && b <= 1.0)
    {
        return Err(FieldError::new(
            path.key("bridge"),
            format!("{b} is not in (0, 1]: the bridge's diameter over the particle's"),
        ));
    }
    if !(spec.shrink > 0.0 && spec.shrink <= 1.0) {
        return Err(FieldError::new(
            path.key("shrink"),
            format!("{} is not in (0, 1]", spec.shrink),
        ));
    }
    Ok(Bed {
        tube: Tube {
            base: Point3::from(spec.base),
            axis,
            radius: spec.radius,
        },
        options: PackingOptions {
            bin: spec.bin,
            slice: spec.slice,
            exclude: spec.exclude,
            gap: spec.gap,
            region: None,
            cap_gap: spec.cap_gap,
            bridge: spec.bridge,
        },
    })
}
