//! Reading triangle meshes from STL (ASCII and binary) and OBJ files, and turning a
//! particle mesh into a checked template.

use std::fs::File;
use std::io::Cursor;
use std::path::Path;

use nalgebra::Point3;

use super::{ConvexPolyhedron, GeometryError, TriMesh, convex_hull};
use crate::Real;

/// How a particle mesh file becomes a template.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParticleMeshOptions {
    /// Use the convex hull of the mesh's vertices instead of rejecting a non-convex or
    /// open mesh.
    pub convex_hull: bool,
    /// Factor applied to every coordinate (for example 1e-3 for a mesh in mm).
    pub scale: Real,
}

impl Default for ParticleMeshOptions {
    fn default() -> Self {
        ParticleMeshOptions {
            convex_hull: false,
            scale: 1.0,
        }
    }
}

fn file_error(path: &Path, message: impl Into<String>) -> GeometryError {
    GeometryError::File {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Reads a mesh, choosing the format from the extension (`.stl` or `.obj`).
pub fn read_mesh(path: &Path) -> Result<TriMesh, GeometryError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("stl") => read_stl(path),
        Some("obj") => read_obj(path),
        _ => Err(file_error(
            path,
            "unknown mesh format (expected .stl or .obj)",
        )),
    }
}

/// Reads an ASCII or binary STL file; vertices with identical coordinates are merged.
pub fn read_stl(path: &Path) -> Result<TriMesh, GeometryError> {
    let bytes = std::fs::read(path).map_err(|e| file_error(path, e.to_string()))?;
    parse_stl(&bytes, path)
}

/// Reads ASCII or binary STL bytes (`path` names them in errors). Nothing is
/// allocated ahead of what the bytes hold: a binary header claiming billions of
/// facets ends in an error at the end of the bytes.
pub fn parse_stl(bytes: &[u8], path: &Path) -> Result<TriMesh, GeometryError> {
    let mesh = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| {
        let claim = match bytes.get(80..84) {
            Some(n) => {
                let n = u32::from_le_bytes(n.try_into().expect("4 bytes")) as u64;
                format!(
                    "; read as binary, its header claims {n} facets ({} bytes), and it holds {}",
                    84 + 50 * n,
                    bytes.len()
                )
            }
            None => String::new(),
        };
        file_error(path, format!("not a valid STL file: {e}{claim}"))
    })?;
    if mesh.faces.is_empty() {
        return Err(file_error(path, "the STL file holds no facets"));
    }
    let vertices = mesh
        .vertices
        .iter()
        .map(|v| Point3::new(v[0] as Real, v[1] as Real, v[2] as Real))
        .collect();
    let triangles = mesh.faces.iter().map(|f| f.vertices).collect();
    TriMesh::new(vertices, triangles).map_err(|e| in_file(path, e))
}

/// Reads the vertices (`v`) and faces (`f`, fan-triangulated) of a Wavefront OBJ file.
pub fn read_obj(path: &Path) -> Result<TriMesh, GeometryError> {
    let text = std::fs::read_to_string(path).map_err(|e| file_error(path, e.to_string()))?;
    parse_obj(&text, path)
}

/// Reads OBJ text (`path` names it in errors).
pub fn parse_obj(text: &str, path: &Path) -> Result<TriMesh, GeometryError> {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (line_no, line) in text.lines().enumerate() {
        let line_no = line_no + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Vec<Real> = words
                    .take(3)
                    .map(|w| w.parse::<Real>())
                    .collect::<Result<_, _>>()
                    .map_err(|e| {
                        file_error(path, format!("line {line_no}: bad vertex coordinate: {e}"))
                    })?;
                if coords.len() != 3 {
                    return Err(file_error(
                        path,
                        format!("line {line_no}: a vertex needs 3 coordinates"),
                    ));
                }
                vertices.push(Point3::new(coords[0], coords[1], coords[2]));
            }
            Some("f") => {
                let mut ids = Vec::new();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| {
                        file_error(path, format!("line {line_no}: bad face index '{w}'"))
                    })?;
                    let index = if i > 0 {
                        i - 1
                    } else if i < 0 {
                        vertices.len() as i64 + i
                    } else {
                        -1
                    };
                    if index < 0 || index as usize >= vertices.len() {
                        return Err(file_error(
                            path,
                            format!(
                                "line {line_no}: face index {i} does not name a vertex defined before it"
                            ),
                        ));
                    }
                    ids.push(index as usize);
                }
                if ids.len() < 3 {
                    return Err(file_error(
                        path,
                        format!("line {line_no}: a face needs at least 3 vertices"),
                    ));
                }
                for k in 1..ids.len() - 1 {
                    triangles.push([ids[0], ids[k], ids[k + 1]]);
                }
            }
            _ => {}
        }
    }
    if triangles.is_empty() {
        return Err(file_error(path, "the OBJ file holds no faces"));
    }
    TriMesh::new(vertices, triangles).map_err(|e| in_file(path, e))
}

fn in_file(path: &Path, e: GeometryError) -> GeometryError {
    GeometryError::InFile {
        path: path.to_path_buf(),
        source: Box::new(e),
    }
}

/// Loads a particle template from a mesh file. A closed convex mesh is used as it is;
/// anything else is an error naming the facet, edge or vertex at fault, unless
/// `options.convex_hull` asks for the hull of its vertices.
pub fn load_particle(
    path: &Path,
    options: ParticleMeshOptions,
) -> Result<ConvexPolyhedron, GeometryError> {
    if !(options.scale.is_finite() && options.scale > 0.0) {
        return Err(GeometryError::InvalidParameter {
            name: "scale",
            value: options.scale,
            reason: "must be a positive finite number",
        });
    }
    let mut mesh = read_mesh(path)?;
    for v in &mut mesh.vertices {
        *v *= options.scale;
    }
    let result = if options.convex_hull {
        convex_hull(&mesh.vertices).and_then(|hull| ConvexPolyhedron::from_convex_mesh(&hull))
    } else {
        ConvexPolyhedron::from_convex_mesh(&mesh)
    };
    result.map_err(|e| in_file(path, e))
}

/// Writes a triangle mesh as a binary STL file.
pub fn write_stl(
    path: &Path,
    vertices: &[Point3<Real>],
    triangles: &[[usize; 3]],
) -> std::io::Result<()> {
    let tris: Vec<stl_io::Triangle> = triangles
        .iter()
        .map(|t| {
            let p = |i: usize| {
                stl_io::Vertex::new([
                    vertices[i].x as f32,
                    vertices[i].y as f32,
                    vertices[i].z as f32,
                ])
            };
            let n = (vertices[t[1]] - vertices[t[0]])
                .cross(&(vertices[t[2]] - vertices[t[0]]))
                .normalize();
            stl_io::Triangle {
                normal: stl_io::Normal::new([n.x as f32, n.y as f32, n.z as f32]),
                vertices: [p(t[0]), p(t[1]), p(t[2])],
            }
        })
        .collect();
    let mut file = std::io::BufWriter::new(File::create(path)?);
    stl_io::write_stl(&mut file, tris.iter())
}
