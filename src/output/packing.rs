//! A packed bed's files:
//!
//! - `packing.json`: the figures of [`crate::analysis::packing::Packing`] (bed
//!   height, region, bed-averaged porosity with the quadrature's error estimate,
//!   coordination and orientation distributions, both profiles, and the reactor
//!   figures: specific surface, diameters, wall contacts, permeabilities);
//! - `packing_radial.csv` (`r_inner,r_outer,porosity,specific_surface`) and
//!   `packing_axial.csv`
//!   (`z_lower,z_upper,porosity`, heights above the tube's base), and their plots
//!   `packing_radial.png` (against the distance from the wall in particle diameters)
//!   and `packing_axial.png`;
//! - `packing_cells.csv`: porosity and specific surface on the cells of a
//!   cylindrical grid (the scene's cylindrical `[fluid]` grid, else the radial bins ×
//!   axial slices), see [`write_porosity_map`];
//! - `poses.csv`: `id,kind,shape,x,y,z,qw,qx,qy,qz` per particle (the body frame's
//!   pose: centroid and principal axes), which `talus analyze` reads back;
//! - `bed.stl`: every particle's surface in place (spheres as 320-triangle
//!   icospheres), each scaled about its centroid by the scene's `shrink`;
//! - `bed_caps.stl`: every particle capped where it touches a neighbour or the
//!   tube, a gap apart from all ([`crate::analysis::packing::mesher`]), and
//!   `contacts.csv` (`id_i,id_j,x,y,z,nx,ny,nz,gap`): the contacts closer than that
//!   gap, normal from `i` to `j`, gap negative for an overlap;
//! - `bed_bridges.stl` (with `[bed] bridge`): the particles at full size joined by a
//!   small prism at each of those contacts and to the tube's wall and floor, united
//!   into one closed surface ([`crate::analysis::packing::bridges`]).

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use nalgebra::{Point3, UnitQuaternion};

use crate::Real;
use plotters::chart::SeriesLabelPosition;

use super::plot::LineChart;
use crate::analysis::packing::bridges::{bridged_bed, bridges};
use crate::analysis::packing::mesher::{SPHERE_LEVEL, bed_contacts, capped_particles};
use crate::analysis::packing::{Bed, Packing, PorosityMap};
use crate::geometry::Shape;
use crate::geometry::generators::icosphere_mesh;
use crate::geometry::mesh_io::write_stl;
use crate::world::World;

/// Writes `packing.json`, the two profile CSVs and their plots.
pub fn write_packing(dir: &Path, packing: &Packing) -> io::Result<()> {
    plot_profiles(dir, packing)?;
    let text = serde_json::to_string_pretty(packing).map_err(io::Error::other)?;
    std::fs::write(dir.join("packing.json"), text + "\n")?;
    let radial = packing
        .radial
        .iter()
        .map(|b| vec![b.r_inner, b.r_outer, b.porosity, b.specific_surface]);
    write_profile(
        &dir.join("packing_radial.csv"),
        "r_inner,r_outer,porosity,specific_surface",
        radial,
    )?;
    let axial = packing
        .axial
        .iter()
        .map(|s| vec![s.z_lower, s.z_upper, s.porosity]);
    write_profile(
        &dir.join("packing_axial.csv"),
        "z_lower,z_upper,porosity",
        axial,
    )
}

/// `packing_radial.png` (porosity against the distance from the tube wall in particle
/// diameters, the usual form of a wall-effect profile) and `packing_axial.png`
/// (porosity against height), each with the bed-averaged porosity.
fn plot_profiles(dir: &Path, packing: &Packing) -> io::Result<()> {
    let d = packing.diameter;
    let radial = packing
        .radial
        .iter()
        .map(|b| {
            (
                (packing.tube_radius - 0.5 * (b.r_inner + b.r_outer)) / d,
                b.porosity,
            )
        })
        .collect::<Vec<_>>();
    let axial = packing
        .axial
        .iter()
        .map(|s| (0.5 * (s.z_lower + s.z_upper), s.porosity))
        .collect::<Vec<_>>();
    let average = format!("bed average {:.4}", packing.porosity);
    let flat = |from: Real, to: Real| vec![(from, packing.porosity), (to, packing.porosity)];
    let wall_distance = packing.tube_radius / d;
    let mut chart = LineChart::new(
        &format!(
            "Radial porosity profile (D/d = {:.2}, {} particles)",
            packing.tube_to_particle, packing.particles
        ),
        &format!(
            "distance from the tube wall (particle diameters, d = {:.3} mm)",
            1e3 * d
        ),
        "porosity (-)",
    )
    .with("porosity of the annular bin", radial)
    .with(&average, flat(0.0, wall_distance));
    chart.y_range = Some((0.0, 1.05));
    chart.legend = SeriesLabelPosition::LowerRight;
    chart.write_png(&dir.join("packing_radial.png"))?;
    let [z0, z1] = packing.region;
    let mut chart = LineChart::new(
        &format!(
            "Axial porosity profile (bed height {:.2} mm)",
            1e3 * packing.bed_height
        ),
        "height above the tube base (m)",
        "porosity (-)",
    )
    .with("porosity of the slice", axial)
    .with(&format!("{average} (its region)"), flat(z0, z1));
    chart.y_range = Some((0.0, 1.05));
    chart.legend = SeriesLabelPosition::LowerRight;
    chart.write_png(&dir.join("packing_axial.png"))
}

