//! A time-averaged field of particle velocities on a square grid over a drum's
//! cross-section, and the flowing-layer thickness read from it.

use super::surface::SurfaceFit;
use crate::Real;

/// Sums of particle velocities per cell of an `n × n` grid covering `[−R, R]²` in
/// cross-section coordinates `(h, v)` about the axis (cells of edge `cell`).
/// Invariant: `count`, `volume` and the velocity sums have `n²` entries, row `j`
/// (height) after row `j − 1`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct VelocityField {
    /// Drum radius, m.
    pub radius: Real,
    /// Cell edge, m.
    pub cell: Real,
    /// Cells per side.
    pub n: usize,
    /// Samples taken.
    pub samples: usize,
    count: Vec<u64>,
    volume: Vec<Real>,
    sum_h: Vec<Real>,
    sum_v: Vec<Real>,
}

/// The averaged values of one cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellMean {
    /// Cell centre (h, v), m.
    pub centre: [Real; 2],
    /// Particle centres counted in the cell over all samples.
    pub count: u64,
    /// Mean velocity of the particles counted (h and v components), m/s.
    pub velocity: [Real; 2],
    /// Particle volume per sample, m³ (divide by the cell's volume for the solid
    /// fraction).
    pub volume: Real,
}

impl VelocityField {
    /// An empty field.
    pub fn new(radius: Real, cell: Real) -> Self {
        let n = ((2.0 * radius / cell).ceil() as usize).max(1);
        VelocityField {
            radius,
            cell,
            n,
            samples: 0,
            count: vec![0; n * n],
            volume: vec![0.0; n * n],
            sum_h: vec![0.0; n * n],
            sum_v: vec![0.0; n * n],
        }
    }

    fn index(&self, p: [Real; 2]) -> Option<usize> {
        let i = ((p[0] + self.radius) / self.cell).floor();
        let j = ((p[1] + self.radius) / self.cell).floor();
        let n = self.n as Real;
        (i >= 0.0 && j >= 0.0 && i < n && j < n).then(|| j as usize * self.n + i as usize)
    }

    /// Adds one sample: particle centres `(h, v)`, velocities `(u_h, u_v)` and
    /// volumes.
    pub fn add_sample(&mut self, particles: &[([Real; 2], [Real; 2], Real)]) {
        for (p, u, vol) in particles {
            if let Some(k) = self.index(*p) {
                self.count[k] += 1;
                self.volume[k] += vol;
                self.sum_h[k] += u[0];
                self.sum_v[k] += u[1];
            }
        }
        self.samples += 1;
    }

    /// The mean of cell `(i, j)` (`i` across, `j` up).
    pub fn cell(&self, i: usize, j: usize) -> CellMean {
        let k = j * self.n + i;
        let c = self.count[k].max(1) as Real;
        CellMean {
            centre: [
                -self.radius + (i as Real + 0.5) * self.cell,
                -self.radius + (j as Real + 0.5) * self.cell,
            ],
            count: self.count[k],
            velocity: [self.sum_h[k] / c, self.sum_v[k] / c],
            volume: self.volume[k] / self.samples.max(1) as Real,
        }
    }

    /// Every cell, row by row from the bottom.
    pub fn cells(&self) -> impl Iterator<Item = CellMean> + '_ {
        (0..self.n).flat_map(move |j| (0..self.n).map(move |i| self.cell(i, j)))
    }

    /// The mean velocity at point `p`, if its cell saw particles in at least a
    /// tenth of the samples.
    pub fn velocity_at(&self, p: [Real; 2]) -> Option<[Real; 2]> {
        let k = self.index(p)?;
        let enough = (self.samples as u64).div_ceil(10).max(1);
        (self.count[k] >= enough).then(|| {
            let c = self.count[k] as Real;
            [self.sum_h[k] / c, self.sum_v[k] / c]
        })
    }

    /// Depth of the flowing layer below the mean free surface `surface`: along the
    /// surface's normal through the point above the axis, the distance from the
    /// surface to where the velocity along the surface turns from downhill
    /// (the flowing layer) to uphill (the bed carried up by the drum), linearly
    /// interpolated between points a quarter cell apart. `None` when the profile
    /// has no such turn.
    pub fn flowing_layer(&self, surface: &SurfaceFit) -> Option<Real> {
        let norm = (1.0 + surface.slope * surface.slope).sqrt();
        // Downhill along the surface, and the surface's upward normal.
        let sign = if surface.slope > 0.0 { -1.0 } else { 1.0 };
        let down = [sign / norm, sign * surface.slope / norm];
        let up = [-surface.slope / norm, 1.0 / norm];
        let foot = [0.0, surface.intercept];
        let step = 0.25 * self.cell;
        let mut previous: Option<(Real, Real)> = None;
        let mut seen_flow = false;
        let mut s = 0.0;
        while s <= 2.0 * self.radius {
            let p = [foot[0] - s * up[0], foot[1] - s * up[1]];
            if let Some(u) = self.velocity_at(p) {
                let along = u[0] * down[0] + u[1] * down[1];
                if along > 0.0 {
                    seen_flow = true;
                } else if seen_flow {
                    let (s0, a0) = previous.expect("flow was seen before");
                    return Some(s0 + (s - s0) * a0 / (a0 - along));
                }
                previous = Some((s, along));
            }
            s += step;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_solid_body_rotation_is_averaged_exactly() {
        let mut field = VelocityField::new(0.1, 0.01);
        let omega = 2.0;
        // Two samples of particles at cell centres turning with ω about the axis.
        for _ in 0..2 {
            let mut ps = Vec::new();
            for j in 0..field.n {
                for i in 0..field.n {
                    let c = field.cell(i, j).centre;
                    ps.push((c, [-omega * c[1], omega * c[0]], 1e-6));
                }
            }
            field.add_sample(&ps);
        }
        for cell in field.cells() {
            let c = cell.centre;
            assert_eq!(cell.count, 2);
            assert!((cell.velocity[0] + omega * c[1]).abs() < 1e-15);
            assert!((cell.velocity[1] - omega * c[0]).abs() < 1e-15);
            assert!((cell.volume - 1e-6).abs() < 1e-21);
        }
    }

    #[test]
    fn the_flowing_layer_ends_where_the_flow_turns() {
        // A flat surface at v = 0.02 with a layer flowing downhill (−h, since the
        // slope is 0 the sign convention takes +h as downhill) 3 cm deep above a bed
        // in solid-body rotation: u_h = a (v − v0) with v0 = 0.02 − 0.03.
        let mut field = VelocityField::new(0.1, 0.002);
        let mut ps = Vec::new();
        for j in 0..field.n {
            for i in 0..field.n {
                let c = field.cell(i, j).centre;
                if c[1] < 0.02 {
                    ps.push((c, [5.0 * (c[1] + 0.01), 0.0], 1e-6));
                }
            }
        }
        field.add_sample(&ps);
        let surface = SurfaceFit {
            slope: 0.0,
            intercept: 0.02,
            points: 10,
        };
        let depth = field.flowing_layer(&surface).expect("a turn");
        // Cell-centre values: the zero lies within half a cell of 3 cm.
        assert!((depth - 0.03).abs() <= 0.5 * field.cell + 1e-12, "{depth}");
    }
}
