//! Broad phase: candidate particle pairs whose bounding spheres overlap.
//!
//! # Method
//! Particles are binned on uniform cell grids by a counting sort (cell index per
//! particle, per-cell counts, an exclusive prefix sum to cell starts, a scatter), with
//! their positions and radii copied in cell order, and the candidate pairs are
//! written to one flat array: the particles, in cell order, each look through half
//! the 27-cell stencil about them (every pair of neighbouring cells is searched from
//! one side only; the cells read as runs along x), in parallel over runs of
//! particles whose pairs are appended in order, so the output order does not
//! depend on the number of threads.
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

use std::ops::{Range, RangeInclusive};

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

    #[inline]
    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Positions in `sorted` of the particles in the cells `x` of row `(y, z)`:
    /// neighbours along x are neighbours in the cell order, so a row's cells are
    /// one run.
    #[inline]
    fn row(&self, x: &RangeInclusive<usize>, y: usize, z: usize) -> Range<usize> {
        let (first, last) = (self.index([*x.start(), y, z]), self.index([*x.end(), y, z]));
        self.starts[first] as usize..self.starts[last + 1] as usize
    }

    /// The cells along axis `k` next to and at `c[k]`, within the grid.
    #[inline]
    fn around(&self, c: &[usize; 3], k: usize) -> RangeInclusive<usize> {
        c[k].saturating_sub(1)..=(c[k] + 1).min(self.dims[k] - 1)
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
                    this.visit_partners(level, m, skin, &mut out);
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

    /// Appends to `out` the pair `[i, j]` (`i < j`) of the particle `i` at `m` in the
    /// cell order of level `own` with each of its partners `j` (see
    /// [`Self::find_pairs`]): in its own level, the partners in its own cell after it
    /// and in the 13 neighbour cells of the forward half of the stencil (each pair of
    /// a level is found once, from one of its two cells); in every coarser level, all
    /// partners in the 27 cells about it.
    ///
    /// The cells are read row by row along x, each row one run of the cell order: the
    /// 13 forward cells in five runs (the rest of its own cell with the next cell
    /// along x, the row `y + 1`, the three rows of `z + 1`), the 27 in nine. Cell by
    /// cell, each cell's lookup and bounds cost about as much as the two or three
    /// particles it holds in a bed of spheres. Each member of a run is written to
    /// `out`, and the end moves past it only if it is a partner: a branch on that,
    /// about a coin toss, was mispredicted often. The search of the pour's list
    /// builds (5000 spheres, one thread) took 1.0–1.1 ms cell by cell, 0.56–0.62 by
    /// rows, 0.53–0.58 by rows without the branch (2026-12-08).
    fn visit_partners(&self, own: usize, m: usize, skin: Real, out: &mut Vec<[u32; 2]>) {
        let grid = &self.levels[own];
        let (p, r, i) = (grid.positions[m], grid.radii[m], grid.sorted[m]);
        let mut visit = |grid: &GridLevel, members: Range<usize>| {
            let mut end = out.len();
            out.resize(end + members.len(), [0; 2]);
            for k in members {
                let (j, reach) = (grid.sorted[k], r + grid.radii[k] + skin);
                out[end] = [i.min(j), i.max(j)];
                end += usize::from((grid.positions[k] - p).norm_squared() < reach * reach);
            }
            out.truncate(end);
        };
        let c = grid.coords(&p, &self.origin);
        let xs = grid.around(&c, 0);
        visit(grid, m + 1..grid.row(&(c[0]..=*xs.end()), c[1], c[2]).end);
        if c[1] + 1 < grid.dims[1] {
            visit(grid, grid.row(&xs, c[1] + 1, c[2]));
        }
        if c[2] + 1 < grid.dims[2] {
            for y in grid.around(&c, 1) {
                visit(grid, grid.row(&xs, y, c[2] + 1));
            }
        }
        for grid in &self.levels[..own] {
            let c = grid.coords(&p, &self.origin);
            let xs = grid.around(&c, 0);
            for z in grid.around(&c, 2) {
                for y in grid.around(&c, 1) {
                    visit(grid, grid.row(&xs, y, z));
                }
            }
        }
    }
}
