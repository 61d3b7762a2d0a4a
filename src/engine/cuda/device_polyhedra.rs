//! Convex polyhedra on a device (`kernels/overlap.cuh`, `kernels/facet.cuh`,
//! `kernels/polyhedra.cu`): a table of shapes in flat arrays, the narrow phase of
//! polyhedron pairs, one thread per pair, each the exact overlap of its two shapes
//! at its relative pose, and the overlap of a shape with the prism under a wall
//! facet, one thread per query.
//!
//! The kernel takes the bit-mask path of [`crate::geometry::overlap`] afresh at
//! every call: it keeps no plan or topology between calls, so where the CPU
//! evaluates a kept topology the two answers differ by round-off (the tests bound
//! it), and where the CPU clips the faces (touching and flush configurations) they
//! are the same operations in the same order.

use nalgebra::{Point3, Vector3};

use super::Kernel;
use super::device::{Arg, Array, Device, DeviceError};
use crate::Real;
use crate::geometry::overlap::OverlapGeometry;
use crate::geometry::wall::FacetOverlap;
use crate::geometry::{ConvexPolyhedron, Pose};

/// Most faces, and most vertices, of a shape the device takes (`MASK_FACES`,
/// `MASK_VERTICES` of overlap.cuh): its vertex sets are 64-bit masks.
pub const MAX_SHAPE_PARTS: usize = 64;
/// Doubles of an overlap's record (`OVERLAP_DOUBLES` of overlap.cuh).
const RECORD: usize = 15;
/// Doubles of a facet overlap's record (`FACET_DOUBLES` of facet.cuh).
const FACET_RECORD: usize = 15;
/// Doubles of a pose of B in A (`POSE_DOUBLES` of polyhedra.cu).
const POSE: usize = 7;

/// Why a set of shapes cannot go to the device.
#[derive(Debug, thiserror::Error)]
pub enum ShapeTableError {
    /// A shape beyond the kernels' bit masks.
    #[error(
        "shape {index} has {vertices} vertices and {faces} faces: the CUDA backend takes convex \
         polyhedra of at most {MAX_SHAPE_PARTS} vertices and {MAX_SHAPE_PARTS} faces"
    )]
    TooLarge {
        /// The shape's index in the set.
        index: usize,
        /// Its vertex count.
        vertices: usize,
        /// Its face count.
        faces: usize,
    },
    /// The device failed.
    #[error(transparent)]
    Device(#[from] DeviceError),
}

/// Convex polyhedra in device memory, each in its body frame (centroid at the
/// origin), as `ShapeTable` of overlap.cuh reads them.
///
/// # Invariant
/// Every shape has at most [`MAX_SHAPE_PARTS`] vertices and faces; `index` holds
/// four words per shape (first vertex, vertex count, first face, face count) that
/// lie within `vertices` and `planes`, `face_masks` and `face_span`.
#[derive(Debug, Default)]
pub struct DeviceShapes {
    index: Array<u32>,
    /// Per face: its first entry of `loops`, its vertex count.
    face_span: Array<u32>,
    loops: Array<u32>,
    face_masks: Array<u64>,
    vertices: Array<Real>,
    planes: Array<Real>,
    circumradius: Array<Real>,
    count: usize,
}

/// The host side of [`DeviceShapes`], built shape by shape.
#[derive(Default)]
struct HostShapes {
    index: Vec<u32>,
    face_span: Vec<u32>,
    loops: Vec<u32>,
    face_masks: Vec<u64>,
    vertices: Vec<Real>,
    planes: Vec<Real>,
    circumradius: Vec<Real>,
}

/// The vertex and face counts of `shape` where either is beyond the kernels' bit
/// masks ([`MAX_SHAPE_PARTS`]).
pub fn beyond_masks(shape: &ConvexPolyhedron) -> Option<(usize, usize)> {
    let (vertices, faces) = (shape.vertices().len(), shape.face_count());
    (vertices > MAX_SHAPE_PARTS || faces > MAX_SHAPE_PARTS).then_some((vertices, faces))
}

