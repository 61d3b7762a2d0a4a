//! `[fluid]` of a scene: checked and built into the world's fluid field.

use nalgebra::{Point3, Vector3};

use super::build::{finite, positive};
use super::error::{FieldError, FieldPath};
use super::spec::FluidSpec;
use crate::fluid::{DragShape, FluidGrid, FluidProperties};
use crate::world::{DragModel, FluidField, World};

/// The fluid field of `spec` over `world` (its body types and gravity set).
pub(super) fn build_fluid(spec: &FluidSpec, world: &World) -> Result<FluidField, FieldError> {
    let path = FieldPath::root("fluid");
    finite(path.key("velocity"), &spec.velocity)?;
    positive(path.key("density"), spec.density)?;
    positive(path.key("viscosity"), spec.viscosity)?;
    if spec.update_interval == 0 {
        return Err(FieldError::new(
            path.key("update_interval"),
            "must be at least 1 step",
        ));
    }
    let grid = FluidGrid::new(
        Point3::from(spec.origin),
        Vector3::from(spec.cell),
        spec.cells,
    )
    .map_err(|e| FieldError::new(path.key(e.key()), e.to_string()))?;
    let gradient = match spec.pressure_gradient {
        Some(g) => {
            finite(path.key("pressure_gradient"), &g)?;
            Vector3::from(g)
        }
        None => world.gravity * spec.density,
    };
    let model = DragModel {
        properties: FluidProperties {
            density: spec.density,
            viscosity: spec.viscosity,
        },
        law: spec.drag,
        correction: spec.shape_correction,
        shapes: world
            .body_types
            .iter()
            .map(|t| DragShape::of(&t.shape))
            .collect(),
    };
    Ok(FluidField::new(
        grid,
        model,
        Vector3::from(spec.velocity),
        gradient,
    ))
}
