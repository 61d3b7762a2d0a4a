//! ParaView output: VTK XML PolyData frames (`.vtp`, binary appended data) and the
//! `.pvd` collections that make them a time series.
//!
//! Particles are written as their actual surfaces: every merged face of a polyhedron
//! is one polygon cell in its current pose (spheres as 80-facet icospheres), with the
//! particle's id, kind, velocity, speed and angular velocity on each of its cells
//! (with a coupled fluid also its drag, slip velocity and local voidage).
//! Walls are their facets in the current pose, with the wall index and the force on
//! each facet. A coupled fluid's grid is ImageData (`.vti`) with its cell fields.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use nalgebra::Point3;

use crate::Real;
use crate::geometry::{Shape, generators};
use crate::world::World;

/// A data array of a `.vtp` file.
enum Array {
    F32 {
        name: String,
        components: usize,
        data: Vec<f32>,
    },
    I64 {
        name: String,
        data: Vec<i64>,
    },
}

impl Array {
    fn header(&self, offset: usize) -> String {
        match self {
            Array::F32 {
                name, components, ..
            } => format!(
                r#"<DataArray type="Float32" Name="{name}" NumberOfComponents="{components}" format="appended" offset="{offset}"/>"#
            ),
            Array::I64 { name, .. } => format!(
                r#"<DataArray type="Int64" Name="{name}" format="appended" offset="{offset}"/>"#
            ),
        }
    }

    fn bytes(&self) -> Vec<u8> {
        match self {
            Array::F32 { data, .. } => data.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Array::I64 { data, .. } => data.iter().flat_map(|x| x.to_le_bytes()).collect(),
        }
    }
}

/// Cells of one kind (VTK verts or polys): each the points `connectivity` lists up
/// to its entry in `offsets`.
#[derive(Default)]
struct Cells {
    connectivity: Vec<i64>,
    offsets: Vec<i64>,
}

impl Cells {
    fn count(&self) -> usize {
        self.offsets.len()
    }
}

/// A polygon soup and a point cloud (VTK verts) with per-cell fields and per-point
/// fields, written as one `.vtp` piece. VTK orders a piece's cells verts first, then
/// polygons: `cell_data` lists the verts' values before the polygons'.
#[derive(Default)]
struct PolyData {
    points: Vec<f32>,
    verts: Cells,
    polys: Cells,
    cell_data: Vec<Array>,
    /// Per point (empty: none).
    point_data: Vec<Array>,
}

impl PolyData {
    fn point_count(&self) -> usize {
        self.points.len() / 3
    }

    fn add_cell(&mut self, vertex: bool, points: impl IntoIterator<Item = Point3<Real>>) {
        let cells = if vertex {
            &mut self.verts
        } else {
            &mut self.polys
        };
        for p in points {
            cells.connectivity.push((self.points.len() / 3) as i64);
            self.points.extend(p.coords.iter().map(|&x| x as f32));
        }
        cells.offsets.push(cells.connectivity.len() as i64);
    }

    fn add_polygon(&mut self, points: impl IntoIterator<Item = Point3<Real>>) {
        self.add_cell(false, points);
    }

    fn add_vertex(&mut self, point: Point3<Real>) {
        self.add_cell(true, [point]);
    }

