//! Loading particle meshes: valid STL (ASCII, binary) and OBJ files load; every kind
//! of bad mesh gets an error that names the problem and where it is.

use std::path::PathBuf;

use nalgebra::Point3;
use talus::geometry::GeometryError;
use talus::geometry::generators;
use talus::geometry::mesh_io::{ParticleMeshOptions, load_particle, read_mesh, write_stl};

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("talus-mesh-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// An OBJ cube of edge 2 centred at the origin, with faces as quads (1-based).
const CUBE_OBJ: &str = "\
# cube
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
";

fn write(name: &str, text: &str) -> PathBuf {
    let p = temp(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn load(path: &std::path::Path) -> Result<talus::geometry::ConvexPolyhedron, GeometryError> {
    load_particle(path, ParticleMeshOptions::default())
}

#[test]
fn obj_cube_loads() {
    let p = load(&write("cube.obj", CUBE_OBJ)).unwrap();
    assert!((p.volume() - 8.0).abs() < 1e-14);
    assert_eq!(p.face_count(), 6);
    // Scaled from mm to m.
    let p = load_particle(
        &write("cube_mm.obj", CUBE_OBJ),
        ParticleMeshOptions {
            convex_hull: false,
            scale: 1e-3,
        },
    )
    .unwrap();
    assert!((p.volume() - 8e-9).abs() < 1e-20);
}

#[test]
fn binary_and_ascii_stl_load() {
    let d = generators::dodecahedron(0.01).unwrap();
    let tris: Vec<[usize; 3]> = d
        .triangles()
        .iter()
        .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
        .collect();
    let path = temp("dodeca.stl");
    write_stl(&path, d.vertices(), &tris).unwrap();
    let back = load(&path).unwrap();
    assert_eq!(back.face_count(), 12);
    // f32 storage: volume right to single precision.
    assert!((back.volume() - d.volume()).abs() < 1e-6 * d.volume());

    let ascii = "solid t\n\
facet normal 0 0 -1\n outer loop\n vertex 0 0 0\n vertex 0 1 0\n vertex 1 0 0\n endloop\nendfacet\n\
facet normal 0 -1 0\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 0 1\n endloop\nendfacet\n\
facet normal -1 0 0\n outer loop\n vertex 0 0 0\n vertex 0 0 1\n vertex 0 1 0\n endloop\nendfacet\n\
facet normal 1 1 1\n outer loop\n vertex 1 0 0\n vertex 0 1 0\n vertex 0 0 1\n endloop\nendfacet\n\
endsolid t\n";
    let tet = load(&write("tet.stl", ascii)).unwrap();
    assert!((tet.volume() - 1.0 / 6.0).abs() < 1e-7);
}

#[test]
fn open_mesh_names_the_edge() {
    let text = CUBE_OBJ.replace("f 4 1 5 8\n", "");
    let err = load(&write("open.obj", &text)).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(&err, GeometryError::InFile { source, .. } if matches!(**source, GeometryError::OpenEdge { .. })),
        "{msg}"
    );
    assert!(
        msg.contains("open.obj") && msg.contains("not closed") && msg.contains("edge"),
        "{msg}"
    );
}

#[test]
fn non_convex_mesh_is_rejected_unless_the_hull_is_asked_for() {
    // Push the top face's centre down: a cube with a dent (top face as 4 triangles).
    let text = CUBE_OBJ.replace(
        "f 5 6 7 8\n",
        "v 0 0 0.5\nf 5 6 9\nf 6 7 9\nf 7 8 9\nf 8 5 9\n",
    );
    let path = write("dent.obj", &text);
    let err = load(&path).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("not convex") && msg.contains("vertex") && msg.contains("facet"),
        "{msg}"
    );
    let hull = load_particle(
        &path,
        ParticleMeshOptions {
            convex_hull: true,
            scale: 1.0,
        },
    )
    .unwrap();
    assert!((hull.volume() - 8.0).abs() < 1e-12);
}

#[test]
fn inconsistent_orientation_is_named() {
    let text = CUBE_OBJ.replace("f 5 6 7 8\n", "f 8 7 6 5\n");
    let msg = load(&write("flip.obj", &text)).unwrap_err().to_string();
    assert!(msg.contains("inconsistent orientation"), "{msg}");
}

#[test]
fn inside_out_mesh_is_flipped() {
    let mut text = String::new();
    for line in CUBE_OBJ.lines() {
        if let Some(rest) = line.strip_prefix("f ") {
            let mut ids: Vec<&str> = rest.split_whitespace().collect();
            ids.reverse();
            text.push_str(&format!("f {}\n", ids.join(" ")));
        } else {
            text.push_str(line);
            text.push('\n');
        }
    }
    let p = load(&write("inside_out.obj", &text)).unwrap();
    assert!((p.volume() - 8.0).abs() < 1e-14);
}

#[test]
fn non_finite_coordinates() {
    let text = CUBE_OBJ.replace("v 1 1 1\n", "v 1 NaN 1\n");
    let msg = load(&write("nan.obj", &text)).unwrap_err().to_string();
    assert!(
        msg.contains("non-finite") && msg.contains("vertex 6"),
        "{msg}"
    );
}

#[test]
fn duplicate_vertices() {
    // Vertex 9 repeats vertex 7; faces use both.
    let text = CUBE_OBJ.replace("f 3 4 8 7\n", "v 1 1 1\nf 3 4 8 9\n");
    let msg = load(&write("dup.obj", &text)).unwrap_err().to_string();
    assert!(msg.contains("vertices 6 and 8 nearly coincide"), "{msg}");
}

#[test]
fn zero_area_facet() {
    let text = CUBE_OBJ.to_string() + "f 1 2 2\n";
    let msg = load(&write("zero.obj", &text)).unwrap_err().to_string();
    assert!(
        msg.contains("zero area") && msg.contains("facet 12"),
        "{msg}"
    );
}

#[test]
fn coplanar_points_are_degenerate() {
    let pts: Vec<Point3<f64>> = (0..10)
        .map(|k| Point3::new(k as f64, (k * k) as f64, 0.0))
        .collect();
    let err = talus::geometry::ConvexPolyhedron::from_hull(&pts).unwrap_err();
    assert!(err.to_string().contains("do not span a volume"), "{err}");
    let three: Vec<Point3<f64>> = pts[..3].to_vec();
    assert!(talus::geometry::ConvexPolyhedron::from_hull(&three).is_err());
}

#[test]
fn file_level_errors_name_the_line() {
    let msg = read_mesh(&write(
        "bad_index.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n",
    ))
    .unwrap_err()
    .to_string();
    assert!(msg.contains("line 4") && msg.contains("index 7"), "{msg}");
    let msg = read_mesh(&write("bad_coord.obj", "v 0 0 zero\n"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("line 1"), "{msg}");
    let msg = read_mesh(&write("garbage.stl", "this is not an stl"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("garbage.stl"), "{msg}");
    let msg = read_mesh(&temp("missing.obj")).unwrap_err().to_string();
    assert!(msg.contains("missing.obj"), "{msg}");
    let msg = read_mesh(&write("shape.ply", "ply"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("unknown mesh format"), "{msg}");
}

#[test]
fn non_manifold_edge() {
    // Two tetrahedra sharing one edge (0-1) with a third facet fan: three facets on it.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 -1 0\nv 0 0 -1\n\
f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 2 5\nf 1 6 2\nf 1 5 6\nf 2 6 5\n";
    let msg = load(&write("nonmanifold.obj", text))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("not a manifold") || msg.contains("inconsistent orientation"),
        "{msg}"
    );
}
