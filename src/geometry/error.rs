//! Errors raised while building or loading shapes.

use std::path::PathBuf;

/// Why a shape could not be built.
///
/// Every variant names the offending element (vertex, facet, edge, line) so that a
/// user can find it in their mesh.
#[derive(Debug, thiserror::Error)]
pub enum GeometryError {
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFiniteVertex {
        /// Index of the vertex in the input.
        vertex: usize,
        /// Its coordinates.
        x: f64,
        /// Its coordinates.
        y: f64,
        /// Its coordinates.
        z: f64,
    },
    /// A facet refers to a vertex that does not exist.
    #[error("facet {facet} refers to vertex {vertex}, but there are only {count} vertices")]
    BadVertexIndex {
        /// Facet index.
        facet: usize,
        /// The index it uses.
        vertex: usize,
        /// Number of vertices.
        count: usize,
    },
    /// All points lie in one plane (or on a line, or coincide): no volume.
    #[error("the {count} points do not span a volume (fewer than 4 non-coplanar points)")]
    Degenerate {
        /// Number of input points.
        count: usize,
    },
    /// Round-off made the hull inconsistent (points spread over many orders of
    /// magnitude, such as one vertex kilometres from the rest).
    #[error(
        "the convex hull of the {count} points cannot be built in floating point: point {point} \
         sees a face whose neighbour across an edge was lost (are the coordinates spread over \
         many orders of magnitude?)"
    )]
    HullRoundOff {
        /// Number of points.
        count: usize,
        /// The point being added.
        point: usize,
    },
    /// A half-space cut would leave nothing of a polytope.
    #[error("cutting the {count}-vertex polytope by a plane leaves nothing of it")]
    CutAway {
        /// Number of vertices before the cut.
        count: usize,
    },
    /// The faces left by a half-space cut do not leave one loop open for the new
    /// face (round-off in a cut through many vertices at once).
    #[error("cutting the {count}-vertex polytope by a plane leaves no single open loop to close")]
    CutRoundOff {
        /// Number of vertices with the cut's crossing points.
        count: usize,
    },
    /// A facet has (almost) no area.
    #[error("facet {facet} has zero area (vertices {a}, {b}, {c})")]
    ZeroAreaFacet {
        /// Facet index.
        facet: usize,
        /// Its vertex indices.
        a: usize,
        /// Its vertex indices.
        b: usize,
        /// Its vertex indices.
        c: usize,
    },
    /// Two distinct vertices lie (almost) on top of each other.
    #[error("vertices {a} and {b} nearly coincide (distance {distance:.3e}); merge them")]
    DuplicateVertex {
        /// First vertex.
        a: usize,
        /// Second vertex.
        b: usize,
        /// Distance between them.
        distance: f64,
    },
    /// The mesh has a hole: an edge bounds only one facet.
    #[error("mesh is not closed: edge ({a}, {b}) borders only facet {facet}")]
    OpenEdge {
        /// Edge end vertex.
        a: usize,
        /// Edge end vertex.
        b: usize,
        /// The one facet that uses it.
        facet: usize,
    },
    /// More than two facets meet at one edge.
    #[error("mesh is not a manifold: edge ({a}, {b}) borders {count} facets")]
    NonManifoldEdge {
        /// Edge end vertex.
        a: usize,
        /// Edge end vertex.
        b: usize,
        /// How many facets share it.
        count: usize,
    },
    /// Two neighbouring facets are wound in the same direction.
    #[error("facets {f1} and {f2} have inconsistent orientation across edge ({a}, {b})")]
    InconsistentOrientation {
        /// First facet.
        f1: usize,
        /// Second facet.
        f2: usize,
        /// Edge end vertex.
        a: usize,
        /// Edge end vertex.
        b: usize,
    },
    /// The mesh is closed but not convex.
    #[error(
        "mesh is not convex: vertex {vertex} lies {distance:.3e} in front of the plane of facet {facet} \
         (ask for its convex hull explicitly to use the hull instead)"
    )]
    NotConvex {
        /// The vertex outside.
        vertex: usize,
        /// The facet whose plane it violates.
        facet: usize,
        /// How far outside.
        distance: f64,
    },
    /// A generator got a parameter out of range.
    #[error("invalid shape parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A mesh file could not be read.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong (with a line number where one is known).
        message: String,
    },
    /// A mesh file is valid but its content is not a usable particle.
    #[error("{path}: {source}")]
    InFile {
        /// The file.
        path: PathBuf,
        /// The underlying problem.
        source: Box<GeometryError>,
    },
}
