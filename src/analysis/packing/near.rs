//! Pairs of particles whose bounding spheres come within a distance of each other:
//! a cell grid on the centres finds the candidates.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};

use crate::Real;

/// The pairs `(i, j)`, `i < j`, of `centres` whose spheres of radius `reach[i]` and
/// `reach[j]` are within `within` of each other, in order of `i`, then `j`.
pub(super) fn near_pairs(
    centres: &[Point3<Real>],
    reach: &[Real],
    within: Real,
) -> Vec<(usize, usize)> {
    let cell = 2.0 * reach.iter().copied().fold(0.0, Real::max) + within;
    let key = |x: &Point3<Real>| (x / cell).coords.map(|c| c.floor() as i64);
    let mut grid: HashMap<Vector3<i64>, Vec<usize>> = HashMap::new();
    for (i, x) in centres.iter().enumerate() {
        grid.entry(key(x)).or_default().push(i);
    }
    let mut pairs = Vec::new();
    for (i, x) in centres.iter().enumerate() {
        let k = key(x);
        let mut near: Vec<usize> = Vec::new();
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&(k + Vector3::new(dx, dy, dz))) {
                        near.extend(list.iter().copied().filter(|&j| j > i));
                    }
                }
            }
        }
        near.sort_unstable();
        pairs.extend(
            near.into_iter()
                .filter(|&j| (centres[j] - x).norm() <= reach[i] + reach[j] + within)
                .map(|j| (i, j)),
        );
    }
    pairs
}
