//! Broad phase: candidate particle pairs whose bounding spheres overlap.
//!
//! # Method
//! Particles are binned on uniform cell grids by a counting sort (cell index per
//! particle, per-cell counts, an exclusive prefix sum to cell starts, a scatter), with
//! their positions and radii copied in cell order, and the candidate pairs are
//! written to one flat array: the particles, in cell order, each look through half
//! the 27-cell stencil about them (every pair of neighbouring cells is searched from
//! one side only), in parallel over runs of particles whose pairs are appended in
//! order, so the output order does not depend on the number of threads.
//!
//! # Wide size distributions
//! One grid sized for the largest particle would put hundreds of small ones in a cell
//! when sizes differ tenfold. Particles are therefore split into levels by bounding
//! radius, each level halving the radius of the one above and having a grid of its own
//! with cells of the level's largest diameter (plus the skin). A particle looks for
//! partners in its own level (partners of higher index only) and in every coarser
//! level (all partners: each cross-level pair is found once, from its smaller member).
//! The cost per particle stays bounded by the crowding of its own size class, as in
//! the hierarchical grids of the triangle-based DEM draft.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use crate::Real;

/// One level of the grid hierarchy.
#[derive(Clone, Debug, Default)]
struct GridLevel {
    /// Edge length of a cell.
    cell: Real,
    /// Number of cells along x, y, z.
    dims: [usize; 3],
    /// Particles of this level, ordered by cell.
    sorted: Vec<u32>,
    /// Their positions and bounding radii in the same order, so that a stencil's
    /// cells are read from contiguous memory.
    positions: Vec<Point3<Real>>,
    radii: Vec<Real>,
    /// `sorted[starts[c]..starts[c + 1]]` are the particles in cell `c`.
    starts: Vec<u32>,
}

impl GridLevel {
    /// Integer coordinates of the cell holding `p` (clamped into the grid).
    ///
    /// The conversion truncates a coordinate already clamped to be positive, which
    /// is its floor (a call to `floor` per coordinate where the target lacks SSE4.1).
    #[inline]
    fn coords(&self, p: &Point3<Real>, origin: &Vector3<Real>) -> [usize; 3] {
        let mut c = [0; 3];
        for k in 0..3 {
            let x = (p[k] - origin[k]) / self.cell;
            c[k] = (x.max(0.0) as usize).min(self.dims[k] - 1);
        }
        c
    }

    /// Positions in `sorted` of the particles in cell `cell`.
    #[inline]
    fn members(&self, cell: usize) -> std::ops::Range<usize> {
        self.starts[cell] as usize..self.starts[cell + 1] as usize
    }

    #[inline]
    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }
}

/// Reusable state of the broad phase (grids and pair offsets).
#[derive(Clone, Debug, Default)]
pub struct BroadPhase {
    levels: Vec<GridLevel>,
    level_of: Vec<u8>,
    origin: Vector3<Real>,
}

/// Smallest run of particles one rayon task takes.
const PARTICLES_PER_TASK: usize = 256;

/// Most levels in the hierarchy (radius ratio up to 2^16).
const MAX_LEVELS: usize = 16;

impl BroadPhase {
    /// All pairs `[i, j]` (`i < j`) with `|x_i − x_j| < r_i + r_j + skin`, written to
    /// `pairs` grouped by the particle that found them (levels from the coarsest,
    /// particles in cell order), in an order that does not depend on the number of
    /// threads.
    pub fn find_pairs(
        &mut self,
        positions: &[Point3<Real>],
        radii: &[Real],
        skin: Real,
        pairs: &mut Vec<[u32; 2]>,
    ) {
        pairs.clear();
        let n = positions.len();
        if n < 2 {
            return;
        }
        self.build(positions, radii, skin);
        // Each level's particles in cell order look for their partners, in parallel
        // over contiguous runs whose pairs are appended in order: the output does not
        // depend on how the runs were split among threads.
        let this = &*self;
        for (level, grid) in self.levels.iter().enumerate() {
            let runs: Vec<Vec<[u32; 2]>> = (0..grid.sorted.len())
                .into_par_iter()
                .with_min_len(PARTICLES_PER_TASK)
                .fold(Vec::new, |mut out, m| {
                    let i = grid.sorted[m] as usize;
                    this.visit_partners(level, m, skin, |j| {
                        out.push([i.min(j) as u32, i.max(j) as u32]);
                    });
                    out
                })
                .collect();
            for run in runs {
                pairs.extend_from_slice(&run);
            }
        }
    }