/// A profile as CSV: bin edges and the bin's figures per row.
fn write_profile(
    path: &Path,
    header: &str,
    rows: impl Iterator<Item = Vec<Real>>,
) -> io::Result<()> {
    let mut out = BufWriter::new(File::create(path)?);
    writeln!(out, "{header}")?;
    for row in rows {
        let cells: Vec<String> = row.iter().map(|x| format!("{x:.9e}")).collect();
        writeln!(out, "{}", cells.join(","))?;
    }
    out.flush()
}

/// Writes `packing_cells.csv`: the porosity and specific surface per cell of the
/// map's cylindrical grid, one row per cell in the grid's flat order (annulus
/// fastest, then slab, then sector: the order of a `[fluid]` cylindrical grid's
/// arrays), with the cell's indices and edges (heights above the base, angles in
/// radians from the grid frame's x axis).
pub fn write_porosity_map(dir: &Path, map: &PorosityMap) -> io::Result<()> {
    let grid = &map.grid;
    let [_, _, sectors] = grid.counts();
    let width = 2.0 * std::f64::consts::PI / sectors as Real;
    let mut out = BufWriter::new(File::create(dir.join("packing_cells.csv"))?);
    writeln!(
        out,
        "annulus,slab,sector,r_inner,r_outer,z_lower,z_upper,theta_lower,theta_upper,porosity,specific_surface"
    )?;
    for c in 0..grid.len() {
        let [i, j, k] = grid.cell(c);
        let inner = if i == 0 { 0.0 } else { grid.radii()[i - 1] };
        let edges = [
            inner,
            grid.radii()[i],
            grid.heights()[j],
            grid.heights()[j + 1],
            k as Real * width,
            (k + 1) as Real * width,
            map.porosity[c],
            map.specific_surface[c],
        ];
        let edges: Vec<String> = edges.iter().map(|x| format!("{x:.9e}")).collect();
        writeln!(out, "{i},{j},{k},{}", edges.join(","))?;
    }
    out.flush()
}

/// Writes `poses.csv`; `shape_names[k]` names body type `k`.
pub fn write_poses(dir: &Path, world: &World, shape_names: &[String]) -> io::Result<()> {
    let mut out = BufWriter::new(File::create(dir.join("poses.csv"))?);
    writeln!(out, "id,kind,shape,x,y,z,qw,qx,qy,qz")?;
    let p = &world.particles;
    for i in 0..p.owned() {
        let (x, q) = (p.position[i], p.orientation[i]);
        let kind = p.body_type[i] as usize;
        writeln!(
            out,
            // Shortest round-trip forms: `talus analyze` reads back the same bits.
            "{},{kind},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            p.id[i],
            shape_names.get(kind).map_or("", String::as_str),
            x.x,
            x.y,
            x.z,
            q.w,
            q.i,
            q.j,
            q.k
        )?;
    }
    out.flush()
}

/// Reads `poses.csv` back into `world` (replacing its particles), each row's kind
/// checked against the world's body types.
pub fn read_poses(path: &Path, world: &mut World) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_poses(&text, path, world)
}

