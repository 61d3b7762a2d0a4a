//! Triangulated walls and the grid that finds their facets near a point.

use nalgebra::{Isometry3, Point3, Translation3, Vector3};

use super::motion::{WallMotion, WallVelocity, advance_pose};
use crate::Real;

/// A rigid triangulated wall. Its mesh is stored in the wall's own frame; `pose` places
/// that frame in the world, so a rigidly moving wall never rebuilds its facet grid.
#[derive(Clone, Debug)]
pub struct Wall {
    /// Name, for output and co-simulation variables.
    pub name: String,
    /// Index into the world's materials.
    pub material: usize,
    /// Vertices in the wall frame.
    pub vertices: Vec<Point3<Real>>,
    /// Facets, counter-clockwise seen from the side particles are on.
    pub triangles: Vec<[u32; 3]>,
    /// Wall frame in the world.
    pub pose: Isometry3<Real>,
    /// Linear velocity of the wall frame's origin.
    pub velocity: Vector3<Real>,
    /// Angular velocity of the wall (world frame).
    pub angular_velocity: Vector3<Real>,
    /// Facet lookup in the wall frame.
    pub grid: FacetGrid,
    /// Force the particles exert on the wall in the current step.
    pub force: Vector3<Real>,
    /// Torque the particles exert about the wall frame's origin.
    pub torque: Vector3<Real>,
    /// Force on each facet in the current step (a patch's force shared by the
    /// facets' overlap volumes).
    pub facet_force: Vec<Vector3<Real>>,
    /// How the wall moves.
    pub motion: WallMotion,
}

impl Wall {
    /// A static wall from a mesh given in world coordinates; `cell` sizes the facet grid
    /// (about the largest particle diameter).
    pub fn new(
        name: &str,
        material: usize,
        vertices: Vec<Point3<Real>>,
        triangles: Vec<[u32; 3]>,
        cell: Real,
    ) -> Self {
        let grid = FacetGrid::new(&vertices, &triangles, cell);
        let n_facets = triangles.len();
        Wall {
            name: name.to_string(),
            material,
            vertices,
            triangles,
            pose: Isometry3::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            grid,
            force: Vector3::zeros(),
            torque: Vector3::zeros(),
            facet_force: vec![Vector3::zeros(); n_facets],
            motion: WallMotion::Fixed,
        }
    }

    /// Puts the wall's reference point (its frame origin, about which torque is
    /// reported and rotation happens) at the world point `reference`; the mesh stays
    /// where it is.
    pub fn with_reference(mut self, reference: Point3<Real>) -> Self {
        let shift = Isometry3::from_parts(Translation3::from(reference.coords), self.pose.rotation);
        let to_new = shift.inverse() * self.pose;
        for v in &mut self.vertices {
            *v = to_new * *v;
        }
        self.pose = shift;
        self.grid = FacetGrid::new(&self.vertices, &self.triangles, self.grid.cell);
        self
    }

    /// Sets the wall's motion (and its velocities at time 0).
    pub fn with_motion(mut self, motion: WallMotion) -> Self {
        self.motion = motion;
        self.set_velocity_at(0.0);
        self
    }

    /// The wall's reference point in the world.
    pub fn reference(&self) -> Point3<Real> {
        Point3::from(self.pose.translation.vector)
    }

    /// Sets the velocities the motion prescribes at time `t` (external motion keeps
    /// what was set).
    pub fn set_velocity_at(&mut self, t: Real) {
        if let Some(v) = self.motion.velocity(t) {
            self.velocity = v.linear;
            self.angular_velocity = v.angular;
        }
    }

    /// Moves the wall from time `t` to `t + dt`: the pose by the velocities at the
    /// middle of the step, and the velocities to their values at the end.
    pub fn advance(&mut self, t: Real, dt: Real) {
        if self.motion.is_fixed() || self.motion.leader().is_some() {
            return;
        }
        let mid = self.motion.velocity(t + 0.5 * dt).unwrap_or(WallVelocity {
            linear: self.velocity,
            angular: self.angular_velocity,
        });
        advance_pose(&mut self.pose, &mid, dt);
        self.set_velocity_at(t + dt);
    }

