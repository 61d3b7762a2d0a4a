//! The figures of the owned particles computed on the device (`kernels/figures.cu`),
//! so that a rank whose particles live on a GPU reduces the whole run's figures
//! every step without copying its particles back.

use nalgebra::{Point3, Vector3};

use super::DeviceWorld;
use crate::Real;
use crate::engine::cuda::Kernel;
use crate::engine::cuda::device::{Arg, Array, DeviceError};
use crate::engine::cuda::device_list::run;
use crate::engine::cuda::device_sums::{Fold, RowSums};
use crate::world::{MassMoments, RunFigures};

/// Doubles of a particle's record of sums and of extrema (`kernels/figures.cu`).
const SUMS: usize = 8;
const EXTREMA: usize = 8;
/// No extremum (`LOWEST_DOUBLE` in `kernels/figures.cu`).
const LOWEST: Real = Real::MIN;

/// The scratch of the figures: the two folds and the one record read back.
#[derive(Debug, Default)]
pub(super) struct FigureSums {
    sums: RowSums,
    extrema: RowSums,
    out: Array<Real>,
}

impl FigureSums {
    /// Device memory held, bytes.
    pub(super) fn bytes(&self, device: &dyn crate::engine::cuda::device::Device) -> usize {
        self.sums.bytes(device) + self.extrema.bytes(device) + self.out.bytes(device)
    }
}

impl DeviceWorld {
    /// The figures of the owned particles ([`RunFigures::of`] of the host world
    /// the particles would be copied to; the sums in a tree, round-off apart from
    /// its serial sums, the extrema and counts exact).
    pub fn particle_figures(&mut self) -> Result<RunFigures, DeviceError> {
        let (d, p, t, f) = (
            self.device.as_mut(),
            &self.particles,
            &self.types,
            &mut self.figures,
        );
        let n = self.n;
        f.out.resize(d, SUMS + EXTREMA)?;
        let sums = f.sums.rows(d, n, SUMS)?;
        let extrema = f.extrema.rows(d, n, EXTREMA)?;
        let g = self.gravity;
        // SAFETY: the parameters of particle_figures (figures.cu): the particles'
        // arrays hold n, the rows n records each.
        unsafe {
            run(
                d,
                Kernel::ParticleFigures,
                n,
                &[
                    Arg::U32(n as u32),
                    p.role.arg(),
                    p.body_type.arg(),
                    t.mass.arg(),
                    t.inertia.arg(),
                    Arg::F64(g.x),
                    Arg::F64(g.y),
                    Arg::F64(g.z),
                    p.position.arg(),
                    p.orientation.arg(),
                    p.velocity.arg(),
                    p.angular_momentum.arg(),
                    p.force.arg(),
                    p.torque.arg(),
                    p.id.arg(),
                    sums.arg(),
                    extrema.arg(),
                ],
            )?;
        }
        f.sums.fold(d, n, SUMS, &f.out, 0)?;
        let max = Fold::Max { lowest: LOWEST };
        f.extrema.fold_by(max, d, n, EXTREMA, &f.out, SUMS)?;
        let r = f.out.read(d)?;
        let (s, e) = r.split_at(SUMS);
        let or = |x: Real, none: Real| if x > LOWEST { x } else { none };
        Ok(RunFigures {
            particles: s[0] as usize,
            frozen: s[1] as usize,
            moments: MassMoments {
                mass: s[2],
                first: Vector3::new(s[3], s[4], s[5]),
            },
            kinetic: s[6],
            potential: s[7],
            max_speed: or(e[0], 0.0),
            upper: Point3::new(
                or(e[1], Real::NEG_INFINITY),
                or(e[2], Real::NEG_INFINITY),
                or(e[3], Real::NEG_INFINITY),
            ),
            lower: Point3::new(
                -or(e[4], Real::NEG_INFINITY),
                -or(e[5], Real::NEG_INFINITY),
                -or(e[6], Real::NEG_INFINITY),
            ),
            non_finite: (e[7] > LOWEST).then(|| (-e[7]) as u64),
        })
    }
}