/// Reads `poses.csv` text (`path` names it in errors) into `world`, as
/// [`read_poses`]; on error the world's particles are left empty or partial.
pub fn parse_poses(text: &str, path: &Path, world: &mut World) -> Result<(), String> {
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim() == "id,kind,shape,x,y,z,qw,qx,qy,qz" => {}
        _ => {
            return Err(format!(
                "{}:1: the header must be id,kind,shape,x,y,z,qw,qx,qy,qz",
                path.display()
            ));
        }
    }
    world.particles = Default::default();
    for (n, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let at = |what: &str| format!("{}:{}: {what}", path.display(), n + 1);
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 10 {
            return Err(at(&format!("{} fields, expected 10", f.len())));
        }
        let id: u64 = f[0]
            .trim()
            .parse()
            .map_err(|_| at("id is not an integer"))?;
        let kind: u32 = f[1]
            .trim()
            .parse()
            .map_err(|_| at("kind is not an integer"))?;
        if kind as usize >= world.body_types.len() {
            return Err(at(&format!(
                "kind {kind}, but the scene has {} particle kinds",
                world.body_types.len()
            )));
        }
        let mut v = [0.0; 7];
        for (k, x) in v.iter_mut().enumerate() {
            *x = f[3 + k]
                .trim()
                .parse::<Real>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| at(&format!("field {} is not a finite number", 4 + k)))?;
        }
        let q = nalgebra::Quaternion::new(v[3], v[4], v[5], v[6]);
        if !(q.norm() > 0.5) {
            return Err(at("the quaternion is not a rotation"));
        }
        // A unit quaternion as written is kept bit for bit; others are normalised.
        let q = if (q.norm() - 1.0).abs() < 1e-12 {
            UnitQuaternion::new_unchecked(q)
        } else {
            crate::geometry::unit_quaternion(v[3], v[4], v[5], v[6])
                .ok_or_else(|| at("the quaternion is not a rotation"))?
        };
        world
            .particles
            .push(kind, Point3::new(v[0], v[1], v[2]), q, id);
    }
    Ok(())
}

/// Writes `contacts.csv`, `bed_caps.stl` and, if the bed asks for bridges,
/// `bed_bridges.stl` (see the module docs).
pub fn write_mesher_beds(dir: &Path, world: &World, bed: &Bed) -> io::Result<()> {
    let gap = bed.cap_gap(world);
    let contacts = bed_contacts(world, gap).map_err(io::Error::other)?;
    let mut out = BufWriter::new(File::create(dir.join("contacts.csv"))?);
    writeln!(out, "id_i,id_j,x,y,z,nx,ny,nz,gap")?;
    let id = &world.particles.id;
    for c in &contacts {
        let (x, n) = (c.point, c.normal);
        writeln!(
            out,
            "{},{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}",
            id[c.i], id[c.j], x.x, x.y, x.z, n.x, n.y, n.z, c.gap
        )?;
    }
    out.flush()?;
    if let Some(diameter) = bed.options.bridge {
        let bridges =
            bridges(world, &bed.tube, gap, diameter, &contacts).map_err(io::Error::other)?;
        let solid = bridged_bed(world, &bridges).map_err(io::Error::other)?;
        write_stl(
            &dir.join("bed_bridges.stl"),
            &solid.vertices,
            &solid.triangles,
        )?;
    }
    let capped = capped_particles(world, &bed.tube, gap, &contacts).map_err(io::Error::other)?;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for c in capped {
        let base = vertices.len();
        vertices.extend(c.vertices);
        triangles.extend(c.triangles.iter().map(|t| t.map(|v| v as usize + base)));
    }
    write_stl(&dir.join("bed_caps.stl"), &vertices, &triangles)?;
    Ok(())
}

/// Writes `bed.stl`: every particle's surface in place, scaled by `shrink` about
/// its centroid.
pub fn write_bed_stl(dir: &Path, world: &World, shrink: Real) -> io::Result<()> {
    let p = &world.particles;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let mut balls = std::collections::HashMap::new();
    for i in 0..p.owned() {
        let t = &world.body_types[p.body_type[i] as usize];
        let (local, tris): (Vec<Point3<Real>>, Vec<[usize; 3]>) = match &t.shape {
            Shape::Polyhedron(poly) => (
                poly.vertices().to_vec(),
                poly.triangles()
                    .iter()
                    .map(|t| t.map(|v| v as usize))
                    .collect(),
            ),
            Shape::Sphere(s) => balls
                .entry(s.radius.to_bits())
                .or_insert_with(|| {
                    let mesh = icosphere_mesh(SPHERE_LEVEL, s.radius).expect("a positive radius");
                    (mesh.vertices, mesh.triangles)
                })
                .clone(),
        };
        let base = vertices.len();
        for v in &local {
            vertices.push(p.position[i] + p.orientation[i] * (v.coords * shrink));
        }
        triangles.extend(tris.iter().map(|t| t.map(|v| v + base)));
    }
    write_stl(&dir.join("bed.stl"), &vertices, &triangles)
}
