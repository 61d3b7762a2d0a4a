//! Broad phase: candidate particle pairs whose bounding spheres overlap.
//!
//! # Method
//! Particles are binned on uniform cell grids by a counting sort (cell index per
//! particle, per-cell counts, an exclusive prefix sum to cell starts, a scatter), and
//! the candidate pairs are written to one flat array: a first pass counts each
//! particle's pairs, a prefix sum turns the counts into offsets, and a second pass
//! writes every particle's pairs into its own slice (the contact-pair
//! parallelism). Both passes are data-parallel over particles and the output order
//! does not depend on the number of threads.
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
    /// `sorted[starts[c]..starts[c + 1]]` are the particles in cell `c`.
    starts: Vec<u32>,
}

impl GridLevel {
    /// Integer coordinates of the cell holding `p` (clamped into the grid).
    #[inline]
    fn coords(&self, p: &Point3<Real>, origin: &Vector3<Real>) -> [usize; 3] {
        let mut c = [0; 3];
        for k in 0..3 {
            let x = ((p[k] - origin[k]) / self.cell).floor();
            c[k] = (x.max(0.0) as usize).min(self.dims[k] - 1);
        }
        c
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
    counts: Vec<u32>,
}

/// Most levels in the hierarchy (radius ratio up to 2^16).
const MAX_LEVELS: usize = 16;

impl BroadPhase {
    /// All pairs `[i, j]` (`i < j`) with `|x_i − x_j| < r_i + r_j + skin`, written to
    /// `pairs` grouped by the particle that found them (the smaller member; the lower
    /// index within a size class), in an order that does not depend on the number of
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
        let mut counts = std::mem::take(&mut self.counts);
        let this = &*self;
        counts.clear();
        counts.par_extend((0..n).into_par_iter().map(|i| {
            let mut k = 0u32;
            this.visit_partners(i, positions, radii, skin, |_| k += 1);
            k
        }));
        let total: usize = counts.iter().map(|&k| k as usize).sum();
        pairs.resize(total, [0, 0]);
        // One output slice per particle, sized by its count (the prefix sum), filled in
        // parallel.
        let mut slices: Vec<&mut [[u32; 2]]> = Vec::with_capacity(n);
        let mut rest: &mut [[u32; 2]] = pairs;
        for &k in &counts {
            let (head, tail) = rest.split_at_mut(k as usize);
            slices.push(head);
            rest = tail;
        }
        slices.into_par_iter().enumerate().for_each(|(i, out)| {
            let mut k = 0;
            this.visit_partners(i, positions, radii, skin, |j| {
                out[k] = [i.min(j) as u32, i.max(j) as u32];
                k += 1;
            });
        });
        self.counts = counts;
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
        }
    }

    /// Calls `found(j)` for every partner `j` of particle `i` (see [`Self::find_pairs`]).
    fn visit_partners(
        &self,
        i: usize,
        positions: &[Point3<Real>],
        radii: &[Real],
        skin: Real,
        mut found: impl FnMut(usize),
    ) {
        let own = self.level_of[i] as usize;
        let p = positions[i];
        for level in 0..=own {
            let grid = &self.levels[level];
            let c = grid.coords(&p, &self.origin);
            let range = |k: usize| c[k].saturating_sub(1)..=(c[k] + 1).min(grid.dims[k] - 1);
            for z in range(2) {
                for y in range(1) {
                    for x in range(0) {
                        let cell = grid.index([x, y, z]);
                        let members = grid.starts[cell] as usize..grid.starts[cell + 1] as usize;
                        for &j in &grid.sorted[members] {
                            let j = j as usize;
                            if level == own && j <= i {
                                continue;
                            }
                            let reach = radii[i] + radii[j] + skin;
                            if (positions[j] - p).norm_squared() < reach * reach {
                                found(j);
                            }
                        }
                    }
                }
            }
        }
    }
}
