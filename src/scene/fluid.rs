//! `[fluid]` of a scene: checked and built into the world's fluid field.

use std::path::Path;

use nalgebra::{Point3, Vector3};

use super::build::{finite, positive};
use super::csv_table::CsvTable;
use super::error::{FieldError, FieldPath};
use super::spec::{FluidSpec, GridKind, UpdateInterval};
use crate::Real;
use crate::fluid::{
    CartesianGrid, CylindricalGrid, DragShape, FluidGrid, FluidProperties, GivenCells, GridError,
};
use crate::world::{DragModel, FluidField, World};

/// The fluid field of `spec` over `world` (its body types and gravity set); files
/// are read relative to `dir`.
pub(super) fn build_fluid(
    spec: &FluidSpec,
    world: &World,
    dir: &Path,
) -> Result<FluidField, FieldError> {
    let path = FieldPath::root("fluid");
    finite(path.key("velocity"), &spec.velocity)?;
    positive(path.key("density"), spec.density)?;
    positive(path.key("viscosity"), spec.viscosity)?;
    if spec.update_interval == UpdateInterval::Steps(0) {
        return Err(FieldError::new(
            path.key("update_interval"),
            "must be at least 1 step",
        ));
    }
    let grid = build_grid(spec, &path, dir)?;
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

/// The cells of `spec`: the keys its kind needs, none of another kind's.
fn build_grid(spec: &FluidSpec, path: &FieldPath, dir: &Path) -> Result<FluidGrid, FieldError> {
    let given = [
        ("origin", spec.origin.is_some()),
        ("cell", spec.cell.is_some()),
        ("cells", spec.cells.is_some()),
        ("base", spec.base.is_some()),
        ("axis", spec.axis.is_some()),
        ("radius", spec.radius.is_some()),
        ("radii", spec.radii.is_some()),
        ("height", spec.height.is_some()),
        ("file", spec.file.is_some()),
    ];
    let (kind, keys): (&str, &[&str]) = match spec.grid {
        GridKind::Cartesian => ("cartesian", &["origin", "cell", "cells"]),
        GridKind::Cylindrical => (
            "cylindrical",
            &["cells", "base", "axis", "radius", "radii", "height"],
        ),
        GridKind::Cells => ("cells", &["file"]),
    };
    if let Some((key, _)) = given.iter().find(|(k, set)| *set && !keys.contains(k)) {
        return Err(FieldError::new(
            path.key(key),
            format!("is not a key of a {kind} grid (grid = \"{kind}\")"),
        ));
    }
    let need = |key: &str| FieldError::new(path.key(key), format!("a {kind} grid needs it"));
    let grid_error = |e: GridError| FieldError::new(path.key(e.key()), e.to_string());
    Ok(match spec.grid {
        GridKind::Cartesian => FluidGrid::Cartesian(
            CartesianGrid::new(
                Point3::from(spec.origin.ok_or_else(|| need("origin"))?),
                Vector3::from(spec.cell.ok_or_else(|| need("cell"))?),
                spec.cells.ok_or_else(|| need("cells"))?,
            )
            .map_err(grid_error)?,
        ),
        GridKind::Cylindrical => {
            let [annuli, slabs, sectors] = spec.cells.ok_or_else(|| need("cells"))?;
            let radii = match (spec.radius, &spec.radii) {
                (Some(r), None) => {
                    positive(path.key("radius"), r)?;
                    (1..=annuli)
                        .map(|i| r * i as Real / annuli.max(1) as Real)
                        .collect()
                }
                (None, Some(radii)) if radii.len() == annuli => radii.clone(),
                (None, Some(radii)) => {
                    return Err(FieldError::new(
                        path.key("radii"),
                        format!("{} radii for {annuli} annuli (cells[0])", radii.len()),
                    ));
                }
                _ => {
                    return Err(FieldError::new(
                        path.key("radius"),
                        "a cylindrical grid needs either radius or radii",
                    ));
                }
            };
            FluidGrid::Cylindrical(
                CylindricalGrid::new(
                    Point3::from(spec.base.ok_or_else(|| need("base"))?),
                    Vector3::from(spec.axis.unwrap_or([0.0, 0.0, 1.0])),
                    radii,
                    spec.height.ok_or_else(|| need("height"))?,
                    slabs,
                    sectors,
                )
                .map_err(grid_error)?,
            )
        }
        GridKind::Cells => {
            let file = dir.join(spec.file.as_ref().ok_or_else(|| need("file"))?);
            let cells = read_cells(&file).map_err(|e| FieldError::new(path.key("file"), e))?;
            let lines = cells.lines;
            FluidGrid::Given(GivenCells::new(cells.centres, cells.volumes).map_err(|e| {
                let line = match &e {
                    GridError::Cell { cell, .. } => format!("{}: ", lines[*cell]),
                    _ => String::new(),
                };
                FieldError::new(path.key("file"), format!("{}:{line}{e}", file.display()))
            })?)
        }
    })
}

/// The cells of a CSV file: each one's centre, volume and line in the file.
#[derive(Clone, Debug, Default)]
pub struct CellsFile {
    /// Centres, m.
    pub centres: Vec<Point3<Real>>,
    /// Volumes, m³.
    pub volumes: Vec<Real>,
    /// The line of each cell (from 1).
    pub lines: Vec<usize>,
}

/// Reads a CSV of cells: a header naming `x`, `y`, `z` and `volume` (any order,
/// other columns ignored), then one cell per line; `#` lines and blank lines are
/// skipped. Errors name the file, the line and the column.
pub fn read_cells(path: &Path) -> Result<CellsFile, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    parse_cells(&text).map_err(|e| format!("{}:{e}", path.display()))
}

/// Parses cell CSV text (errors start with the line number).
pub fn parse_cells(text: &str) -> Result<CellsFile, String> {
    let table = CsvTable::parse(text, "x,y,z,volume")?;
    let mut cols = [0usize; 4];
    for (c, name) in cols.iter_mut().zip(["x", "y", "z", "volume"]) {
        *c = table.require(name)?;
    }
    let mut cells = CellsFile::default();
    for record in table.records() {
        let [x, y, z, v] = cols.map(|c| record.value(c));
        cells.centres.push(Point3::new(x?, y?, z?));
        let v = v?;
        if !(v > 0.0) {
            return Err(format!("{}: the volume {v} is not positive", record.line));
        }
        cells.volumes.push(v);
        cells.lines.push(record.line);
    }
    if cells.centres.is_empty() {
        return Err(format!(
            "{}: no cells after the header",
            table.header_line()
        ));
    }
    Ok(cells)
}