impl HostShapes {
    fn push(&mut self, index: usize, shape: &ConvexPolyhedron) -> Result<(), ShapeTableError> {
        if let Some((vertices, faces)) = beyond_masks(shape) {
            return Err(ShapeTableError::TooLarge {
                index,
                vertices,
                faces,
            });
        }
        let (vertices, faces) = (shape.vertices().len(), shape.face_count());
        let word = |n: usize| n as u32;
        self.index.extend([
            word(self.vertices.len() / 3),
            word(vertices),
            word(self.planes.len() / 4),
            word(faces),
        ]);
        for p in shape.vertices() {
            self.vertices.extend(p.coords.iter());
        }
        for (f, plane) in shape.planes().iter().enumerate() {
            self.planes.extend(plane.normal.iter());
            self.planes.push(plane.offset);
            let face = shape.face(f);
            self.face_span
                .extend([word(self.loops.len()), word(face.len())]);
            self.loops.extend_from_slice(face);
            // At most 64 vertices: the low half holds the whole set.
            self.face_masks.push(shape.face_vertex_masks()[f] as u64);
        }
        self.circumradius.push(shape.circumradius());
        Ok(())
    }
}

impl DeviceShapes {
    /// Uploads `shapes`; shape `k` is addressed by `k` in the pairs of
    /// [`Self::overlaps`].
    pub fn upload(
        device: &mut dyn Device,
        shapes: &[&ConvexPolyhedron],
    ) -> Result<Self, ShapeTableError> {
        let mut host = HostShapes::default();
        for (k, shape) in shapes.iter().enumerate() {
            host.push(k, shape)?;
        }
        let mut table = DeviceShapes {
            count: shapes.len(),
            ..Default::default()
        };
        table.index.write(device, &host.index)?;
        table.face_span.write(device, &host.face_span)?;
        table.loops.write(device, &host.loops)?;
        table.face_masks.write(device, &host.face_masks)?;
        table.vertices.write(device, &host.vertices)?;
        table.planes.write(device, &host.planes)?;
        table.circumradius.write(device, &host.circumradius)?;
        Ok(table)
    }

    /// Bytes of device memory held.
    pub fn bytes(&self, device: &dyn Device) -> usize {
        let words = [&self.index, &self.face_span, &self.loops];
        let doubles = [&self.vertices, &self.planes, &self.circumradius];
        words.iter().map(|a| a.bytes(device)).sum::<usize>()
            + doubles.iter().map(|a| a.bytes(device)).sum::<usize>()
            + self.face_masks.bytes(device)
    }

    /// How many shapes it holds.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether it holds no shape.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The table as the first launch arguments of a kernel that reads shapes.
    pub(super) fn args(&self) -> [Arg; 7] {
        [
            self.index.arg(),
            self.face_span.arg(),
            self.loops.arg(),
            self.face_masks.arg(),
            self.vertices.arg(),
            self.planes.arg(),
            self.circumradius.arg(),
        ]
    }
}

/// The per-pair arrays of the narrow phase of polyhedra on a device, kept from call
/// to call (a buffer grows, and is reused while it has room).
#[derive(Debug, Default)]
pub struct PolyhedronPairs {
    /// Two shape indices per pair.
    shapes: Array<u32>,
    /// A pose of B in A per pair (`POSE` doubles).
    poses: Array<Real>,
    /// An overlap's record per pair (`RECORD` doubles).
    records: Array<Real>,
    host: Vec<Real>,
}