    fn write(self, path: &Path) -> io::Result<()> {
        let n_points = self.point_count();
        let points = Array::F32 {
            name: "points".into(),
            components: 3,
            data: self.points,
        };
        let mut blocks: Vec<Vec<u8>> = Vec::new();
        let mut xml = String::new();
        let mut offset = 0usize;
        let mut header = |a: &Array, xml: &mut String, blocks: &mut Vec<Vec<u8>>| {
            let b = a.bytes();
            let _ = writeln!(xml, "        {}", a.header(offset));
            offset += 8 + b.len();
            blocks.push(b);
        };
        let _ = writeln!(
            xml,
            r#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <PolyData>
    <Piece NumberOfPoints="{n_points}" NumberOfVerts="{}" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="{}">
      <CellData>"#,
            self.verts.count(),
            self.polys.count()
        );
        for a in &self.cell_data {
            header(a, &mut xml, &mut blocks);
        }
        xml.push_str("      </CellData>\n");
        // Only where there are point fields: the frames without are as they were.
        if !self.point_data.is_empty() {
            xml.push_str("      <PointData>\n");
            for a in &self.point_data {
                header(a, &mut xml, &mut blocks);
            }
            xml.push_str("      </PointData>\n");
        }
        xml.push_str("      <Points>\n");
        header(&points, &mut xml, &mut blocks);
        xml.push_str("      </Points>\n");
        for (section, cells) in [("Verts", self.verts), ("Polys", self.polys)] {
            if cells.count() == 0 {
                continue;
            }
            let _ = writeln!(xml, "      <{section}>");
            let conn = Array::I64 {
                name: "connectivity".into(),
                data: cells.connectivity,
            };
            let offs = Array::I64 {
                name: "offsets".into(),
                data: cells.offsets,
            };
            header(&conn, &mut xml, &mut blocks);
            header(&offs, &mut xml, &mut blocks);
            let _ = writeln!(xml, "      </{section}>");
        }
        xml.push_str("    </Piece>\n  </PolyData>\n");
        write_appended(path, &xml, blocks)
    }
}

/// Writes the XML head `xml` and then `blocks` as the raw appended data (each headed
/// by its length).
fn write_appended(path: &Path, xml: &str, blocks: Vec<Vec<u8>>) -> io::Result<()> {
    let mut out = BufWriter::new(File::create(path)?);
    out.write_all(xml.as_bytes())?;
    out.write_all(b"  <AppendedData encoding=\"raw\">\n   _")?;
    for b in blocks {
        out.write_all(&(b.len() as u64).to_le_bytes())?;
        out.write_all(&b)?;
    }
    out.write_all(b"\n  </AppendedData>\n</VTKFile>\n")?;
    out.flush()
}

/// The file extension of [`write_fluid`]'s frames for the fluid of `world`:
/// `vti` for a structured grid, `vtp` for other cells.
pub fn fluid_extension(world: &World) -> &'static str {
    match world.fluid.as_ref().map(|f| f.grid.as_cartesian()) {
        Some(None) => "vtp",
        _ => "vti",
    }
}

/// Writes the fluid cells of `world` to `path`, with per cell: the solid fraction
/// and the mean particle velocity of the last update, the fluid velocity and
/// pressure gradient set, and the drag the particles in it receive at this step (N;
/// the momentum source is its opposite). A structured grid is VTK ImageData
/// (`.vti`); other cells are PolyData points at their centres (`.vtp`: cylindrical
/// cells at mid-radius, mid-angle and mid-height) with the cell volume as well.
pub fn write_fluid(world: &World, path: &Path) -> io::Result<()> {
    let Some(fluid) = &world.fluid else {
        return Ok(());
    };
    let grid = &fluid.grid;
    let p = &world.particles;
    let mut drag = vec![nalgebra::Vector3::zeros(); grid.len()];
    // Summed by id: the same bits whatever the order the particles are stored in.
    for i in p.owned_by_id() {
        if let Some(f) = fluid.exchange.drag.get(i) {
            fluid.weights(i, p.id[i], &p.position[i], |c, w| drag[c] += f * w);
        }
    }
    let vectors = |name: &str, v: &[nalgebra::Vector3<Real>]| Array::F32 {
        name: name.into(),
        components: 3,
        data: v.iter().flat_map(|x| x.iter().map(|&y| y as f32)).collect(),
    };
    let arrays = [
        Array::F32 {
            name: "solid_fraction".into(),
            components: 1,
            data: fluid.solid_fraction.iter().map(|&x| x as f32).collect(),
        },
        vectors("fluid_velocity", &fluid.velocity),
        vectors("pressure_gradient", &fluid.pressure_gradient),
        vectors("particle_velocity", &fluid.particle_velocity),
        vectors("particle_drag", &drag),
    ];
    let Some(grid) = grid.as_cartesian() else {
        let mut cloud = PolyData::default();
        for c in 0..grid.len() {
            cloud.add_vertex(grid.centre(c));
        }
        cloud.cell_data.extend(arrays);
        cloud.cell_data.push(Array::F32 {
            name: "cell_volume".into(),
            components: 1,
            data: (0..grid.len())
                .map(|c| grid.cell_volume(c) as f32)
                .collect(),
        });
        return cloud.write(path);
    };
    let [nx, ny, nz] = grid.counts();
    let o = grid.centre(0) - grid.cell_size() * 0.5;
    let h = grid.cell_size();
    let mut xml = format!(
        r#"<?xml version="1.0"?>
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <ImageData WholeExtent="0 {nx} 0 {ny} 0 {nz}" Origin="{} {} {}" Spacing="{} {} {}">
    <Piece Extent="0 {nx} 0 {ny} 0 {nz}">
      <CellData>
"#,
        o.x, o.y, o.z, h.x, h.y, h.z
    );
    let (mut offset, mut blocks) = (0, Vec::new());
    for a in &arrays {
        let b = a.bytes();
        let _ = writeln!(xml, "        {}", a.header(offset));
        offset += 8 + b.len();
        blocks.push(b);
    }
    xml.push_str("      </CellData>\n    </Piece>\n  </ImageData>\n");
    write_appended(path, &xml, blocks)
}