    /// Facet `f` in world coordinates.
    pub fn facet_world(&self, f: usize) -> [Point3<Real>; 3] {
        self.triangles[f].map(|v| self.pose * self.vertices[v as usize])
    }

    /// Power the wall delivers to the particles: minus the rate of work of the force
    /// and torque they exert on it.
    pub fn power(&self) -> Real {
        -(self.force.dot(&self.velocity) + self.torque.dot(&self.angular_velocity))
    }

    /// Velocity of the wall material at world point `x`.
    pub fn velocity_at(&self, x: &Point3<Real>) -> Vector3<Real> {
        self.velocity + self.angular_velocity.cross(&(x - self.reference()))
    }
}

/// Uniform grid over a wall's facets, in the wall frame: each cell lists the facets
/// whose bounding box meets it.
#[derive(Clone, Debug, Default)]
pub struct FacetGrid {
    origin: Vector3<Real>,
    cell: Real,
    dims: [usize; 3],
    starts: Vec<u32>,
    facets: Vec<u32>,
}

impl FacetGrid {
    /// Builds the grid (cell edge `cell`, coarsened if the mesh is very large).
    pub fn new(vertices: &[Point3<Real>], triangles: &[[u32; 3]], cell: Real) -> Self {
        let (lo, hi) = vertices.iter().fold(
            (
                Vector3::repeat(Real::INFINITY),
                Vector3::repeat(Real::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
        );
        if triangles.is_empty() {
            return FacetGrid::default();
        }
        let mut cell = cell.max(Real::MIN_POSITIVE);
        let count = |cell: Real| (hi - lo).map(|e| (e / cell).floor() + 1.0);
        const MOST: Real = (1 << 22) as Real;
        while count(cell).product() > MOST {
            cell *= 2.0;
        }
        // Each facet is listed in every cell its box covers: a few facets much larger
        // than the cells (a tube kilometres long) must not make billions of entries.
        let covered = |cell: Real| -> Real {
            triangles
                .iter()
                .map(|t| {
                    let pts = t.map(|v| vertices[v as usize].coords);
                    let a = pts[0].inf(&pts[1]).inf(&pts[2]) - lo;
                    let b = pts[0].sup(&pts[1]).sup(&pts[2]) - lo;
                    (0..3)
                        .map(|k| (b[k] / cell).floor() - (a[k] / cell).floor() + 1.0)
                        .product::<Real>()
                })
                .sum()
        };
        while covered(cell) > MOST.max(8.0 * triangles.len() as Real) {
            cell *= 2.0;
        }
        let d = count(cell);
        let dims = [d.x as usize, d.y as usize, d.z as usize];
        let mut grid = FacetGrid {
            origin: lo,
            cell,
            dims,
            starts: vec![0; dims.iter().product::<usize>() + 1],
            facets: Vec::new(),
        };
        let boxes: Vec<([usize; 3], [usize; 3])> = triangles
            .iter()
            .map(|t| {
                let pts = t.map(|v| vertices[v as usize].coords);
                let a = pts[0].inf(&pts[1]).inf(&pts[2]);
                let b = pts[0].sup(&pts[1]).sup(&pts[2]);
                (grid.coords(&a), grid.coords(&b))
            })
            .collect();
        for (a, b) in &boxes {
            grid.for_cells(*a, *b, |c, starts| starts[c + 1] += 1);
        }
        for c in 0..grid.starts.len() - 1 {
            grid.starts[c + 1] += grid.starts[c];
        }
        let mut fill = grid.starts.clone();
        grid.facets = vec![0; *grid.starts.last().unwrap_or(&0) as usize];
        for (f, (a, b)) in boxes.iter().enumerate() {
            let mut cells = Vec::new();
            grid.for_cells(*a, *b, |c, _| cells.push(c));
            for c in cells {
                grid.facets[fill[c] as usize] = f as u32;
                fill[c] += 1;
            }
        }
        grid
    }

    /// The grid's lowest corner, in the wall frame.
    pub fn origin(&self) -> Vector3<Real> {
        self.origin
    }

    /// The cells' edge.
    pub fn cell(&self) -> Real {
        self.cell
    }

    /// The cells along x, y and z (none for a wall without facets).
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Per cell (x fastest, then y, then z) where its facets begin in
    /// [`Self::entries`], and last their count (empty for a wall without facets).
    pub fn cell_starts(&self) -> &[u32] {
        &self.starts
    }

    /// The cells' facets, each cell's ascending.
    pub fn entries(&self) -> &[u32] {
        &self.facets
    }

    fn coords(&self, p: &Vector3<Real>) -> [usize; 3] {
        let mut c = [0; 3];
        for k in 0..3 {
            let x = ((p[k] - self.origin[k]) / self.cell).floor();
            c[k] = (x.max(0.0) as usize).min(self.dims[k] - 1);
        }
        c
    }

    fn for_cells(&mut self, a: [usize; 3], b: [usize; 3], mut f: impl FnMut(usize, &mut Vec<u32>)) {
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    let c = (z * self.dims[1] + y) * self.dims[0] + x;
                    f(c, &mut self.starts);
                }
            }
        }
    }

    /// Facets whose bounding boxes may meet the ball (`centre`, `radius`) given in the
    /// wall frame, sorted and without repeats.
    pub fn query(&self, centre: &Point3<Real>, radius: Real, out: &mut Vec<u32>) {
        out.clear();
        if self.dims == [0; 3] {
            return;
        }
        let lo = centre.coords - Vector3::repeat(radius);
        let hi = centre.coords + Vector3::repeat(radius);
        // Entirely outside the mesh's box: nothing.
        let top = self.origin + Vector3::from(self.dims.map(|d| d as Real)) * self.cell;
        if (0..3).any(|k| hi[k] < self.origin[k] || lo[k] > top[k]) {
            return;
        }
        let (a, b) = (self.coords(&lo), self.coords(&hi));
        // Row by row along x: a row's cells are one run of the cell order (cell by
        // cell, each cell's lookup cost more than its few facets).
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                let row = (z * self.dims[1] + y) * self.dims[0];
                let (first, end) = (self.starts[row + a[0]], self.starts[row + b[0] + 1]);
                out.extend_from_slice(&self.facets[first as usize..end as usize]);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    use super::*;

    /// A query returns, sorted and once each, every facet whose box meets the
    /// ball's box, and no facet whose box lies more than a cell from it (the grid's
    /// resolution).
    #[test]
    fn a_query_finds_the_facets_whose_boxes_meet_the_balls() {
        let mut rng = Pcg64::seed_from_u64(3);
        let mut point =
            |scale: Real| Point3::from(Vector3::from_fn(|_, _| rng.random_range(0.0..scale)));
        // Small facets scattered in a 1 m box, and a few large ones across it.
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..300 {
            let size = if k % 50 == 0 { 0.8 } else { 0.03 };
            let a = point(1.0);
            let (b, c) = (a + point(size).coords, a + point(size).coords);
            let first = vertices.len() as u32;
            vertices.extend([a, b, c]);
            triangles.push([first, first + 1, first + 2]);
        }
        let grid = FacetGrid::new(&vertices, &triangles, 0.02);
        let boxes: Vec<(Vector3<Real>, Vector3<Real>)> = triangles
            .iter()
            .map(|t| {
                let p = t.map(|v| vertices[v as usize].coords);
                (p[0].inf(&p[1]).inf(&p[2]), p[0].sup(&p[1]).sup(&p[2]))
            })
            .collect();
        let apart = |(lo, hi): &(Vector3<Real>, Vector3<Real>), c: &Vector3<Real>, r: Real| {
            (0..3).any(|k| hi[k] < c[k] - r || lo[k] > c[k] + r)
        };
        let mut found = Vec::new();
        let mut met = 0;
        for _ in 0..500 {
            let centre = point(1.1).coords - Vector3::repeat(0.05);
            let radius = 0.007;
            grid.query(&Point3::from(centre), radius, &mut found);
            assert!(found.windows(2).all(|w| w[0] < w[1]), "sorted, once each");
            for (f, b) in boxes.iter().enumerate() {
                if !apart(b, &centre, radius) {
                    met += 1;
                    assert!(found.contains(&(f as u32)), "facet {f} at {centre:?}");
                }
            }
            for &f in &found {
                let b = &boxes[f as usize];
                assert!(
                    !apart(b, &centre, radius + grid.cell()),
                    "facet {f} too far"
                );
            }
        }
        assert!(met > 100, "the balls meet facets ({met})");
    }
}