impl PolyhedronPairs {
    /// The overlap of each pair `(a, b)` of `pairs` (indices into `table`) with B at
    /// pose `poses[k]` in A's frame, as [`crate::geometry::overlap::overlap`] gives
    /// it: `None` where they do not overlap or only touch.
    ///
    /// # Panics
    /// When `pairs` and `poses` differ in length or a pair names a shape beyond
    /// the table.
    pub fn overlaps(
        &mut self,
        device: &mut dyn Device,
        table: &DeviceShapes,
        pairs: &[(u32, u32)],
        poses: &[Pose],
    ) -> Result<Vec<Option<OverlapGeometry>>, DeviceError> {
        assert_eq!(pairs.len(), poses.len(), "a pose per pair");
        assert!(
            pairs
                .iter()
                .all(|&(a, b)| (a.max(b) as usize) < table.len()),
            "pairs of the table's shapes"
        );
        if pairs.is_empty() {
            return Ok(Vec::new());
        }
        let shapes: Vec<u32> = pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
        self.host.clear();
        self.host.reserve(POSE * poses.len());
        for pose in poses {
            let q = pose.rotation.quaternion();
            self.host.extend(pose.translation.vector.iter());
            self.host.extend([q.w, q.i, q.j, q.k]);
        }
        self.shapes.write(device, &shapes)?;
        self.poses.write(device, &self.host)?;
        self.records.resize(device, RECORD * pairs.len())?;
        let mut args = vec![Arg::U32(pairs.len() as u32)];
        args.extend(table.args());
        args.extend([self.shapes.arg(), self.poses.arg(), self.records.arg()]);
        // SAFETY: the table's invariant; two shapes and a pose per pair, a record
        // written per pair.
        unsafe { device.launch(Kernel::PolyhedronOverlaps, pairs.len(), &args)? };
        self.records.read_into(device, &mut self.host)?;
        Ok(self
            .host
            .chunks_exact(RECORD)
            .map(overlap_of_record)
            .collect())
    }
}

/// The per-query arrays of the polyhedra's wall-facet overlaps on a device, kept
/// from call to call.
#[derive(Debug, Default)]
pub struct FacetQueries {
    shapes: Array<u32>,
    /// Three vertices per query.
    triangles: Array<Real>,
    records: Array<Real>,
    host: Vec<Real>,
}

impl FacetQueries {
    /// The overlap of each shape `queries[k].0` (an index into `table`) with the
    /// prism under the triangle `queries[k].1` (in the shape's body frame), as
    /// [`crate::geometry::wall::polyhedron_triangle`] gives it.
    ///
    /// # Panics
    /// When a query names a shape beyond the table.
    pub fn overlaps(
        &mut self,
        device: &mut dyn Device,
        table: &DeviceShapes,
        queries: &[(u32, [Point3<Real>; 3])],
    ) -> Result<Vec<Option<FacetOverlap>>, DeviceError> {
        assert!(
            queries.iter().all(|&(s, _)| (s as usize) < table.len()),
            "queries of the table's shapes"
        );
        if queries.is_empty() {
            return Ok(Vec::new());
        }
        let shapes: Vec<u32> = queries.iter().map(|q| q.0).collect();
        self.host.clear();
        for (_, tri) in queries {
            self.host
                .extend(tri.iter().flat_map(|p| p.coords.iter().copied()));
        }
        self.shapes.write(device, &shapes)?;
        self.triangles.write(device, &self.host)?;
        self.records.resize(device, FACET_RECORD * queries.len())?;
        let mut args = vec![Arg::U32(queries.len() as u32)];
        args.extend(table.args());
        args.extend([self.shapes.arg(), self.triangles.arg(), self.records.arg()]);
        // SAFETY: the table's invariant; a shape and a triangle per query, a record
        // written per query.
        unsafe { device.launch(Kernel::PolyhedronFacets, queries.len(), &args)? };
        self.records.read_into(device, &mut self.host)?;
        let v = |r: &[Real], k: usize| Vector3::new(r[k], r[k + 1], r[k + 2]);
        Ok(self
            .host
            .chunks_exact(FACET_RECORD)
            .map(|r| {
                (r[0] > 0.0).then(|| FacetOverlap {
                    volume: r[0],
                    centroid: Point3::from(v(r, 1)),
                    volume_gradient: v(r, 4),
                    rotation_gradient: v(r, 7),
                    depth: r[10],
                    section_area: r[11],
                    facet_normal: v(r, 12),
                })
            })
            .collect())
    }
}

/// The overlap a record holds (`polyhedron_overlap` of overlap.cuh).
fn overlap_of_record(r: &[Real]) -> Option<OverlapGeometry> {
    let v = |k: usize| Vector3::new(r[k], r[k + 1], r[k + 2]);
    (r[0] > 0.0).then(|| OverlapGeometry {
        volume: r[0],
        centroid: Point3::from(v(1)),
        normal: v(4),
        area: r[7],
        depth: r[8],
        rotation_gradient_a: v(9),
        rotation_gradient_b: v(12),
    })
}