/// Writes the particles of `world` to `path`: polyhedra as their faces and spheres
/// as 80-facet icospheres or, with `sphere_points`, as one point each (VTK verts,
/// listed first) with the point field `radius` (0 on the polyhedra's points) for
/// ParaView's Point Gaussian or Glyph: 12 bytes and a few fields a sphere where an
/// icosphere takes about 9 kB.
pub fn write_particles(world: &World, path: &Path, sphere_points: bool) -> io::Result<()> {
    let sphere = generators::icosphere_mesh(1, 1.0).expect("valid icosphere");
    let mut pd = PolyData::default();
    let (mut id, mut kind, mut vel, mut speed, mut omega) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    // With a coupled fluid: each particle's drag, slip and local voidage.
    let (mut drag, mut slip, mut voidage) = (Vec::new(), Vec::new(), Vec::new());
    let mut radius: Vec<f32> = Vec::new();
    let p = &world.particles;
    let is_point = |i: usize| {
        sphere_points
            && matches!(
                world.body_types[p.body_type[i] as usize].shape,
                Shape::Sphere(_)
            )
    };
    // The points' cells first (VTK's order of verts before polygons), then the rest,
    // each by id (whatever the order the particles are stored in).
    let by_id = p.owned_by_id();
    let order = (by_id.iter().copied())
        .filter(|&i| is_point(i))
        .chain(by_id.iter().copied().filter(|&i| !is_point(i)));
    for i in order {
        let t = &world.body_types[p.body_type[i] as usize];
        let pose = nalgebra::Isometry3::from_parts(p.position[i].coords.into(), p.orientation[i]);
        let cells = match &t.shape {
            Shape::Sphere(_) if sphere_points => {
                pd.add_vertex(p.position[i]);
                1
            }
            Shape::Polyhedron(poly) => {
                for f in 0..poly.face_count() {
                    pd.add_polygon(
                        poly.face(f)
                            .iter()
                            .map(|&v| pose * poly.vertices()[v as usize]),
                    );
                }
                poly.face_count()
            }
            Shape::Sphere(s) => {
                for tri in &sphere.triangles {
                    pd.add_polygon(
                        tri.iter()
                            .map(|&v| p.position[i] + sphere.vertices[v].coords * s.radius),
                    );
                }
                sphere.triangles.len()
            }
        };
        if sphere_points {
            let r = t.shape.as_sphere().map_or(0.0, |s| s.radius as f32);
            radius.resize(pd.point_count(), r);
        }
        let w = world.angular_velocity(i);
        for _ in 0..cells {
            id.push(p.id[i] as i64);
            kind.push(p.body_type[i] as i64);
            vel.extend(p.velocity[i].iter().map(|&x| x as f32));
            speed.push(p.velocity[i].norm() as f32);
            omega.extend(w.iter().map(|&x| x as f32));
        }
        if let Some(fluid) = &world.fluid {
            let f = fluid.at_particle(p, i);
            for _ in 0..cells {
                drag.extend(f.drag.iter().map(|&x| x as f32));
                slip.extend(f.slip.iter().map(|&x| x as f32));
                voidage.push(f.voidage as f32);
            }
        }
    }
    if sphere_points {
        pd.point_data.push(Array::F32 {
            name: "radius".into(),
            components: 1,
            data: radius,
        });
    }
    pd.cell_data = vec![
        Array::I64 {
            name: "id".into(),
            data: id,
        },
        Array::I64 {
            name: "kind".into(),
            data: kind,
        },
        Array::F32 {
            name: "velocity".into(),
            components: 3,
            data: vel,
        },
        Array::F32 {
            name: "speed".into(),
            components: 1,
            data: speed,
        },
        Array::F32 {
            name: "angular_velocity".into(),
            components: 3,
            data: omega,
        },
    ];
    if world.fluid.is_some() {
        pd.cell_data.extend([
            Array::F32 {
                name: "drag".into(),
                components: 3,
                data: drag,
            },
            Array::F32 {
                name: "slip".into(),
                components: 3,
                data: slip,
            },
            Array::F32 {
                name: "voidage".into(),
                components: 1,
                data: voidage,
            },
        ]);
    }
    pd.write(path)
}

