//! Cells a coupled code gives by their centres and volumes (an unstructured CFD
//! mesh): talus takes them as the Voronoi cells of the centres, so that each point
//! belongs to the cell of its nearest centre, and splits a particle's volume among
//! them exactly ([`crate::geometry::voronoi_volumes`]); the solid fraction of a cell
//! is its share over the volume the coupled code gives. For structured and most
//! hexahedral and polyhedral meshes the Voronoi cell of a centre is the cell itself
//! (a structured grid given by its centres gets the structured grid's shares); the
//! cells at a mesh's boundary take what lies beyond it.

use nalgebra::{Point3, Vector3};
use rstar::RTree;
use rstar::primitives::GeomWithData;

use super::grid::{GridError, MAX_CELLS};
use crate::Real;
use crate::geometry::cell_volumes::placed_faces;
use crate::geometry::voronoi_volumes::{polyhedron_voronoi_volumes, sphere_voronoi_volumes};
use crate::geometry::{Pose, Shape};

type Centre = GeomWithData<[Real; 3], u32>;

/// Cells given by centres and volumes.
///
/// # Invariant
/// At least one cell; centres finite and distinct, volumes positive and finite;
/// `tree` holds every centre with its index (the flat order of the cells).
#[derive(Clone, Debug)]
pub struct GivenCells {
    centres: Vec<Point3<Real>>,
    volumes: Vec<Real>,
    tree: RTree<Centre>,
}

impl PartialEq for GivenCells {
    fn eq(&self, other: &Self) -> bool {
        self.centres == other.centres && self.volumes == other.volumes
    }
}

impl GivenCells {
    /// Cells of `centres` and `volumes` (one each per cell), or why they make none.
    pub fn new(centres: Vec<Point3<Real>>, volumes: Vec<Real>) -> Result<Self, GridError> {
        let cell = |cell: usize, what: String| Err(GridError::Cell { cell, what });
        if centres.is_empty() || centres.len() > MAX_CELLS {
            return Err(GridError::Counts([centres.len(), 1, 1]));
        }
        if centres.len() != volumes.len() {
            return cell(
                centres.len().min(volumes.len()),
                format!("{} centres and {} volumes", centres.len(), volumes.len()),
            );
        }
        if let Some(k) = centres
            .iter()
            .position(|c| !c.coords.iter().all(|x| x.is_finite()))
        {
            return cell(k, "the centre is not finite".into());
        }
        if let Some(k) = volumes.iter().position(|v| !(*v > 0.0 && v.is_finite())) {
            return cell(k, format!("the volume {} is not positive", volumes[k]));
        }
        let mut order: Vec<usize> = (0..centres.len()).collect();
        let key = |k: &usize| centres[*k].coords.into();
        order.sort_by(|a, b| {
            let (p, q): ([Real; 3], [Real; 3]) = (key(a), key(b));
            p.partial_cmp(&q).expect("finite")
        });
        if let Some(w) = order.windows(2).find(|w| centres[w[0]] == centres[w[1]]) {
            return cell(
                w[0].max(w[1]),
                format!("the same centre as cell {}", w[0].min(w[1])),
            );
        }
        let tree = RTree::bulk_load(
            centres
                .iter()
                .enumerate()
                .map(|(k, c)| Centre::new(c.coords.into(), k as u32))
                .collect(),
        );
        Ok(GivenCells {
            centres,
            volumes,
            tree,
        })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.centres.len()
    }

    /// Whether there are no cells (never: see the invariant).
    pub fn is_empty(&self) -> bool {
        self.centres.is_empty()
    }

    /// The volume the coupled code gives for cell `c`.
    pub fn cell_volume(&self, c: usize) -> Real {
        self.volumes[c]
    }

    /// The centre of cell `c`.
    pub fn centre(&self, c: usize) -> Point3<Real> {
        self.centres[c]
    }

    /// The cell whose centre is nearest to `p`.
    pub fn cell_of(&self, p: &Point3<Real>) -> usize {
        self.tree
            .nearest_neighbor(p.coords.into())
            .expect("at least one cell")
            .data as usize
    }

    /// The cells `shape` at `pose` reaches, ascending, with its volume in each.
    pub fn shares(&self, shape: &Shape, pose: &Pose) -> Vec<(u32, Real)> {
        let p = Point3::from(pose.translation.vector);
        let reach = shape.circumradius();
        let nearest = self.cell_of(&p);
        // Every centre nearest to some point within `reach` of p lies within
        // d₀ + 2 reach of p (d₀: the nearest centre's distance).
        let d = (self.centres[nearest] - p).norm() + 2.0 * reach;
        let mut near: Vec<usize> = self
            .tree
            .locate_within_distance(p.coords.into(), d * d)
            .map(|c| c.data as usize)
            .collect();
        near.sort_unstable();
        let a = self.centres[nearest];
        // Wholly on the nearest centre's side of every bisecting plane: one cell.
        let inside = near.iter().filter(|&&k| k != nearest).all(|&k| {
            let n: Vector3<Real> = self.centres[k] - a;
            n.dot(&(p - nalgebra::center(&a, &self.centres[k]))) <= -reach * n.norm()
        });
        if inside {
            return vec![(nearest as u32, shape.volume())];
        }
        let local: Vec<Point3<Real>> = near.iter().map(|&k| self.centres[k]).collect();
        let mut out = Vec::new();
        let push = |k: usize, v: Real| out.push((near[k] as u32, v));
        match shape {
            Shape::Polyhedron(poly) => {
                polyhedron_voronoi_volumes(&placed_faces(poly, pose), &local, push)
            }
            Shape::Sphere(s) => {
                sphere_voronoi_volumes(p, s.radius, &local, push);
            }
        }
        out
    }
}