    /// Bins the particles on the level grids (counting sort per level).
    fn build(&mut self, positions: &[Point3<Real>], radii: &[Real], skin: Real) {
        let r_max = radii
            .iter()
            .copied()
            .fold(0.0, Real::max)
            .max(Real::MIN_POSITIVE);
        self.level_of.clear();
        self.level_of.extend(radii.iter().map(|&r| {
            let ratio = r_max / r.max(Real::MIN_POSITIVE);
            (ratio.log2().floor().max(0.0) as usize).min(MAX_LEVELS - 1) as u8
        }));
        let used = *self.level_of.iter().max().unwrap_or(&0) as usize + 1;
        // The box of the finite positions: a particle that went non-finite (a blown-up
        // state, reported by the caller after the step) is binned into a corner cell,
        // never sizing the grid.
        let (lo, hi) = positions
            .iter()
            .filter(|p| p.coords.iter().all(|x| x.is_finite()))
            .fold(
                (
                    Vector3::repeat(Real::INFINITY),
                    Vector3::repeat(Real::NEG_INFINITY),
                ),
                |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
            );
        let (lo, hi) = if lo.x <= hi.x {
            (lo, hi)
        } else {
            (Vector3::zeros(), Vector3::zeros())
        };
        self.origin = lo;
        let extent = hi - lo;
        // A sparse scene must not allocate a huge grid: coarsen until the cell count is
        // bounded by a multiple of the particle count.
        let cap = (8 * positions.len()).max(1 << 12) as Real;
        self.levels.resize_with(used, GridLevel::default);
        for (level, grid) in self.levels.iter_mut().enumerate() {
            grid.cell = 2.0 * r_max / (1u64 << level) as Real + skin;
            let cells_along = |cell: Real| extent.map(|e| (e / cell).floor() + 1.0);
            while cells_along(grid.cell).product() > cap {
                grid.cell *= 2.0;
            }
            let d = cells_along(grid.cell);
            grid.dims = [d.x, d.y, d.z].map(|x| (x as usize).max(1));
            let cells = grid.dims.iter().product::<usize>();
            grid.starts.clear();
            grid.starts.resize(cells + 1, 0);
            let level_of = &self.level_of;
            let members = (0..positions.len()).filter(|&i| level_of[i] as usize == level);
            for i in members.clone() {
                let c = grid.index(grid.coords(&positions[i], &lo));
                grid.starts[c + 1] += 1;
            }
            for c in 0..cells {
                grid.starts[c + 1] += grid.starts[c];
            }
            grid.sorted.clear();
            grid.sorted.resize(grid.starts[cells] as usize, 0);
            let mut fill = grid.starts.clone();
            for i in members {
                let c = grid.index(grid.coords(&positions[i], &lo));
                grid.sorted[fill[c] as usize] = i as u32;
                fill[c] += 1;
            }
            grid.positions.clear();
            grid.positions
                .extend(grid.sorted.iter().map(|&i| positions[i as usize]));
            grid.radii.clear();
            grid.radii
                .extend(grid.sorted.iter().map(|&i| radii[i as usize]));
        }
    }

    /// Calls `found(j)` for every partner `j` of the particle at `m` in the cell order
    /// of level `own` (see [`Self::find_pairs`]): in its own level, the partners in
    /// its own cell after it and in the 13 neighbour cells of the forward half of the
    /// stencil (each pair of a level is found once, from one of its two cells); in
    /// every coarser level, all partners in the 27 cells about it.
    fn visit_partners(&self, own: usize, m: usize, skin: Real, mut found: impl FnMut(usize)) {
        let grid = &self.levels[own];
        let (p, r) = (grid.positions[m], grid.radii[m]);
        let mut visit = |grid: &GridLevel, members: std::ops::Range<usize>| {
            for k in members {
                let reach = r + grid.radii[k] + skin;
                if (grid.positions[k] - p).norm_squared() < reach * reach {
                    found(grid.sorted[k] as usize);
                }
            }
        };
        let c = grid.coords(&p, &self.origin);
        let cell = grid.index(c);
        visit(grid, m + 1..grid.members(cell).end);
        for [dx, dy, dz] in FORWARD {
            let neighbour = [c[0] as isize + dx, c[1] as isize + dy, c[2] as isize + dz];
            if (0..3).all(|k| (0..grid.dims[k] as isize).contains(&neighbour[k])) {
                let cell = grid.index(neighbour.map(|x| x as usize));
                visit(grid, grid.members(cell));
            }
        }
        for grid in &self.levels[..own] {
            let c = grid.coords(&p, &self.origin);
            let range = |k: usize| c[k].saturating_sub(1)..=(c[k] + 1).min(grid.dims[k] - 1);
            for z in range(2) {
                for y in range(1) {
                    for x in range(0) {
                        let cell = grid.index([x, y, z]);
                        visit(grid, grid.members(cell));
                    }
                }
            }
        }
    }
}

/// The 13 neighbour cells of the forward half of a 27-cell stencil: the offsets that
/// come after `(0, 0, 0)` in the order `(z, y, x)`.
const FORWARD: [[isize; 3]; 13] = [
    [1, 0, 0],
    [-1, 1, 0],
    [0, 1, 0],
    [1, 1, 0],
    [-1, -1, 1],
    [0, -1, 1],
    [1, -1, 1],
    [-1, 0, 1],
    [0, 0, 1],
    [1, 0, 1],
    [-1, 1, 1],
    [0, 1, 1],
    [1, 1, 1],
];