/// Writes every wall's facets in their current pose to `path`.
pub fn write_walls(world: &World, path: &Path) -> io::Result<()> {
    let mut pd = PolyData::default();
    let (mut index, mut force) = (Vec::new(), Vec::new());
    for (w, wall) in world.walls.iter().enumerate() {
        for f in 0..wall.triangles.len() {
            pd.add_polygon(wall.facet_world(f));
            index.push(w as i64);
            force.extend(wall.facet_force[f].iter().map(|&x| x as f32));
        }
    }
    pd.cell_data = vec![
        Array::I64 {
            name: "wall".into(),
            data: index,
        },
        Array::F32 {
            name: "facet_force".into(),
            components: 3,
            data: force,
        },
    ];
    pd.write(path)
}

/// A `.pvd` collection, rewritten whole after every frame so that it is valid even
/// when a run is interrupted.
#[derive(Clone, Debug)]
pub struct Collection {
    path: PathBuf,
    frames: Vec<(Real, String)>,
}

impl Collection {
    /// A collection written to `path`; frame file names are relative to its directory.
    pub fn new(path: PathBuf) -> Self {
        Collection {
            path,
            frames: Vec::new(),
        }
    }

    /// A collection of these frames (time, file), written now unless empty: a
    /// resumed run's.
    pub fn restore(path: PathBuf, frames: Vec<(Real, String)>) -> io::Result<Self> {
        let c = Collection { path, frames };
        if !c.frames.is_empty() {
            c.write()?;
        }
        Ok(c)
    }

    /// The frames (time, file).
    pub fn frames(&self) -> &[(Real, String)] {
        &self.frames
    }

    /// Adds a frame at `time` and rewrites the collection.
    pub fn add(&mut self, time: Real, file: String) -> io::Result<()> {
        self.frames.push((time, file));
        self.write()
    }

    fn write(&self) -> io::Result<()> {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n",
        );
        for (t, f) in &self.frames {
            let _ = writeln!(
                s,
                "    <DataSet timestep=\"{t:.9e}\" group=\"\" part=\"0\" file=\"{f}\"/>"
            );
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        std::fs::write(&self.path, s)
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }
}
